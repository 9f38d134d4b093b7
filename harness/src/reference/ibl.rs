//! Monte Carlo reference for image-based lighting, in f64: the full PBR BRDF (the same
//! [`reference::pbr`] the analytic lights are checked against) integrated against the
//! environment image for sampled pixels of the read-back G-buffer, to measure what the split
//! sum and the precomputed maps cost in accuracy.
//!
//! Estimator: multiple importance sampling with the balance heuristic over four strategies,
//! each drawing the same number of directions: the environment's radiance (a 2D table over the
//! equirectangular texels, weighted by `sin(theta)` times the largest `max(R, G, B)` of the
//! texel's 3x3 neighbourhood, which bounds the bilinear lookups), the cosine lobe, the GGX lobe
//! of the base layer and the GGX lobe of the clearcoat. A bright sun is found by the first,
//! sharp reflections by the GGX strategies. Directions come from stratified low-discrepancy sets
//! under seeded random shifts (randomised quasi-Monte Carlo, 8 replicas), so the reference is
//! deterministic and the standard error returned with each estimate is measured from the
//! replicas' spread.

use super::ReferenceError;
use std::f64::consts::PI;

use engine::plan;
use engine::renderer::Frame;
use engine::scene::{EnvironmentImage, LightingModel, Scene};
use glam::DVec3;

use crate::reference::{self, Surface};

/// One pixel's reference.
#[derive(Clone, Debug)]
pub struct PixelReference {
    /// Pixel index in the frame.
    pub index: usize,
    /// The surface there.
    pub surface: Surface,
    /// Exposed radiance the lighting pass should write (IBL only).
    pub radiance: DVec3,
    /// Standard error of `radiance` (per channel).
    pub standard_error: DVec3,
}

/// Environment radiance lookups and importance sampling in world space.
pub struct EnvironmentSampler<'a> {
    image: &'a EnvironmentImage,
    cos_rotation: f64,
    sin_rotation: f64,
    scale: f64,
    /// Cumulative texel weights, row-major, normalised to end at 1.
    cdf: Vec<f64>,
    /// Texel probabilities.
    probability: Vec<f64>,
}

impl<'a> EnvironmentSampler<'a> {
    /// For `image` rotated by `rotation_degrees` about +Y, radiance scaled by `scale`.
    pub fn new(image: &'a EnvironmentImage, rotation_degrees: f64, scale: f64) -> Self {
        let (w, h) = (image.width as usize, image.height as usize);
        let texel_radiance = |x: usize, y: usize| {
            let t = image.texels[y * w + x];
            f64::from(t[0].max(t[1]).max(t[2]).max(0.0))
        };
        let mut weights = Vec::with_capacity(w * h);
        for y in 0..h {
            let sin_theta = (PI * (y as f64 + 0.5) / h as f64).sin();
            for x in 0..w {
                // The largest radiance of the 3x3 neighbourhood: a bilinear lookup anywhere in
                // this texel is bounded by it, so a direction next to a bright sun is never
                // drawn with a tiny pdf and a large radiance (which made rare huge samples).
                let mut r = 0.0f64;
                for dy in -1i64..=1 {
                    let yy = (y as i64 + dy).clamp(0, h as i64 - 1) as usize;
                    for dx in -1i64..=1 {
                        let xx = (x as i64 + dx).rem_euclid(w as i64) as usize;
                        r = r.max(texel_radiance(xx, yy));
                    }
                }
                // A floor keeps every direction reachable by this strategy.
                weights.push((r + 1e-3) * sin_theta);
            }
        }
        let total: f64 = weights.iter().sum();
        let probability: Vec<f64> = weights.iter().map(|w| w / total).collect();
        let mut cdf = Vec::with_capacity(probability.len());
        let mut running = 0.0;
        for p in &probability {
            running += p;
            cdf.push(running);
        }
        let r = rotation_degrees.to_radians();
        Self {
            image,
            cos_rotation: r.cos(),
            sin_rotation: r.sin(),
            scale,
            cdf,
            probability,
        }
    }

    fn world_to_environment(&self, d: DVec3) -> DVec3 {
        let (c, s) = (self.cos_rotation, self.sin_rotation);
        DVec3::new(c * d.x - s * d.z, d.y, s * d.x + c * d.z)
    }

    fn environment_to_world(&self, e: DVec3) -> DVec3 {
        let (c, s) = (self.cos_rotation, self.sin_rotation);
        DVec3::new(c * e.x + s * e.z, e.y, -s * e.x + c * e.z)
    }

    fn uv(e: DVec3) -> (f64, f64) {
        let u = 0.5 + e.x.atan2(-e.z) / (2.0 * PI);
        (u.rem_euclid(1.0), e.y.clamp(-1.0, 1.0).acos() / PI)
    }

    /// The equirectangular coordinates of world direction `d`, for [`Self::radiance`] and
    /// [`Self::pdf`] (an estimator needs both for each direction: one projection serves).
    pub fn coordinates(&self, d: DVec3) -> (f64, f64) {
        Self::uv(self.world_to_environment(d))
    }

    /// Radiance arriving from the direction at `coordinates` (bilinear, as the skybox reads it).
    pub fn radiance(&self, (u, v): (f64, f64)) -> DVec3 {
        let (w, h) = (self.image.width as i64, self.image.height as i64);
        let fx = u * w as f64 - 0.5;
        let fy = v * h as f64 - 0.5;
        let (x0, y0) = (fx.floor(), fy.floor());
        let (tx, ty) = (fx - x0, fy - y0);
        let mut out = DVec3::ZERO;
        for (dx, dy, weight) in [
            (0, 0, (1.0 - tx) * (1.0 - ty)),
            (1, 0, tx * (1.0 - ty)),
            (0, 1, (1.0 - tx) * ty),
            (1, 1, tx * ty),
        ] {
            let x = (x0 as i64 + dx).rem_euclid(w);
            let y = (y0 as i64 + dy).clamp(0, h - 1);
            let t = self.image.texels[(y * w + x) as usize];
            out += DVec3::new(f64::from(t[0]), f64::from(t[1]), f64::from(t[2])).max(DVec3::ZERO)
                * weight;
        }
        out * self.scale
    }

    /// Solid-angle density of [`Self::sample`] at the direction at `coordinates`.
    pub fn pdf(&self, (u, v): (f64, f64)) -> f64 {
        let (w, h) = (self.image.width as usize, self.image.height as usize);
        let x = ((u * w as f64) as usize).min(w - 1);
        let y = ((v * h as f64) as usize).min(h - 1);
        let sin_theta = (v * PI).sin().max(1e-9);
        self.probability[y * w + x] * (w * h) as f64 / (2.0 * PI * PI * sin_theta)
    }

    /// A world direction drawn in proportion to the texel weights, from uniform `(a, b, c)`.
    pub fn sample(&self, a: f64, b: f64, c: f64) -> DVec3 {
        let (w, h) = (self.image.width as usize, self.image.height as usize);
        let i = self.cdf.partition_point(|&p| p < a).min(w * h - 1);
        let (x, y) = (i % w, i / w);
        let u = (x as f64 + b) / w as f64;
        let v = (y as f64 + c) / h as f64;
        let phi = (u - 0.5) * 2.0 * PI;
        let theta = v * PI;
        // Inverse of uv(): u = 0.5 + atan2(x, -z) / 2pi, v = acos(y) / pi.
        let e = DVec3::new(
            theta.sin() * phi.sin(),
            theta.cos(),
            -theta.sin() * phi.cos(),
        );
        self.environment_to_world(e)
    }
}

/// SplitMix64: a small seeded generator (no global state).
struct Random(u64);

impl Random {
    fn next(&mut self) -> f64 {
        self.0 = self.0.wrapping_add(0x9e37_79b9_7f4a_7c15);
        let mut z = self.0;
        z = (z ^ (z >> 30)).wrapping_mul(0xbf58_476d_1ce4_e5b9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94d0_49bb_1331_11eb);
        ((z ^ (z >> 31)) >> 11) as f64 / (1u64 << 53) as f64
    }
}

fn frame_of(n: DVec3) -> (DVec3, DVec3) {
    let sign = 1f64.copysign(n.z);
    let a = -1.0 / (sign + n.z);
    let b = n.x * n.y * a;
    (
        DVec3::new(1.0 + sign * n.x * n.x * a, sign * b, -sign * n.x),
        DVec3::new(b, sign + n.y * n.y * a, -n.y),
    )
}

/// GGX half-vector sampling of the reflected direction about `n`, whose tangent frame is
/// `(t, bt)` ([`frame_of`]).
fn ggx_sample(n: DVec3, (t, bt): (DVec3, DVec3), v: DVec3, alpha: f64, a: f64, b: f64) -> DVec3 {
    let a2 = alpha * alpha;
    let cos_theta = ((1.0 - a) / (1.0 + (a2 - 1.0) * a)).max(0.0).sqrt();
    let sin_theta = (1.0 - cos_theta * cos_theta).max(0.0).sqrt();
    let phi = 2.0 * PI * b;
    let h = t * (sin_theta * phi.cos()) + bt * (sin_theta * phi.sin()) + n * cos_theta;
    2.0 * v.dot(h) * h - v
}

fn ggx_pdf(n: DVec3, v: DVec3, l: DVec3, alpha: f64) -> f64 {
    let h = (v + l).normalize_or_zero();
    let v_dot_h = v.dot(h);
    if v_dot_h <= 0.0 || n.dot(l) <= 0.0 {
        return 0.0;
    }
    let n_dot_h = n.dot(h).clamp(0.0, 1.0);
    reference::d_ggx(n_dot_h, alpha) * n_dot_h / (4.0 * v_dot_h)
}

/// A cosine-weighted direction about `n`, whose tangent frame is `(t, bt)` ([`frame_of`]).
fn cosine_sample(n: DVec3, (t, bt): (DVec3, DVec3), a: f64, b: f64) -> DVec3 {
    let r = a.sqrt();
    let phi = 2.0 * PI * b;
    t * (r * phi.cos()) + bt * (r * phi.sin()) + n * (1.0 - a).max(0.0).sqrt()
}

/// The IBL radiance of one surface seen from `v`, with its standard error, from
/// `samples_per_strategy` directions per strategy.
pub fn integrate(
    environment: &EnvironmentSampler<'_>,
    s: &Surface,
    v: DVec3,
    samples_per_strategy: usize,
    seed: u64,
) -> (DVec3, DVec3) {
    let n = s.normal;
    let alpha = (s.roughness * s.roughness + 0.001).max(1e-3);
    let coat_alpha = (s.clearcoat_roughness * s.clearcoat_roughness + 0.001).max(1e-3);
    let mut random = Random(seed);
    let strategies = if s.clearcoat > 0.0 { 4 } else { 3 };
    let pdfs = |l: DVec3, coordinates: (f64, f64)| {
        let cosine = (n.dot(l) / PI).max(0.0);
        [
            environment.pdf(coordinates),
            cosine,
            ggx_pdf(n, v, l, alpha),
            if strategies == 4 {
                ggx_pdf(n, v, l, coat_alpha)
            } else {
                0.0
            },
        ]
    };
    // Randomised quasi-Monte Carlo: each strategy's directions come from a stratified
    // low-discrepancy set ((i + 1/2) / n, radical inverses in bases 2 and 3), in REPLICAS
    // independent random shifts (Cranley-Patterson). The estimate is the mean over the
    // replicas of (sum over strategies of the strategy's mean) / K, and its standard error the
    // replicas' spread / sqrt(REPLICAS): an honest error bar for stratified samples.
    let k = strategies as f64;
    let per_replica = (samples_per_strategy / REPLICAS).max(1);
    // The unshifted set is the same for every replica and strategy: computed once.
    let unshifted: Vec<(f64, f64)> = (0..per_replica as u64)
        .map(|i| (radical_inverse(i, 2), radical_inverse(i, 3)))
        .collect();
    let frame = frame_of(n);
    let mut replica_estimates = Vec::with_capacity(REPLICAS);
    for _ in 0..REPLICAS {
        let mut replica = DVec3::ZERO;
        for strategy in 0..strategies {
            let shift = (random.next(), random.next(), random.next());
            let mut sum = DVec3::ZERO;
            for (i, &(base_2, base_3)) in unshifted.iter().enumerate() {
                let a = ((i as f64 + 0.5) / per_replica as f64 + shift.0).fract();
                let b = (base_2 + shift.1).fract();
                let c = (base_3 + shift.2).fract();
                let l = match strategy {
                    0 => environment.sample(a, b, c),
                    1 => cosine_sample(n, frame, b, c),
                    2 => ggx_sample(n, frame, v, alpha, a, b),
                    _ => ggx_sample(n, frame, v, coat_alpha, a, b),
                };
                if n.dot(l) > 0.0 {
                    let coordinates = environment.coordinates(l);
                    let mixture: f64 = pdfs(l, coordinates).iter().sum::<f64>() / k;
                    if mixture > 0.0 {
                        sum +=
                            reference::pbr(s, v, l) * environment.radiance(coordinates) / mixture;
                    }
                }
            }
            replica += sum / per_replica as f64 / k;
        }
        replica_estimates.push(replica);
    }
    let r = REPLICAS as f64;
    let estimate = replica_estimates.iter().copied().sum::<DVec3>() / r;
    let variance = replica_estimates
        .iter()
        .map(|e| (*e - estimate) * (*e - estimate))
        .sum::<DVec3>()
        / (r - 1.0);
    (estimate, (variance / r).powf(0.5))
}

/// Independent random shifts of the low-discrepancy sets (for the error bar).
const REPLICAS: usize = 8;

fn radical_inverse(mut i: u64, base: u64) -> f64 {
    let (mut result, mut scale) = (0.0, 1.0 / base as f64);
    while i > 0 {
        result += (i % base) as f64 * scale;
        i /= base;
        scale /= base as f64;
    }
    result
}

/// The reference for `pixels` sampled pixels of the frame's PBR surfaces (deterministic pick,
/// seeded), each with `samples_per_strategy` directions per strategy.
pub fn reference_pixels(
    scene: &Scene,
    frame: &Frame,
    pixels: usize,
    samples_per_strategy: usize,
) -> Result<Vec<PixelReference>, ReferenceError> {
    let environment = scene
        .environment
        .as_ref()
        .ok_or_else(|| ReferenceError::SceneLacks {
            scene: scene.name.clone(),
            what: "environment".to_owned(),
        })?;
    let gbuffer = crate::reference::lighting::gbuffer_images(frame)?;
    let mask = frame
        .output(plan::TargetId::Mask(0))
        .and_then(|m| m.as_u8())
        .ok_or(ReferenceError::MissingOutput {
            target: plan::TargetId::Mask(0),
            storage: "8-bit",
        })?;
    let channel = frame
        .plan
        .mask_channels
        .iter()
        .find(|c| c.model == LightingModel::Pbr && c.target == 0)
        .ok_or(ReferenceError::NoPixels("PBR pixels"))?
        .channel;
    let covered: Vec<usize> = (0..mask.len() / 4)
        .filter(|i| mask[i * 4 + channel] > 127)
        .collect();
    if covered.is_empty() {
        return Err(ReferenceError::NoPixels("PBR pixels"));
    }
    let sampler = EnvironmentSampler::new(
        &environment.image,
        f64::from(environment.rotation_degrees),
        f64::from(environment.intensity) * f64::from(scene.quality.exposure),
    );
    let step = (covered.len() / pixels.max(1)).max(1);
    let picks: Vec<usize> = covered.iter().step_by(step).copied().take(pixels).collect();
    let results = std::thread::scope(|scope| {
        let chunks: Vec<_> = picks
            .chunks(picks.len().div_ceil(2).max(1))
            .map(|chunk| {
                let sampler = &sampler;
                let gbuffer = &gbuffer;
                scope.spawn(move || {
                    chunk
                        .iter()
                        .map(|&index| {
                            let surface = reference::surface_at(gbuffer, index);
                            let v = (-surface.position)
                                .try_normalize()
                                .unwrap_or(surface.normal);
                            let (radiance, standard_error) =
                                integrate(sampler, &surface, v, samples_per_strategy, index as u64);
                            PixelReference {
                                index,
                                surface,
                                radiance,
                                standard_error,
                            }
                        })
                        .collect::<Vec<_>>()
                })
            })
            .collect();
        chunks
            .into_iter()
            .flat_map(|h| h.join().expect("reference thread panicked"))
            .collect::<Vec<_>>()
    });
    Ok(results)
}

fn light_buffer(frame: &Frame) -> &[f32] {
    frame
        .output(plan::TargetId::Light)
        .and_then(|i| i.as_f32())
        .unwrap_or(&[])
}

/// Relative error (r + g + b) of the light buffer at one reference pixel.
pub fn pixel_error(light: &[f32], r: &PixelReference) -> Option<f64> {
    signed_pixel_error(light, r).map(f64::abs)
}

/// (render - reference) / reference of the sum r + g + b at a reference pixel: positive where
/// the render is too bright.
pub fn signed_pixel_error(light: &[f32], r: &PixelReference) -> Option<f64> {
    let g = light.get(r.index * 4..r.index * 4 + 3)?;
    let expected = r.radiance.element_sum();
    Some((f64::from(g[0] + g[1] + g[2]) - expected) / expected.max(1e-6))
}

/// Relative error (r + g + b) of the light buffer at every reference pixel.
pub fn pixel_errors(frame: &Frame, references: &[PixelReference]) -> Vec<f64> {
    let light = light_buffer(frame);
    references
        .iter()
        .filter_map(|r| pixel_error(light, r))
        .collect()
}

/// Error of the light buffer against the reference, grouped by roughness (rounded to 0.1).
#[derive(Clone, Debug, serde::Serialize)]
pub struct RoughnessError {
    /// Perceptual roughness of the group.
    pub roughness: f64,
    /// Pixels in the group.
    pub pixels: usize,
    /// Mean over pixels of the relative error of the luminance-like sum r + g + b.
    pub mean_relative: f64,
    /// Median relative error (robust to the few grazing pixels where the split sum is worst).
    pub median_relative: f64,
    /// Largest relative error in the group.
    pub max_relative: f64,
    /// Mean relative standard error of the reference itself (its noise).
    pub reference_noise: f64,
}

/// Per-roughness error of `frame`'s light buffer against `references`.
pub fn error_by_roughness(frame: &Frame, references: &[PixelReference]) -> Vec<RoughnessError> {
    let light = light_buffer(frame);
    let mut groups: std::collections::BTreeMap<i64, Vec<(f64, f64)>> = Default::default();
    for r in references {
        let Some(error) = pixel_error(light, r) else {
            continue;
        };
        let noise = r.standard_error.element_sum() / r.radiance.element_sum().max(1e-6);
        groups
            .entry((r.surface.roughness * 10.0).round() as i64)
            .or_default()
            .push((error, noise));
    }
    groups
        .into_iter()
        .map(|(key, values)| RoughnessError {
            roughness: key as f64 / 10.0,
            pixels: values.len(),
            median_relative: engine::stats::median(values.iter().map(|v| v.0).collect())
                .unwrap_or(0.0),
            mean_relative: values.iter().map(|v| v.0).sum::<f64>() / values.len() as f64,
            max_relative: values.iter().map(|v| v.0).fold(0.0, f64::max),
            reference_noise: values.iter().map(|v| v.1).sum::<f64>() / values.len() as f64,
        })
        .collect()
}

/// One cell of [`error_by_family`]: the reference pixels of one material row at one roughness.
#[derive(Clone, Debug, serde::Serialize)]
pub struct CellError {
    /// Perceptual roughness (rounded to 0.1).
    pub roughness: f64,
    /// Mean relative error (r + g + b) over the cell's pixels.
    pub mean: f64,
    /// 95th percentile (nearest rank) of the cell's relative errors.
    pub p95: f64,
    /// Mean signed relative error: positive where the render is brighter than the reference
    /// on average, negative where darker (which way an approximation misses).
    pub bias: f64,
    /// Reference pixels in the cell.
    pub pixels: usize,
}

/// One material row of [`error_by_family`]: the family and its cells, by roughness.
pub type FamilyRow = (String, Vec<CellError>);

/// The material family of a surface, for grouping errors: `anisotropic`, `clearcoat`, `metal`
/// or `dielectric` (first that applies).
pub fn material_family(s: &Surface) -> &'static str {
    if s.anisotropy.abs() > 0.01 {
        "anisotropic"
    } else if s.clearcoat > 0.01 {
        "clearcoat"
    } else if s.metallic > 0.5 {
        "metal"
    } else {
        "dielectric"
    }
}

/// Mean and 95th-percentile relative error (r + g + b) per material family and roughness
/// (rounded to 0.1), as rows of a table: family, then one cell per roughness.
pub fn error_by_family(frame: &Frame, references: &[PixelReference]) -> Vec<FamilyRow> {
    let light = light_buffer(frame);
    let mut groups: std::collections::BTreeMap<(&str, i64), Vec<f64>> = Default::default();
    for r in references {
        let Some(error) = signed_pixel_error(light, r) else {
            continue;
        };
        groups
            .entry((
                material_family(&r.surface),
                (r.surface.roughness * 10.0).round() as i64,
            ))
            .or_default()
            .push(error);
    }
    let mut rows: Vec<FamilyRow> = Vec::new();
    for ((family, key), signed) in groups {
        let count = signed.len() as f64;
        let mut errors: Vec<f64> = signed.iter().map(|e| e.abs()).collect();
        errors.sort_by(f64::total_cmp);
        let cell = CellError {
            roughness: key as f64 / 10.0,
            mean: errors.iter().sum::<f64>() / count,
            p95: engine::stats::percentile_of_sorted(&errors, 0.95),
            bias: signed.iter().sum::<f64>() / count,
            pixels: errors.len(),
        };
        match rows.iter_mut().find(|(f, _)| f == family) {
            Some((_, cells)) => cells.push(cell),
            None => rows.push((family.to_owned(), vec![cell])),
        }
    }
    rows
}

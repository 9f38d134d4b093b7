//! CPU reference of the lighting pass in f64.
//!
//! It evaluates the same lighting models as `lighting.wgsl`, written independently from the
//! formulas (Filament's BRDF for PBR, r2's Blinn-Phong), on the G-buffer read back from the GPU.
//! Feeding both the same G-buffer isolates the lighting pass's arithmetic: what is left is f32
//! against f64 and fp16 storage of the light buffer.
//!
//! Error metric: per channel, `|gpu - ref| / max(|ref|, 1e-3 * max(ref))` over every
//! pixel some lighting model covers; the 99.9th percentile must stay under 2e-3.

use std::f64::consts::PI;

use engine::plan::TargetId;

pub use super::ReferenceError;
use engine::renderer::Frame;
use engine::scene::{Light, LightingModel, Scene};
use engine::Image;
use glam::DVec3;

/// Largest value the lighting pass writes (fp16-safe clamp in `lighting.wgsl`).
const FP16_SAFE_MAX: f64 = 65000.0;

/// The G-buffer at one pixel, in f64.
#[derive(Clone, Copy, Debug)]
pub struct Surface {
    /// Camera-relative position.
    pub position: DVec3,
    /// Perceptual roughness.
    pub roughness: f64,
    /// Unit normal.
    pub normal: DVec3,
    /// Specular.
    pub specular: f64,
    /// Tangent.
    pub tangent: DVec3,
    /// Base color.
    pub base_color: DVec3,
    /// Anisotropy.
    pub anisotropy: f64,
    /// Metallic.
    pub metallic: f64,
    /// Clearcoat strength.
    pub clearcoat: f64,
    /// Clearcoat roughness.
    pub clearcoat_roughness: f64,
    /// Blinn-Phong exponent.
    pub specular_exponent: f64,
}

/// A light as the reference sees it: camera-relative, exposure applied.
#[derive(Clone, Copy, Debug)]
pub enum RefLight {
    /// Direction towards the light and radiance.
    Directional(DVec3, DVec3),
    /// Camera-relative position, radiance, radius, 1 / falloff.
    Point(DVec3, DVec3, f64, f64),
}

/// The scene's lights for the reference, derived here from the scene in f64 (exposure applied,
/// positions relative to the camera), sharing no code with the renderer's uniform packing: a
/// wrong intensity, direction or falloff there shows up as a reference failure. Directional
/// lights are points at infinity: a disc's angular radius (only an extracted sun has one) is
/// not modelled here.
pub fn reference_lights(scene: &Scene) -> Vec<RefLight> {
    let exposure = f64::from(scene.quality.exposure);
    let radiance = |color: &[f32; 3], intensity: f32| {
        DVec3::new(
            f64::from(color[0]),
            f64::from(color[1]),
            f64::from(color[2]),
        ) * f64::from(intensity)
            * exposure
    };
    scene
        .lights
        .iter()
        .map(|light| match light {
            Light::Directional {
                direction,
                color,
                intensity,
                ..
            } => RefLight::Directional(direction.normalize(), radiance(color, *intensity)),
            Light::Point {
                position,
                color,
                intensity,
                radius,
                falloff,
                ..
            } => RefLight::Point(
                *position - scene.camera.position,
                radiance(color, *intensity),
                f64::from(*radius),
                1.0 / f64::from(*falloff),
            ),
        })
        .collect()
}

/// The scene's uniform ambient radiance with exposure applied, from the scene in f64.
pub fn reference_ambient(scene: &Scene) -> DVec3 {
    let [r, g, b] = scene.ambient;
    DVec3::new(f64::from(r), f64::from(g), f64::from(b)) * f64::from(scene.quality.exposure)
}

fn pow5(x: f64) -> f64 {
    x * x * x * x * x
}

/// GGX distribution.
pub fn d_ggx(n_dot_h: f64, alpha: f64) -> f64 {
    let a2 = alpha * alpha;
    let f = n_dot_h * n_dot_h * (a2 - 1.0) + 1.0;
    a2 / (PI * f * f)
}

/// Height-correlated Smith-GGX visibility.
pub fn v_smith_ggx_correlated(n_dot_v: f64, n_dot_l: f64, alpha: f64) -> f64 {
    let a2 = alpha * alpha;
    let lv = n_dot_l * (n_dot_v * n_dot_v * (1.0 - a2) + a2).sqrt();
    let ll = n_dot_v * (n_dot_l * n_dot_l * (1.0 - a2) + a2).sqrt();
    0.5 / (lv + ll)
}

/// Anisotropic GGX distribution (Burley; Filament's form).
pub fn d_ggx_anisotropic(at: f64, ab: f64, t_dot_h: f64, b_dot_h: f64, n_dot_h: f64) -> f64 {
    let x = t_dot_h / at;
    let y = b_dot_h / ab;
    let d = x * x + y * y + n_dot_h * n_dot_h;
    1.0 / (PI * at * ab * d * d)
}

/// Anisotropic height-correlated Smith-GGX visibility (Heitz; Filament's form), with `v` and
/// `l` in the tangent frame: (T.x, B.x, N.x).
pub fn v_smith_ggx_correlated_anisotropic(at: f64, ab: f64, v: DVec3, l: DVec3) -> f64 {
    let (n_dot_v, n_dot_l) = (v.z, l.z);
    let lv = n_dot_l * DVec3::new(at * v.x, ab * v.y, n_dot_v).length();
    let ll = n_dot_v * DVec3::new(at * l.x, ab * l.y, n_dot_l).length();
    0.5 / (lv + ll)
}

/// Filament's PBR BRDF times N.L.
pub fn pbr(s: &Surface, v: DVec3, l: DVec3) -> DVec3 {
    let n = s.normal;
    let n_dot_l = n.dot(l).clamp(0.0, 1.0);
    if n_dot_l <= 0.0 {
        return DVec3::ZERO;
    }
    let n_dot_v = n.dot(v).max(1e-4);
    let h = (v + l).try_normalize().unwrap_or(n);
    let n_dot_h = n.dot(h).clamp(0.0, 1.0);
    let l_dot_h = l.dot(h).clamp(0.0, 1.0);
    let alpha = s.roughness * s.roughness + 0.001;
    let f0 = DVec3::splat(0.16 * s.specular * s.specular * (1.0 - s.metallic))
        + s.base_color * s.metallic;
    let fresnel = f0 + (DVec3::ONE - f0) * pow5(1.0 - l_dot_h);
    let (d, vis) = if s.anisotropy != 0.0 {
        let t = s.tangent;
        let b = n.cross(t);
        let at = (alpha * (1.0 + s.anisotropy)).max(0.001);
        let ab = (alpha * (1.0 - s.anisotropy)).max(0.001);
        (
            d_ggx_anisotropic(at, ab, t.dot(h), b.dot(h), n_dot_h),
            v_smith_ggx_correlated_anisotropic(
                at,
                ab,
                DVec3::new(t.dot(v), b.dot(v), n_dot_v),
                DVec3::new(t.dot(l), b.dot(l), n_dot_l),
            ),
        )
    } else {
        (
            d_ggx(n_dot_h, alpha),
            v_smith_ggx_correlated(n_dot_v, n_dot_l, alpha),
        )
    };
    let specular = fresnel * (d * vis);
    let diffuse = s.base_color * (DVec3::ONE - fresnel) * (1.0 - s.metallic) / PI;
    let clearcoat_alpha = s.clearcoat_roughness * s.clearcoat_roughness + 0.001;
    let clearcoat_fresnel = (0.04 + 0.96 * pow5(1.0 - l_dot_h)) * s.clearcoat;
    let clearcoat =
        d_ggx(n_dot_h, clearcoat_alpha) * 0.25 / (l_dot_h * l_dot_h).max(1e-4) * clearcoat_fresnel;
    ((diffuse + specular) * (1.0 - clearcoat_fresnel) + DVec3::splat(clearcoat)) * n_dot_l
}

/// Lambert diffuse plus Blinn-Phong specular (r2), times N.L for the diffuse part.
pub fn blinn_phong(s: &Surface, v: DVec3, l: DVec3) -> DVec3 {
    let n_dot_l = s.normal.dot(l);
    if n_dot_l <= 0.0 {
        return DVec3::ZERO;
    }
    let h = (v + l).try_normalize().unwrap_or(s.normal);
    let n_dot_h = s.normal.dot(h).max(0.0);
    s.base_color * n_dot_l + DVec3::splat(s.specular * n_dot_h.powf(s.specular_exponent.max(0.0)))
}

/// Direction to the light and radiance arriving at the surface.
fn incoming(light: &RefLight, s: &Surface) -> (DVec3, DVec3) {
    match *light {
        RefLight::Directional(d, c) => (d, c),
        RefLight::Point(p, c, radius, inverse_falloff) => {
            let to_light = p - s.position;
            let distance = to_light.length();
            let l = if distance > 1e-6 {
                to_light / distance
            } else {
                s.normal
            };
            let ratio = (distance / radius.max(1e-6)).min(1.0);
            (l, c * (1.0 - ratio.powf(inverse_falloff)).max(0.0))
        }
    }
}

/// Exposed radiance the lighting pass should write for a surface.
pub fn shade(model: LightingModel, s: &Surface, lights: &[RefLight], ambient: DVec3) -> DVec3 {
    let v = (-s.position).try_normalize().unwrap_or(s.normal);
    let mut radiance = match model {
        LightingModel::Pbr => s.base_color * (1.0 - s.metallic) * ambient,
        LightingModel::Unlit => s.base_color,
        _ => s.base_color * ambient,
    };
    if model != LightingModel::Unlit {
        for light in lights {
            let (l, li) = incoming(light, s);
            let f = match model {
                LightingModel::Pbr => pbr(s, v, l),
                LightingModel::BlinnPhong => blinn_phong(s, v, l),
                LightingModel::Lambert => s.base_color * s.normal.dot(l).max(0.0) / PI,
                LightingModel::Toon => {
                    let n_dot_l = s.normal.dot(l);
                    let band = if n_dot_l > 0.8 {
                        1.0
                    } else if n_dot_l > 0.4 {
                        0.7
                    } else if n_dot_l > 0.0 {
                        0.35
                    } else {
                        0.0
                    };
                    s.base_color * band
                }
                LightingModel::Unlit => DVec3::ZERO,
            };
            radiance += f * li;
        }
    }
    radiance.clamp(DVec3::ZERO, DVec3::splat(FP16_SAFE_MAX))
}

/// Result of comparing the GPU light buffer with the reference.
#[derive(Clone, Debug, serde::Serialize)]
pub struct LightingError {
    /// Pixels compared (covered by some lighting model).
    pub pixels: usize,
    /// 99.9th percentile of the relative error over all compared channels.
    pub p999_relative: f64,
    /// Largest relative error.
    pub max_relative: f64,
    /// Non-finite values in the GPU light buffer.
    pub non_finite: usize,
    /// Pixel (x, y) of the largest error.
    pub worst_pixel: (u32, u32),
}

fn f32_image(frame: &Frame, target: TargetId) -> Result<&Image, ReferenceError> {
    frame.output(target).ok_or(ReferenceError::no_float(target))
}

fn sample(image: &Image, index: usize) -> [f64; 4] {
    match &image.data {
        engine::ImageData::F32(d) => {
            let p = &d[index * 4..index * 4 + 4];
            [p[0] as f64, p[1] as f64, p[2] as f64, p[3] as f64]
        }
        engine::ImageData::U8(d) => {
            let p = &d[index * 4..index * 4 + 4];
            [
                p[0] as f64 / 255.0,
                p[1] as f64 / 255.0,
                p[2] as f64 / 255.0,
                p[3] as f64 / 255.0,
            ]
        }
    }
}

/// The frame's five G-buffer outputs, in attachment order.
pub fn gbuffer_images(frame: &Frame) -> Result<[&Image; 5], ReferenceError> {
    let [p, n, t, a, m] = TargetId::GBUFFER;
    Ok([
        f32_image(frame, p)?,
        f32_image(frame, n)?,
        f32_image(frame, t)?,
        f32_image(frame, a)?,
        f32_image(frame, m)?,
    ])
}

/// The G-buffer surface at pixel `index`.
pub fn surface_at(gbuffer: &[&Image; 5], index: usize) -> Surface {
    let [p, n, t, a, m] = gbuffer.map(|image| sample(image, index));
    Surface {
        position: DVec3::new(p[0], p[1], p[2]),
        roughness: p[3].clamp(0.0, 1.0),
        normal: DVec3::new(n[0], n[1], n[2]).normalize_or_zero(),
        specular: n[3],
        tangent: DVec3::new(t[0], t[1], t[2]),
        base_color: DVec3::new(a[0], a[1], a[2]),
        anisotropy: a[3].clamp(-1.0, 1.0),
        metallic: m[0],
        clearcoat: m[1],
        clearcoat_roughness: m[2].clamp(0.0, 1.0),
        specular_exponent: m[3],
    }
}

/// The reference light buffer for every covered pixel: (pixel index, model, radiance).
pub fn reference_light_buffer(
    scene: &Scene,
    frame: &Frame,
) -> Result<Vec<(usize, LightingModel, DVec3)>, ReferenceError> {
    let gbuffer = gbuffer_images(frame)?;
    let masks: Vec<&Image> = (0..2)
        .map(TargetId::Mask)
        .filter_map(|mask| frame.output(mask))
        .collect();
    if masks.is_empty() {
        return Err(ReferenceError::MissingOutput {
            target: TargetId::Mask(0),
            storage: "8-bit",
        });
    }
    let lights = reference_lights(scene);
    let ambient = reference_ambient(scene);
    let pixels = (frame.plan.width * frame.plan.height) as usize;
    let mut out = Vec::new();
    for index in 0..pixels {
        let model = frame.plan.mask_channels.iter().find(|c| {
            masks
                .get(c.target)
                .is_some_and(|m| sample(m, index)[c.channel] > 0.5)
        });
        if let Some(channel) = model {
            let s = surface_at(&gbuffer, index);
            out.push((
                index,
                channel.model,
                shade(channel.model, &s, &lights, ambient),
            ));
        }
    }
    Ok(out)
}

/// Compares the frame's light buffer with the reference (the metric of the module docs).
pub fn lighting_error(scene: &Scene, frame: &Frame) -> Result<LightingError, ReferenceError> {
    let light = f32_image(frame, TargetId::Light)?;
    let reference = reference_light_buffer(scene, frame)?;
    let image_max = reference
        .iter()
        .map(|(_, _, r)| r.max_element())
        .fold(0.0, f64::max);
    let floor = (1e-3 * image_max).max(f64::MIN_POSITIVE);
    let mut errors = Vec::with_capacity(reference.len() * 3);
    let mut non_finite = 0;
    let mut worst = (0.0, 0usize);
    for &(index, _, r) in &reference {
        let g = sample(light, index);
        for c in 0..3 {
            if !g[c].is_finite() {
                non_finite += 1;
                continue;
            }
            let e = (g[c] - r[c]).abs() / r[c].abs().max(floor);
            if e > worst.0 {
                worst = (e, index);
            }
            errors.push(e);
        }
    }
    errors.sort_by(f64::total_cmp);
    let p999 = engine::stats::percentile_of_sorted(&errors, 0.999);
    Ok(LightingError {
        pixels: reference.len(),
        p999_relative: p999,
        max_relative: worst.0,
        non_finite,
        worst_pixel: (
            (worst.1 as u32) % frame.plan.width,
            (worst.1 as u32) / frame.plan.width,
        ),
    })
}

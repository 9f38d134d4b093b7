//! Extracting an environment's sun into an analytic directional light.
//!
//! A small, very bright sun is where the split sum (and a few filtered samples) fail: its
//! reflection is a handful of texels carrying a third of the image's flux (interior.exr: 50
//! texels of 1024 x 512, 38%). With `[quality.ibl] extract_sun = true` the sun is cut out of the
//! image before the maps are built (its texels replaced by the sky around it) and lit instead as
//! a directional light carrying its flux, which the lighting pass evaluates with the full BRDF
//! (anisotropy included) at every pixel. The light is a disc of the sun's solid angle (its
//! specular highlight widened and dimmed to match, as for Karis's sphere lights) and casts a
//! shadow unless `[quality.ibl] sun_shadow = false`.
//!
//! The sun is the 8-connected region around the brightest texel (by luminance) of texels
//! brighter than `max(1% of the peak, 100 x the median)`; there is none when the peak is under
//! 1000 x the median, or the region covers more than 1% of the image (a sky, not a sun).
//!
//! An interior has several: interior.exr's two lamps are two such regions (11 and 16 texels,
//! together a third of its flux), and a bright patch of 105 texels a third. With
//! `[quality.ibl] extracted_lights = N` the rule is applied again to what each extraction leaves,
//! up to N times, and every region found becomes a light of its own ([`extract`]):
//! what filtered importance samples alias (a lamp a sample's footprint catches once, twice or
//! not at all) is then lit exactly.

use glam::{DVec3, Vec3};

use super::IblMaps;
use crate::scene::{Environment, EnvironmentImage, Light, Scene, ShadowSettings};

/// An extracted sun, in the environment image's frame (before the environment's rotation).
#[derive(Clone, Debug, PartialEq)]
pub struct Sun {
    /// Unit direction towards the sun's flux-weighted centre.
    pub direction: Vec3,
    /// Irradiance it gives a surface facing it: the excess radiance over the sky behind it
    /// times solid angle, summed over its texels, per RGB channel.
    pub irradiance: [f32; 3],
    /// Solid angle of its texels, steradians.
    pub solid_angle: f32,
    /// Texels it covered.
    pub texels: usize,
}

fn luminance(t: &[f32; 4]) -> f64 {
    0.2126 * f64::from(t[0]) + 0.7152 * f64::from(t[1]) + 0.0722 * f64::from(t[2])
}

/// Direction through the centre of texel (x, y) (the inverse of [`super::cube::equirect_uv`]).
fn texel_direction(x: u32, y: u32, width: u32, height: u32) -> DVec3 {
    let u = (f64::from(x) + 0.5) / f64::from(width);
    let v = (f64::from(y) + 0.5) / f64::from(height);
    let phi = (u - 0.5) * std::f64::consts::TAU;
    let theta = v * std::f64::consts::PI;
    // u = 0.5 + atan2(d.x, -d.z) / 2pi, v = acos(d.y) / pi.
    DVec3::new(
        theta.sin() * phi.sin(),
        theta.cos(),
        -theta.sin() * phi.cos(),
    )
}

/// Solid angle of a texel in row `y`.
fn texel_solid_angle(y: u32, width: u32, height: u32) -> f64 {
    let theta = (f64::from(y) + 0.5) / f64::from(height) * std::f64::consts::PI;
    (std::f64::consts::TAU / f64::from(width))
        * (std::f64::consts::PI / f64::from(height))
        * theta.sin()
}

/// The sun's texels (indices) and the sky radiance around them, if the image has a sun.
fn sun_region(image: &EnvironmentImage) -> Option<(Vec<usize>, [f32; 3])> {
    let (w, h) = (image.width as usize, image.height as usize);
    if w == 0 || h == 0 || image.texels.len() != w * h {
        return None;
    }
    let lum: Vec<f64> = image.texels.iter().map(luminance).collect();
    let (peak_index, &peak) = lum
        .iter()
        .enumerate()
        .filter(|(_, l)| l.is_finite())
        .max_by(|a, b| a.1.total_cmp(b.1))?;
    let median = crate::stats::median(lum.iter().copied().filter(|l| l.is_finite()).collect())?;
    if peak < 1000.0 * median.max(1e-6) {
        return None;
    }
    let threshold = (0.01 * peak).max(100.0 * median);
    let mut inside = vec![false; w * h];
    let mut region = vec![peak_index];
    inside[peak_index] = true;
    let mut next = 0;
    while next < region.len() {
        let (x, y) = (region[next] % w, region[next] / w);
        next += 1;
        for (dx, dy) in [
            (-1i64, -1i64),
            (0, -1),
            (1, -1),
            (-1, 0),
            (1, 0),
            (-1, 1),
            (0, 1),
            (1, 1),
        ] {
            let ny = y as i64 + dy;
            if ny < 0 || ny >= h as i64 {
                continue;
            }
            let nx = (x as i64 + dx).rem_euclid(w as i64) as usize;
            let n = ny as usize * w + nx;
            if !inside[n] && lum[n] > threshold {
                inside[n] = true;
                region.push(n);
            }
        }
        if region.len() > w * h / 100 {
            return None;
        }
    }
    // The sky behind it: the mean of the texels that border the region.
    let mut sky = [0.0f64; 3];
    let mut count = 0usize;
    for &i in &region {
        let (x, y) = (i % w, i / w);
        for (dx, dy) in [(-1i64, 0i64), (1, 0), (0, -1), (0, 1)] {
            let ny = y as i64 + dy;
            if ny < 0 || ny >= h as i64 {
                continue;
            }
            let n = ny as usize * w + (x as i64 + dx).rem_euclid(w as i64) as usize;
            if !inside[n] {
                for (sum, value) in sky.iter_mut().zip(image.texels[n]) {
                    *sum += f64::from(value.max(0.0));
                }
                count += 1;
            }
        }
    }
    let sky = sky.map(|s| (s / count.max(1) as f64) as f32);
    Some((region, sky))
}

/// Up to `count` of the image's suns (see the module documentation), the brightest texel's
/// first, and the image without them: each sun's texels replaced by the sky around it, and the
/// rule applied again to what is left, for as long as that has a sun (an interior's lamps after
/// its brightest). `None` when the image has no sun at all.
pub fn extract(image: &EnvironmentImage, count: u32) -> Option<(EnvironmentImage, Vec<Sun>)> {
    let mut residual = image.clone();
    let mut suns = Vec::new();
    while suns.len() < count as usize {
        let Some((region, sky)) = sun_region(&residual) else {
            break;
        };
        suns.push(cut_out(&mut residual, &region, sky));
    }
    (!suns.is_empty()).then_some((residual, suns))
}

/// The sun of `region` (texel indices), its texels in `image` replaced by `sky`.
fn cut_out(image: &mut EnvironmentImage, region: &[usize], sky: [f32; 3]) -> Sun {
    let (w, h) = (image.width, image.height);
    let mut irradiance = [0.0f64; 3];
    let mut weighted = DVec3::ZERO;
    let mut solid_angle = 0.0;
    for &i in region {
        let (x, y) = ((i % w as usize) as u32, (i / w as usize) as u32);
        let omega = texel_solid_angle(y, w, h);
        let t = image.texels[i];
        let mut excess = 0.0;
        for c in 0..3 {
            let e = (f64::from(t[c]) - f64::from(sky[c])).max(0.0) * omega;
            irradiance[c] += e;
            excess += e;
        }
        weighted += texel_direction(x, y, w, h) * excess;
        solid_angle += omega;
        image.texels[i] = [sky[0], sky[1], sky[2], t[3]];
    }
    Sun {
        direction: weighted.normalize_or_zero().as_vec3(),
        irradiance: irradiance.map(|e| e as f32),
        solid_angle: solid_angle as f32,
        texels: region.len(),
    }
}

/// Angular radius of the disc with the sun's solid angle: `omega = 2 pi (1 - cos radius)`.
pub fn angular_radius(sun: &Sun) -> f32 {
    let omega = f64::from(sun.solid_angle).clamp(0.0, 4.0 * std::f64::consts::PI);
    (1.0 - omega / std::f64::consts::TAU).acos() as f32
}

/// The directional light that stands for `sun` in the world (the environment's rotation and
/// intensity applied): a disc of the sun's solid angle, casting `shadow` if any.
pub fn light(
    environment: &Environment,
    sun: &Sun,
    shadow: Option<ShadowSettings>,
) -> Option<Light> {
    let r = environment.rotation_degrees.to_radians();
    let (c, s) = (r.cos(), r.sin());
    // The inverse of the lighting pass's environment_direction (a rotation about +Y).
    let d = sun.direction;
    let world = Vec3::new(c * d.x + s * d.z, d.y, -s * d.x + c * d.z);
    let peak = sun.irradiance.iter().copied().fold(0.0f32, f32::max);
    if peak <= 0.0 {
        return None;
    }
    Some(Light::Directional {
        direction: world.as_dvec3(),
        color: sun.irradiance.map(|e| e / peak),
        intensity: peak * environment.intensity,
        angular_radius: angular_radius(sun),
        shadow,
    })
}

/// The scene as the renderer draws it: with the suns that `maps` (built with `extract_sun`)
/// cut out of the environment added as directional lights, each with a shadow unless
/// `[quality.ibl] sun_shadow` is off; `None` when there are none, the scene as it is.
pub fn scene_with_sun(scene: &Scene, maps: Option<&IblMaps>) -> Option<Scene> {
    let shadow = scene.quality.ibl.sun_shadow.then(ShadowSettings::default);
    let environment = scene.environment.as_ref()?;
    let lights: Vec<Light> = maps?
        .suns
        .iter()
        .filter_map(|sun| light(environment, sun, shadow))
        .collect();
    if lights.is_empty() {
        return None;
    }
    let mut with_sun = scene.clone();
    with_sun.lights.extend(lights);
    Some(with_sun)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn sky_with_sun(sun: Option<(u32, u32, f32)>) -> EnvironmentImage {
        let (width, height) = (64u32, 32u32);
        let mut texels = vec![[0.5, 0.6, 0.7, 1.0]; (width * height) as usize];
        if let Some((x, y, radiance)) = sun {
            for (dx, dy) in [(0, 0), (1, 0), (0, 1), (1, 1)] {
                texels[((y + dy) * width + x + dx) as usize] = [radiance, radiance, radiance, 1.0];
            }
        }
        EnvironmentImage {
            label: "test".into(),
            width,
            height,
            texels,
        }
    }

    #[test]
    fn a_sun_carries_its_excess_flux_towards_its_texels() {
        let image = sky_with_sun(Some((40, 10, 1e4)));
        let (residual, suns) = extract(&image, 1).expect("a sun");
        let sun = suns[0].clone();
        assert_eq!(suns.len(), 1);
        assert_eq!(sun.texels, 4);
        // Excess radiance over the sky, times the four texels' solid angle.
        let omega: f64 = [10, 11]
            .iter()
            .map(|&y| 2.0 * texel_solid_angle(y, 64, 32))
            .sum();
        let expected = (1e4 - 0.5) * omega;
        assert!((f64::from(sun.irradiance[0]) / expected - 1.0).abs() < 1e-4);
        // Its direction is the middle of the 2x2 block: texel corner (41, 11).
        let (u, v) = super::super::cube::equirect_uv(sun.direction);
        assert!(
            (u * 64.0 - 41.0).abs() < 0.05 && (v * 32.0 - 11.0).abs() < 0.05,
            "{u} {v}"
        );
        assert!(residual.texels.iter().all(|t| t[0] < 1.0));
        // Its disc has the four texels' solid angle.
        let radius = f64::from(angular_radius(&sun));
        let disc = std::f64::consts::TAU * (1.0 - radius.cos());
        assert!((disc / omega - 1.0).abs() < 1e-3, "{disc} vs {omega}");
    }

    #[test]
    fn an_even_sky_has_no_sun() {
        assert!(extract(&sky_with_sun(None), 1).is_none());
        assert!(extract(&sky_with_sun(None), 3).is_none());
    }

    #[test]
    fn several_suns_are_cut_out_one_after_another_and_no_more_than_there_are() {
        // Two suns: the one with the brightest texel first, whatever their flux.
        let mut image = sky_with_sun(Some((40, 10, 1e4)));
        for (dx, dy) in [(0, 0), (1, 0), (2, 0), (0, 1), (1, 1), (2, 1)] {
            image.texels[((20 + dy) * 64 + 8 + dx) as usize] = [3e3, 3e3, 3e3, 1.0];
        }
        let (residual, suns) = extract(&image, 3).expect("two suns");
        assert_eq!(suns.iter().map(|s| s.texels).collect::<Vec<_>>(), [4, 6]);
        assert!(residual.texels.iter().all(|t| t[0] < 1.0));
        // One asked for is the first, and the second stays in the image.
        let (one_left, one) = extract(&image, 1).unwrap();
        assert_eq!(one[..], suns[..1]);
        assert!(one_left.texels.iter().any(|t| t[0] == 3e3));
    }
}

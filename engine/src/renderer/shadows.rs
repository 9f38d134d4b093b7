//! Shadow maps: light-space matrices (directional: orthographic, fitted to the shadow casters'
//! bounds; point: six 90-degree faces in a 3x2 atlas), the uniform block the lighting pass
//! samples them with, the soft filters' jitter and the VSM blur's weights. The passes that fill
//! the maps are recorded in `passes/shadow.rs`.
//!
//! Everything is camera-relative and computed in f64, like the rest of the renderer.

use glam::{DMat4, DVec3};

use crate::scene::{Light, Scene, ShadowSettings};

/// A light's shadow-map views.
#[derive(Clone, Debug)]
pub struct ShadowView {
    /// Index of the light.
    pub light: usize,
    /// Camera-relative world to light clip space: one (directional) or six (point) matrices.
    pub faces: Vec<DMat4>,
    /// Point light (atlas of six faces) or directional.
    pub point: bool,
    /// Face size in texels.
    pub size: u32,
    /// Texel size in meters (directional) or in meters per meter of distance (point).
    pub texel_world: f64,
    /// The light's settings.
    pub settings: ShadowSettings,
}

/// Cube faces in atlas order: +X, -X, +Y, -Y, +Z, -Z (direction, up).
const FACES: [(DVec3, DVec3); 6] = [
    (DVec3::X, DVec3::NEG_Y),
    (DVec3::NEG_X, DVec3::NEG_Y),
    (DVec3::Y, DVec3::Z),
    (DVec3::NEG_Y, DVec3::NEG_Z),
    (DVec3::Z, DVec3::NEG_Y),
    (DVec3::NEG_Z, DVec3::NEG_Y),
];

/// Camera-relative corners of every shadow caster's bounds.
fn caster_corners(scene: &Scene) -> Vec<DVec3> {
    let mut corners = Vec::new();
    for object in scene.objects.iter().filter(|o| o.casts_shadows) {
        let m = object.transform.relative_to(scene.camera.position);
        let (lo, hi) = (object.mesh.bounds.min, object.mesh.bounds.max);
        for i in 0..8 {
            let pick = |axis: usize| {
                if i & (1 << axis) == 0 {
                    f64::from(lo[axis])
                } else {
                    f64::from(hi[axis])
                }
            };
            corners.push(m.transform_point3(DVec3::new(pick(0), pick(1), pick(2))));
        }
    }
    corners
}

/// The shadow views of every light that casts shadows (when some object casts them).
pub fn shadow_views(scene: &Scene) -> Vec<ShadowView> {
    let corners = caster_corners(scene);
    if corners.is_empty() {
        return Vec::new();
    }
    let mut views = Vec::new();
    for (index, light) in scene.lights.iter().enumerate() {
        match light {
            Light::Directional {
                direction,
                shadow: Some(settings),
                ..
            } => {
                let (lo, hi) = corners.iter().fold(
                    (DVec3::splat(f64::MAX), DVec3::splat(f64::MIN)),
                    |(lo, hi), c| (lo.min(*c), hi.max(*c)),
                );
                let center = (lo + hi) / 2.0;
                let radius = ((hi - lo).length() / 2.0).max(1e-3);
                let dir = direction.normalize();
                let up = if dir.y.abs() > 0.99 {
                    DVec3::Z
                } else {
                    DVec3::Y
                };
                let view = DMat4::look_at_rh(center + dir * radius * 2.0, center, up);
                let (vlo, vhi) = corners.iter().fold(
                    (DVec3::splat(f64::MAX), DVec3::splat(f64::MIN)),
                    |(lo, hi), c| {
                        let v = view.transform_point3(*c);
                        (lo.min(v), hi.max(v))
                    },
                );
                // A margin of one texel keeps casters' edges off the map border.
                let size = f64::from(settings.map_size);
                let margin = (vhi.x - vlo.x).max(vhi.y - vlo.y) / size;
                let (left, right) = (vlo.x - margin, vhi.x + margin);
                let (bottom, top) = (vlo.y - margin, vhi.y + margin);
                let near = (-vhi.z - radius * 0.01).max(1e-4);
                let far = -vlo.z + radius * 0.01;
                let projection = DMat4::orthographic_rh(left, right, bottom, top, near, far);
                views.push(ShadowView {
                    light: index,
                    faces: vec![projection * view],
                    point: false,
                    size: settings.map_size,
                    texel_world: (right - left).max(top - bottom) / size,
                    settings: *settings,
                });
            }
            Light::Point {
                position,
                radius,
                shadow: Some(settings),
                ..
            } => {
                let eye = *position - scene.camera.position;
                let far = f64::from(*radius);
                let near = (far * 1e-2).min(far * 0.5);
                let projection = DMat4::perspective_rh(std::f64::consts::FRAC_PI_2, 1.0, near, far);
                let faces = FACES
                    .iter()
                    .map(|(dir, up)| projection * DMat4::look_at_rh(eye, eye + *dir, *up))
                    .collect();
                views.push(ShadowView {
                    light: index,
                    faces,
                    point: true,
                    size: settings.map_size,
                    texel_world: 2.0 / f64::from(settings.map_size),
                    settings: *settings,
                });
            }
            _ => {}
        }
    }
    views
}

/// `ShadowUniforms` of `lighting.wgsl` for a view (or the "no shadow" block), as floats.
pub fn shadow_uniforms(view: Option<&ShadowView>) -> Vec<f32> {
    let mut data = Vec::with_capacity(6 * 16 + 16);
    let Some(view) = view else {
        data.resize(6 * 16 + 16, 0.0);
        return data;
    };
    for face in 0..6 {
        let m = view.faces.get(face).unwrap_or(&view.faces[0]).as_mat4();
        data.extend_from_slice(&m.to_cols_array());
    }
    let s = &view.settings;
    // The kind, the filter and the Vogel sample count are the lighting draw's override
    // constants (plan::LightingVariant); their slots here stay 0.
    data.extend_from_slice(&[0.0, s.bias, s.slope_bias, s.normal_offset]);
    let (w, h) = if view.point {
        (3 * view.size, 2 * view.size)
    } else {
        (view.size, view.size)
    };
    data.extend_from_slice(&[0.0, 1.0 / w as f32, 1.0 / h as f32, view.texel_world as f32]);
    data.extend_from_slice(&[s.soft_radius, s.reach(), 0.0, 0.0]);
    data.extend_from_slice(&[s.vsm_min_variance, s.vsm_bleeding_reduction, 0.0, 0.0]);
    data
}

/// Sectors per ring of the stratified soft filter.
pub const SOFT_SECTORS: usize = 4;
/// Rings of the stratified soft filter.
pub const SOFT_RINGS: usize = 4;
/// Size of the per-pixel jitter tile (pixels are mapped to it modulo this size).
pub const JITTER_TILE: u32 = 32;

/// The jitter texture's texels ([`compute_jitter_texels`]), computed once per process.
pub fn jitter_texels() -> &'static [u16] {
    static TEXELS: std::sync::OnceLock<Vec<u16>> = std::sync::OnceLock::new();
    TEXELS.get_or_init(compute_jitter_texels)
}

/// The jitter texture of the stratified soft filter: a `JITTER_TILE`-square 2D array with one
/// layer per pair of samples (8 layers); layer `2r + k` holds samples `2k` and `2k + 1` of ring
/// `r` (ring 3 is the outer one) as (x, y, x, y) offsets in the unit disk. Each sample lies in
/// its own ring x sector cell, jittered by a fixed-seed PCG hash: deterministic.
pub fn compute_jitter_texels() -> Vec<u16> {
    let layers = SOFT_RINGS * SOFT_SECTORS / 2;
    let tile = JITTER_TILE as usize;
    let mut out = Vec::with_capacity(layers * tile * tile * 4);
    let hash = |mut x: u32| {
        // PCG-style integer hash.
        x = x.wrapping_mul(747_796_405).wrapping_add(2_891_336_453);
        let word = ((x >> ((x >> 28) + 4)) ^ x).wrapping_mul(277_803_737);
        ((word >> 22) ^ word) as f32 / u32::MAX as f32
    };
    for layer in 0..layers {
        let ring = layer / 2;
        for y in 0..tile {
            for x in 0..tile {
                for k in 0..2 {
                    let sector = (layer % 2) * 2 + k;
                    let seed = (((y * tile + x) * 64 + ring * 4 + sector) as u32).wrapping_mul(2);
                    let (u, v) = (hash(seed), hash(seed + 1));
                    // Uniform area within the ring: radius from the squared-radius interval.
                    let (r0, r1) = (
                        ring as f32 / SOFT_RINGS as f32,
                        (ring + 1) as f32 / SOFT_RINGS as f32,
                    );
                    let radius = (r0 * r0 + u * (r1 * r1 - r0 * r0)).sqrt();
                    let angle = (sector as f32 + v) * std::f32::consts::TAU / SOFT_SECTORS as f32;
                    out.push(half::f16::from_f32(radius * angle.cos()).to_bits());
                    out.push(half::f16::from_f32(radius * angle.sin()).to_bits());
                }
            }
        }
    }
    out
}

/// Weights of the VSM blur's taps at distance 0..=16 texels (20 floats, zero past `radius`): a
/// Gaussian with sigma = radius / 2, normalized so the 2 radius + 1 taps sum to 1.
pub fn blur_weights(radius: u32) -> Vec<f32> {
    let sigma = (f64::from(radius) * 0.5).max(0.5);
    let raw: Vec<f64> = (0..=radius.min(16))
        .map(|k| (-0.5 * f64::from(k * k) / (sigma * sigma)).exp())
        .collect();
    let total: f64 = raw[0] + 2.0 * raw[1..].iter().sum::<f64>();
    let mut weights: Vec<f32> = raw.iter().map(|w| (w / total) as f32).collect();
    weights.resize(20, 0.0);
    weights
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn blur_weights_are_a_normalized_decreasing_gaussian() {
        for radius in [1u32, 2, 5, 16] {
            let w = blur_weights(radius);
            assert_eq!(w.len(), 20);
            let r = radius as usize;
            let total: f32 = w[0] + 2.0 * w[1..=r].iter().sum::<f32>();
            assert!((total - 1.0).abs() < 1e-6, "radius {radius}: sum {total}");
            assert!(w[..=r].windows(2).all(|p| p[0] > p[1]), "radius {radius}");
            assert!(w[r + 1..].iter().all(|&x| x == 0.0));
        }
    }
}

//! The prefiltered specular cube: per mip level, the environment convolved with the GGX lobe of
//! that level's roughness (split-sum approximation, `N = V = R`).
//!
//! Roughness to mip: level `m` of `L` levels holds perceptual roughness `m / (L - 1)`
//! (alpha = roughness^2); the lighting pass samples at `lod = roughness * (L - 1)`. Level 0 is
//! the environment itself at the specular size.
//!
//! Filtered importance sampling (Krivanek & Colbert, GPU Gems 3 ch. 20): each GGX sample reads
//! the source cube at the mip whose texel solid angle matches the sample's,
//! `lod = 0.5 log2(omega_sample / omega_texel) + 1`, with `omega_sample = 1 / (N pdf)`. A sample
//! that lands on a bright sun then reads the sun already averaged over the sample's footprint,
//! which is what keeps isolated fireflies out of the rough levels.

use glam::Vec3;

use super::cube::{texel_direction, CubeLevel, CubeMap, Lod};
use super::{d_ggx, ggx_half_vector, hammersley, tangent_frame, IblSettings};

/// Krivanek & Colbert's bias added to the source lod (1 in Karis's and their examples).
const LOD_BIAS: f32 = 1.0;

/// GGX samples per texel at `level`: `base` at level 1, four times more per level after it (a
/// level has a quarter of the texels of the one before, so each level costs the same), at most
/// 16384.
pub fn samples_at(base: u32, level: u32) -> u32 {
    base.saturating_mul(1 << (2 * level.saturating_sub(1)).min(16))
        .clamp(1, 16384)
}

/// Number of levels of the prefiltered cube for a base size (down to 4 x 4 faces).
pub fn level_count(specular_size: u32) -> u32 {
    (specular_size.max(4).ilog2() - 1).max(1)
}

/// Perceptual roughness that level `level` of `levels` holds.
pub fn level_roughness(level: u32, levels: u32) -> f32 {
    if levels <= 1 {
        0.0
    } else {
        level as f32 / (levels - 1) as f32
    }
}

/// Prefilters `source` (the environment cube with its full mip chain) into the specular cube.
pub fn prefilter(source: &CubeMap, settings: &IblSettings) -> CubeMap {
    let size = settings.specular_size;
    let levels = level_count(size);
    let source_size = source.levels[0].size;
    // Level 0: the source mip at the specular size (box-filtered, no lobe).
    let base_mip = (source_size / size).max(1).ilog2() as usize;
    let mut out = vec![source.levels[base_mip.min(source.levels.len() - 1)].clone()];
    let texel_omega = 4.0 * std::f32::consts::PI / (6.0 * (source_size * source_size) as f32);
    for level in 1..levels {
        let n = samples_at(settings.specular_samples, level);
        let roughness = level_roughness(level, levels);
        let alpha = (roughness * roughness).max(1e-4);
        // Tangent-space samples and their source lod, shared by every texel of the level.
        let samples: Vec<(Vec3, f32, Lod)> = (0..n)
            .filter_map(|i| {
                let (u1, u2) = hammersley(i, n, settings.seed);
                let h = ggx_half_vector(u1, u2, alpha);
                let n_dot_l = 2.0 * h.z * h.z - 1.0;
                if n_dot_l <= 0.0 {
                    return None;
                }
                let l = Vec3::new(2.0 * h.z * h.x, 2.0 * h.z * h.y, n_dot_l);
                // pdf of L with N = V: D(h) (n.h) / (4 v.h) = D / 4.
                let pdf = d_ggx(h.z, alpha) / 4.0;
                let omega = 1.0 / (n as f32 * pdf);
                let lod = (0.5 * (omega / texel_omega).log2() + LOD_BIAS).max(0.0);
                Some((l, n_dot_l, source.lod(lod)))
            })
            .collect();
        let level_size = (size >> level).max(1);
        out.push(CubeLevel::from_fn(level_size, |face, x, y| {
            let normal = texel_direction(face, x, y, level_size);
            let (t, b) = tangent_frame(normal);
            let mut sum = [0.0f32; 3];
            let mut weight = 0.0;
            for &(l, n_dot_l, lod) in &samples {
                let d = t * l.x + b * l.y + normal * l.z;
                let c = source.sample_at(d, lod);
                for k in 0..3 {
                    sum[k] += c[k] * n_dot_l;
                }
                weight += n_dot_l;
            }
            sum.map(|s| if weight > 0.0 { s / weight } else { 0.0 })
        }));
    }
    CubeMap { levels: out }
}

//! The DFG (BRDF) lookup table of the split sum: for `NoV` across and perceptual roughness
//! down (alpha = roughness^2, the mapping the prefiltered cube uses), the directional albedo of
//! the GGX specular lobe split as `E = F0 * scale + bias` (Karis 2013):
//! `scale = int (1 - Fc) G_vis`, `bias = int Fc G_vis` with `Fc = (1 - v.h)^5` and Filament's
//! height-correlated Smith visibility. Integrated in f64 with Hammersley-sampled GGX half
//! vectors. Texel `i` holds parameter `i / (size - 1)`, so the first and last texel centers sit
//! exactly at 0 and 1 and lookups remap `t` to `(t (size - 1) + 0.5) / size` ([`lookup`], and
//! `lighting.wgsl` the same way): `NoV = 1` and roughness 1 are read exactly, not clamped to a
//! texel center half a texel inside.

use glam::DVec3;

use super::hammersley;

/// Samples per texel (1024 leave errors near 0.009 at grazing NoV; 4096 stay within 0.0015 of
/// the reference values).
pub const SAMPLES: u32 = 4096;

/// Texel side of the table.
pub const SIZE: u32 = 64;

/// `(scale, bias)` for one `NoV` and perceptual roughness.
pub fn integrate(n_dot_v: f64, roughness: f64, samples: u32) -> (f64, f64) {
    let alpha = (roughness * roughness).max(1e-4);
    let n_dot_v = n_dot_v.clamp(1e-4, 1.0);
    let v = DVec3::new((1.0 - n_dot_v * n_dot_v).sqrt(), 0.0, n_dot_v);
    let a2 = alpha * alpha;
    let (mut scale, mut bias) = (0.0, 0.0);
    for i in 0..samples {
        let (u1, u2) = hammersley(i, samples, 0);
        let (u1, u2) = (f64::from(u1), f64::from(u2));
        let cos_theta = ((1.0 - u1) / (1.0 + (a2 - 1.0) * u1)).sqrt();
        let sin_theta = (1.0 - cos_theta * cos_theta).max(0.0).sqrt();
        let phi = std::f64::consts::TAU * u2;
        let h = DVec3::new(sin_theta * phi.cos(), sin_theta * phi.sin(), cos_theta);
        let v_dot_h = v.dot(h);
        let l = 2.0 * v_dot_h * h - v;
        let n_dot_l = l.z;
        if n_dot_l <= 0.0 || v_dot_h <= 0.0 {
            continue;
        }
        let n_dot_h = h.z;
        let visibility = 0.5
            / (n_dot_l * (n_dot_v * n_dot_v * (1.0 - a2) + a2).sqrt()
                + n_dot_v * (n_dot_l * n_dot_l * (1.0 - a2) + a2).sqrt());
        // f cos / pdf with pdf(l) = D (n.h) / (4 v.h): D cancels.
        let g_vis = visibility * 4.0 * n_dot_l * v_dot_h / n_dot_h;
        let fc = (1.0 - v_dot_h).powi(5);
        scale += (1.0 - fc) * g_vis;
        bias += fc * g_vis;
    }
    (scale / f64::from(samples), bias / f64::from(samples))
}

/// The table, row-major, `NoV` across and roughness down: `(scale, bias)` per texel.
pub fn table(size: u32, samples: u32) -> Vec<[f32; 2]> {
    super::parallel_map((size * size) as usize, |i| {
        let (x, y) = (i as u32 % size, i as u32 / size);
        let step = 1.0 / f64::from(size.max(2) - 1);
        let n_dot_v = f64::from(x) * step;
        let roughness = f64::from(y) * step;
        let (scale, bias) = integrate(n_dot_v, roughness, samples);
        [scale as f32, bias as f32]
    })
}

/// Bilinear lookup with clamp-to-edge, as the GPU samples the table.
pub fn lookup(table: &[[f32; 2]], size: u32, n_dot_v: f32, roughness: f32) -> [f32; 2] {
    let n = size as i64;
    let last = (size.max(1) - 1) as f32;
    let fx = n_dot_v.clamp(0.0, 1.0) * last;
    let fy = roughness.clamp(0.0, 1.0) * last;
    let (x0, y0) = (fx.floor(), fy.floor());
    let (tx, ty) = (fx - x0, fy - y0);
    let mut out = [0.0; 2];
    for (dx, dy, w) in [
        (0, 0, (1.0 - tx) * (1.0 - ty)),
        (1, 0, tx * (1.0 - ty)),
        (0, 1, (1.0 - tx) * ty),
        (1, 1, tx * ty),
    ] {
        let x = (x0 as i64 + dx).clamp(0, n - 1);
        let y = (y0 as i64 + dy).clamp(0, n - 1);
        let t = table[(y * n + x) as usize];
        out[0] += t[0] * w;
        out[1] += t[1] * w;
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The split-sum DFG values listed for checking in the project's reference design
    /// (DESIGN.md, References: Filament's BRDF, GGX with the height-correlated Smith term;
    /// DFG1 = scale, DFG2 = bias), read through the table as the lighting pass reads it.
    #[test]
    fn table_matches_the_reference_values() {
        let t = table(SIZE, SAMPLES);
        for (pr, n_dot_v, scale, bias) in [
            (0.5, 0.1, 0.7520, 0.1397),
            (0.5, 0.5, 0.8349, 0.0223),
            (0.5, 1.0, 0.9158, 0.0),
            (1.0, 0.1, 0.7363, 0.0239),
            (1.0, 1.0, 0.3068, 0.0),
        ] {
            let [s, b] = lookup(&t, SIZE, n_dot_v, pr);
            assert!(
                (f64::from(s) - scale).abs() < 0.005 && (f64::from(b) - bias).abs() < 0.005,
                "pr {pr} NoV {n_dot_v}: {s:.4}/{b:.4}, expected {scale}/{bias}"
            );
        }
    }

    /// At alpha = 1 the directional albedo has a closed form: E(mu) = 1 - mu ln(1 + 1/mu).
    #[test]
    fn rough_albedo_has_the_closed_form() {
        for mu in [0.1f64, 0.3, 0.6, 0.9] {
            let (s, b) = integrate(mu, 1.0, 4096);
            let exact = 1.0 - mu * (1.0 + 1.0 / mu).ln();
            assert!(
                (s + b - exact).abs() < 2e-3,
                "mu {mu}: {} vs {exact}",
                s + b
            );
        }
    }
}

//! The screen-space ambient occlusion's kernel and tangent frame, in f64: what the occlusion
//! pass uploads (`passes/ambient_occlusion.rs`, `shaders/ssao.wgsl`), and what a CPU reference
//! evaluates against exact geometry.
//!
//! The kernel is uniform in the unit hemisphere's volume (r2's clusters towards the origin), so
//! the expected occlusion of a point has a closed form where the geometry has one: on a floor
//! at distance d from a wall meeting it at a right angle, the wall takes the part of the
//! hemisphere beyond the plane x = d, a fraction [`corner_occlusion`] of its volume.

use glam::DVec3;

/// Kernel point `i` of `samples`, in the unit hemisphere around +z: its direction uniform on
/// the hemisphere (z stratified, azimuth on the golden angle), its radius the cube root of a
/// base-3 Halton value, so that the points are uniform in volume. Deterministic.
pub fn kernel(samples: u32) -> Vec<DVec3> {
    let n = f64::from(samples.max(1));
    (0..samples.max(1))
        .map(|i| {
            let z = (f64::from(i) + 0.5) / n;
            let azimuth = std::f64::consts::TAU * (f64::from(i) * 0.618_033_988_749_894_9).fract();
            let radius = halton3(i + 1).cbrt();
            let ring = (1.0 - z * z).max(0.0).sqrt();
            DVec3::new(ring * azimuth.cos(), ring * azimuth.sin(), z) * radius
        })
        .collect()
}

/// The base-3 radical inverse of `i` (in 0..1).
fn halton3(mut i: u32) -> f64 {
    let (mut value, mut scale) = (0.0, 1.0 / 3.0);
    while i > 0 {
        value += f64::from(i % 3) * scale;
        i /= 3;
        scale /= 3.0;
    }
    value
}

/// The tangent frame the shader builds around unit normal `n` (Duff et al. 2017): tangent,
/// bitangent, normal.
pub fn tangent_frame(n: DVec3) -> [DVec3; 3] {
    let sign = if n.z >= 0.0 { 1.0 } else { -1.0 };
    let a = -1.0 / (sign + n.z);
    let b = n.x * n.y * a;
    [
        DVec3::new(1.0 + sign * n.x * n.x * a, sign * b, -sign * n.x),
        DVec3::new(b, sign + n.y * n.y * a, -n.y),
        n,
    ]
}

/// The fraction of a hemisphere of radius `radius` (on a floor, around its normal) that lies
/// beyond a wall at distance `distance`, perpendicular to the floor: the expected occlusion of
/// a kernel uniform in volume. Half the spherical cap beyond the plane, over the hemisphere:
/// (R - d)^2 (2R + d) / (4 R^3); 1/2 at the wall, 0 from d = R on.
pub fn corner_occlusion(distance: f64, radius: f64) -> f64 {
    let d = distance.clamp(0.0, radius);
    (radius - d).powi(2) * (2.0 * radius + d) / (4.0 * radius.powi(3))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_kernel_fills_the_hemisphere_evenly() {
        let points = kernel(64);
        assert!(points.iter().all(|p| p.z > 0.0 && p.length() < 1.0));
        // Uniform in volume: the mean of z is 3/8, the mean radius 3/4.
        let mean_z = points.iter().map(|p| p.z).sum::<f64>() / 64.0;
        let mean_r = points.iter().map(|p| p.length()).sum::<f64>() / 64.0;
        assert!((mean_z - 0.375).abs() < 0.02, "{mean_z}");
        assert!((mean_r - 0.75).abs() < 0.02, "{mean_r}");
        assert_eq!(kernel(64), points, "deterministic");
    }

    /// The kernel's own estimate of the corner's occlusion (the fraction of its points beyond
    /// the wall) converges to the closed form.
    #[test]
    fn the_corner_occlusion_matches_the_kernel_it_expects() {
        let points = kernel(4096);
        for d in [0.0, 0.1, 0.3, 0.6, 0.9] {
            let beyond = points.iter().filter(|p| p.x > d).count() as f64 / 4096.0;
            let exact = corner_occlusion(d, 1.0);
            assert!((beyond - exact).abs() < 0.01, "d {d}: {beyond} vs {exact}");
        }
        assert_eq!(corner_occlusion(0.0, 2.0), 0.5);
        assert_eq!(corner_occlusion(3.0, 2.0), 0.0);
    }

    #[test]
    fn the_tangent_frame_is_orthonormal() {
        for n in [
            DVec3::Z,
            -DVec3::Z,
            DVec3::new(0.3, -0.5, 0.8).normalize(),
            DVec3::X,
        ] {
            let [t, b, m] = tangent_frame(n);
            for (x, y) in [(t, b), (t, m), (b, m)] {
                assert!(x.dot(y).abs() < 1e-12);
            }
            assert!((t.length() - 1.0).abs() < 1e-12 && (b.length() - 1.0).abs() < 1e-12);
            assert!((t.cross(b) - n).length() < 1e-12, "right-handed around n");
        }
    }
}

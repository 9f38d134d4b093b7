//! Tests of `harness::reference::lighting`.

use glam::DVec3;
use harness::reference::lighting::*;
use std::f64::consts::PI;

/// The GGX lobe integrates to one over the projected hemisphere: int D(h) (n.h) dh = 1.
#[test]
fn ggx_is_normalised() {
    for alpha in [0.05, 0.3, 1.0] {
        let steps = 20000;
        let mut sum = 0.0;
        for i in 0..steps {
            let theta = (i as f64 + 0.5) / steps as f64 * PI / 2.0;
            sum += d_ggx(theta.cos(), alpha)
                * theta.cos()
                * theta.sin()
                * 2.0
                * PI
                * (PI / 2.0 / steps as f64);
        }
        assert!((sum - 1.0).abs() < 1e-3, "alpha {alpha}: {sum}");
    }
}

/// The anisotropic forms reduce to the isotropic ones at zero anisotropy.
#[test]
fn anisotropic_matches_isotropic_at_zero_anisotropy() {
    let n = DVec3::Z;
    let t = DVec3::X;
    let b = n.cross(t);
    let v = DVec3::new(0.3, -0.2, 0.9).normalize();
    let l = DVec3::new(-0.5, 0.4, 0.6).normalize();
    let h = (v + l).normalize();
    let alpha = 0.35;
    let iso = d_ggx(n.dot(h), alpha);
    let aniso = d_ggx_anisotropic(alpha, alpha, t.dot(h), b.dot(h), n.dot(h));
    assert!((iso - aniso).abs() / iso < 1e-12);
    let iso_v = v_smith_ggx_correlated(n.dot(v), n.dot(l), alpha);
    let aniso_v = v_smith_ggx_correlated_anisotropic(
        alpha,
        alpha,
        DVec3::new(t.dot(v), b.dot(v), n.dot(v)),
        DVec3::new(t.dot(l), b.dot(l), n.dot(l)),
    );
    assert!((iso_v - aniso_v).abs() / iso_v < 1e-12);
}

//! Tests of `harness::reference::ibl`.

use engine::scene::EnvironmentImage;
use glam::DVec3;
use harness::reference::ibl::*;
use harness::reference::Surface;

fn surface(base: f64, metallic: f64, roughness: f64, specular: f64) -> Surface {
    Surface {
        position: DVec3::new(0.0, 0.0, -3.0),
        roughness,
        normal: DVec3::new(0.3, 0.0, 1.0).normalize(),
        specular,
        tangent: DVec3::X,
        base_color: DVec3::splat(base),
        anisotropy: 0.0,
        metallic,
        clearcoat: 0.0,
        clearcoat_roughness: 0.0,
        specular_exponent: 0.0,
    }
}

/// Under a uniform environment of radiance 1 the reference reproduces the closed forms: a
/// white Lambert surface returns 1, a white rough metal 1 - mu ln(1 + 1/mu), within 3 of its
/// own standard errors, and those errors are small.
#[test]
fn uniform_environment_closed_forms() {
    let image = EnvironmentImage {
        label: "uniform".into(),
        width: 64,
        height: 32,
        texels: vec![[1.0, 1.0, 1.0, 1.0]; 64 * 32],
    };
    let environment = EnvironmentSampler::new(&image, 30.0, 1.0);
    let lambert = surface(1.0, 0.0, 0.5, 0.0);
    let v = DVec3::Z;
    let (value, error) = integrate(&environment, &lambert, v, 2048, 1);
    assert!(
        (value.x - 1.0).abs() <= 3.0 * error.x + 2e-3,
        "{value} +- {error}"
    );
    let metal = surface(1.0, 1.0, 1.0, 0.5);
    let mu = metal.normal.dot(v);
    let expected = 1.0 - mu * (1.0 + 1.0 / mu).ln();
    let (value, error) = integrate(&environment, &metal, v, 2048, 2);
    // alpha = 1.001 in the BRDF, not 1: allow 0.2% for it.
    assert!(
        (value.x - expected).abs() <= 3.0 * error.x + 2e-3 * expected,
        "{value} +- {error}, expected {expected}"
    );
    assert!(error.x < 5e-3 * expected, "{error}");
}

/// The signed error says which way a pixel misses; the relative error is its size.
#[test]
fn a_pixel_too_bright_has_a_positive_signed_error_and_one_too_dark_a_negative() {
    let reference = |index| PixelReference {
        index,
        surface: surface(0.5, 0.0, 0.5, 0.5),
        radiance: DVec3::splat(1.0),
        standard_error: DVec3::ZERO,
    };
    // Pixel 0 renders 6 (r + g + b against the reference's 3), pixel 1 renders 1.5.
    let light = [2.0, 2.0, 2.0, 1.0, 0.5, 0.5, 0.5, 1.0];
    assert_eq!(signed_pixel_error(&light, &reference(0)), Some(1.0));
    assert_eq!(signed_pixel_error(&light, &reference(1)), Some(-0.5));
    assert_eq!(pixel_error(&light, &reference(1)), Some(0.5));
    assert_eq!(signed_pixel_error(&light, &reference(2)), None);
}

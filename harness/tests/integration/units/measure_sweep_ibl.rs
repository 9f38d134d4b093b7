//! Tests of `harness::measure::sweep::ibl`.

use harness::measure::sweep::ibl::*;

#[test]
fn the_specular_cube_holds_six_rgba16f_faces_per_level_down_to_4x4() {
    let cube = |specular_size| engine::ibl::IblSettings {
        specular_size,
        ..Default::default()
    };
    // 128, 64, 32, 16, 8 and 4: 21,840 texels a face.
    let bytes = 6.0 * 8.0 * 21_840.0;
    assert_eq!(specular_mib(&cube(128)), bytes / f64::from(1u32 << 20));
    assert!((specular_mib(&cube(512)) / specular_mib(&cube(256)) - 4.0).abs() < 1e-3);
}

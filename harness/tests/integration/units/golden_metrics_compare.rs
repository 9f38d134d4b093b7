//! Tests of `harness::golden::metrics::compare`.

use engine::backend::TextureFormat;
use engine::image::{Image, ImageData};
use harness::golden::metrics::compare::*;

fn rgba8(pixels: &[[u8; 4]], width: u32) -> Image {
    Image {
        width,
        height: pixels.len() as u32 / width,
        format: TextureFormat::Rgba8Unorm,
        data: ImageData::U8(pixels.iter().flatten().copied().collect()),
    }
}

fn rgba_f32(pixels: &[[f32; 4]], width: u32) -> Image {
    Image {
        width,
        height: pixels.len() as u32 / width,
        format: TextureFormat::Rgba16Float,
        data: ImageData::F32(pixels.iter().flatten().copied().collect()),
    }
}

#[test]
fn u8_difference_counts_pixels_over_tolerance() {
    let a = rgba8(
        &[
            [10, 10, 10, 255],
            [0, 0, 0, 255],
            [50, 60, 70, 255],
            [1, 2, 3, 4],
        ],
        2,
    );
    let b = rgba8(
        &[
            [11, 10, 10, 255],
            [0, 3, 0, 255],
            [50, 60, 70, 255],
            [1, 2, 3, 4],
        ],
        2,
    );
    let d = u8_difference(&a, &b, 1).unwrap();
    assert_eq!(d.max_abs, 3);
    assert_eq!(d.pixels_over, 1);
    assert!((d.fraction_within - 0.75).abs() < 1e-12);
    assert_eq!(u8_difference(&a, &a, 0).unwrap().fraction_within, 1.0);
}

#[test]
fn relative_difference_finds_the_worst_pixel() {
    let a = rgba_f32(&[[1.0, 2.0, 0.0, 1.0], [4.0, 4.0, 4.0, 1.0]], 2);
    let b = rgba_f32(&[[1.0, 2.0, 0.0, 1.0], [4.0, 4.04, 4.0, 1.0]], 2);
    let d = relative_difference(&a, &b, 1e-3, 1e-3).unwrap();
    assert!((d.max_relative - 0.04 / 4.04).abs() < 1e-6, "{d:?}");
    assert_eq!(d.worst_pixel, (1, 0));
    assert_eq!(d.pixels_over, 1);
    assert!((d.fraction_within - 0.5).abs() < 1e-12);
    assert!(!d.non_finite);
}

#[test]
fn relative_difference_floor_tames_zeros_and_flags_nan() {
    let a = rgba_f32(&[[0.0, 0.0, 0.0, 0.0]], 1);
    let b = rgba_f32(&[[1e-6, 0.0, 0.0, 0.0]], 1);
    let d = relative_difference(&a, &b, 1e-3, 1e-2).unwrap();
    assert!((d.max_relative - 1e-3).abs() < 1e-9, "{d:?}");
    let c = rgba_f32(&[[f32::NAN, 0.0, 0.0, 0.0]], 1);
    assert!(relative_difference(&a, &c, 1e-3, 1e-2).unwrap().non_finite);
}

#[test]
fn mismatched_shapes_are_refused() {
    let a = rgba8(&[[0; 4]; 4], 2);
    let b = rgba8(&[[0; 4]; 4], 4);
    assert!(matches!(
        u8_difference(&a, &b, 0),
        Err(CompareError::Shape { .. })
    ));
    let f = rgba_f32(&[[0.0; 4]; 4], 2);
    assert!(matches!(
        u8_difference(&f, &f, 0),
        Err(CompareError::Kind(_))
    ));
}

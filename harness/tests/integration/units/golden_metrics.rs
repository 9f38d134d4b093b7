//! Tests of `harness::golden::metrics` on synthetic images with known answers.

use engine::{Image, ImageData};

use engine::backend::TextureFormat;
use harness::golden::metrics::*;

fn u8_image(width: u32, height: u32, f: impl Fn(u32, u32) -> [u8; 4]) -> Image {
    let mut data = Vec::new();
    for y in 0..height {
        for x in 0..width {
            data.extend_from_slice(&f(x, y));
        }
    }
    Image {
        width,
        height,
        format: TextureFormat::Rgba8UnormSrgb,
        data: ImageData::U8(data),
    }
}

fn f32_image(width: u32, height: u32, f: impl Fn(u32, u32) -> [f32; 4]) -> Image {
    let mut data = Vec::new();
    for y in 0..height {
        for x in 0..width {
            data.extend_from_slice(&f(x, y));
        }
    }
    Image {
        width,
        height,
        format: TextureFormat::Rgba16Float,
        data: ImageData::F32(data),
    }
}

#[test]
fn identical_images_have_zero_error() {
    let a = u8_image(8, 8, |x, y| [x as u8 * 30, y as u8 * 30, 7, 255]);
    let pair = Pair::new(&a, &a).unwrap();
    assert_eq!(pair.max_abs(0, Channels::All), 0.0);
    assert_eq!(pair.fraction_over(0.0, 0, None, Channels::All), 0.0);
    assert_eq!(pair.rmse(), 0.0);
    assert!(pair.psnr().is_infinite());
    let map = Pair::flip_map(&a, &a).unwrap();
    assert_eq!(flip_stats(&map, 0.99), (0.0, 0.0));
    assert!(pair.identical());
}

#[test]
fn a_flip_map_computed_again_is_the_kept_one_and_equals_nv_flip() {
    let golden = u8_image(24, 16, |x, y| [x as u8 * 9, y as u8 * 13, 40, 255]);
    let actual = u8_image(24, 16, |x, y| {
        [x as u8 * 9 + (x % 3) as u8, y as u8 * 13, 41, 255]
    });
    let rgb = |i: &Image| -> Vec<u8> {
        let ImageData::U8(d) = &i.data else {
            unreachable!()
        };
        d.chunks_exact(4).flat_map(|p| [p[0], p[1], p[2]]).collect()
    };
    let direct = |reference: &Image, test: &Image| {
        nv_flip::flip(
            nv_flip::FlipImageRgb8::with_data(24, 16, &rgb(reference)),
            nv_flip::FlipImageRgb8::with_data(24, 16, &rgb(test)),
            nv_flip::DEFAULT_PIXELS_PER_DEGREE,
        )
        .to_vec()
    };
    let first = Pair::flip_map(&actual, &golden).unwrap();
    assert_eq!(first, direct(&golden, &actual));
    assert!(first.iter().any(|&v| v > 0.0));
    // The second evaluation is the kept map; the swapped pair (FLIP is not symmetric) has its
    // own.
    assert_eq!(Pair::flip_map(&actual, &golden).unwrap(), first);
    assert_eq!(
        Pair::flip_map(&golden, &actual).unwrap(),
        direct(&actual, &golden)
    );
}

#[test]
fn largest_difference_says_where_and_how_many() {
    let golden = u8_image(4, 3, |_, _| [10, 10, 10, 255]);
    let actual = u8_image(4, 3, |x, y| match (x, y) {
        (2, 1) => [10, 30, 10, 255],
        (0, 2) => [12, 10, 10, 255],
        _ => [10, 10, 10, 255],
    });
    let worst = Pair::new(&actual, &golden)
        .unwrap()
        .largest_difference()
        .unwrap();
    assert_eq!((worst.x, worst.y, worst.differing_pixels), (2, 1, 2));
    assert!((worst.difference - 20.0 / 255.0).abs() < 1e-6);
    // Said against the golden's value in that channel too: 20 of 10 is 200%.
    assert!((worst.golden.unwrap() - 10.0 / 255.0).abs() < 1e-6);
    assert_eq!(
        worst.to_string(),
        "2 px differ, the most 7.8431e-2 (200.000% of the golden's 3.9216e-2) at (2, 1)"
    );
    assert_eq!(
        Pair::new(&golden, &golden).unwrap().largest_difference(),
        None
    );
}

#[test]
fn identical_means_bit_for_bit_and_finite() {
    let golden = f32_image(4, 4, |x, y| [x as f32, y as f32, 0.5, 1.0]);
    assert!(Pair::new(&golden, &golden).unwrap().identical());
    let one_off = f32_image(4, 4, |x, y| {
        let z = if (x, y) == (3, 3) { 0.5000001 } else { 0.5 };
        [x as f32, y as f32, z, 1.0]
    });
    assert!(!Pair::new(&one_off, &golden).unwrap().identical());
    // -0.0 equals 0.0 in value but not in bits: not called identical (the metrics say 0).
    let zero = f32_image(1, 1, |_, _| [0.0; 4]);
    let negative_zero = f32_image(1, 1, |_, _| [-0.0; 4]);
    assert!(!Pair::new(&negative_zero, &zero).unwrap().identical());
    let nan = f32_image(1, 1, |_, _| [f32::NAN; 4]);
    assert!(!Pair::new(&nan, &nan).unwrap().identical());
}

#[test]
fn known_differences_give_known_numbers() {
    // 10 of 100 pixels differ by 51/255 = 0.2 in red only.
    let golden = u8_image(10, 10, |_, _| [100, 100, 100, 255]);
    let actual = u8_image(10, 10, |x, _| {
        [if x == 3 { 151 } else { 100 }, 100, 100, 255]
    });
    let pair = Pair::new(&actual, &golden).unwrap();
    assert!((pair.max_abs(0, Channels::All) - 0.2).abs() < 1e-6);
    assert_eq!(pair.max_abs_per_channel()[1], 0.0);
    assert!((pair.fraction_over(0.1, 0, None, Channels::All) - 0.1).abs() < 1e-12);
    assert_eq!(pair.fraction_over(0.25, 0, None, Channels::All), 0.0);
    // RMSE: 10 of 400 values off by 0.2 -> sqrt(10 * 0.04 / 400) = sqrt(0.001).
    assert!((pair.rmse() - 0.001f64.sqrt()).abs() < 1e-6);
    assert!((pair.psnr() - 30.0).abs() < 1e-3);
}

#[test]
fn shift_radius_forgives_a_one_pixel_edge_move() {
    let golden = u8_image(16, 4, |x, _| if x < 8 { [0; 4] } else { [255; 4] });
    let actual = u8_image(16, 4, |x, _| if x < 9 { [0; 4] } else { [255; 4] });
    let pair = Pair::new(&actual, &golden).unwrap();
    assert!((pair.fraction_over(0.5, 0, None, Channels::All) - 4.0 / 64.0).abs() < 1e-12);
    assert_eq!(pair.fraction_over(0.5, 1, None, Channels::All), 0.0);
    assert_eq!(pair.max_abs(1, Channels::All), 0.0);
}

#[test]
fn relative_error_uses_an_absolute_floor_for_dark_pixels() {
    let golden = f32_image(2, 1, |x, _| if x == 0 { [100.0; 4] } else { [0.0; 4] });
    let actual = f32_image(2, 1, |x, _| if x == 0 { [101.0; 4] } else { [0.05; 4] });
    let pair = Pair::new(&actual, &golden).unwrap();
    // RGB only: 6 values. Bright pixel: 1/100; dark pixel: 0.05 / floor 0.1 = 0.5, however
    // bright the rest of the image is.
    let errors = pair.relative_errors(0.1, Channels::Rgb);
    assert_eq!(errors.len(), 6);
    assert!((errors[0] - 0.01).abs() < 1e-9);
    assert!((errors[5] - 0.5).abs() < 1e-6);
    assert!((pair.relative_percentile(0.5, 0.1, Channels::Rgb) - 0.01).abs() < 1e-9);
    // A sun 1000x brighter elsewhere does not change the dark pixel's error.
    let sunny = f32_image(3, 1, |x, _| match x {
        0 => [100.0; 4],
        1 => [0.0; 4],
        _ => [1e5; 4],
    });
    let sunny_actual = f32_image(3, 1, |x, _| match x {
        0 => [101.0; 4],
        1 => [0.05; 4],
        _ => [1e5; 4],
    });
    let pair = Pair::new(&sunny_actual, &sunny).unwrap();
    assert!((pair.relative_percentile(1.0, 0.1, Channels::Rgb) - 0.5).abs() < 1e-6);
}

#[test]
fn channels_and_relative_fraction_over() {
    // Alpha differs everywhere, RGB on one pixel of four by 2% relative.
    let golden = f32_image(4, 1, |_, _| [2.0, 2.0, 2.0, 1.0]);
    let actual = f32_image(4, 1, |x, _| {
        let v = if x == 0 { 2.04 } else { 2.0 };
        [v, 2.0, 2.0, 2.0]
    });
    let pair = Pair::new(&actual, &golden).unwrap();
    assert_eq!(pair.fraction_over(0.5, 0, None, Channels::All), 1.0);
    assert_eq!(pair.fraction_over(0.5, 0, None, Channels::Rgb), 0.0);
    // Relative above a floor of 1: 0.04 / 2 = 2%.
    assert_eq!(pair.fraction_over(0.01, 0, Some(1.0), Channels::Rgb), 0.25);
    assert_eq!(pair.fraction_over(0.03, 0, Some(1.0), Channels::Rgb), 0.0);
    // Below the floor the error is absolute / floor: 0.04 / 4 = 1%.
    assert_eq!(pair.fraction_over(0.011, 0, Some(4.0), Channels::Rgb), 0.0);
    assert!((pair.max_abs(0, Channels::Rgb) - 0.04).abs() < 1e-6);
}

#[test]
fn non_finite_values_are_counted_and_make_errors_infinite() {
    let golden = f32_image(2, 1, |_, _| [1.0; 4]);
    let actual = f32_image(2, 1, |x, _| {
        if x == 0 {
            [f32::NAN, 1.0, 1.0, 1.0]
        } else {
            [1.0; 4]
        }
    });
    let pair = Pair::new(&actual, &golden).unwrap();
    assert_eq!(pair.non_finite(), 1);
    assert!(pair.max_abs(0, Channels::All).is_infinite());
    assert!(pair
        .relative_percentile(1.0, 1e-3, Channels::Rgb)
        .is_infinite());
}

#[test]
fn flip_grows_with_the_difference() {
    let golden = u8_image(32, 32, |x, y| [(x * 6) as u8, (y * 8) as u8, 128, 255]);
    let small = u8_image(32, 32, |x, y| [(x * 6) as u8 + 2, (y * 8) as u8, 128, 255]);
    let large = u8_image(32, 32, |x, y| [(x * 6) as u8 + 40, (y * 8) as u8, 128, 255]);
    let (small_mean, _) = flip_stats(&Pair::flip_map(&small, &golden).unwrap(), 0.99);
    let (large_mean, _) = flip_stats(&Pair::flip_map(&large, &golden).unwrap(), 0.99);
    assert!(small_mean > 0.0 && small_mean < 0.05, "{small_mean}");
    assert!(
        large_mean > 3.0 * small_mean,
        "{small_mean} vs {large_mean}"
    );
}

#[test]
fn mismatched_sizes_are_an_error() {
    let a = u8_image(2, 2, |_, _| [0; 4]);
    let b = u8_image(3, 2, |_, _| [0; 4]);
    assert!(Pair::new(&a, &b).is_err());
}

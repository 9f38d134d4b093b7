//! Tests of `harness::golden::portability::rounding`.

use engine::assets::linear_to_srgb_u8;
use engine::scene::ToneMap;
use engine::{Image, ImageData};
use harness::golden::portability::rounding::*;

#[test]
fn ulp_steps_move_by_one_representable_value() {
    for fp16 in [true, false] {
        for x in [0.0f32, 1.0, -1.0, 0.1, 123.4, -7e-3] {
            let up = step_ulps(x, 1, fp16);
            let down = step_ulps(x, -1, fp16);
            assert!(up > x && down < x, "{x}: {down} {up} (fp16 {fp16})");
            if fp16 {
                let h = half::f16::from_f32(x).to_f32();
                assert_eq!(step_ulps(up, -1, true), h, "{x}");
                assert!(((up - h) / h.abs().max(1e-4)).abs() < 2e-3, "{x}: {up}");
            } else {
                assert_eq!(step_ulps(up, -1, false), x);
                if x > 0.0 {
                    assert_eq!(up, f32::from_bits(x.to_bits() + 1));
                }
            }
        }
    }
    assert_eq!(step_ulps(0.0, 1, false), f32::from_bits(1));
    assert_eq!(step_ulps(0.0, -1, false), -f32::from_bits(1));
    assert!(step_ulps(f32::NAN, 1, true).is_nan());
    assert_eq!(step_ulps(65504.0, 1, true), 65504.0);
}

#[test]
fn ulp_noise_is_seeded_and_moves_about_two_thirds_of_the_values() {
    let image = Image {
        width: 64,
        height: 64,
        format: engine::backend::TextureFormat::Rgba16Float,
        data: ImageData::F32(vec![0.75; 64 * 64 * 4]),
    };
    let a = ulp_noise(&image, 7);
    assert_eq!(a, ulp_noise(&image, 7));
    assert_ne!(a, ulp_noise(&image, 8));
    let values = a.as_f32().unwrap();
    let moved = values.iter().filter(|&&v| v != 0.75).count() as f64 / values.len() as f64;
    assert!((moved - 2.0 / 3.0).abs() < 0.03, "{moved}");
    assert!(values
        .iter()
        .all(|&v| ((v - 0.75) / 0.75).abs() <= 2f32.powi(-11) * 1.34));
}

#[test]
fn requantized_final_follows_the_exact_curve() {
    // A gradient through the whole ACES range: the f64 evaluation rounds exactly.
    let n = 4096;
    let light = Image {
        width: n as u32,
        height: 1,
        format: engine::backend::TextureFormat::Rgba16Float,
        data: ImageData::F32((0..n).flat_map(|i| [i as f32 / 256.0; 4]).collect()),
    };
    let f = requantize_final(&light, ToneMap::Aces);
    let values = f.as_u8().unwrap();
    assert_eq!(values[0], 0);
    assert_eq!(values[(n - 1) * 4], 255);
    // Mid-grey 0.18 -> ACES 0.26690 -> sRGB 0.55346 -> 141.13 -> 141.
    assert!((tone_map(0.18, ToneMap::Aces) - 0.266_899).abs() < 1e-6);
    // sRGB 0.553457 x 255 = 141.13.
    assert_eq!(linear_to_srgb_u8(0.266_899), 141);
    let grey = requantize_final(
        &Image {
            width: 1,
            height: 1,
            format: engine::backend::TextureFormat::Rgba16Float,
            data: ImageData::F32(vec![0.18, 0.18, 0.18, 1.0]),
        },
        ToneMap::Aces,
    );
    // 0.18 in fp16 storage is 0.17993, still 141.
    assert_eq!(grey.as_u8().unwrap(), [141, 141, 141, 255]);
}

//! Texture decoding and CPU mip chain correctness.

use crate::common::fixture;
use engine::assets::{
    generate_mips, generate_mips_f32, load_texture, load_texture_with_limits, ColorSpace, Limits,
    TexelFormat,
};

/// R = 16x + 64y, G = 255 - R, B = 7, A = 255 except (3,3) = 0.
fn ramp() -> Vec<u8> {
    let mut v = Vec::new();
    for y in 0..4u32 {
        for x in 0..4u32 {
            let r = (16 * x + 64 * y) as u8;
            v.extend_from_slice(&[r, 255 - r, 7, if (x, y) == (3, 3) { 0 } else { 255 }]);
        }
    }
    v
}

#[test]
fn linear_mips_of_known_4x4() {
    let mips = generate_mips(4, 4, &ramp(), ColorSpace::Linear);
    assert_eq!(mips.len(), 3);
    assert_eq!(mips[0], ramp());
    #[rustfmt::skip]
    let level1 = vec![
        40, 215, 7, 255,   72, 183, 7, 255,
        168, 87, 7, 255,   200, 55, 7, 191,
    ];
    assert_eq!(mips[1], level1);
    assert_eq!(mips[2], vec![120, 135, 7, 239]);
}

#[test]
fn png_decode_matches_in_memory_mips() {
    let tex = load_texture(&fixture("textures/ramp4x4.png"), ColorSpace::Linear).unwrap();
    assert_eq!((tex.width, tex.height), (4, 4));
    assert_eq!(tex.mips, generate_mips(4, 4, &ramp(), ColorSpace::Linear));
    assert_eq!(tex.mip_size(1), (2, 2));
}

#[test]
fn srgb_averages_in_linear_light() {
    // Black/white pairs: linear average 128, sRGB average of 0.5 linear = 188.
    let img = [0, 0, 0, 255, 255, 255, 255, 255];
    let lin = generate_mips(2, 1, &img, ColorSpace::Linear);
    let srgb = generate_mips(2, 1, &img, ColorSpace::Srgb);
    assert_eq!(lin[1], vec![128, 128, 128, 255]);
    assert_eq!(srgb[1], vec![188, 188, 188, 255]);
    // Checker PNG decoded as sRGB: every level below 0 is uniform 188.
    let tex = load_texture(&fixture("textures/checker.png"), ColorSpace::Srgb).unwrap();
    assert!(tex.mips[1].chunks(4).all(|p| p == [188, 188, 188, 255]));
    assert_eq!(tex.mips[2], vec![188, 188, 188, 255]);
}

#[test]
fn srgb_uniform_images_are_stable() {
    for v in 0..=255u8 {
        let img: Vec<u8> = [v, v, v, v].repeat(4);
        let mips = generate_mips(2, 2, &img, ColorSpace::Srgb);
        assert_eq!(mips[1], vec![v, v, v, v], "value {v}");
    }
}

/// An odd size is box filtered over the whole area: no row or column is dropped. (Before, the
/// 2x2 box dropped the last column and row: level 1 of this 5x3 texture was [25, 50] and
/// [125, 50], as if x = 4 and y = 2 did not exist.)
#[test]
fn odd_sizes_are_box_filtered_over_every_texel_and_reach_1x1() {
    let tex = load_texture(&fixture("textures/odd5x3.png"), ColorSpace::Linear).unwrap();
    let sizes: Vec<_> = (0..tex.mips.len()).map(|l| tex.mip_size(l)).collect();
    assert_eq!(sizes, [(5, 3), (2, 1), (1, 1)]);
    for (level, data) in tex.mips.iter().enumerate() {
        let (w, h) = tex.mip_size(level);
        assert_eq!(data.len(), (w * h * 4) as usize);
    }
    // 5 -> 2 columns: texel 0 covers x in [0, 2.5): weights 0.4, 0.4, 0.2 on R = 0, 50, 100;
    // texel 1 covers [2.5, 5): 0.2, 0.4, 0.4 on R = 100, 150, 200. 3 -> 1 rows: a third each
    // of G = 0, 100, 200.
    assert_eq!(tex.mips[1], [40, 100, 0, 255, 160, 100, 0, 255]);
    // 2x1 -> 1x1: the mean of the two.
    assert_eq!(tex.mips[2], [100, 100, 0, 255]);
    // A 1-texel-wide column: x is clamped, y is box filtered.
    let col = generate_mips(1, 2, &[10, 0, 0, 255, 20, 0, 0, 255], ColorSpace::Linear);
    assert_eq!(col[1], vec![15, 0, 0, 255]);
}

#[test]
fn mips_are_deterministic() {
    let a = load_texture(&fixture("textures/checker.png"), ColorSpace::Srgb).unwrap();
    let b = load_texture(&fixture("textures/checker.png"), ColorSpace::Srgb).unwrap();
    assert_eq!(a.mips, b.mips);
}

#[test]
fn texture_errors_name_the_file() {
    let e = load_texture(&fixture("textures/corrupt.png"), ColorSpace::Srgb).unwrap_err();
    assert!(
        e.to_string().contains("corrupt.png: cannot decode image"),
        "{e}"
    );
    let e = load_texture(&fixture("textures/absent.png"), ColorSpace::Srgb).unwrap_err();
    assert!(
        e.to_string().contains("absent.png: cannot read file"),
        "{e}"
    );
}

/// A texture is checked against its limits from its header, before it is decoded, with errors
/// that name the limit; within them, the decoder adds no limit of its own (the `image` crate's
/// default of 512 MiB refused a 16384x16384 texture the default limits allow, as "Memory limit
/// exceeded").
#[test]
fn a_texture_over_its_limits_is_refused_naming_the_limit() {
    let checker = fixture("textures/checker.png");
    let limits = |side, bytes| Limits {
        max_texture_side: side,
        max_total_bytes: bytes,
        ..Limits::DEFAULT
    };
    let e = load_texture_with_limits(&checker, ColorSpace::Srgb, limits(1, u64::MAX)).unwrap_err();
    assert!(e.to_string().contains("is above the limit of 1"), "{e}");
    let e = load_texture_with_limits(&checker, ColorSpace::Srgb, limits(16384, 10)).unwrap_err();
    assert!(
        e.to_string().contains("total decoded bytes") && e.to_string().contains("limit of 10"),
        "{e}"
    );
    let within = load_texture_with_limits(&checker, ColorSpace::Srgb, Limits::DEFAULT).unwrap();
    assert_eq!(
        within.mips,
        load_texture(&checker, ColorSpace::Srgb).unwrap().mips
    );
    let e = load_texture(&fixture("textures/too_wide_16385x1.png"), ColorSpace::Srgb).unwrap_err();
    assert!(e.to_string().contains("above the limit of 16384"), "{e}");
}

/// An odd size in sRGB averages in linear light, like the even sizes: 3x1 of 0, 255, 0 gives
/// the sRGB encoding of one third.
#[test]
fn odd_srgb_sizes_average_in_linear_light() {
    let row = [0, 0, 0, 255, 255, 255, 255, 255, 0, 0, 0, 255];
    let mips = generate_mips(3, 1, &row, ColorSpace::Srgb);
    let third = engine::assets::linear_to_srgb_u8(1.0 / 3.0);
    assert_eq!(mips[1], [third, third, third, 255]);
    let floats = generate_mips_f32(3, 1, vec![[0.0; 4], [1.0; 4], [0.0; 4]]);
    assert!((floats[1][0][0] - 1.0 / 3.0).abs() < 1e-7);
}

/// JPEG, TGA and BMP fixtures (written by another encoder, Pillow) decode to the gradient they
/// hold: R = 32x, G = 64y, B = 100 on 8x4 (JPEG within its loss).
#[test]
fn jpeg_tga_and_bmp_textures_load() {
    for (file, tolerance) in [
        ("textures/gradient.jpg", 12),
        ("textures/gradient.tga", 0),
        ("textures/gradient.bmp", 0),
    ] {
        let tex = load_texture(&fixture(file), ColorSpace::Linear)
            .unwrap_or_else(|e| panic!("{file}: {e}"));
        assert_eq!((tex.width, tex.height, tex.bits()), (8, 4, 8), "{file}");
        assert_eq!(tex.format, TexelFormat::Rgba8, "{file}");
        assert_eq!(tex.mips.len(), 4, "{file}");
        for y in 0..4u32 {
            for x in 0..8u32 {
                let at = ((y * 8 + x) * 4) as usize;
                let texel = &tex.mips[0][at..at + 4];
                let expected = [32 * x, 64 * y, 100, 255];
                for (got, want) in texel.iter().zip(expected) {
                    assert!(
                        (i64::from(*got) - i64::from(want)).abs() <= tolerance,
                        "{file} ({x}, {y}): {texel:?} against {expected:?}"
                    );
                }
            }
        }
    }
}

/// A 16-bit PNG keeps more than 8 bits: its values 32768, 32800, 32832 and 32896 (all 128 in
/// 8 bits) stay four different values, each within half an f16 step of value / 65535.
#[test]
fn sixteen_bit_png_keeps_its_precision() {
    let tex = load_texture(&fixture("textures/fine16.png"), ColorSpace::Linear).unwrap();
    assert_eq!((tex.width, tex.height, tex.bits()), (4, 1, 16));
    assert_eq!(tex.format, TexelFormat::Rgba16Float);
    let reds: Vec<f32> = tex.mips[0]
        .chunks_exact(8)
        .map(|texel| half::f16::from_le_bytes([texel[0], texel[1]]).to_f32())
        .collect();
    for (red, value) in reds.iter().zip([32768.0f32, 32800.0, 32832.0, 32896.0]) {
        // f16 has a step of 2^-11 between 0.5 and 1.
        assert!(
            (red - value / 65535.0).abs() <= 2f32.powi(-12),
            "{red} for {value}"
        );
    }
    let mut distinct = reds.clone();
    distinct.dedup();
    assert_eq!(distinct.len(), 4, "{reds:?}");
    // Alpha (none in the file) is 1; the mip chain goes down to 1x1.
    assert_eq!(
        half::f16::from_le_bytes([tex.mips[0][6], tex.mips[0][7]]).to_f32(),
        1.0
    );
    assert_eq!(tex.mips.len(), 3);
}

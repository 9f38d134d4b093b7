//! Texture decoding and CPU mip chain correctness.

mod common;

use common::fixture;
use engine::assets::{generate_mips, load_texture, ColorSpace};

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

#[test]
fn odd_sizes_clamp_and_reach_1x1() {
    let tex = load_texture(&fixture("textures/odd5x3.png"), ColorSpace::Linear).unwrap();
    let sizes: Vec<_> = (0..tex.mips.len()).map(|l| tex.mip_size(l)).collect();
    assert_eq!(sizes, [(5, 3), (2, 1), (1, 1)]);
    for (level, data) in tex.mips.iter().enumerate() {
        let (w, h) = tex.mip_size(level);
        assert_eq!(data.len(), (w * h * 4) as usize);
    }
    // Level 1 texel (0,0) averages x 0..1, y 0..1: R = (0+50+0+50)/4, G = (0+0+100+100)/4.
    assert_eq!(&tex.mips[1][..4], &[25, 50, 0, 255]);
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

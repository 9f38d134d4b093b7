//! The four board textures (albedo, roughness, normal, clearcoat), sampled from the wood
//! model and encoded as PNG.

use image::ExtendedColorType;

use crate::math::{add, lerp, normalize, scale, sub, Vec3};
use crate::noise::pcg;
use crate::texture_encoding::{byte, png};
use crate::wood::{nearest_joint, wood_grain, wood_site};

/// Half width of the joint grooves and gaps, texture space.
pub(crate) const JOINT_HALF_WIDTH: f64 = 0.0055;

/// sRGB albedo (0..255) at (u, v).
pub(crate) fn albedo(u: f64, v: f64) -> Vec3 {
    let site = wood_site(u, v);
    let (late, fibre) = wood_grain(&site, site.along, site.across);
    let (early_colour, late_colour) = site.wood.colours();
    let colour = add(early_colour, scale(sub(late_colour, early_colour), late));
    let tint = if site.in_play {
        0.95 + 0.1 * f64::from(pcg(site.seed ^ 5)) / f64::from(u32::MAX)
    } else {
        1.0
    };
    let mut shade = tint * (0.92 + 0.16 * fibre);
    let (d, _) = nearest_joint(u, v);
    shade *= 1.0 - 0.35 * (1.0 - d / (0.45 * JOINT_HALF_WIDTH)).max(0.0);
    scale(colour, shade)
}

/// Linear roughness at (u, v).
pub(crate) fn roughness(u: f64, v: f64) -> f64 {
    let site = wood_site(u, v);
    let (late, fibre) = wood_grain(&site, site.along, site.across);
    let r = site.wood.roughness() + 0.08 * (late - 0.5) + 0.04 * (fibre - 0.5);
    let (d, _) = nearest_joint(u, v);
    lerp(r, 0.65, (1.0 - d / (0.75 * JOINT_HALF_WIDTH)).max(0.0))
}

/// Tangent-space normal (+X along u, +Y along v, +Z out) at (u, v).
pub(crate) fn tangent_normal(u: f64, v: f64) -> Vec3 {
    let site = wood_site(u, v);
    let height = |along: f64, across: f64| {
        let (late, fibre) = wood_grain(&site, along, across);
        -1.2e-4 * late + 2.0e-5 * fibre
    };
    let step = 2.0e-4;
    let h0 = height(site.along, site.across);
    let dh_along = (height(site.along + step, site.across) - h0) / step;
    let dh_across = (height(site.along, site.across + step) - h0) / step;
    let mut gu = dh_along * site.dir_along[0] + dh_across * site.dir_across[0];
    let mut gv = dh_along * site.dir_along[1] + dh_across * site.dir_across[1];
    // V-groove: the surface falls towards the joint with slope 0.5 (about 27°).
    let (d, away) = nearest_joint(u, v);
    if d < JOINT_HALF_WIDTH {
        gu += 0.5 * away[0];
        gv += 0.5 * away[1];
    }
    normalize([-gu, -gv, 1.0])
}

/// Samples `f(u, v)` over a `size` x `size` texture, averaging `ss` x `ss` points per texel.
/// Row 0 is the top of the image (v = 1).
pub(crate) fn sample_texture(size: u32, ss: u32, f: impl Fn(f64, f64) -> Vec3) -> Vec<Vec3> {
    let n = f64::from(size);
    let k = f64::from(ss);
    let mut out = Vec::with_capacity((size * size) as usize);
    for py in 0..size {
        for px in 0..size {
            let mut sum = [0.0; 3];
            for sy in 0..ss {
                for sx in 0..ss {
                    let u = (f64::from(px) + (f64::from(sx) + 0.5) / k) / n;
                    let v = 1.0 - (f64::from(py) + (f64::from(sy) + 0.5) / k) / n;
                    sum = add(sum, f(u, v));
                }
            }
            out.push(scale(sum, 1.0 / (k * k)));
        }
    }
    out
}

/// The four board textures: `(file name, PNG bytes, size)`.
pub(crate) fn board_textures() -> Vec<(&'static str, Vec<u8>, u32)> {
    let albedo_px: Vec<u8> = sample_texture(512, 2, albedo)
        .iter()
        .flat_map(|c| c.map(byte))
        .collect();
    let gray = |f: fn(f64, f64) -> f64, ss: u32| -> Vec<u8> {
        sample_texture(256, ss, |u, v| [f(u, v), 0.0, 0.0])
            .iter()
            .map(|c| byte(c[0] * 255.0))
            .collect()
    };
    let normal_px: Vec<u8> = sample_texture(256, 4, tangent_normal)
        .iter()
        .flat_map(|n| normalize(*n).map(|x| byte((x * 0.5 + 0.5) * 255.0)))
        .collect();
    let clearcoat = |u: f64, v: f64| if wood_site(u, v).in_play { 0.9 } else { 0.7 };
    vec![
        (
            "board_albedo.png",
            png(512, &albedo_px, ExtendedColorType::Rgb8),
            512,
        ),
        (
            "board_roughness.png",
            png(256, &gray(roughness, 2), ExtendedColorType::L8),
            256,
        ),
        (
            "board_normal.png",
            png(256, &normal_px, ExtendedColorType::Rgb8),
            256,
        ),
        (
            "board_clearcoat.png",
            png(256, &gray(clearcoat, 1), ExtendedColorType::L8),
            256,
        ),
    ]
}

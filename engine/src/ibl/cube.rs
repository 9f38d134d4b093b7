//! CPU cube maps: face layout, direction <-> texel mapping, bilinear and trilinear lookups, and
//! the equirectangular-to-cube conversion.
//!
//! Faces follow the OpenGL/Vulkan cube-map convention (+X, -X, +Y, -Y, +Z, -Z; texel row 0 is
//! `t = 0`), so the texels upload unchanged to both APIs and sample the same there as here.

use glam::Vec3;

use crate::scene::EnvironmentImage;

/// One mip level of a cube map: six square faces of `size` x `size` RGB texels, face-major,
/// rows top (t = 0) first.
#[derive(Clone, Debug, PartialEq)]
pub struct CubeLevel {
    /// Face side in texels.
    pub size: u32,
    /// `6 * size * size` linear RGB texels.
    pub texels: Vec<[f32; 3]>,
}

/// A cube map with its mip chain (level 0 first).
#[derive(Clone, Debug, PartialEq)]
pub struct CubeMap {
    /// Levels, each half the size of the one before.
    pub levels: Vec<CubeLevel>,
}

/// `x.floor()` for the texel coordinates of a lookup (|x| far below 2^24), without the libm
/// call that `f32::floor` compiles to on the x86-64 baseline (no SSE4.1 `roundss`): the same
/// value, -0 and NaN included.
fn floor(x: f32) -> f32 {
    let truncated = x as i64 as f32;
    if truncated > x {
        truncated - 1.0
    } else if truncated < x {
        truncated
    } else {
        x // whole (keeping -0), or NaN
    }
}

/// Direction through face coordinates `(u, v)` in -1..1 of `face`.
pub fn face_direction(face: usize, u: f32, v: f32) -> Vec3 {
    match face {
        0 => Vec3::new(1.0, -v, -u),
        1 => Vec3::new(-1.0, -v, u),
        2 => Vec3::new(u, 1.0, v),
        3 => Vec3::new(u, -1.0, -v),
        4 => Vec3::new(u, -v, 1.0),
        _ => Vec3::new(-u, -v, -1.0),
    }
}

/// Face and face coordinates (-1..1) a direction goes through (the inverse of
/// [`face_direction`]).
pub fn direction_face(d: Vec3) -> (usize, f32, f32) {
    let a = d.abs();
    if a.x >= a.y && a.x >= a.z {
        if d.x > 0.0 {
            (0, -d.z / a.x, -d.y / a.x)
        } else {
            (1, d.z / a.x, -d.y / a.x)
        }
    } else if a.y >= a.z {
        if d.y > 0.0 {
            (2, d.x / a.y, d.z / a.y)
        } else {
            (3, d.x / a.y, -d.z / a.y)
        }
    } else if d.z > 0.0 {
        (4, d.x / a.z, -d.y / a.z)
    } else {
        (5, -d.x / a.z, -d.y / a.z)
    }
}

/// Unit direction through the center of texel `(x, y)` of `face` at face size `size`.
pub fn texel_direction(face: usize, x: u32, y: u32, size: u32) -> Vec3 {
    let u = (x as f32 + 0.5) / size as f32 * 2.0 - 1.0;
    let v = (y as f32 + 0.5) / size as f32 * 2.0 - 1.0;
    face_direction(face, u, v).normalize()
}

/// Solid angle of texel `(x, y)` of a face of side `size` (exact, from the area of the
/// projected square on the unit cube).
pub fn texel_solid_angle(x: u32, y: u32, size: u32) -> f32 {
    fn corner(u: f64, v: f64) -> f64 {
        (u * v).atan2((u * u + v * v + 1.0).sqrt())
    }
    let step = 2.0 / f64::from(size);
    let (u0, v0) = (f64::from(x) * step - 1.0, f64::from(y) * step - 1.0);
    let (u1, v1) = (u0 + step, v0 + step);
    (corner(u0, v0) - corner(u0, v1) - corner(u1, v0) + corner(u1, v1)) as f32
}

impl CubeLevel {
    /// A level of `size` filled by `f(face, x, y)`.
    pub fn from_fn(size: u32, f: impl Fn(usize, u32, u32) -> [f32; 3] + Sync) -> Self {
        let n = size as usize;
        let texels = super::parallel_map(6 * n * n, |i| {
            let face = i / (n * n);
            let within = i % (n * n);
            f(face, (within % n) as u32, (within / n) as u32)
        });
        Self { size, texels }
    }

    fn texel(&self, face: usize, x: i64, y: i64) -> [f32; 3] {
        let n = i64::from(self.size);
        let (x, y) = (x.clamp(0, n - 1), y.clamp(0, n - 1));
        self.texels[face * (n * n) as usize + (y * n + x) as usize]
    }

    /// Bilinear lookup at face coordinates (from [`direction_face`]; edges clamp within the
    /// face). A lookup of one direction in several levels projects it once.
    fn sample_face(&self, (face, u, v): (usize, f32, f32)) -> [f32; 3] {
        let n = self.size as f32;
        let fx = (u + 1.0) * 0.5 * n - 0.5;
        let fy = (v + 1.0) * 0.5 * n - 0.5;
        let (x0, y0) = (floor(fx), floor(fy));
        let (tx, ty) = (fx - x0, fy - y0);
        // The four texels' indices within the face, clamped to its edges.
        let last = i64::from(self.size) - 1;
        let (x0, y0) = (x0 as i64, y0 as i64);
        let columns = [x0.clamp(0, last) as usize, (x0 + 1).clamp(0, last) as usize];
        let rows = [y0.clamp(0, last) as usize, (y0 + 1).clamp(0, last) as usize];
        let side = self.size as usize;
        let face = &self.texels[face * side * side..(face + 1) * side * side];
        let mut out = [0.0; 3];
        for (dx, dy, w) in [
            (0, 0, (1.0 - tx) * (1.0 - ty)),
            (1, 0, tx * (1.0 - ty)),
            (0, 1, (1.0 - tx) * ty),
            (1, 1, tx * ty),
        ] {
            let t = face[rows[dy] * side + columns[dx]];
            for c in 0..3 {
                out[c] += t[c] * w;
            }
        }
        out
    }

    /// The level half this size: each texel the mean of the four it covers.
    pub fn downsampled(&self) -> Self {
        let half = (self.size / 2).max(1);
        Self::from_fn(half, |face, x, y| {
            let mut sum = [0.0; 3];
            for (dx, dy) in [(0, 0), (1, 0), (0, 1), (1, 1)] {
                let t = self.texel(face, i64::from(2 * x + dx), i64::from(2 * y + dy));
                for c in 0..3 {
                    sum[c] += t[c] * 0.25;
                }
            }
            sum
        })
    }
}

impl CubeMap {
    /// `base` and its box-filtered mips down to `smallest` texels a side.
    pub fn with_mips(base: CubeLevel, smallest: u32) -> Self {
        let mut levels = vec![base];
        while let Some(last) = levels.last().filter(|l| l.size / 2 >= smallest.max(1)) {
            let next = last.downsampled();
            levels.push(next);
        }
        Self { levels }
    }

    /// The two levels and the blend between them that a lookup at `lod` reads (clamped to the
    /// chain): worked out once for a lod that many lookups share.
    pub fn lod(&self, lod: f32) -> Lod {
        let top = (self.levels.len() - 1) as f32;
        let lod = lod.clamp(0.0, top);
        let lower = floor(lod) as usize;
        Lod {
            lower,
            upper: (lower + 1).min(self.levels.len() - 1),
            t: lod - lower as f32,
        }
    }

    /// Trilinear lookup of direction `d` at a [`CubeMap::lod`] of this map.
    pub fn sample_at(&self, d: Vec3, lod: Lod) -> [f32; 3] {
        let at = direction_face(d);
        let a = self.levels[lod.lower].sample_face(at);
        if lod.t == 0.0 {
            return a;
        }
        let b = self.levels[lod.upper].sample_face(at);
        [0, 1, 2].map(|c| a[c] + (b[c] - a[c]) * lod.t)
    }
}

/// Where a trilinear lookup reads a [`CubeMap`]: two adjacent levels and the weight of the upper
/// one.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Lod {
    lower: usize,
    upper: usize,
    t: f32,
}

/// Equirectangular convention shared with `skybox.wgsl`: `u = 0.5 + atan2(d.x, -d.z) / 2pi`,
/// `v = acos(d.y) / pi` (north pole at the top row).
pub fn equirect_uv(d: Vec3) -> (f32, f32) {
    let u = 0.5 + d.x.atan2(-d.z) / std::f32::consts::TAU;
    let v = d.y.clamp(-1.0, 1.0).acos() / std::f32::consts::PI;
    (u, v)
}

/// Bilinear lookup of an equirectangular image (wrapping in u, clamping in v).
pub fn sample_equirect(image: &EnvironmentImage, d: Vec3) -> [f32; 3] {
    let mut out = [0.0; 3];
    for (texel, weight) in equirect_footprint(image, equirect_uv(d)) {
        for c in 0..3 {
            out[c] += texel[c] * weight;
        }
    }
    out
}

/// The four texels a bilinear lookup of an equirectangular image at texture coordinates
/// `(u, v)` reads (wrapping in u, clamping in v), each with its weight: what
/// [`sample_equirect`] sums, for a caller that needs the texels too (how far a GPU's
/// fixed-point filter weights may move the result depends on their spread; the sky test takes
/// `(u, v)` as skybox.wgsl computes them).
pub fn equirect_footprint(image: &EnvironmentImage, (u, v): (f32, f32)) -> [([f32; 4], f32); 4] {
    let (w, h) = (image.width as i64, image.height as i64);
    let fx = u * w as f32 - 0.5;
    let fy = v * h as f32 - 0.5;
    let (x0, y0) = (floor(fx), floor(fy));
    let (tx, ty) = (fx - x0, fy - y0);
    [
        (0, 0, (1.0 - tx) * (1.0 - ty)),
        (1, 0, tx * (1.0 - ty)),
        (0, 1, (1.0 - tx) * ty),
        (1, 1, tx * ty),
    ]
    .map(|(dx, dy, weight)| {
        let x = (x0 as i64 + dx).rem_euclid(w);
        let y = (y0 as i64 + dy).clamp(0, h - 1);
        (image.texels[(y * w + x) as usize], weight)
    })
}

/// Supersampling of the equirectangular image per cube texel (4 x 4), so that a small bright sun
/// lands in the cube with its energy instead of being hit or missed by one lookup.
const SUPERSAMPLES: u32 = 4;

/// The environment as a cube level of side `size` (each texel the mean of 4 x 4 bilinear lookups
/// spread over it). Non-finite or negative texels count as zero.
pub fn cube_from_equirect(image: &EnvironmentImage, size: u32) -> CubeLevel {
    CubeLevel::from_fn(size, |face, x, y| {
        let mut sum = [0.0f32; 3];
        let n = SUPERSAMPLES;
        for sy in 0..n {
            for sx in 0..n {
                let u = (x as f32 + (sx as f32 + 0.5) / n as f32) / size as f32 * 2.0 - 1.0;
                let v = (y as f32 + (sy as f32 + 0.5) / n as f32) / size as f32 * 2.0 - 1.0;
                let t = sample_equirect(image, face_direction(face, u, v).normalize());
                for c in 0..3 {
                    sum[c] += if t[c].is_finite() { t[c].max(0.0) } else { 0.0 };
                }
            }
        }
        sum.map(|s| s / (n * n) as f32)
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn floor_is_f32_floor() {
        for x in [
            -0.0f32,
            0.0,
            0.3,
            -0.3,
            1.0,
            -1.0,
            2.5,
            -2.5,
            127.999,
            -0.5,
            1e-30,
            -1e-30,
            f32::NAN,
        ] {
            assert_eq!(floor(x).to_bits(), x.floor().to_bits(), "{x}");
        }
        // Every representable value in -4..260 spaced by 1/1024, as texel coordinates are.
        for i in -4096..266_240 {
            let x = i as f32 / 1024.0;
            assert_eq!(floor(x).to_bits(), x.floor().to_bits(), "{x}");
        }
    }

    #[test]
    fn face_mapping_round_trips() {
        for face in 0..6 {
            for (u, v) in [(0.0, 0.0), (0.5, -0.25), (-0.9, 0.8)] {
                let d = face_direction(face, u, v);
                let (f, u2, v2) = direction_face(d);
                assert_eq!(f, face);
                assert!(
                    (u - u2).abs() < 1e-6 && (v - v2).abs() < 1e-6,
                    "{face} {u} {v}"
                );
            }
        }
    }

    #[test]
    fn solid_angles_cover_the_sphere() {
        let size = 16;
        let mut total = 0.0f64;
        for y in 0..size {
            for x in 0..size {
                total += f64::from(texel_solid_angle(x, y, size));
            }
        }
        assert!(
            (total * 6.0 - 4.0 * std::f64::consts::PI).abs() < 1e-4,
            "{total}"
        );
    }
}

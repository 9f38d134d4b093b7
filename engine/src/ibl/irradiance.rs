//! Diffuse irradiance, stored divided by pi (so a white Lambert surface returns the stored value
//! directly), as a small cube map built one of two ways:
//!
//! - **convolution** (default): the exact cosine-weighted sum over every texel of a 32 x 32
//!   source mip, with exact texel solid angles. The cosine lobe is wide, so the 32-texel source
//!   loses nothing visible, and a bright sun keeps its energy and position. On the CPU it costs
//!   tens of milliseconds, so there is no reason to approximate.
//! - **sh9**: nine spherical-harmonic coefficients and Ramamoorthi & Hanrahan's cosine
//!   convolution. Cheaper to store, but it rings around a strong sun (the error the sweep
//!   reports); negative lobes are clamped to zero.

use glam::Vec3;

use super::cube::{texel_direction, texel_solid_angle, CubeLevel, CubeMap};
use super::IrradianceMethod;

/// Size of the source mip the irradiance is integrated from.
const SOURCE_SIZE: u32 = 32;

/// Irradiance / pi of `source` as a cube of side `size`.
pub fn irradiance(source: &CubeMap, size: u32, method: IrradianceMethod) -> CubeLevel {
    let level = source
        .levels
        .iter()
        .find(|l| l.size <= SOURCE_SIZE)
        .unwrap_or_else(|| source.levels.last().expect("a cube has a level"));
    // (direction, radiance * solid angle) per source texel.
    let n = level.size;
    let mut texels = Vec::with_capacity(level.texels.len());
    for face in 0..6 {
        for y in 0..n {
            for x in 0..n {
                let omega = texel_solid_angle(x, y, n);
                let c = level.texels[face * (n * n) as usize + (y * n + x) as usize];
                texels.push((texel_direction(face, x, y, n), c.map(|v| v * omega)));
            }
        }
    }
    match method {
        IrradianceMethod::Convolution => CubeLevel::from_fn(size, |face, x, y| {
            let normal = texel_direction(face, x, y, size);
            let mut sum = [0.0f64; 3];
            for (d, c) in &texels {
                let cosine = normal.dot(*d);
                if cosine > 0.0 {
                    for k in 0..3 {
                        sum[k] += f64::from(c[k] * cosine);
                    }
                }
            }
            sum.map(|s| (s / std::f64::consts::PI) as f32)
        }),
        IrradianceMethod::Sh9 => {
            let mut coefficients = [[0.0f64; 3]; 9];
            for (d, c) in &texels {
                let basis = sh9_basis(*d);
                for (i, b) in basis.iter().enumerate() {
                    for k in 0..3 {
                        coefficients[i][k] += f64::from(c[k]) * b;
                    }
                }
            }
            // Cosine-lobe convolution per band (A0 = pi, A1 = 2pi/3, A2 = pi/4), then / pi.
            let band = [
                1.0,
                2.0 / 3.0,
                2.0 / 3.0,
                2.0 / 3.0,
                0.25,
                0.25,
                0.25,
                0.25,
                0.25,
            ];
            CubeLevel::from_fn(size, |face, x, y| {
                let basis = sh9_basis(texel_direction(face, x, y, size));
                let mut sum = [0.0f64; 3];
                for i in 0..9 {
                    for k in 0..3 {
                        sum[k] += coefficients[i][k] * band[i] * basis[i];
                    }
                }
                sum.map(|s| s.max(0.0) as f32)
            })
        }
    }
}

/// Real spherical harmonics up to band 2 at unit direction `d`.
pub fn sh9_basis(d: Vec3) -> [f64; 9] {
    let (x, y, z) = (f64::from(d.x), f64::from(d.y), f64::from(d.z));
    [
        0.282_094_791_773_878_14,
        0.488_602_511_902_919_9 * y,
        0.488_602_511_902_919_9 * z,
        0.488_602_511_902_919_9 * x,
        1.092_548_430_592_079_2 * x * y,
        1.092_548_430_592_079_2 * y * z,
        0.315_391_565_252_520_05 * (3.0 * z * z - 1.0),
        1.092_548_430_592_079_2 * x * z,
        0.546_274_215_296_039_6 * (x * x - y * y),
    ]
}

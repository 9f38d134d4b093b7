//! Deterministic value noise: an integer (PCG) hash of lattice points, smoothly
//! interpolated, and its fractal sum.

use crate::math::lerp;

/// PCG-style integer hash (O'Neill's RXS-M-XS output over one LCG step).
pub(crate) fn pcg(x: u32) -> u32 {
    let state = x.wrapping_mul(747_796_405).wrapping_add(2_891_336_453);
    let word = ((state >> ((state >> 28) + 4)) ^ state).wrapping_mul(277_803_737);
    (word >> 22) ^ word
}

/// Hash of a lattice point under `seed`, in [0, 1].
pub(crate) fn lattice(ix: i64, iy: i64, seed: u32) -> f64 {
    // Truncating the coordinates to 32 bits only wraps the lattice far outside the texture.
    let h = pcg(pcg(pcg(seed) ^ ix as u32) ^ iy as u32);
    f64::from(h) / f64::from(u32::MAX)
}

/// Value noise in [0, 1]: smoothly interpolated lattice hashes.
pub(crate) fn value_noise(x: f64, y: f64, seed: u32) -> f64 {
    let (fx, fy) = (x.floor(), y.floor());
    let (ix, iy) = (fx as i64, fy as i64);
    let (tx, ty) = (x - fx, y - fy);
    let (sx, sy) = (tx * tx * (3.0 - 2.0 * tx), ty * ty * (3.0 - 2.0 * ty));
    let top = lerp(lattice(ix, iy, seed), lattice(ix + 1, iy, seed), sx);
    let bottom = lerp(lattice(ix, iy + 1, seed), lattice(ix + 1, iy + 1, seed), sx);
    lerp(top, bottom, sy)
}

/// Fractal sum of `octaves` octaves of value noise, in [0, 1].
pub(crate) fn fbm(x: f64, y: f64, seed: u32, octaves: u32) -> f64 {
    let (mut sum, mut weight, mut amplitude, mut frequency) = (0.0, 0.0, 1.0, 1.0);
    for octave in 0..octaves {
        sum += amplitude * value_noise(x * frequency, y * frequency, seed.wrapping_add(octave));
        weight += amplitude;
        amplitude *= 0.5;
        frequency *= 2.0;
    }
    sum / weight
}

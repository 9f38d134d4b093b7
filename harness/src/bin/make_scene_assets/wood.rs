//! The board's woods: which square or frame strip a texture point lies on, its grain, and
//! the distance to the nearest joint.

use crate::board::{BOARD_HALF, TEX_FRAME, TEX_SQUARE};
use crate::math::{smoothstep, Vec2, Vec3};
use crate::noise::{fbm, pcg, value_noise};

/// The three woods of the board.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) enum Wood {
    /// Light squares.
    Maple,
    /// Dark squares.
    Walnut,
    /// The frame.
    Frame,
}

impl Wood {
    /// sRGB colour of earlywood and of latewood, 0..255.
    pub(crate) fn colours(self) -> (Vec3, Vec3) {
        match self {
            Wood::Maple => ([226.0, 194.0, 146.0], [188.0, 146.0, 96.0]),
            Wood::Walnut => ([98.0, 64.0, 38.0], [62.0, 38.0, 21.0]),
            Wood::Frame => ([122.0, 76.0, 45.0], [82.0, 48.0, 27.0]),
        }
    }

    /// Growth rings per meter across the grain.
    pub(crate) fn ring_frequency(self) -> f64 {
        match self {
            Wood::Maple => 150.0,
            Wood::Walnut => 120.0,
            Wood::Frame => 100.0,
        }
    }

    /// Base roughness under the lacquer.
    pub(crate) fn roughness(self) -> f64 {
        match self {
            Wood::Maple => 0.40,
            Wood::Walnut => 0.44,
            Wood::Frame => 0.48,
        }
    }
}

/// Where a texture point lies on the board and how its grain runs.
pub(crate) struct WoodSite {
    pub(crate) wood: Wood,
    /// Position along and across the grain, meters (with a per-piece offset).
    pub(crate) along: f64,
    pub(crate) across: f64,
    /// Unit directions of `along` and `across` in texture space (u right, v up).
    pub(crate) dir_along: Vec2,
    pub(crate) dir_across: Vec2,
    pub(crate) seed: u32,
    /// Inside the 8x8 squares.
    pub(crate) in_play: bool,
}

/// Which square or frame strip contains texture point (u, v), and its grain there.
pub(crate) fn wood_site(u: f64, v: f64) -> WoodSite {
    // Texture space in (roughly) meters, u right and v up.
    let (mu, mv) = (u * 2.0 * BOARD_HALF, v * 2.0 * BOARD_HALF);
    let (lo, hi) = (TEX_FRAME, 1.0 - TEX_FRAME);
    if (lo..hi).contains(&u) && (lo..hi).contains(&v) {
        let file = (((u - lo) / TEX_SQUARE).floor() as u32).min(7);
        let rank = (((v - lo) / TEX_SQUARE).floor() as u32).min(7);
        let seed = pcg(0x5eed_0000 + file * 8 + rank);
        let random = |k: u32| f64::from(pcg(seed ^ k)) / f64::from(u32::MAX);
        // Grain along u or v by a coin toss, slanted a little.
        let slant = (random(1) - 0.5) * 0.2;
        let len = (1.0 + slant * slant).sqrt();
        let (a, b) = (1.0 / len, slant / len);
        let (dir_along, dir_across) = if random(2) < 0.5 {
            ([a, b], [-b, a])
        } else {
            ([b, a], [a, -b])
        };
        WoodSite {
            wood: if (file + rank).is_multiple_of(2) {
                Wood::Walnut
            } else {
                Wood::Maple
            },
            along: mu * dir_along[0] + mv * dir_along[1] + random(3) * 2.0,
            across: mu * dir_across[0] + mv * dir_across[1] + random(4) * 0.5,
            dir_along,
            dir_across,
            seed,
            in_play: true,
        }
    } else {
        // Frame strips meet at mitres: the nearest outer edge decides the strip.
        let edges = [u, 1.0 - u, v, 1.0 - v];
        let strip = (0..4)
            .min_by(|&a, &b| edges[a].total_cmp(&edges[b]))
            .expect("four edges");
        let depth = edges[strip] * 2.0 * BOARD_HALF;
        let (along, dir_along, dir_across) = match strip {
            0 => (mv, [0.0, 1.0], [1.0, 0.0]),
            1 => (mv, [0.0, 1.0], [-1.0, 0.0]),
            2 => (mu, [1.0, 0.0], [0.0, 1.0]),
            _ => (mu, [1.0, 0.0], [0.0, -1.0]),
        };
        let seed = pcg(0xf4a3_0000 + strip as u32);
        WoodSite {
            wood: Wood::Frame,
            along: along + f64::from(seed % 1000) * 0.01,
            across: depth + 0.13,
            dir_along,
            dir_across,
            seed,
            in_play: false,
        }
    }
}

/// Latewood amount (0 earlywood .. 1 latewood band) and a fibre streak value, both in [0, 1].
pub(crate) fn wood_grain(site: &WoodSite, along: f64, across: f64) -> (f64, f64) {
    let seed = site.seed;
    let warp = fbm(along * 6.0, across * 40.0, seed, 3) - 0.5;
    let figure = fbm(along * 1.5, across * 8.0, seed ^ 0x9e37_79b9, 2) - 0.5;
    let t = across * site.wood.ring_frequency() + warp * 1.2 + figure * 3.0;
    let ring = t - t.floor();
    let late = smoothstep(0.45, 0.85, ring) * (1.0 - smoothstep(0.88, 1.0, ring));
    let fibre = value_noise(along * 40.0, across * 700.0, seed ^ 0x51ed_270b);
    (late, fibre)
}

/// Distance in texture space from (u, v) to the nearest joint (square edges and frame mitres),
/// and the unit direction pointing away from it.
pub(crate) fn nearest_joint(u: f64, v: f64) -> (f64, Vec2) {
    let (lo, hi) = (TEX_FRAME, 1.0 - TEX_FRAME);
    let mut best = (f64::INFINITY, [0.0, 0.0]);
    let mut consider = |a: Vec2, b: Vec2| {
        let (dx, dy) = (b[0] - a[0], b[1] - a[1]);
        let t = (((u - a[0]) * dx + (v - a[1]) * dy) / (dx * dx + dy * dy)).clamp(0.0, 1.0);
        let (ex, ey) = (u - (a[0] + t * dx), v - (a[1] + t * dy));
        let d = (ex * ex + ey * ey).sqrt();
        if d < best.0 {
            best = if d > 0.0 {
                (d, [ex / d, ey / d])
            } else {
                (0.0, [0.0, 0.0])
            };
        }
    };
    for k in 0..=8 {
        let line = lo + f64::from(k) * TEX_SQUARE;
        consider([line, lo], [line, hi]);
        consider([lo, line], [hi, line]);
    }
    consider([0.0, 0.0], [lo, lo]);
    consider([1.0, 0.0], [hi, lo]);
    consider([0.0, 1.0], [lo, hi]);
    consider([1.0, 1.0], [hi, hi]);
    best
}

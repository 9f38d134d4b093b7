//! The draughts piece: a fluted, bevelled disc with a rim and two grooves on top.

use std::f64::consts::PI;

use crate::lathe::{arc, extend, flat, groove, lathe, Fluting, Ring, Section, UvMap};
use crate::math::{lerp, smoothstep, smoothstep_derivative};
use crate::obj_writer::{Group, Mesh};

/// Checker radius.
pub(crate) const CHECKER_RADIUS: f64 = 0.021;
/// Checker height; the base is at y = 0.
pub(crate) const CHECKER_HEIGHT: f64 = 0.009;

/// A draughts piece: bevelled disc with 24 flutes round its side, a raised rim and two grooves on
/// top; 96 segments.
pub(crate) fn checker_mesh() -> Mesh {
    let (radius, height) = (CHECKER_RADIUS, CHECKER_HEIGHT);
    let bevel = 0.0015;
    let field = 0.008;
    let inner = radius - bevel;

    // Side: bottom bevel, fluted wall, top bevel; smooth throughout, cylindrical texture.
    let mut side = arc([inner, bevel], bevel, -PI / 2.0, 0.0, 4, true);
    let (wall0, wall1) = (bevel, height - bevel);
    let taper = 0.0012;
    let wall_steps = 12;
    extend(
        &mut side,
        (0..=wall_steps)
            .map(|i| {
                let y = lerp(wall0, wall1, f64::from(i) / f64::from(wall_steps));
                let (lo, hi) = (
                    smoothstep(0.0, taper, y - wall0),
                    smoothstep(0.0, taper, wall1 - y),
                );
                let (dlo, dhi) = (
                    smoothstep_derivative(0.0, taper, y - wall0),
                    smoothstep_derivative(0.0, taper, wall1 - y),
                );
                Ring {
                    flute: lo * hi,
                    flute_dy: dlo * hi - lo * dhi,
                    ..Ring::new(radius, y, 1.0, 0.0)
                }
            })
            .collect(),
    );
    extend(
        &mut side,
        arc([inner, height - bevel], bevel, 0.0, PI / 2.0, 4, true),
    );
    for ring in &mut side {
        ring.v = ring.y / height;
    }
    // Snap the bevel ends onto the flat faces exactly.
    let last = side.len() - 1;
    (side[0].r, side[0].y) = (inner, 0.0);
    (side[last].r, side[last].y) = (inner, height);

    // Rim: flat top, rounded inner edge, 45° slope down to the field (hard crease there).
    let rim_flat = 0.0182;
    let crest = 0.0006;
    let mut rim = flat(inner, rim_flat, height, 1.0);
    let crest_rings = arc(
        [rim_flat, height - crest],
        crest,
        PI / 2.0,
        PI * 0.75,
        3,
        true,
    );
    let crest_end = *crest_rings.last().expect("arc has rings");
    extend(&mut rim, crest_rings);
    let slope_foot = crest_end.r - (crest_end.y - field);
    rim.push(Ring::new(slope_foot, field, crest_end.nr, crest_end.ny));

    let top = UvMap::PlanarTop(radius);
    let (g1, g2, half_width, depth) = (0.0130, 0.0095, 0.0004, 0.0003);
    let sections = [
        Section {
            rings: flat(0.0, inner, 0.0, -1.0),
            uv: UvMap::PlanarBottom(radius),
        },
        Section {
            rings: side,
            uv: UvMap::Cylindrical,
        },
        Section {
            rings: rim,
            uv: top,
        },
        Section {
            rings: flat(slope_foot, g1 + half_width, field, 1.0),
            uv: top,
        },
        Section {
            rings: groove(g1, field, half_width, depth, 6),
            uv: top,
        },
        Section {
            rings: flat(g1 - half_width, g2 + half_width, field, 1.0),
            uv: top,
        },
        Section {
            rings: groove(g2, field, half_width, depth, 6),
            uv: top,
        },
        Section {
            rings: flat(g2 - half_width, 0.0, field, 1.0),
            uv: top,
        },
    ];
    let mut group = Group::new("checker", "checker");
    lathe(
        &mut group,
        &sections,
        96,
        Some(Fluting {
            count: 24.0,
            depth: 0.0004,
        }),
    );
    Mesh {
        name: "checker",
        description: "Draughts piece, radius 0.021 m, height 0.009 m, base at y = 0",
        groups: vec![group],
    }
}

//! The chess board mesh and the mapping of board coordinates into its texture layout.

use crate::math::{Vec2, Vec3};
use crate::obj_writer::{Group, Mesh};

/// Half the playing area's width (8 squares of 0.05 m).
pub(crate) const BOARD_PLAY_HALF: f64 = 0.2;
/// Half the board's width (playing area plus a 0.03 m frame).
pub(crate) const BOARD_HALF: f64 = 0.23;
/// Board thickness; the top is at y = 0.
pub(crate) const BOARD_THICKNESS: f64 = 0.025;
/// Width of the frame band in texture space.
pub(crate) const TEX_FRAME: f64 = 1.0 / 16.0;
/// Width of one square in texture space.
pub(crate) const TEX_SQUARE: f64 = 7.0 / 64.0;

/// Texture u of board coordinate `x`: piecewise linear, frame and squares to their regions.
pub(crate) fn board_u(x: f64) -> f64 {
    let frame = BOARD_HALF - BOARD_PLAY_HALF;
    if x < -BOARD_PLAY_HALF {
        (x + BOARD_HALF) / frame * TEX_FRAME
    } else if x <= BOARD_PLAY_HALF {
        TEX_FRAME + (x + BOARD_PLAY_HALF) / (2.0 * BOARD_PLAY_HALF) * (1.0 - 2.0 * TEX_FRAME)
    } else {
        1.0 - TEX_FRAME + (x - BOARD_PLAY_HALF) / frame * TEX_FRAME
    }
}

/// Texture v of board coordinate `z` (v up is -Z).
pub(crate) fn board_v(z: f64) -> f64 {
    board_u(-z)
}

/// Texture coordinates of a point on the board's top.
pub(crate) fn board_top_uv(p: Vec3) -> Vec2 {
    [board_u(p[0]), board_v(p[2])]
}

/// The board: `board_top` (one quad over the squares) and `board_frame` (mitred frame top, the
/// four sides and the bottom, each split at the playing area's edges so the mesh is watertight).
pub(crate) fn board_mesh() -> Mesh {
    let (h, p, t) = (BOARD_HALF, BOARD_PLAY_HALF, BOARD_THICKNESS);
    let up = [0.0, 1.0, 0.0];

    let mut top = Group::new("board_top", "board_squares");
    top.flat_quad(
        [[-p, 0.0, p], [p, 0.0, p], [p, 0.0, -p], [-p, 0.0, -p]],
        board_top_uv,
        up,
    );

    let mut frame = Group::new("board_frame", "board_frame");
    let breaks = [-h, -p, p, h];
    // Frame top: a 3x3 grid without its centre; corner cells split along the mitre.
    for i in 0..3 {
        for k in 0..3 {
            if i == 1 && k == 1 {
                continue;
            }
            let (x0, x1, z0, z1) = (breaks[i], breaks[i + 1], breaks[k], breaks[k + 1]);
            let mut corners = [[x0, 0.0, z0], [x1, 0.0, z0], [x1, 0.0, z1], [x0, 0.0, z1]];
            if i != 1 && k != 1 {
                // Start at the outer corner so the split diagonal is the mitre.
                let outer = corners
                    .iter()
                    .position(|c| c[0].abs() == h && c[2].abs() == h)
                    .expect("a corner cell has an outer corner");
                corners.rotate_left(outer);
            }
            frame.flat_quad(corners, board_top_uv, up);
        }
    }
    // Sides: the outer strip of the band on the same edge, v (or u) running with y, oriented so
    // that no side is mirrored in texture space (each keeps a right-handed tangent frame).
    let rise = |y: f64| (y + t) / (BOARD_HALF - BOARD_PLAY_HALF) * TEX_FRAME;
    for seg in 0..3 {
        let (a, b) = (breaks[seg], breaks[seg + 1]);
        frame.flat_quad(
            [[a, 0.0, h], [b, 0.0, h], [b, -t, h], [a, -t, h]],
            |q| [board_u(q[0]), rise(q[1])],
            [0.0, 0.0, 1.0],
        );
        frame.flat_quad(
            [[a, 0.0, -h], [b, 0.0, -h], [b, -t, -h], [a, -t, -h]],
            |q| [board_u(q[0]), 1.0 - rise(q[1])],
            [0.0, 0.0, -1.0],
        );
        frame.flat_quad(
            [[h, 0.0, a], [h, 0.0, b], [h, -t, b], [h, -t, a]],
            |q| [1.0 - rise(q[1]), board_v(q[2])],
            [1.0, 0.0, 0.0],
        );
        frame.flat_quad(
            [[-h, 0.0, a], [-h, 0.0, b], [-h, -t, b], [-h, -t, a]],
            |q| [rise(q[1]), board_v(q[2])],
            [-1.0, 0.0, 0.0],
        );
    }
    // Bottom: the +Z strip of the band (v in [0, 0.05], clear of the joint grooves), seen from
    // below (v grows towards +Z, so it is not mirrored either).
    for i in 0..3 {
        for k in 0..3 {
            let (x0, x1, z0, z1) = (breaks[i], breaks[i + 1], breaks[k], breaks[k + 1]);
            frame.flat_quad(
                [[x0, -t, z0], [x1, -t, z0], [x1, -t, z1], [x0, -t, z1]],
                |q| [board_u(q[0]), board_v(-q[2]) * 0.05],
                [0.0, -1.0, 0.0],
            );
        }
    }
    Mesh {
        name: "board",
        description: "Lacquered chess board, 0.46 m square, 0.025 m thick, top at y = 0",
        groups: vec![top, frame],
    }
}

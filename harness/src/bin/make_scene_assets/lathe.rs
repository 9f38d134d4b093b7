//! Surfaces of revolution about +Y: profile rings, sections, fluting and the lathe that
//! revolves them into triangles.

use std::f64::consts::TAU;

use crate::math::{add, lerp, scale, Vec2};
use crate::obj_writer::Group;

/// How a lathe section gets its texture coordinates.
#[derive(Clone, Copy, Debug)]
pub(crate) enum UvMap {
    /// u = angle / 2π (the seam is duplicated), v = the ring's own `v`.
    Cylindrical,
    /// Seen from +Y: u = 0.5 + x / (2 radius), v = 0.5 - z / (2 radius).
    PlanarTop(f64),
    /// Seen from -Y (not mirrored): u = 0.5 + x / (2 radius), v = 0.5 + z / (2 radius).
    PlanarBottom(f64),
}

/// One ring of a surface of revolution about +Y: a profile point and its profile normal.
#[derive(Clone, Copy, Debug)]
pub(crate) struct Ring {
    /// Radius; exactly 0 makes the ring a pole (a fan of triangles).
    pub(crate) r: f64,
    pub(crate) y: f64,
    /// Unit profile normal: radial and vertical parts.
    pub(crate) nr: f64,
    pub(crate) ny: f64,
    /// Texture v for [`UvMap::Cylindrical`].
    pub(crate) v: f64,
    /// Fluting weight (0 none, 1 full) and its derivative along y; only on vertical walls.
    pub(crate) flute: f64,
    pub(crate) flute_dy: f64,
}

impl Ring {
    pub(crate) fn new(r: f64, y: f64, nr: f64, ny: f64) -> Self {
        Self {
            r,
            y,
            nr,
            ny,
            v: 0.0,
            flute: 0.0,
            flute_dy: 0.0,
        }
    }
}

/// Rings with smooth normals between them. Consecutive sections meet at a shared profile point
/// with split vertices: a hard edge, or a texture seam where the normals agree.
pub(crate) struct Section {
    pub(crate) rings: Vec<Ring>,
    pub(crate) uv: UvMap,
}

/// Vertical grooves cut into fluted walls: `count` of them, `depth` deep.
#[derive(Clone, Copy, Debug)]
pub(crate) struct Fluting {
    pub(crate) count: f64,
    pub(crate) depth: f64,
}

impl Fluting {
    /// Radial offset at angle `theta` and its derivative with respect to `theta`.
    pub(crate) fn offset(self, theta: f64) -> (f64, f64) {
        let (s, c) = (self.count * theta).sin_cos();
        (
            -0.5 * self.depth * (1.0 - c),
            -0.5 * self.depth * self.count * s,
        )
    }
}

/// Revolves `sections` about +Y with `segments` steps into `group`. Angle θ runs
/// counter-clockwise seen from above: a ring point is (r cos θ, y, -r sin θ). Profiles must run
/// so that the outside is on their right seen from +Z at θ = 0 (bottom centre outwards, up the
/// side, top inwards); then the triangles come out counter-clockwise seen from outside.
pub(crate) fn lathe(
    group: &mut Group,
    sections: &[Section],
    segments: u32,
    fluting: Option<Fluting>,
) {
    let n = f64::from(segments);
    for section in sections {
        let mut previous: Option<(bool, u32)> = None;
        for ring in &section.rings {
            let pole = ring.r == 0.0;
            let first = u32::try_from(group.vertices.len()).expect("fewer than 2^32 vertices");
            // A pole gets one vertex per segment, at the segment's middle angle, so that each
            // fan triangle has its own normal and texture u there.
            let count = if pole { segments } else { segments + 1 };
            for j in 0..count {
                let t = if pole {
                    (f64::from(j) + 0.5) / n
                } else {
                    f64::from(j) / n
                };
                let theta = if pole {
                    TAU * t
                } else {
                    TAU * f64::from(j % segments) / n
                };
                let (s, c) = theta.sin_cos();
                let e_r = [c, 0.0, -s];
                let e_theta = [-s, 0.0, -c];
                let (g, dg) = match fluting {
                    Some(f) if ring.flute != 0.0 || ring.flute_dy != 0.0 => f.offset(theta),
                    _ => (0.0, 0.0),
                };
                let r = ring.r + ring.flute * g;
                let p = [r * c, ring.y, -r * s];
                let mut normal = add(scale(e_r, ring.nr), [0.0, ring.ny, 0.0]);
                if g != 0.0 || dg != 0.0 {
                    // Gradient of r - r0 - w(y) g(θ): tilt against the slopes of the flutes.
                    normal = add(normal, [0.0, -ring.nr * ring.flute_dy * g, 0.0]);
                    normal = add(normal, scale(e_theta, -ring.nr * ring.flute * dg / r));
                }
                let uv = match section.uv {
                    UvMap::Cylindrical => [t, ring.v],
                    UvMap::PlanarTop(radius) => {
                        [0.5 + p[0] / (2.0 * radius), 0.5 - p[2] / (2.0 * radius)]
                    }
                    UvMap::PlanarBottom(radius) => {
                        [0.5 + p[0] / (2.0 * radius), 0.5 + p[2] / (2.0 * radius)]
                    }
                };
                group.vertex(p, uv, normal);
            }
            if let Some((previous_pole, a0)) = previous {
                for j in 0..segments {
                    let (a, b) = (a0 + j, a0 + j + 1);
                    let (c, d) = (first + j + 1, first + j);
                    match (previous_pole, pole) {
                        (false, false) => {
                            group.triangles.push([a, b, c]);
                            group.triangles.push([a, c, d]);
                        }
                        (false, true) => group.triangles.push([a, b, first + j]),
                        (true, false) => group.triangles.push([a0 + j, c, d]),
                        (true, true) => panic!("two poles in a row"),
                    }
                }
            }
            previous = Some((pole, first));
        }
    }
}

/// Rings along a circular arc about `centre` (r, y) of radius `radius`, from angle `a0` to `a1`
/// (radians from +r towards +y), in `steps` steps, ends included. Convex arcs have normals
/// pointing away from the centre, concave ones towards it.
pub(crate) fn arc(
    centre: Vec2,
    radius: f64,
    a0: f64,
    a1: f64,
    steps: u32,
    convex: bool,
) -> Vec<Ring> {
    (0..=steps)
        .map(|i| {
            let a = lerp(a0, a1, f64::from(i) / f64::from(steps));
            let (s, c) = a.sin_cos();
            let sign = if convex { 1.0 } else { -1.0 };
            Ring::new(
                centre[0] + radius * c,
                centre[1] + radius * s,
                sign * c,
                sign * s,
            )
        })
        .collect()
}

/// Appends `more` to `rings`, dropping a first ring that repeats the last one.
pub(crate) fn extend(rings: &mut Vec<Ring>, more: Vec<Ring>) {
    let mut more = more.into_iter().peekable();
    if let (Some(last), Some(next)) = (rings.last(), more.peek()) {
        if (last.r - next.r).abs() < 1e-12 && (last.y - next.y).abs() < 1e-12 {
            more.next();
        }
    }
    rings.extend(more);
}

/// A round-bottomed decorative groove in a flat top at height `y0`, centred on radius `rc`, running
/// inwards: profile from `rc + half_width` to `rc - half_width`, lips exact.
pub(crate) fn groove(rc: f64, y0: f64, half_width: f64, depth: f64, steps: u32) -> Vec<Ring> {
    let radius = (half_width * half_width + depth * depth) / (2.0 * depth);
    let cy = y0 - depth + radius;
    let a0 = half_width.atan2(radius - depth);
    let mut rings: Vec<Ring> = (0..=steps)
        .map(|i| {
            let a = lerp(a0, -a0, f64::from(i) / f64::from(steps));
            let (s, c) = a.sin_cos();
            Ring::new(rc + radius * s, cy - radius * c, -s, c)
        })
        .collect();
    let last = rings.len() - 1;
    (rings[0].r, rings[0].y) = (rc + half_width, y0);
    (rings[last].r, rings[last].y) = (rc - half_width, y0);
    rings
}

/// Two rings of a flat annulus (or disc, when `r1` is 0) at height `y` with vertical normal `ny`.
pub(crate) fn flat(r0: f64, r1: f64, y: f64, ny: f64) -> Vec<Ring> {
    vec![Ring::new(r0, y, 0.0, ny), Ring::new(r1, y, 0.0, ny)]
}

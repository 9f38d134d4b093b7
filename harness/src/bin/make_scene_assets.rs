//! `make_scene_assets`: generates the meshes and textures of the canonical render-regression
//! scenes (`scenes/*.toml`).
//!
//! ```text
//! cargo run -p harness --bin make_scene_assets -- scenes/assets
//! ```
//!
//! writes into the given directory (created if missing):
//!
//! | file | contents |
//! | --- | --- |
//! | `board.obj`, `board.mtl` | lacquered 8x8 chess board: 0.05 m squares, 0.03 m frame, 0.46 m square, 0.025 m thick |
//! | `board_albedo.png` | 512x512 sRGB albedo: maple and walnut squares with wood grain, mid-dark wood frame |
//! | `board_roughness.png` | 256x256 linear grayscale roughness (lacquer, rougher in the joints) |
//! | `board_normal.png` | 256x256 tangent-space normal map (OpenGL: +Y up in texture space, +Z out) |
//! | `board_clearcoat.png` | 256x256 linear grayscale clearcoat weight (0.9 squares, 0.7 frame) |
//! | `checker.obj`, `checker.mtl` | draughts piece: radius 0.021 m, height 0.009 m, fluted side, rim and two grooves on top |
//! | `arrow.obj`, `arrow.mtl` | arrow along +X from the origin: shaft 0.12 m, cone head 0.04 m |
//! | `sphere.obj`, `sphere.mtl` | UV sphere of radius 1, 64 segments x 32 rings |
//! | `crate.obj`, `crate.mtl`, `crate_*` | the untidy crate of `scenes/models/crate.toml`: a model as people's files come (CRLF, Latin-1 comments, quads, an undefined and a nameless `usemtl`), with JPEG, TGA, 16-bit PNG and BMP maps |
//! | `README.md` | the files with their sizes and triangle counts |
//!
//! # Conventions
//!
//! Meters, right-handed, +Y up. The board is centred on the origin with its playing surface at
//! y = 0; square a1 (dark) is at the (-X, +Z) corner, so White sits on the +Z side. Every OBJ vertex
//! has a position, a texture coordinate (OBJ convention: v up) and a normal, written in lockstep
//! (`f i/i/i`); faces are triangles, counter-clockwise seen from outside. Normals are smooth across
//! smooth surfaces and split at hard edges. Every mesh is closed (watertight by position) and no
//! triangle is degenerate, in position or in texture space: the sphere's poles (and the centres of
//! the checker's and arrow's discs and the arrow's tip) get one vertex per segment, at the
//! segment's middle angle, so each fan triangle has its own normal and u and a finite tangent.
//! Each object is written with both an `o` and a `g` line of the same name.
//!
//! # Board texture layout
//!
//! All four board maps share one layout in UV space, a top view of the board with -Z at the top of
//! the image: the 8x8 squares fill u, v in [1/16, 15/16] (each square 7/64 wide, so square edges
//! fall on texel edges at 256 and 512 texels), the frame is the outer 1/16 band. `board_top` maps
//! onto the squares, `board_frame` onto the band: its top exactly; each side onto the outer 5/6 of
//! the band's strip on the same edge (grain running along the side); the bottom onto the +Z strip.
//! No face is mirrored in texture space, so every tangent frame is right-handed (T x B = N).
//!
//! # Determinism
//!
//! No clock, no OS randomness: the wood is value noise over an integer (PCG) hash of lattice points
//! with fixed seeds, the meshes are written with 6 decimals, and the PNGs are encoded with fixed
//! settings. Running twice gives byte-identical files.

use std::f64::consts::{PI, TAU};
use std::fmt::Write as _;
use std::path::{Path, PathBuf};
use std::{env, fs, io, process};

use harness::images::{self, PngCompression};
use image::{ExtendedColorType, ImageEncoder};

type Vec3 = [f64; 3];
type Vec2 = [f64; 2];

fn add(a: Vec3, b: Vec3) -> Vec3 {
    [a[0] + b[0], a[1] + b[1], a[2] + b[2]]
}

fn sub(a: Vec3, b: Vec3) -> Vec3 {
    [a[0] - b[0], a[1] - b[1], a[2] - b[2]]
}

fn scale(a: Vec3, s: f64) -> Vec3 {
    [a[0] * s, a[1] * s, a[2] * s]
}

fn dot(a: Vec3, b: Vec3) -> f64 {
    a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
}

fn cross(a: Vec3, b: Vec3) -> Vec3 {
    [
        a[1] * b[2] - a[2] * b[1],
        a[2] * b[0] - a[0] * b[2],
        a[0] * b[1] - a[1] * b[0],
    ]
}

fn normalize(a: Vec3) -> Vec3 {
    scale(a, 1.0 / dot(a, a).sqrt())
}

fn lerp(a: f64, b: f64, t: f64) -> f64 {
    a + (b - a) * t
}

/// Hermite step from 0 at `e0` to 1 at `e1`.
fn smoothstep(e0: f64, e1: f64, x: f64) -> f64 {
    let t = ((x - e0) / (e1 - e0)).clamp(0.0, 1.0);
    t * t * (3.0 - 2.0 * t)
}

/// Derivative of [`smoothstep`] with respect to `x`.
fn smoothstep_derivative(e0: f64, e1: f64, x: f64) -> f64 {
    let t = (x - e0) / (e1 - e0);
    if (0.0..=1.0).contains(&t) {
        6.0 * t * (1.0 - t) / (e1 - e0)
    } else {
        0.0
    }
}

/// A number with 6 decimals; negative zero is written as zero.
fn num(x: f64) -> String {
    let s = format!("{x:.6}");
    if s == "-0.000000" {
        "0.000000".to_owned()
    } else {
        s
    }
}

// ---------------------------------------------------------------------------------------------
// Meshes
// ---------------------------------------------------------------------------------------------

/// One OBJ vertex. Position, texture coordinate and normal are written in lockstep, so a face
/// corner reads `i/i/i`.
#[derive(Clone, Copy, Debug, PartialEq)]
struct Vertex {
    p: Vec3,
    uv: Vec2,
    n: Vec3,
}

/// An OBJ object (`o` and `g` lines) drawn with one material.
#[derive(Clone, Debug)]
struct Group {
    name: &'static str,
    material: &'static str,
    vertices: Vec<Vertex>,
    /// Indices into `vertices`, counter-clockwise seen from outside.
    triangles: Vec<[u32; 3]>,
}

impl Group {
    fn new(name: &'static str, material: &'static str) -> Self {
        Self {
            name,
            material,
            vertices: Vec::new(),
            triangles: Vec::new(),
        }
    }

    /// Adds a vertex (the normal is normalised) and returns its index.
    fn vertex(&mut self, p: Vec3, uv: Vec2, n: Vec3) -> u32 {
        self.vertices.push(Vertex {
            p,
            uv,
            n: normalize(n),
        });
        u32::try_from(self.vertices.len() - 1).expect("fewer than 2^32 vertices")
    }

    /// Adds a flat quad with its own vertices (a hard edge all round), normal `n`, texture
    /// coordinates from `uv`. The corners go round the quad in either direction; the winding is
    /// made counter-clockwise seen from the side `n` points to. The quad is split along the
    /// diagonal from `corners[0]` to `corners[2]`.
    fn flat_quad(&mut self, corners: [Vec3; 4], uv: impl Fn(Vec3) -> Vec2, n: Vec3) {
        let facing = dot(
            cross(sub(corners[1], corners[0]), sub(corners[2], corners[0])),
            n,
        );
        let order = if facing > 0.0 {
            [0, 1, 2, 3]
        } else {
            [0, 3, 2, 1]
        };
        let i = order.map(|k| self.vertex(corners[k], uv(corners[k]), n));
        self.triangles.push([i[0], i[1], i[2]]);
        self.triangles.push([i[0], i[2], i[3]]);
    }
}

/// A mesh, written as one OBJ file that names its MTL file.
#[derive(Clone, Debug)]
struct Mesh {
    /// File stem: `NAME.obj` and `NAME.mtl`.
    name: &'static str,
    /// One line for the OBJ header.
    description: &'static str,
    groups: Vec<Group>,
}

impl Mesh {
    fn triangle_count(&self) -> usize {
        self.groups.iter().map(|g| g.triangles.len()).sum()
    }

    fn vertex_count(&self) -> usize {
        self.groups.iter().map(|g| g.vertices.len()).sum()
    }

    /// The OBJ text: per group `o`/`g`, its `v`/`vt`/`vn` lines, `usemtl` and its faces.
    fn to_obj(&self) -> String {
        let mut s = String::new();
        let _ = writeln!(
            s,
            "# {} - generated by make_scene_assets; do not edit.",
            self.description
        );
        let _ = writeln!(
            s,
            "# Meters, right-handed, +Y up; faces counter-clockwise seen from outside."
        );
        let _ = writeln!(
            s,
            "# {} vertices, {} triangles. CC0 1.0 (public domain).",
            self.vertex_count(),
            self.triangle_count()
        );
        let _ = writeln!(s, "mtllib {}.mtl", self.name);
        let mut base = 1usize;
        for g in &self.groups {
            let _ = writeln!(s, "o {}", g.name);
            let _ = writeln!(s, "g {}", g.name);
            for v in &g.vertices {
                let _ = writeln!(s, "v {} {} {}", num(v.p[0]), num(v.p[1]), num(v.p[2]));
            }
            for v in &g.vertices {
                let _ = writeln!(s, "vt {} {}", num(v.uv[0]), num(v.uv[1]));
            }
            for v in &g.vertices {
                let _ = writeln!(s, "vn {} {} {}", num(v.n[0]), num(v.n[1]), num(v.n[2]));
            }
            let _ = writeln!(s, "usemtl {}", g.material);
            for t in &g.triangles {
                let [a, b, c] = t.map(|i| i as usize + base);
                let _ = writeln!(s, "f {a}/{a}/{a} {b}/{b}/{b} {c}/{c}/{c}");
            }
            base += g.vertices.len();
        }
        s
    }
}

/// An MTL material.
struct Material {
    name: &'static str,
    kd: Vec3,
    ks: Vec3,
    ns: f64,
    /// Texture statements, `(key, file)`.
    maps: &'static [(&'static str, &'static str)],
}

/// The MTL text for `materials`, after the `comment` lines.
fn mtl(comment: &[&str], materials: &[Material]) -> String {
    let mut s = String::new();
    for line in comment {
        let _ = writeln!(s, "# {line}");
    }
    for m in materials {
        let _ = writeln!(s, "\nnewmtl {}", m.name);
        let _ = writeln!(s, "Ka 0.000000 0.000000 0.000000");
        let _ = writeln!(s, "Kd {} {} {}", num(m.kd[0]), num(m.kd[1]), num(m.kd[2]));
        let _ = writeln!(s, "Ks {} {} {}", num(m.ks[0]), num(m.ks[1]), num(m.ks[2]));
        let _ = writeln!(s, "Ns {}", num(m.ns));
        let _ = writeln!(s, "d 1.000000");
        let _ = writeln!(s, "illum 2");
        for (key, file) in m.maps {
            let _ = writeln!(s, "{key} {file}");
        }
    }
    s
}

// ----- Surfaces of revolution ------------------------------------------------------------------

/// How a lathe section gets its texture coordinates.
#[derive(Clone, Copy, Debug)]
enum UvMap {
    /// u = angle / 2π (the seam is duplicated), v = the ring's own `v`.
    Cylindrical,
    /// Seen from +Y: u = 0.5 + x / (2 radius), v = 0.5 - z / (2 radius).
    PlanarTop(f64),
    /// Seen from -Y (not mirrored): u = 0.5 + x / (2 radius), v = 0.5 + z / (2 radius).
    PlanarBottom(f64),
}

/// One ring of a surface of revolution about +Y: a profile point and its profile normal.
#[derive(Clone, Copy, Debug)]
struct Ring {
    /// Radius; exactly 0 makes the ring a pole (a fan of triangles).
    r: f64,
    y: f64,
    /// Unit profile normal: radial and vertical parts.
    nr: f64,
    ny: f64,
    /// Texture v for [`UvMap::Cylindrical`].
    v: f64,
    /// Fluting weight (0 none, 1 full) and its derivative along y; only on vertical walls.
    flute: f64,
    flute_dy: f64,
}

impl Ring {
    fn new(r: f64, y: f64, nr: f64, ny: f64) -> Self {
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
struct Section {
    rings: Vec<Ring>,
    uv: UvMap,
}

/// Vertical grooves cut into fluted walls: `count` of them, `depth` deep.
#[derive(Clone, Copy, Debug)]
struct Fluting {
    count: f64,
    depth: f64,
}

impl Fluting {
    /// Radial offset at angle `theta` and its derivative with respect to `theta`.
    fn offset(self, theta: f64) -> (f64, f64) {
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
fn lathe(group: &mut Group, sections: &[Section], segments: u32, fluting: Option<Fluting>) {
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
fn arc(centre: Vec2, radius: f64, a0: f64, a1: f64, steps: u32, convex: bool) -> Vec<Ring> {
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
fn extend(rings: &mut Vec<Ring>, more: Vec<Ring>) {
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
fn groove(rc: f64, y0: f64, half_width: f64, depth: f64, steps: u32) -> Vec<Ring> {
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
fn flat(r0: f64, r1: f64, y: f64, ny: f64) -> Vec<Ring> {
    vec![Ring::new(r0, y, 0.0, ny), Ring::new(r1, y, 0.0, ny)]
}

// ----- Board -----------------------------------------------------------------------------------

/// Half the playing area's width (8 squares of 0.05 m).
const BOARD_PLAY_HALF: f64 = 0.2;
/// Half the board's width (playing area plus a 0.03 m frame).
const BOARD_HALF: f64 = 0.23;
/// Board thickness; the top is at y = 0.
const BOARD_THICKNESS: f64 = 0.025;
/// Width of the frame band in texture space.
const TEX_FRAME: f64 = 1.0 / 16.0;
/// Width of one square in texture space.
const TEX_SQUARE: f64 = 7.0 / 64.0;

/// Texture u of board coordinate `x`: piecewise linear, frame and squares to their regions.
fn board_u(x: f64) -> f64 {
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
fn board_v(z: f64) -> f64 {
    board_u(-z)
}

/// Texture coordinates of a point on the board's top.
fn board_top_uv(p: Vec3) -> Vec2 {
    [board_u(p[0]), board_v(p[2])]
}

/// The board: `board_top` (one quad over the squares) and `board_frame` (mitred frame top, the
/// four sides and the bottom, each split at the playing area's edges so the mesh is watertight).
fn board_mesh() -> Mesh {
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

// ----- Checker ---------------------------------------------------------------------------------

/// Checker radius.
const CHECKER_RADIUS: f64 = 0.021;
/// Checker height; the base is at y = 0.
const CHECKER_HEIGHT: f64 = 0.009;

/// A draughts piece: bevelled disc with 24 flutes round its side, a raised rim and two grooves on
/// top; 96 segments.
fn checker_mesh() -> Mesh {
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

// ----- Arrow -----------------------------------------------------------------------------------

/// An arrow along +X with its back at the origin: shaft radius 0.006 m, length 0.12 m; cone head
/// radius 0.015 m, length 0.04 m; closed by a disc at the back and an annulus behind the head.
fn arrow_mesh() -> Mesh {
    let (shaft_r, shaft_len, head_r, head_len) = (0.006, 0.12, 0.015, 0.04);
    let length = shaft_len + head_len;
    let back = UvMap::PlanarBottom(head_r);
    let cone_n = normalize([head_len, head_r, 0.0]);
    let mut shaft = vec![
        Ring::new(shaft_r, 0.0, 1.0, 0.0),
        Ring::new(shaft_r, shaft_len, 1.0, 0.0),
    ];
    let mut cone = vec![
        Ring::new(head_r, shaft_len, cone_n[0], cone_n[1]),
        Ring::new(0.0, length, cone_n[0], cone_n[1]),
    ];
    for ring in shaft.iter_mut().chain(cone.iter_mut()) {
        ring.v = ring.y / length;
    }
    let sections = [
        Section {
            rings: flat(0.0, shaft_r, 0.0, -1.0),
            uv: back,
        },
        Section {
            rings: shaft,
            uv: UvMap::Cylindrical,
        },
        Section {
            rings: flat(shaft_r, head_r, shaft_len, -1.0),
            uv: back,
        },
        Section {
            rings: cone,
            uv: UvMap::Cylindrical,
        },
    ];
    let mut group = Group::new("arrow", "arrow");
    lathe(&mut group, &sections, 32, None);
    // Lay the +Y axis along +X: a proper rotation (x, y, z) -> (y, -x, z) keeps the winding.
    for v in &mut group.vertices {
        v.p = [v.p[1], -v.p[0], v.p[2]];
        v.n = [v.n[1], -v.n[0], v.n[2]];
    }
    Mesh {
        name: "arrow",
        description: "Arrow along +X from the origin, 0.16 m long",
        groups: vec![group],
    }
}

// ----- Sphere ----------------------------------------------------------------------------------

/// A UV sphere of radius 1: 64 segments by 32 rings, u = longitude (0 at +X, growing
/// counter-clockwise seen from above), v = latitude (0 south pole, 1 north pole). The seam column
/// is duplicated; each pole has one vertex per segment at the segment's middle longitude, so no
/// triangle is degenerate, in position or in texture space.
fn sphere_mesh() -> Mesh {
    let rings = 32u32;
    let profile = (0..=rings)
        .map(|i| {
            let a = PI * f64::from(i) / f64::from(rings);
            let (s, c) = a.sin_cos();
            let (r, y) = match i {
                0 => (0.0, -1.0),
                i if i == rings => (0.0, 1.0),
                _ => (s, -c),
            };
            Ring {
                v: f64::from(i) / f64::from(rings),
                ..Ring::new(r, y, r, y)
            }
        })
        .collect();
    let mut group = Group::new("sphere", "sphere");
    lathe(
        &mut group,
        &[Section {
            rings: profile,
            uv: UvMap::Cylindrical,
        }],
        64,
        None,
    );
    Mesh {
        name: "sphere",
        description: "UV sphere, radius 1, 64 segments x 32 rings",
        groups: vec![group],
    }
}

/// Every mesh with its MTL text.
fn meshes() -> Vec<(Mesh, String)> {
    let dielectric = [0.04, 0.04, 0.04];
    let board_maps: &[(&str, &str)] = &[
        ("map_Kd", "board_albedo.png"),
        ("map_roughness", "board_roughness.png"),
        ("norm", "board_normal.png"),
        ("map_clearcoat", "board_clearcoat.png"),
    ];
    let licence = "CC0 1.0 (public domain). Generated by make_scene_assets; do not edit.";
    vec![
        (
            board_mesh(),
            mtl(
                &[
                    "Lacquered chess board.",
                    "Both materials use the same textures on purpose: a texture used twice must load once.",
                    "map_roughness, norm and map_clearcoat hold linear data; map_Kd is sRGB.",
                    licence,
                ],
                &[
                    Material {
                        name: "board_squares",
                        kd: [1.0, 1.0, 1.0],
                        ks: dielectric,
                        ns: 64.0,
                        maps: board_maps,
                    },
                    Material {
                        name: "board_frame",
                        kd: [1.0, 1.0, 1.0],
                        ks: dielectric,
                        ns: 43.0,
                        maps: board_maps,
                    },
                ],
            ),
        ),
        (
            checker_mesh(),
            mtl(
                &[
                    "Draughts piece; no textures: the scene sets the colour per piece.",
                    licence,
                ],
                &[Material {
                    name: "checker",
                    kd: [0.8, 0.8, 0.8],
                    ks: dielectric,
                    ns: 96.0,
                    maps: &[],
                }],
            ),
        ),
        (
            arrow_mesh(),
            mtl(
                &["Arrow; no textures.", licence],
                &[Material {
                    name: "arrow",
                    kd: [0.9, 0.2, 0.1],
                    ks: dielectric,
                    ns: 64.0,
                    maps: &[],
                }],
            ),
        ),
        (
            sphere_mesh(),
            mtl(
                &["Unit sphere; no textures.", licence],
                &[Material {
                    name: "sphere",
                    kd: [1.0, 1.0, 1.0],
                    ks: dielectric,
                    ns: 32.0,
                    maps: &[],
                }],
            ),
        ),
    ]
}

// ---------------------------------------------------------------------------------------------
// Board textures
// ---------------------------------------------------------------------------------------------

/// PCG-style integer hash (O'Neill's RXS-M-XS output over one LCG step).
fn pcg(x: u32) -> u32 {
    let state = x.wrapping_mul(747_796_405).wrapping_add(2_891_336_453);
    let word = ((state >> ((state >> 28) + 4)) ^ state).wrapping_mul(277_803_737);
    (word >> 22) ^ word
}

/// Hash of a lattice point under `seed`, in [0, 1].
fn lattice(ix: i64, iy: i64, seed: u32) -> f64 {
    // Truncating the coordinates to 32 bits only wraps the lattice far outside the texture.
    let h = pcg(pcg(pcg(seed) ^ ix as u32) ^ iy as u32);
    f64::from(h) / f64::from(u32::MAX)
}

/// Value noise in [0, 1]: smoothly interpolated lattice hashes.
fn value_noise(x: f64, y: f64, seed: u32) -> f64 {
    let (fx, fy) = (x.floor(), y.floor());
    let (ix, iy) = (fx as i64, fy as i64);
    let (tx, ty) = (x - fx, y - fy);
    let (sx, sy) = (tx * tx * (3.0 - 2.0 * tx), ty * ty * (3.0 - 2.0 * ty));
    let top = lerp(lattice(ix, iy, seed), lattice(ix + 1, iy, seed), sx);
    let bottom = lerp(lattice(ix, iy + 1, seed), lattice(ix + 1, iy + 1, seed), sx);
    lerp(top, bottom, sy)
}

/// Fractal sum of `octaves` octaves of value noise, in [0, 1].
fn fbm(x: f64, y: f64, seed: u32, octaves: u32) -> f64 {
    let (mut sum, mut weight, mut amplitude, mut frequency) = (0.0, 0.0, 1.0, 1.0);
    for octave in 0..octaves {
        sum += amplitude * value_noise(x * frequency, y * frequency, seed.wrapping_add(octave));
        weight += amplitude;
        amplitude *= 0.5;
        frequency *= 2.0;
    }
    sum / weight
}

/// The three woods of the board.
#[derive(Clone, Copy, Debug, PartialEq)]
enum Wood {
    /// Light squares.
    Maple,
    /// Dark squares.
    Walnut,
    /// The frame.
    Frame,
}

impl Wood {
    /// sRGB colour of earlywood and of latewood, 0..255.
    fn colours(self) -> (Vec3, Vec3) {
        match self {
            Wood::Maple => ([226.0, 194.0, 146.0], [188.0, 146.0, 96.0]),
            Wood::Walnut => ([98.0, 64.0, 38.0], [62.0, 38.0, 21.0]),
            Wood::Frame => ([122.0, 76.0, 45.0], [82.0, 48.0, 27.0]),
        }
    }

    /// Growth rings per meter across the grain.
    fn ring_frequency(self) -> f64 {
        match self {
            Wood::Maple => 150.0,
            Wood::Walnut => 120.0,
            Wood::Frame => 100.0,
        }
    }

    /// Base roughness under the lacquer.
    fn roughness(self) -> f64 {
        match self {
            Wood::Maple => 0.40,
            Wood::Walnut => 0.44,
            Wood::Frame => 0.48,
        }
    }
}

/// Where a texture point lies on the board and how its grain runs.
struct WoodSite {
    wood: Wood,
    /// Position along and across the grain, meters (with a per-piece offset).
    along: f64,
    across: f64,
    /// Unit directions of `along` and `across` in texture space (u right, v up).
    dir_along: Vec2,
    dir_across: Vec2,
    seed: u32,
    /// Inside the 8x8 squares.
    in_play: bool,
}

/// Which square or frame strip contains texture point (u, v), and its grain there.
fn wood_site(u: f64, v: f64) -> WoodSite {
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
fn wood_grain(site: &WoodSite, along: f64, across: f64) -> (f64, f64) {
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
fn nearest_joint(u: f64, v: f64) -> (f64, Vec2) {
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

/// Half width of the joint grooves and gaps, texture space.
const JOINT_HALF_WIDTH: f64 = 0.0055;

/// sRGB albedo (0..255) at (u, v).
fn albedo(u: f64, v: f64) -> Vec3 {
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
fn roughness(u: f64, v: f64) -> f64 {
    let site = wood_site(u, v);
    let (late, fibre) = wood_grain(&site, site.along, site.across);
    let r = site.wood.roughness() + 0.08 * (late - 0.5) + 0.04 * (fibre - 0.5);
    let (d, _) = nearest_joint(u, v);
    lerp(r, 0.65, (1.0 - d / (0.75 * JOINT_HALF_WIDTH)).max(0.0))
}

/// Tangent-space normal (+X along u, +Y along v, +Z out) at (u, v).
fn tangent_normal(u: f64, v: f64) -> Vec3 {
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
fn sample_texture(size: u32, ss: u32, f: impl Fn(f64, f64) -> Vec3) -> Vec<Vec3> {
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

/// A value in 0..=255 from `x` in 0..=255, rounded.
fn byte(x: f64) -> u8 {
    x.round().clamp(0.0, 255.0) as u8
}

/// PNG bytes of 8-bit `data`, compressed with fixed settings.
fn png(size: u32, data: &[u8], colour: ExtendedColorType) -> Vec<u8> {
    images::png_bytes(data, size, size, colour, PngCompression::Smallest)
        .expect("encoding a PNG into memory cannot fail")
}

/// The four board textures: `(file name, PNG bytes, size)`.
fn board_textures() -> Vec<(&'static str, Vec<u8>, u32)> {
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

// ---------------------------------------------------------------------------------------------
// The untidy crate: a model as people's files come
// ---------------------------------------------------------------------------------------------

/// The crate's edge length (m).
const CRATE_SIZE: f64 = 0.3;

/// Which plank (0..5, along v) a texture coordinate falls on, and how far across it (0..1).
fn crate_plank(v: f64) -> (u32, f64) {
    let t = v.clamp(0.0, 1.0 - 1e-9) * 5.0;
    (t.floor() as u32, t.fract())
}

/// Depth of the groove between planks at `across` (0 on the plank, 1 at the joint's middle).
fn crate_groove(across: f64) -> f64 {
    let edge = across.min(1.0 - across);
    1.0 - smoothstep(0.0, 0.06, edge)
}

/// The crate's sRGB albedo at (u, v): five planks of pine, each its own shade, darker joints.
fn crate_albedo(u: f64, v: f64) -> Vec3 {
    let (plank, across) = crate_plank(v);
    let shade = 0.85 + 0.3 * lattice(i64::from(plank), 7, 41);
    let grain = fbm(u * 3.0 + f64::from(plank) * 17.0, across * 0.5, 43, 4);
    let wood = [0.62, 0.45, 0.27].map(|c| c * shade * (0.8 + 0.4 * grain));
    let dark = 1.0 - 0.6 * crate_groove(across);
    wood.map(|c| (c * dark * 255.0).min(255.0))
}

/// The crate's linear roughness: lacquer-free pine, rougher in the joints.
fn crate_roughness(u: f64, v: f64) -> f64 {
    let (plank, across) = crate_plank(v);
    let grain = fbm(u * 5.0, f64::from(plank) + across, 47, 3);
    (0.55 + 0.2 * grain + 0.25 * crate_groove(across)).min(1.0)
}

/// The crate's tangent-space normal: the joints' rounded edges tilt the normal along v.
fn crate_normal(_u: f64, v: f64) -> Vec3 {
    let (_, across) = crate_plank(v);
    let slope = if across < 0.5 {
        smoothstep_derivative(0.0, 0.06, across)
    } else {
        -smoothstep_derivative(0.0, 0.06, 1.0 - across)
    };
    normalize([0.0, -0.02 * slope, 1.0])
}

/// An 8-bit texture of `width` x `height` texels from `f(u, v)` (texel centres, v up) with
/// `channels` values per texel.
fn crate_texels(width: u32, height: u32, f: impl Fn(f64, f64) -> Vec<f64>) -> Vec<f64> {
    let mut out = Vec::new();
    for y in 0..height {
        for x in 0..width {
            let u = (f64::from(x) + 0.5) / f64::from(width);
            let v = 1.0 - (f64::from(y) + 0.5) / f64::from(height);
            out.extend(f(u, v));
        }
    }
    out
}

/// The crate's OBJ as bytes: CRLF line ends, a Latin-1 comment, quads, a label
/// whose material no MTL defines, and a nameless `usemtl` before the bottom face.
fn crate_obj() -> Vec<u8> {
    let h = CRATE_SIZE / 2.0;
    let mut text = String::new();
    let mut line = |s: &str| {
        text.push_str(s);
        text.push_str("\r\n");
    };
    line("# crate.obj: generated by make_scene_assets (see scenes/assets/README.md)");
    line("# LATIN1-COMMENT");
    line("mtllib crate.mtl");
    line("o crate");
    // Corners: x, y, z in {-h, h} x {0, 2h} x {-h, h}.
    for (x, y, z) in [
        (-h, 0.0, h),
        (h, 0.0, h),
        (h, 2.0 * h, h),
        (-h, 2.0 * h, h),
        (-h, 0.0, -h),
        (h, 0.0, -h),
        (h, 2.0 * h, -h),
        (-h, 2.0 * h, -h),
    ] {
        line(&format!("v {} {} {}", num(x), num(y), num(z)));
    }
    for (u, v) in [(0.0, 0.0), (1.0, 0.0), (1.0, 1.0), (0.0, 1.0)] {
        line(&format!("vt {} {}", num(u), num(v)));
    }
    // One normal per face: front, right, back, left, top, bottom.
    for n in ["0 0 1", "1 0 0", "0 0 -1", "-1 0 0", "0 1 0", "0 -1 0"] {
        line(&format!("vn {n}"));
    }
    line("g crate");
    line("usemtl crate_wood");
    // Front, right, back, left, top: counter-clockwise seen from outside.
    for (n, face) in [
        [1, 2, 3, 4],
        [2, 6, 7, 3],
        [6, 5, 8, 7],
        [5, 1, 4, 8],
        [4, 3, 7, 8],
    ]
    .iter()
    .enumerate()
    {
        let n = n + 1;
        line(&format!(
            "f {}/1/{n} {}/2/{n} {}/3/{n} {}/4/{n}",
            face[0], face[1], face[2], face[3]
        ));
    }
    line("usemtl");
    line("f 5/1/6 6/2/6 2/3/6 1/4/6");
    // The shipping label, 1 mm in front of the front face.
    line("g label");
    line("usemtl shipping_label");
    let z = h + 0.001;
    for (x, y) in [(-0.08, 0.1), (0.08, 0.1), (0.08, 0.2), (-0.08, 0.2)] {
        line(&format!("v {} {} {}", num(x), num(y), num(z)));
    }
    line("f 9/1/1 10/2/1 11/3/1 12/4/1");
    // A Latin-1 byte (e-acute, 0xE9) where the placeholder comment is: not UTF-8.
    let mut bytes = text.into_bytes();
    let at = bytes
        .windows(14)
        .position(|w| w == b"LATIN1-COMMENT")
        .expect("the placeholder is written above");
    bytes.splice(
        at..at + 14,
        b"caisse en bois, fa\xe7ade avant, \xe9tiquette"
            .iter()
            .copied(),
    );
    bytes
}

/// The crate's MTL as bytes: a Latin-1 comment, the four maps in four file formats.
fn crate_mtl() -> Vec<u8> {
    let mut bytes =
        b"# crate.mtl: pin (sapin) non verni, \xe9tiquette sans mat\xe9riau\r\n".to_vec();
    bytes.extend_from_slice(
        b"newmtl crate_wood\r\nKd 1 1 1\r\nKs 0.5 0.5 0.5\r\nNs 40\r\nmap_Kd crate_albedo.jpg\r\n\
          map_Pr crate_roughness.tga\r\nnorm crate_normal.png\r\nmap_Ks crate_specular.bmp\r\n",
    );
    bytes
}

/// The crate's files: `(name, bytes, what)`. Textures in the formats people ship: JPEG albedo
/// (an odd size, 120x75), TGA roughness, 16-bit PNG normal map, BMP specular.
fn crate_assets() -> Vec<(String, Vec<u8>, String)> {
    use image::codecs::{bmp::BmpEncoder, jpeg::JpegEncoder, tga::TgaEncoder};
    let bytes8 = |values: &[f64]| values.iter().map(|&x| byte(x)).collect::<Vec<u8>>();
    let albedo = bytes8(&crate_texels(120, 75, |u, v| crate_albedo(u, v).to_vec()));
    let mut jpeg = Vec::new();
    JpegEncoder::new_with_quality(&mut jpeg, 90)
        .write_image(&albedo, 120, 75, ExtendedColorType::Rgb8)
        .expect("encoding a JPEG into memory cannot fail");
    let roughness = bytes8(&crate_texels(64, 64, |u, v| {
        vec![crate_roughness(u, v) * 255.0]
    }));
    let mut tga = Vec::new();
    TgaEncoder::new(&mut tga)
        .write_image(&roughness, 64, 64, ExtendedColorType::L8)
        .expect("encoding a TGA into memory cannot fail");
    let normal: Vec<u8> = crate_texels(64, 64, |u, v| {
        crate_normal(u, v).map(|x| x * 0.5 + 0.5).to_vec()
    })
    .iter()
    .flat_map(|&x| ((x * 65535.0).round().clamp(0.0, 65535.0) as u16).to_ne_bytes())
    .collect();
    let png16 = png(64, &normal, ExtendedColorType::Rgb16);
    let specular = bytes8(&crate_texels(64, 64, |u, v| {
        let s = 0.35 + 0.15 * fbm(u * 4.0, v * 4.0, 53, 3);
        vec![s * 255.0; 3]
    }));
    let mut bmp = Vec::new();
    BmpEncoder::new(&mut bmp)
        .write_image(&specular, 64, 64, ExtendedColorType::Rgb8)
        .expect("encoding a BMP into memory cannot fail");
    vec![
        (
            "crate.obj".to_owned(),
            crate_obj(),
            "untidy crate, 0.3 m: CRLF, a Latin-1 comment, quads, a label with an undefined material, a nameless `usemtl`".to_owned(),
        ),
        (
            "crate.mtl".to_owned(),
            crate_mtl(),
            "material `crate_wood` (Latin-1 comment), maps in four formats".to_owned(),
        ),
        (
            "crate_albedo.jpg".to_owned(),
            jpeg,
            "120x75 sRGB albedo, JPEG quality 90: five pine planks".to_owned(),
        ),
        (
            "crate_roughness.tga".to_owned(),
            tga,
            "64x64 linear roughness, 8-bit gray TGA".to_owned(),
        ),
        (
            "crate_normal.png".to_owned(),
            png16,
            "64x64 tangent-space normal map, 16-bit RGB PNG".to_owned(),
        ),
        (
            "crate_specular.bmp".to_owned(),
            bmp,
            "64x64 linear specular, 24-bit BMP".to_owned(),
        ),
    ]
}

// ---------------------------------------------------------------------------------------------
// Output
// ---------------------------------------------------------------------------------------------

/// Every output file, `(name, bytes)`, README last.
fn build_assets() -> Vec<(String, Vec<u8>)> {
    let mut files = Vec::new();
    let mut rows = Vec::new();
    for (mesh, material) in meshes() {
        let obj = mesh.to_obj();
        rows.push(format!(
            "| `{}.obj` | {} | {} triangles, {} vertices; {} |",
            mesh.name,
            obj.len(),
            mesh.triangle_count(),
            mesh.vertex_count(),
            mesh.description
        ));
        rows.push(format!(
            "| `{}.mtl` | {} | materials: {} |",
            mesh.name,
            material.len(),
            mesh.groups
                .iter()
                .map(|g| format!("`{}`", g.material))
                .collect::<Vec<_>>()
                .join(", ")
        ));
        files.push((format!("{}.obj", mesh.name), obj.into_bytes()));
        files.push((format!("{}.mtl", mesh.name), material.into_bytes()));
    }
    let what = [
        "sRGB albedo: maple and walnut squares, frame band",
        "linear roughness, gray",
        "tangent-space normal map, OpenGL (+Y up), RGB = n * 0.5 + 0.5",
        "linear clearcoat weight, gray: 0.9 squares, 0.7 frame",
    ];
    for ((name, bytes, size), what) in board_textures().into_iter().zip(what) {
        rows.push(format!(
            "| `{name}` | {} | {size}x{size} {what} |",
            bytes.len()
        ));
        files.push((name.to_owned(), bytes));
    }
    for (name, bytes, what) in crate_assets() {
        rows.push(format!("| `{name}` | {} | {what} |", bytes.len()));
        files.push((name, bytes));
    }
    let mut readme = String::new();
    let _ = writeln!(readme, "# Scene assets (generated)\n");
    let _ = writeln!(
        readme,
        "Meshes and textures of the canonical scenes, generated by\n`harness/src/bin/make_scene_assets.rs`:\n\n```sh\ncargo run -p harness --bin make_scene_assets -- scenes/assets\n```\n\nThe generator is deterministic (fixed-seed hash noise, fixed number formatting and PNG\nsettings): running it again gives byte-identical files. Do not edit these files by hand;\nchange the generator and run it again.\n"
    );
    let _ = writeln!(readme, "| file | bytes | contents |\n| --- | ---: | --- |");
    for row in rows {
        let _ = writeln!(readme, "{row}");
    }
    let _ = writeln!(
        readme,
        "\nConventions: meters, right-handed, +Y up; the board is centred on the origin with its\nplaying surface at y = 0 and square a1 at the (-X, +Z) corner. OBJ faces are triangles,\ncounter-clockwise seen from outside, with `v`/`vt`/`vn` on every corner; texture v is up.\nThe board's textures share one layout: the squares fill u, v in [1/16, 15/16], the frame is the\nouter band. See the generator's module documentation for details.\n\nLicence: CC0 1.0 (public domain), or at your option the project's licence. The EXR\nenvironments in this folder are not generated here; see `HDRI-LICENSE.txt`."
    );
    files.push(("README.md".to_owned(), readme.into_bytes()));
    files
}

/// Writes every output file into `dir`, creating it.
fn write_assets(dir: &Path) -> io::Result<()> {
    fs::create_dir_all(dir)?;
    for (name, bytes) in build_assets() {
        fs::write(dir.join(&name), &bytes)?;
        println!("{:>9} bytes  {}", bytes.len(), dir.join(&name).display());
    }
    Ok(())
}

fn main() {
    let mut args = env::args_os().skip(1);
    let (Some(dir), None) = (args.next(), args.next()) else {
        eprintln!("usage: make_scene_assets OUT_DIR");
        process::exit(2);
    };
    if let Err(e) = write_assets(&PathBuf::from(dir)) {
        eprintln!("make_scene_assets: {e}");
        process::exit(1);
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::collections::HashMap;

    /// Indices in range, unit normals, no degenerate triangles, every face turned the way its
    /// vertex normals point, texture space neither degenerate nor mirrored, watertight by position
    /// with consistent winding, positive volume.
    #[test]
    fn meshes_are_closed_outward_and_clean() {
        for (mesh, _) in meshes() {
            let mut volume = 0.0;
            let mut edges: HashMap<(String, String), i32> = HashMap::new();
            let key = |p: Vec3| format!("{} {} {}", num(p[0]), num(p[1]), num(p[2]));
            for g in &mesh.groups {
                for v in &g.vertices {
                    assert!((dot(v.n, v.n).sqrt() - 1.0).abs() < 1e-9, "{}", mesh.name);
                    assert!(
                        v.uv.iter().all(|x| (0.0..=1.0).contains(x)),
                        "{}",
                        mesh.name
                    );
                }
                for t in &g.triangles {
                    assert!(t.iter().all(|&i| (i as usize) < g.vertices.len()));
                    let [a, b, c] = t.map(|i| g.vertices[i as usize]);
                    let normal = cross(sub(b.p, a.p), sub(c.p, a.p));
                    assert!(
                        dot(normal, normal).sqrt() > 1e-10,
                        "degenerate in {}",
                        mesh.name
                    );
                    let smooth = add(add(a.n, b.n), c.n);
                    assert!(dot(normal, smooth) > 0.0, "inward face in {}", mesh.name);
                    volume += dot(a.p, cross(b.p, c.p)) / 6.0;
                    // Texture space: not degenerate (finite tangents) and not mirrored.
                    let (e1, e2) = (
                        [b.uv[0] - a.uv[0], b.uv[1] - a.uv[1]],
                        [c.uv[0] - a.uv[0], c.uv[1] - a.uv[1]],
                    );
                    assert!(e1[0] * e2[1] - e2[0] * e1[1] > 1e-12, "uv in {}", mesh.name);
                    for (p, q) in [(a.p, b.p), (b.p, c.p), (c.p, a.p)] {
                        *edges.entry((key(p), key(q))).or_default() += 1;
                    }
                }
            }
            assert!(volume > 0.0, "{}", mesh.name);
            for ((p, q), count) in &edges {
                assert_eq!(*count, 1, "{}: edge {p} -> {q}", mesh.name);
                let back = edges.get(&(q.clone(), p.clone())).copied().unwrap_or(0);
                assert_eq!(back, 1, "{}: open edge {p} -> {q}", mesh.name);
            }
        }
    }

    #[test]
    fn board_volume_and_dark_corner() {
        let mesh = board_mesh();
        let mut volume = 0.0;
        for g in &mesh.groups {
            for t in &g.triangles {
                let [a, b, c] = t.map(|i| g.vertices[i as usize].p);
                volume += dot(a, cross(b, c)) / 6.0;
            }
        }
        assert!((volume - 0.46 * 0.46 * 0.025).abs() < 1e-9);
        // a1 (u, v small) is walnut, h1 maple.
        assert_eq!(wood_site(0.1, 0.1).wood, Wood::Walnut);
        assert_eq!(wood_site(0.9, 0.1).wood, Wood::Maple);
        assert_eq!(wood_site(0.03, 0.5).wood, Wood::Frame);
    }

    #[test]
    fn meshes_are_deterministic() {
        let a: Vec<String> = meshes().iter().map(|(m, t)| m.to_obj() + t).collect();
        let b: Vec<String> = meshes().iter().map(|(m, t)| m.to_obj() + t).collect();
        assert_eq!(a, b);
    }
}

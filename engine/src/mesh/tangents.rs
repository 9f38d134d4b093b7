//! Tangents for [`MeshData::from_triangles`](super::MeshData::from_triangles): MikkTSpace (via
//! `bevy_mikktspace`) on the triangles that are non-degenerate in both position and UV space,
//! validation and repair of what it returns, and the vertex split where the corners of one
//! vertex receive different tangents (e.g. at a UV mirror seam).
//!
//! Like the asset loaders it serves, this code sees untrusted file data and must not panic.

#![cfg_attr(
    not(test),
    deny(
        clippy::unwrap_used,
        clippy::expect_used,
        clippy::panic,
        clippy::indexing_slicing
    )
)]

use std::collections::HashMap;

use bevy_mikktspace::{Geometry, TangentSpace};
use glam::{Vec2, Vec3};

use super::Vertex;

/// Which vertices touch at least one triangle that is non-degenerate in both position and UV
/// space; the others get a fallback tangent.
pub(super) fn healthy_vertices(pos: &[Vec3], uv: &[Vec2], tris: &[[u32; 3]]) -> Vec<bool> {
    let mut healthy = vec![false; pos.len()];
    for t in tris {
        if let Some(([pa, pb, pc], [ua, ub, uc])) = corners(pos, uv, t) {
            if !tri_degenerate(pa, pb, pc) && !uv_degenerate(ua, ub, uc) {
                for i in t.map(|i| i as usize) {
                    if let Some(h) = healthy.get_mut(i) {
                        *h = true;
                    }
                }
            }
        }
    }
    healthy
}

/// A triangle's corner positions and UVs, or None where an index is out of range.
fn corners(pos: &[Vec3], uv: &[Vec2], t: &[u32; 3]) -> Option<([Vec3; 3], [Vec2; 3])> {
    let [a, b, c] = t.map(|i| i as usize);
    Some((
        [*pos.get(a)?, *pos.get(b)?, *pos.get(c)?],
        [*uv.get(a)?, *uv.get(b)?, *uv.get(c)?],
    ))
}

/// The most triangles one vertex (by its position, normal and UV, as MikkTSpace welds them)
/// may touch for MikkTSpace to run: its time grows with the square of a vertex's triangle count
/// (a 25 000-triangle fan took 17 s), while meshes of real models stay far below this.
pub(super) const MAX_MIKKTSPACE_VALENCE: usize = 2048;

/// The largest number of triangles that share one vertex, vertices told apart as MikkTSpace
/// tells them (equal position, normal and UV are one vertex).
pub(super) fn max_valence(pos: &[Vec3], nrm: &[Vec3], uv: &[Vec2], tris: &[[u32; 3]]) -> usize {
    let mut count: HashMap<[u32; 8], usize> = HashMap::new();
    for &i in tris.iter().flatten() {
        let i = i as usize;
        let (p, n, t) = (
            pos.get(i).copied().unwrap_or(Vec3::ZERO),
            nrm.get(i).copied().unwrap_or(Vec3::ZERO),
            uv.get(i).copied().unwrap_or(Vec2::ZERO),
        );
        let key = [p.x, p.y, p.z, n.x, n.y, n.z, t.x, t.y].map(f32::to_bits);
        *count.entry(key).or_default() += 1;
    }
    count.into_values().max().unwrap_or(0)
}

/// Tangents by per-vertex accumulation (Lengyel's method: each triangle's UV-space tangent
/// and bitangent, summed at its corners' vertices), one slot per corner: the linear-time
/// stand-in for MikkTSpace on meshes beyond [`MAX_MIKKTSPACE_VALENCE`].
pub(super) fn accumulated_tangents(
    pos: &[Vec3],
    nrm: &[Vec3],
    uv: &[Vec2],
    tris: &[[u32; 3]],
) -> Vec<Option<[f32; 4]>> {
    let mut tangent = vec![Vec3::ZERO; pos.len()];
    let mut bitangent = vec![Vec3::ZERO; pos.len()];
    for t in tris {
        let Some(([pa, pb, pc], [ua, ub, uc])) = corners(pos, uv, t) else {
            continue;
        };
        let (e1, e2) = (pb - pa, pc - pa);
        let (d1, d2) = (ub - ua, uc - ua);
        let det = d1.x * d2.y - d2.x * d1.y;
        if det.abs() < 1e-20 || !det.is_finite() {
            continue;
        }
        let r = 1.0 / det;
        let (ft, fb) = ((e1 * d2.y - e2 * d1.y) * r, (e2 * d1.x - e1 * d2.x) * r);
        for i in t.map(|i| i as usize) {
            if let (Some(t), Some(b)) = (tangent.get_mut(i), bitangent.get_mut(i)) {
                *t += ft;
                *b += fb;
            }
        }
    }
    tris.iter()
        .flatten()
        .map(|&i| {
            let i = i as usize;
            let n = nrm.get(i).copied()?;
            let t = tangent.get(i).copied()?;
            let t = (t - n * n.dot(t)).try_normalize()?;
            let sign = if n.cross(t).dot(bitangent.get(i).copied()?) < 0.0 {
                -1.0
            } else {
                1.0
            };
            Some([t.x, t.y, t.z, sign])
        })
        .collect()
}

/// MikkTSpace tangents, one slot per triangle corner (`None` where it produced none), and
/// whether MikkTSpace succeeded.
pub(super) fn corner_tangents(
    pos: &[Vec3],
    nrm: &[Vec3],
    uv: &[Vec2],
    tris: &[[u32; 3]],
) -> (Vec<Option<[f32; 4]>>, bool) {
    let mut geo = Geo {
        pos,
        nrm,
        uv,
        tris,
        out: vec![None; tris.len() * 3],
    };
    let ok = bevy_mikktspace::generate_tangents(&mut geo).is_ok();
    (geo.out, ok)
}

/// The vertices and indices of the final mesh, and how many triangle corners got a fallback
/// tangent.
pub(super) struct Welded {
    /// One vertex per distinct (input vertex, repaired tangent).
    pub(super) vertices: Vec<Vertex>,
    /// Triangle list into `vertices`.
    pub(super) indices: Vec<u32>,
    /// Corners whose tangent was missing or degenerate.
    pub(super) fallback: usize,
}

/// Repairs each corner's tangent (corners of unhealthy vertices get the fallback) and splits
/// vertices that got different tangents, in corner order.
pub(super) fn weld(
    pos: &[Vec3],
    nrm: &[Vec3],
    uv: &[Vec2],
    tris: &[[u32; 3]],
    healthy: &[bool],
    corner_tangents: &[Option<[f32; 4]>],
) -> Welded {
    let mut fallback = 0usize;
    let mut map: HashMap<(u32, [u32; 4]), u32> = HashMap::new();
    let mut vertices: Vec<Vertex> = Vec::new();
    let mut out_indices: Vec<u32> = Vec::with_capacity(tris.len() * 3);
    for (corner, &vi) in tris.iter().flatten().enumerate() {
        let v = vi as usize;
        let normal = nrm.get(v).copied().unwrap_or(Vec3::Y);
        let raw = if healthy.get(v).copied().unwrap_or(false) {
            corner_tangents.get(corner).copied().flatten()
        } else {
            None
        };
        let (tangent, ok) = repair_tangent(raw, normal);
        if !ok {
            fallback += 1;
        }
        let key = (vi, tangent.map(f32::to_bits));
        let idx = match map.get(&key) {
            Some(&i) => i,
            None => {
                let i = vertices.len() as u32;
                vertices.push(Vertex {
                    position: pos.get(v).copied().unwrap_or(Vec3::ZERO).into(),
                    normal: normal.into(),
                    uv: uv.get(v).copied().unwrap_or(Vec2::ZERO).into(),
                    tangent,
                });
                map.insert(key, i);
                i
            }
        };
        out_indices.push(idx);
    }
    Welded {
        vertices,
        indices: out_indices,
        fallback,
    }
}

fn tri_degenerate(a: Vec3, b: Vec3, c: Vec3) -> bool {
    let (e1, e2, e3) = (b - a, c - a, c - b);
    let max_sq = e1
        .length_squared()
        .max(e2.length_squared())
        .max(e3.length_squared());
    let cross = e1.cross(e2).length();
    !(max_sq > 0.0 && cross.is_finite() && cross > 1e-6 * max_sq)
}

fn uv_degenerate(a: Vec2, b: Vec2, c: Vec2) -> bool {
    let (e1, e2, e3) = (b - a, c - a, c - b);
    let max_sq = e1
        .length_squared()
        .max(e2.length_squared())
        .max(e3.length_squared());
    let cross = e1.perp_dot(e2).abs();
    !(max_sq > 0.0 && cross.is_finite() && cross > 1e-6 * max_sq)
}

/// Gram-Schmidt against the unit normal `n`, normalize, snap `w` to ±1.
/// Falls back to an arbitrary unit vector orthogonal to `n` with `w = +1`
/// (returning `false`) when the input is missing or degenerate.
fn repair_tangent(t: Option<[f32; 4]>, n: Vec3) -> ([f32; 4], bool) {
    if let Some([x, y, z, w]) = t {
        let t = Vec3::new(x, y, z);
        let o = t - n * n.dot(t);
        let len = o.length();
        if len.is_finite() && len > 1e-4 {
            let o = o / len;
            if o.is_finite() && o.dot(n).abs() <= 1e-4 {
                let w = if w < 0.0 { -1.0 } else { 1.0 };
                return ([o.x, o.y, o.z, w], true);
            }
        }
    }
    let o = n.any_orthonormal_vector();
    ([o.x, o.y, o.z, 1.0], false)
}

/// Adapter between our arrays and the MikkTSpace interface; one tangent slot
/// per triangle corner.
struct Geo<'a> {
    pos: &'a [Vec3],
    nrm: &'a [Vec3],
    uv: &'a [Vec2],
    tris: &'a [[u32; 3]],
    out: Vec<Option<[f32; 4]>>,
}

impl Geo<'_> {
    fn vertex(&self, face: usize, vert: usize) -> usize {
        self.tris
            .get(face)
            .and_then(|t| t.get(vert))
            .map_or(usize::MAX, |&i| i as usize)
    }
}

impl Geometry for Geo<'_> {
    fn num_faces(&self) -> usize {
        self.tris.len()
    }

    fn num_vertices_of_face(&self, _face: usize) -> usize {
        3
    }

    fn position(&self, face: usize, vert: usize) -> [f32; 3] {
        self.pos
            .get(self.vertex(face, vert))
            .copied()
            .unwrap_or(Vec3::ZERO)
            .into()
    }

    fn normal(&self, face: usize, vert: usize) -> [f32; 3] {
        self.nrm
            .get(self.vertex(face, vert))
            .copied()
            .unwrap_or(Vec3::Y)
            .into()
    }

    fn tex_coord(&self, face: usize, vert: usize) -> [f32; 2] {
        self.uv
            .get(self.vertex(face, vert))
            .copied()
            .unwrap_or(Vec2::ZERO)
            .into()
    }

    fn set_tangent(&mut self, tangent_space: Option<TangentSpace>, face: usize, vert: usize) {
        if let Some(slot) = face
            .checked_mul(3)
            .and_then(|f| f.checked_add(vert))
            .and_then(|i| self.out.get_mut(i))
        {
            *slot = tangent_space.map(|t| t.tangent_encoded());
        }
    }
}

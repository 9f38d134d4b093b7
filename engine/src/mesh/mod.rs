//! Mesh data as the geometry pass consumes it: interleaved [`Vertex`]es with MikkTSpace-style
//! tangents, 32-bit indices and bounds. Everything about [`MeshData`] lives in this module:
//!
//! - here: [`Vertex`], [`Aabb`], [`MeshData`] and its basic methods ([`MeshData::new`],
//!   [`MeshData::triangle_count`], [`MeshData::subdivided`]);
//! - `from_triangles.rs`: [`MeshData::from_triangles`], which turns a loader's de-indexed arrays
//!   into a render-ready mesh (sanitized positions and indices, generated or repaired normals,
//!   fallback UVs);
//! - `tangents.rs`: the MikkTSpace tangents `from_triangles` uses, their validation and repair,
//!   and the vertex split where corners of one vertex get different tangents;
//! - `shapes.rs`: procedural constructors ([`uv_sphere`], [`cube`], [`plane`]) that tests and hard
//!   cases build scenes from without touching the file system.
//!
//! The asset loaders re-export these types as `engine::assets::{Aabb, MeshData, Vertex}`.

#![forbid(unsafe_code)]
#![warn(missing_docs)]

use bytemuck::{Pod, Zeroable};
use glam::Vec3;
use serde::Serialize;

mod from_triangles;
mod shapes;
mod tangents;

pub use shapes::{cube, plane, uv_sphere};

/// One interleaved vertex as the geometry pass reads it (48 bytes).
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, PartialEq, Pod, Zeroable)]
pub struct Vertex {
    /// Object-space position.
    pub position: [f32; 3],
    /// Object-space unit normal.
    pub normal: [f32; 3],
    /// Texture coordinates, OBJ convention (v grows upwards in the image).
    pub uv: [f32; 2],
    /// Object-space unit tangent (xyz, along +u) and handedness (w = +1 or -1): the bitangent is
    /// `cross(normal, tangent.xyz) * w`, along +v.
    pub tangent: [f32; 4],
}

/// Axis-aligned bounds.
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub struct Aabb {
    /// Smallest corner.
    pub min: [f32; 3],
    /// Largest corner.
    pub max: [f32; 3],
}

impl Aabb {
    /// Bounds of a set of points; an empty set gives a zero box at the origin.
    pub fn from_points(points: impl IntoIterator<Item = [f32; 3]>) -> Self {
        let mut min = Vec3::splat(f32::INFINITY);
        let mut max = Vec3::splat(f32::NEG_INFINITY);
        for p in points {
            min = min.min(Vec3::from(p));
            max = max.max(Vec3::from(p));
        }
        if min.x > max.x {
            return Self {
                min: [0.0; 3],
                max: [0.0; 3],
            };
        }
        Self {
            min: min.into(),
            max: max.into(),
        }
    }
}

/// A triangle mesh with one material slot.
#[derive(Clone, Debug)]
pub struct MeshData {
    /// Object or group name from the file (or the generator's name).
    pub name: String,
    /// Interleaved vertices.
    pub vertices: Vec<Vertex>,
    /// Triangle list indices into `vertices`.
    pub indices: Vec<u32>,
    /// Index of the material in the model's material list, if any.
    pub material: Option<usize>,
    /// Object-space bounds.
    pub bounds: Aabb,
}

impl MeshData {
    /// Builds a mesh and computes its bounds.
    pub fn new(name: &str, vertices: Vec<Vertex>, indices: Vec<u32>) -> Self {
        let bounds = Aabb::from_points(vertices.iter().map(|v| v.position));
        Self {
            name: name.to_owned(),
            vertices,
            indices,
            material: None,
            bounds,
        }
    }

    /// Number of triangles.
    pub fn triangle_count(&self) -> usize {
        self.indices.len() / 3
    }

    /// The same surface with four times the triangles: each triangle split at its edge
    /// midpoints (attributes interpolated linearly, normals and tangents renormalized; midpoints
    /// are not shared between triangles). For benchmarks of triangle cost.
    pub fn subdivided(&self) -> MeshData {
        let mut vertices = Vec::with_capacity(self.indices.len() * 2);
        let mut indices = Vec::with_capacity(self.indices.len() * 4);
        let midpoint = |a: &Vertex, b: &Vertex| {
            let mix = |x: &[f32], y: &[f32]| -> Vec<f32> {
                x.iter().zip(y).map(|(x, y)| 0.5 * (x + y)).collect()
            };
            let normal = Vec3::from_slice(&mix(&a.normal, &b.normal)).normalize_or_zero();
            let tangent =
                Vec3::from_slice(&mix(&a.tangent[..3], &b.tangent[..3])).normalize_or_zero();
            let p = mix(&a.position, &b.position);
            let uv = mix(&a.uv, &b.uv);
            Vertex {
                position: [p[0], p[1], p[2]],
                normal: normal.into(),
                uv: [uv[0], uv[1]],
                tangent: [tangent.x, tangent.y, tangent.z, a.tangent[3]],
            }
        };
        for triangle in self.indices.chunks_exact(3) {
            let [a, b, c] = [0, 1, 2].map(|i| self.vertices[triangle[i] as usize]);
            let base = vertices.len() as u32;
            vertices.extend([
                a,
                b,
                c,
                midpoint(&a, &b),
                midpoint(&b, &c),
                midpoint(&c, &a),
            ]);
            let [ia, ib, ic, iab, ibc, ica] = [0, 1, 2, 3, 4, 5].map(|i| base + i);
            indices.extend([ia, iab, ica, iab, ib, ibc, ica, ibc, ic, iab, ibc, ica]);
        }
        MeshData {
            material: self.material,
            ..MeshData::new(&self.name, vertices, indices)
        }
    }
}

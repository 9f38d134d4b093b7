//! Mesh data as the geometry pass consumes it: interleaved [`Vertex`]es with MikkTSpace-style
//! tangents, 32-bit indices, bounds, and a few procedural meshes (sphere, plane) that tests and
//! hard cases build scenes from without touching the file system.

use bytemuck::{Pod, Zeroable};
use glam::Vec3;
use serde::Serialize;

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

/// A UV sphere of radius 1 at the origin: `segments` around, `rings` from pole to pole, with the
/// seam duplicated. Tangents follow +u (eastwards), the bitangent +v (northwards); at the poles,
/// where +u is undefined, the tangent of the ring next to the pole is used.
pub fn uv_sphere(segments: u32, rings: u32) -> MeshData {
    let segments = segments.max(3);
    let rings = rings.max(2);
    let mut vertices = Vec::with_capacity(((segments + 1) * (rings + 1)) as usize);
    for ring in 0..=rings {
        let v = 1.0 - ring as f32 / rings as f32;
        let theta = std::f32::consts::PI * ring as f32 / rings as f32;
        for segment in 0..=segments {
            let u = segment as f32 / segments as f32;
            let phi = std::f32::consts::TAU * u;
            let normal = Vec3::new(
                theta.sin() * phi.cos(),
                theta.cos(),
                -theta.sin() * phi.sin(),
            );
            // d(position)/d(phi), normalised; independent of theta, so also valid at the poles.
            let tangent = Vec3::new(-phi.sin(), 0.0, -phi.cos());
            vertices.push(Vertex {
                position: normal.into(),
                normal: normal.into(),
                uv: [u, v],
                tangent: [tangent.x, tangent.y, tangent.z, 1.0],
            });
        }
    }
    let mut indices = Vec::with_capacity((segments * rings * 6) as usize);
    let stride = segments + 1;
    for ring in 0..rings {
        for segment in 0..segments {
            let a = ring * stride + segment;
            let b = a + stride;
            // Counter-clockwise seen from outside; skip the degenerate triangle at each pole.
            if ring != 0 {
                indices.extend_from_slice(&[a, b, a + 1]);
            }
            if ring != rings - 1 {
                indices.extend_from_slice(&[a + 1, b, b + 1]);
            }
        }
    }
    MeshData::new("uv_sphere", vertices, indices)
}

/// An axis-aligned box from -1 to 1 with flat faces (four vertices each), outward normals,
/// per-face UVs 0..1 and tangents along +u.
pub fn cube() -> MeshData {
    let faces = [
        Vec3::X,
        Vec3::NEG_X,
        Vec3::Y,
        Vec3::NEG_Y,
        Vec3::Z,
        Vec3::NEG_Z,
    ];
    let mut vertices = Vec::with_capacity(24);
    let mut indices = Vec::with_capacity(36);
    for (face, n) in faces.into_iter().enumerate() {
        // v runs along `up` (or -Z on the top and bottom faces), u along up x n.
        let up = if n.y.abs() > 0.5 {
            Vec3::new(0.0, 0.0, -n.y)
        } else {
            Vec3::Y
        };
        let u_axis = up.cross(n);
        for (a, b) in [(-1.0, -1.0), (1.0, -1.0), (1.0, 1.0), (-1.0, 1.0)] {
            let p = n + u_axis * a + up * b;
            vertices.push(Vertex {
                position: p.into(),
                normal: n.into(),
                uv: [(a + 1.0) / 2.0, (b + 1.0) / 2.0],
                tangent: [u_axis.x, u_axis.y, u_axis.z, 1.0],
            });
        }
        let base = face as u32 * 4;
        indices.extend_from_slice(&[base, base + 1, base + 2, base, base + 2, base + 3]);
    }
    MeshData::new("cube", vertices, indices)
}

/// A square in the XZ plane, `size` wide, facing +Y, with UVs 0..`uv_scale`.
pub fn plane(size: f32, uv_scale: f32) -> MeshData {
    let h = size / 2.0;
    let corners = [
        (-h, h, 0.0, 0.0),
        (h, h, 1.0, 0.0),
        (h, -h, 1.0, 1.0),
        (-h, -h, 0.0, 1.0),
    ];
    let vertices = corners
        .iter()
        .map(|&(x, z, u, v)| Vertex {
            position: [x, 0.0, z],
            normal: [0.0, 1.0, 0.0],
            uv: [u * uv_scale, v * uv_scale],
            tangent: [1.0, 0.0, 0.0, 1.0],
        })
        .collect();
    MeshData::new("plane", vertices, vec![0, 1, 2, 0, 2, 3])
}

#[cfg(test)]
mod tests {
    use super::*;

    fn check_winding_and_frames(mesh: &MeshData) {
        for tri in mesh.indices.chunks_exact(3) {
            let p = |i: u32| Vec3::from(mesh.vertices[i as usize].position);
            let n = Vec3::from(mesh.vertices[tri[0] as usize].normal);
            let face = (p(tri[1]) - p(tri[0])).cross(p(tri[2]) - p(tri[0]));
            assert!(face.dot(n) > 0.0, "{tri:?} winds clockwise");
        }
        for v in &mesh.vertices {
            let n = Vec3::from(v.normal);
            let t = Vec3::new(v.tangent[0], v.tangent[1], v.tangent[2]);
            assert!((n.length() - 1.0).abs() < 1e-5);
            assert!((t.length() - 1.0).abs() < 1e-5);
            assert!(n.dot(t).abs() < 1e-5);
        }
    }

    #[test]
    fn sphere_is_closed_outward_and_has_orthonormal_frames() {
        let mesh = uv_sphere(16, 8);
        check_winding_and_frames(&mesh);
        assert_eq!(mesh.triangle_count(), 16 * 8 * 2 - 2 * 16);
    }

    #[test]
    fn cube_is_closed_and_outward() {
        let mesh = cube();
        check_winding_and_frames(&mesh);
        assert_eq!(mesh.triangle_count(), 12);
    }

    #[test]
    fn plane_faces_up() {
        check_winding_and_frames(&plane(2.0, 1.0));
    }

    #[test]
    fn sphere_tangent_points_along_increasing_u() {
        let mesh = uv_sphere(32, 16);
        let v = &mesh.vertices[(8 * 33 + 4) as usize];
        let next = &mesh.vertices[(8 * 33 + 5) as usize];
        let along_u = Vec3::from(next.position) - Vec3::from(v.position);
        let t = Vec3::new(v.tangent[0], v.tangent[1], v.tangent[2]);
        assert!(along_u.normalize().dot(t) > 0.99);
    }
}

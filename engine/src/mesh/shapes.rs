//! Procedural meshes: constructors of [`MeshData`] for a UV sphere, a cube and a plane, which
//! tests and hard cases build scenes from without touching the file system.

use glam::Vec3;

use super::{MeshData, Vertex};

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

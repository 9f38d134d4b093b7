//! Normal and tangent guarantees on small fixture meshes.

use crate::common;
use crate::common::{check_model, load};

#[test]
fn vertex_is_48_bytes_and_pod() {
    assert_eq!(std::mem::size_of::<engine::assets::Vertex>(), 48);
    let v = engine::assets::Vertex {
        position: [1.0, 2.0, 3.0],
        normal: [0.0, 1.0, 0.0],
        uv: [0.5, 0.5],
        tangent: [1.0, 0.0, 0.0, 1.0],
    };
    assert_eq!(bytemuck::bytes_of(&v).len(), 48);
}

#[test]
fn cube_with_normals_and_uvs() {
    let model = load("cube.obj").unwrap();
    check_model(&model);
    let mesh = &model.meshes[0];
    assert_eq!(mesh.triangle_count(), 12);
    assert_eq!(mesh.vertices.len(), 24);
    assert_eq!(mesh.bounds.min, [-1.0; 3]);
    assert_eq!(mesh.bounds.max, [1.0; 3]);
    // On the +Z face u runs along +X, so the tangent is +X with w = +1.
    for v in mesh.vertices.iter().filter(|v| v.normal == [0.0, 0.0, 1.0]) {
        assert!((v.tangent[0] - 1.0).abs() < 1e-4, "{v:?}");
        assert_eq!(v.tangent[3], 1.0);
    }
}

#[test]
fn mirrored_uvs_get_opposite_handedness_and_split_seam() {
    let model = load("mirrored_quad.obj").unwrap();
    check_model(&model);
    let mesh = &model.meshes[0];
    assert_eq!(mesh.triangle_count(), 4);
    // 6 positions; the 2 seam vertices are split into a +1 and a -1 copy.
    assert_eq!(mesh.vertices.len(), 8, "{:#?}", mesh.vertices);
    for v in &mesh.vertices {
        let x = v.position[0];
        if x < 1.0 {
            assert_eq!(v.tangent[3], 1.0, "{v:?}");
            assert!((v.tangent[0] - 1.0).abs() < 1e-4, "{v:?}");
        } else if x > 1.0 {
            assert_eq!(v.tangent[3], -1.0, "{v:?}");
            assert!((v.tangent[0] + 1.0).abs() < 1e-4, "{v:?}");
        }
    }
    let seam: Vec<_> = mesh
        .vertices
        .iter()
        .filter(|v| v.position[0] == 1.0)
        .collect();
    assert_eq!(seam.len(), 4);
    assert_eq!(seam.iter().filter(|v| v.tangent[3] == 1.0).count(), 2);
    assert_eq!(seam.iter().filter(|v| v.tangent[3] == -1.0).count(), 2);
    // Every triangle uses one handedness only.
    for tri in mesh.indices.chunks(3) {
        let w: Vec<f32> = tri
            .iter()
            .map(|&i| mesh.vertices[i as usize].tangent[3])
            .collect();
        assert!(w.iter().all(|&x| x == w[0]), "mixed handedness in {tri:?}");
    }
}

#[test]
fn collapsed_uvs_fall_back_to_plus_one() {
    let model = load("collapsed_uv.obj").unwrap();
    check_model(&model);
    for v in &model.meshes[0].vertices {
        assert_eq!(v.tangent[3], 1.0);
        assert_eq!(v.normal, [0.0, 0.0, 1.0]);
    }
    assert!(
        model.warnings.iter().any(|w| w.contains("degenerate")),
        "{:?}",
        model.warnings
    );
}

#[test]
fn zero_area_triangle() {
    let model = load("zero_area.obj").unwrap();
    check_model(&model);
    assert_eq!(model.meshes.len(), 2);
    let degenerate = model
        .meshes
        .iter()
        .find(|m| m.name == "degenerate")
        .unwrap();
    assert_eq!(degenerate.triangle_count(), 1);
    for v in &degenerate.vertices {
        assert_eq!(
            v.normal,
            [0.0, 1.0, 0.0],
            "zero-area normal falls back to +Y"
        );
        assert_eq!(v.tangent[3], 1.0);
    }
    let healthy = model.meshes.iter().find(|m| m.name == "healthy").unwrap();
    for v in &healthy.vertices {
        assert!(
            (v.normal[2] - 1.0).abs() < 1e-6,
            "generated normal is +Z: {v:?}"
        );
    }
}

#[test]
fn mesh_without_normals_gets_generated_normals() {
    let model = load("no_normals.obj").unwrap();
    check_model(&model);
    for v in &model.meshes[0].vertices {
        assert!((v.normal[2] - 1.0).abs() < 1e-6, "{v:?}");
    }
    assert!(
        model.warnings.iter().any(|w| w.contains("no normals")),
        "{:?}",
        model.warnings
    );
}

#[test]
fn mesh_without_uvs_gets_tangents() {
    let model = load("no_uvs.obj").unwrap();
    check_model(&model);
    assert_eq!(model.meshes[0].triangle_count(), 12);
    assert!(
        model.warnings.iter().any(|w| w.contains("no UVs")),
        "{:?}",
        model.warnings
    );
}

#[test]
fn zero_normal_is_replaced() {
    let model = load("zero_normal.obj").unwrap();
    check_model(&model);
    for v in &model.meshes[0].vertices {
        assert!((v.normal[2] - 1.0).abs() < 1e-6, "{v:?}");
    }
    assert!(model
        .warnings
        .iter()
        .any(|w| w.contains("zero or non-finite normals")));
}

#[test]
fn from_triangles_survives_hostile_input() {
    let mut notes = Vec::new();
    let nan = f32::NAN;
    let mesh = engine::assets::MeshData::from_triangles(
        "hostile",
        &[
            [0.0, 0.0, 0.0],
            [nan, 1.0, 0.0],
            [0.0, 1.0, f32::INFINITY],
            [1.0, 1.0, 1.0],
        ],
        Some(&[
            [nan, 0.0, 0.0],
            [0.0; 3],
            [0.0, 0.0, 2.0],
            [1e-30, 0.0, 0.0],
        ]),
        Some(&[[nan, 0.0], [0.0; 2], [0.0; 2], [1.0, 1.0]]),
        &[0, 1, 2, 0, 2, 3, 7, 8, 9, 0, 0, 0, 1],
        &mut notes,
    );
    for (i, v) in mesh.vertices.iter().enumerate() {
        common::check_vertex(v, &format!("hostile {i}"));
    }
    assert_eq!(mesh.triangle_count(), 3);
    assert!(!notes.is_empty());
}

/// A disc fanned from one centre vertex shared by more triangles than MikkTSpace is run for
/// (its time grows with the square of that count: 25 000 took 17 s) gets tangents by per-vertex
/// accumulation instead, with a note, valid, along +u with +v as the bitangent.
#[test]
fn a_vertex_shared_by_thousands_of_triangles_gets_accumulated_tangents() {
    let segments = 3000u32;
    let mut positions = vec![[0.0f32, 0.0, 0.0]];
    let mut uvs = vec![[0.5f32, 0.5]];
    for i in 0..=segments {
        let a = std::f32::consts::TAU * i as f32 / segments as f32;
        positions.push([a.cos(), a.sin(), 0.0]);
        uvs.push([0.5 + 0.5 * a.cos(), 0.5 + 0.5 * a.sin()]);
    }
    let normals = vec![[0.0f32, 0.0, 1.0]; positions.len()];
    let indices: Vec<u32> = (0..segments).flat_map(|i| [0, i + 1, i + 2]).collect();
    let mut notes = Vec::new();
    let start = std::time::Instant::now();
    let mesh = engine::assets::MeshData::from_triangles(
        "fan",
        &positions,
        Some(&normals),
        Some(&uvs),
        &indices,
        &mut notes,
    );
    assert!(start.elapsed().as_secs_f64() < 2.0, "{:?}", start.elapsed());
    assert!(
        notes
            .iter()
            .any(|n| n.contains("shared by 3000 triangles") && n.contains("accumulation")),
        "{notes:?}"
    );
    for (i, v) in mesh.vertices.iter().enumerate() {
        common::check_vertex(v, &format!("fan {i}"));
        // The UVs are the positions scaled: +u is +x, +v is +y.
        assert!(
            v.tangent[0] > 0.999 && v.tangent[3] == 1.0,
            "{i}: {:?}",
            v.tangent
        );
    }
}

/// A closed surface wound clockwise seen from outside is a warning naming the mesh and the
/// rule; wound counter-clockwise, or open, it is not. Vertices split by texture coordinate
/// (as a loader splits them) are the same corner.
#[test]
fn an_inside_out_closed_surface_is_warned_about() {
    // A tetrahedron, counter-clockwise seen from outside, its apex twice (two UVs).
    let positions = [
        [0.0, 0.0, 0.0],
        [1.0, 0.0, 0.0],
        [0.0, 1.0, 0.0],
        [0.0, 0.0, 1.0],
        [0.0, 0.0, 1.0],
    ];
    let outward: [u32; 12] = [0, 2, 1, 0, 1, 3, 1, 2, 4, 2, 0, 4];
    let inward: Vec<u32> = outward.chunks(3).flat_map(|t| [t[0], t[2], t[1]]).collect();
    let warned_at = |positions: &[[f32; 3]], indices: &[u32]| {
        let mut notes = Vec::new();
        engine::assets::MeshData::from_triangles("tet", positions, None, None, indices, &mut notes);
        notes.iter().any(|n| {
            n.starts_with("mesh `tet`: a closed surface whose triangles are wound clockwise")
                && n.contains("counter-clockwise triangles are front faces")
        })
    };
    let warned = |indices: &[u32]| warned_at(&positions, indices);
    assert!(!warned(&outward));
    assert!(warned(&inward));
    // Open (one face fewer), either way: no inside to speak of.
    assert!(!warned(&inward[3..]));
    // Far from the origin, and with -0.0 for a corner's 0: the same.
    let far = positions.map(|[x, y, z]| [x + 1e5, y, z]);
    assert!(warned_at(&far, &inward) && !warned_at(&far, &outward));
    let mut signed = positions;
    signed[4] = [-0.0, 0.0, 1.0];
    assert!(warned_at(&signed, &inward));
}

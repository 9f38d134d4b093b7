//! Bad-input fixtures: each must error (naming file, line and problem) or
//! load with a warning, and never panic.

use std::time::{Duration, Instant};

use crate::common;
use crate::common::{fixture, load, load_err};

#[test]
fn empty_obj() {
    let e = load_err("empty.obj");
    assert!(e.contains("no geometry"), "{e}");
}

#[test]
fn truncated_face() {
    let e = load_err("truncated_face.obj");
    assert!(
        e.contains("truncated_face.obj:4: face has 2 vertices, need at least 3"),
        "{e}"
    );
}

#[test]
fn truncated_vertex() {
    let e = load_err("truncated_vertex.obj");
    assert!(
        e.contains("truncated_vertex.obj:2: vertex has 2 coordinates, need 3"),
        "{e}"
    );
}

#[test]
fn face_index_out_of_range() {
    let e = load_err("out_of_range.obj");
    assert!(
        e.ends_with("out_of_range.obj:10: face index 9 out of range (8 positions)"),
        "{e}"
    );
    let err = load("out_of_range.obj").unwrap_err();
    assert_eq!(err.line(), Some(10));
    assert_eq!(err.path(), fixture("out_of_range.obj"));
}

#[test]
fn face_index_zero() {
    let e = load_err("zero_index.obj");
    assert!(
        e.contains("zero_index.obj:4: face index 0 is invalid"),
        "{e}"
    );
}

#[test]
fn relative_indices() {
    let e = load_err("relative_out_of_range.obj");
    assert!(
        e.contains(":4: relative face index -9 out of range (3 positions)"),
        "{e}"
    );
    let model = load("relative_ok.obj").unwrap();
    assert_eq!(model.meshes[0].triangle_count(), 1);
}

#[test]
fn nan_and_inf_coordinates() {
    let e = load_err("nan_coord.obj");
    assert!(
        e.contains("nan_coord.obj:2: vertex has non-finite value `nan`"),
        "{e}"
    );
    let e = load_err("inf_coord.obj");
    assert!(
        e.contains("inf_coord.obj:3: vertex has non-finite value `inf`"),
        "{e}"
    );
    let e = load_err("overflow_uv.obj");
    assert!(
        e.contains("overflow_uv.obj:5: texture coordinate has non-finite value `1e39`"),
        "{e}"
    );
}

/// Bytes that are not UTF-8 (a Latin-1 name) are read lossily with one warning naming the
/// file, the line and the byte; the model loads.
#[test]
fn non_utf8_bytes_load_with_a_warning() {
    let model = load("non_utf8.obj").unwrap();
    assert_eq!(model.meshes.len(), 1);
    let warnings: Vec<_> = model
        .warnings
        .iter()
        .filter(|w| w.contains("UTF-8"))
        .collect();
    assert_eq!(warnings.len(), 1, "{:?}", model.warnings);
    assert!(
        warnings[0].contains("non_utf8.obj:4: not UTF-8 at byte 6 (1 lines in all)"),
        "{}",
        warnings[0]
    );
    assert_eq!(model.meshes[0].name, "caf\u{fffd} \u{fffd}\u{fffd}");
}

/// A Latin-1 MTL loads with a warning of its own, and its material is found by the OBJ's
/// equally Latin-1 `usemtl` (both names are decoded the same way).
#[test]
fn latin1_mtl_loads_with_a_warning_and_its_material_is_used() {
    let model = load("latin1_mtl.obj").unwrap();
    assert!(
        model
            .warnings
            .iter()
            .any(|w| w.contains("latin1.mtl:1: not UTF-8 at byte 11 (2 lines in all)")),
        "{:?}",
        model.warnings
    );
    assert_eq!(model.materials.len(), 1);
    assert_eq!(model.meshes[0].material, Some(0));
    assert_eq!(model.materials[0].diffuse, Some([0.8, 0.2, 0.1]));
    assert!(!model
        .warnings
        .iter()
        .any(|w| w.contains("names no material")));
}

/// A missing library, a nameless `usemtl` and a name no MTL defines: each warns once, naming
/// the file and line, and their faces take the default material (no material index).
#[test]
fn untidy_material_references_warn_and_use_the_default_material() {
    let model = load("untidy_materials.obj").unwrap();
    let expect = [
        "untidy_materials.obj:2: material library",
        "does_not_exist.mtl` cannot be read",
        "untidy_materials.obj:7: `usemtl` without a name; the faces after it use the default material",
        "untidy_materials.obj:9: usemtl `nowhere` names no material in the loaded MTL files (2 uses)",
    ];
    for needle in expect {
        assert!(
            model.warnings.iter().any(|w| w.contains(needle)),
            "no warning with `{needle}`: {:?}",
            model.warnings
        );
    }
    assert_eq!(
        model
            .warnings
            .iter()
            .filter(|w| w.contains("nowhere"))
            .count(),
        1,
        "{:?}",
        model.warnings
    );
    let triangles: usize = model.meshes.iter().map(|m| m.indices.len() / 3).sum();
    assert_eq!(triangles, 3);
    assert!(model.meshes.iter().all(|m| m.material.is_none()));
}

#[test]
fn gigantic_indices_fail_fast() {
    for (name, needle) in [
        ("huge_index.obj", ":4: face index 4000000000 out of range (3 positions)"),
        ("huge_index_2_40.obj", ":4: face index 1099511627776 out of range (3 positions)"),
        (
            "huge_index_overflow.obj",
            ":5: texture coordinate index 99999999999999999999999 out of range (1 texture coordinates)",
        ),
    ] {
        let start = Instant::now();
        let e = load_err(name);
        assert!(start.elapsed() < Duration::from_secs(1), "{name} took {:?}", start.elapsed());
        assert!(e.contains(needle), "{e}");
    }
}

/// A library that is not there is a warning naming the OBJ's `mtllib` line and the file; the
/// mesh loads with the default material.
#[test]
fn missing_mtl_loads_with_a_warning() {
    let model = load("missing_mtl.obj").unwrap();
    assert_eq!(model.meshes.len(), 1);
    assert!(model.materials.is_empty());
    assert!(
        model
            .warnings
            .iter()
            .any(|w| w.contains("missing_mtl.obj:1: material library")
                && w.contains("does_not_exist.mtl` cannot be read")),
        "{:?}",
        model.warnings
    );
}

#[test]
fn missing_texture() {
    let e = load_err("missing_texture.obj");
    assert!(
        e.contains("missing_texture.mtl:4: `map_Kd` texture failed to load"),
        "{e}"
    );
    assert!(e.contains("textures/nope.png: cannot read file"), "{e}");
    let err = load("missing_texture.obj").unwrap_err();
    assert_eq!(err.path(), fixture("textures/nope.png"));
}

#[test]
fn corrupt_texture() {
    let e = load_err("corrupt_texture.obj");
    assert!(
        e.contains("corrupt_texture.mtl:2: `map_roughness` texture failed to load"),
        "{e}"
    );
    assert!(e.contains("corrupt.png: cannot decode image"), "{e}");
}

#[test]
fn short_kd_is_an_error_not_a_panic() {
    // tobj's own MTL parser panics on this line.
    let e = load_err("short_kd.obj");
    assert!(
        e.contains("short_kd.mtl:2: `Kd` needs 3 values, found 2"),
        "{e}"
    );
}

#[test]
fn unknown_mtl_keys_warn() {
    let model = load("unknown_keys.obj").unwrap();
    let w = model.warnings.join("\n");
    assert!(
        w.contains("unknown_keys.mtl:3: unknown MTL key `foo_bar` ignored"),
        "{w}"
    );
    assert!(
        w.contains("unknown_keys.mtl:6: unknown texture option `-zz` ignored"),
        "{w}"
    );
    assert!(!w.contains("`Ka`") && !w.contains("`illum`"), "{w}");
    assert!(model.materials[0].maps.base_color.is_some());
}

#[test]
fn points_and_lines_are_skipped() {
    let model = load("points_lines.obj").unwrap();
    assert_eq!(model.meshes.len(), 1);
    assert_eq!(model.meshes[0].triangle_count(), 1);
    let w = model.warnings.join("\n");
    assert!(
        w.contains("points_lines.obj:5: skipped 1 point (p) and 2 line (l) elements"),
        "{w}"
    );
}

#[test]
fn quads_and_ngons_are_triangulated() {
    let model = load("ngons.obj").unwrap();
    assert_eq!(model.meshes[0].triangle_count(), 5);
    assert!(model
        .warnings
        .iter()
        .any(|w| w.contains("triangulated 2 polygons")));
    common::check_model(&model);
}

#[test]
fn groups_stay_separate_meshes() {
    let model = load("groups.obj").unwrap();
    let names: Vec<&str> = model.meshes.iter().map(|m| m.name.as_str()).collect();
    assert_eq!(names, ["left", "right"]);
}

#[test]
fn missing_obj() {
    let e = load_err("no_such_file.obj");
    assert!(e.contains("cannot read file"), "{e}");
}

/// A face whose vertices mix forms (one names a texture coordinate or normal, another not)
/// is refused with its line: loaded, it would leave the mesh without one per vertex, and all
/// of them generated, with no line to find it by.
#[test]
fn a_face_that_mixes_vertex_forms_names_its_line() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("mixed.obj");
    let head = "v 0 0 0\nv 1 0 0\nv 0 1 0\nvt 0 0\nvt 1 0\nvn 0 0 1\n";
    for (face, says) in [
        (
            "f 1/1 2/2 3/",
            ":7: face mixes vertex forms: `1/1` names a texture coordinate and `3/` does not",
        ),
        (
            "f 1//1 2 3//1",
            ":7: face mixes vertex forms: `1//1` names a normal and `2` does not",
        ),
    ] {
        std::fs::write(&path, format!("{head}{face}\n")).unwrap();
        let e = engine::assets::load_obj(&path, &mut engine::assets::TextureCache::new())
            .unwrap_err()
            .to_string();
        assert!(e.contains(&format!("mixed.obj{says}")), "{e}");
    }
    std::fs::write(&path, format!("{head}f 1/1/1 2/2/1 3/1/1\n")).unwrap();
    assert!(engine::assets::load_obj(&path, &mut engine::assets::TextureCache::new()).is_ok());
    // Faces of two forms in one mesh load, with a warning naming both lines; in two meshes
    // (a group between them), without.
    let load = |faces: &str| {
        std::fs::write(&path, format!("{head}{faces}")).unwrap();
        engine::assets::load_obj(&path, &mut engine::assets::TextureCache::new())
            .unwrap()
            .warnings
    };
    let warnings = load("f 1/1 2/2 3/1\nf 1 2 3\n");
    assert!(
        warnings.iter().any(|w| w.ends_with(
            "mixed.obj:7: this face names texture coordinates and the face at line 8 of the \
             same mesh does not: the mesh's texture coordinates are generated for all of it"
        )),
        "{warnings:?}"
    );
    let warnings = load("f 1/1 2/2 3/1\ng two\nf 1 2 3\n");
    assert!(
        !warnings.iter().any(|w| w.contains("this face names")),
        "{warnings:?}"
    );
}

#[test]
fn random_garbage_never_panics() {
    // Deterministic xorshift fuzz over OBJ-ish tokens.
    let tokens = [
        "v", "vt", "vn", "f", "l", "p", "o", "g", "s", "usemtl", "mtllib", "1", "-1", "0", "2/1",
        "1//1", "3/2/1", "nan", "1e40", "0.5", "-3", "/", "//", "\n", "\n", " ", "x",
    ];
    let dir = tempfile::tempdir().unwrap();
    let mut state = 0x2545_f491_4f6c_dd1du64;
    for case in 0..200 {
        let mut text = String::new();
        for _ in 0..60 {
            state ^= state << 13;
            state ^= state >> 7;
            state ^= state << 17;
            text.push_str(tokens[(state % tokens.len() as u64) as usize]);
            text.push(' ');
        }
        let path = dir.path().join(format!("fuzz{case}.obj"));
        std::fs::write(&path, text).unwrap();
        let _ = engine::assets::load_obj(&path, &mut engine::assets::TextureCache::new());
    }
}

/// A `newmtl` without a name (assimp's `empty_mat.obj` has one) warns, naming the file and line,
/// and its block is dropped unread (its missing texture is never loaded); the named material
/// after it loads, and faces without a material take the default.
#[test]
fn a_nameless_newmtl_warns_and_its_block_is_ignored() {
    let model = load("empty_mat.obj").unwrap();
    assert!(
        model
            .warnings
            .iter()
            .any(|w| w.contains("empty_mat.mtl:2: `newmtl` without a name; its block is ignored")),
        "{:?}",
        model.warnings
    );
    assert_eq!(model.materials.len(), 1, "{:?}", model.materials);
    assert_eq!(model.materials[0].name, "red");
    assert_eq!(model.materials[0].diffuse, Some([0.8, 0.1, 0.1]));
    let materials: Vec<Option<usize>> = model.meshes.iter().map(|m| m.material).collect();
    assert!(
        materials.contains(&Some(0)) && materials.contains(&None),
        "{materials:?}"
    );
}

/// OBJ files in UTF-16 with a byte-order mark (assimp's `box_UTF16BE.obj` is one) are decoded,
/// with a warning naming the file and the encoding, and load like their UTF-8 original.
#[test]
fn utf16_obj_files_with_a_byte_order_mark_are_decoded() {
    let original = load("cube.obj").unwrap();
    for (name, encoding) in [
        ("box_utf16be.obj", "UTF-16 BE"),
        ("box_utf16le.obj", "UTF-16 LE"),
    ] {
        let model = load(name).unwrap_or_else(|e| panic!("{name}: {e}"));
        assert!(
            model
                .warnings
                .iter()
                .any(|w| w.contains(&format!("{name}: {encoding} text")) && w.contains("decoded")),
            "{name}: {:?}",
            model.warnings
        );
        let triangles = |m: &engine::assets::Model| -> usize {
            m.meshes.iter().map(|mesh| mesh.indices.len() / 3).sum()
        };
        assert_eq!(triangles(&model), triangles(&original), "{name}");
        assert_eq!(
            model.meshes[0].vertices, original.meshes[0].vertices,
            "{name}: the decoded cube differs from the UTF-8 one"
        );
    }
}

/// A mesh's notes (here: corners whose UVs collapse, so their tangent is a fallback) name the
/// OBJ file as well as the mesh, whose name alone (`unnamed_object` without `o` or `g`) does
/// not say where it is.
#[test]
fn a_mesh_note_names_the_obj_file() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("flat_uvs.obj");
    std::fs::write(
        &path,
        "v 0 0 0\nv 1 0 0\nv 0 1 0\nvt 0.5 0.5\nf 1/1 2/1 3/1\n",
    )
    .unwrap();
    let model = engine::assets::load_obj(&path, &mut engine::assets::TextureCache::new()).unwrap();
    let prefix = format!("{}: mesh `", path.display());
    assert!(
        model
            .warnings
            .iter()
            .any(|w| w.starts_with(&prefix) && w.contains("arbitrary tangent")),
        "{:?}",
        model.warnings
    );
}

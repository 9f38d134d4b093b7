//! Shared helpers for the integration tests.
#![allow(dead_code)]

use std::path::PathBuf;

use engine::assets::{AssetError, Model, TextureCache, Vertex};

/// Absolute path of a file under `tests/fixtures`.
pub fn fixture(name: &str) -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
        .join("tests/fixtures")
        .join(name)
}

/// Loads a fixture OBJ with a fresh texture cache.
pub fn load(name: &str) -> Result<Model, AssetError> {
    let _ = env_logger::builder().is_test(true).try_init();
    engine::assets::load_obj(&fixture(name), &mut TextureCache::new())
}

/// Loads a fixture that must fail and returns the error's Display text,
/// checking that it names the fixture (or its same-stem `.mtl`).
pub fn load_err(name: &str) -> String {
    match load(name) {
        Ok(m) => panic!("{name} loaded but should fail: {} meshes", m.meshes.len()),
        Err(e) => {
            let text = e.to_string();
            println!("{name}: {text}");
            let stem = name.rsplit_once('.').map_or(name, |(s, _)| s);
            assert!(text.contains(stem), "error does not name {name}: {text}");
            text
        }
    }
}

fn len3(v: [f32; 3]) -> f32 {
    (v[0] * v[0] + v[1] * v[1] + v[2] * v[2]).sqrt()
}

fn dot3(a: [f32; 3], b: [f32; 3]) -> f32 {
    a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
}

/// Asserts the normal/tangent guarantees on one vertex.
pub fn check_vertex(v: &Vertex, what: &str) {
    let n = v.normal;
    let t = [v.tangent[0], v.tangent[1], v.tangent[2]];
    assert!(
        v.tangent.iter().chain(&n).all(|c| c.is_finite()),
        "{what}: non-finite {v:?}"
    );
    assert!((len3(n) - 1.0).abs() <= 1e-3, "{what}: |n| = {}", len3(n));
    assert!((len3(t) - 1.0).abs() <= 1e-3, "{what}: |t| = {}", len3(t));
    assert!(dot3(t, n).abs() <= 1e-3, "{what}: t.n = {}", dot3(t, n));
    assert!(
        v.tangent[3] == 1.0 || v.tangent[3] == -1.0,
        "{what}: w = {}",
        v.tangent[3]
    );
}

/// Asserts the guarantees on every vertex of every mesh, and index validity.
pub fn check_model(model: &Model) {
    assert!(!model.meshes.is_empty());
    for mesh in &model.meshes {
        assert_eq!(mesh.indices.len() % 3, 0);
        for &i in &mesh.indices {
            assert!((i as usize) < mesh.vertices.len());
        }
        for (i, v) in mesh.vertices.iter().enumerate() {
            check_vertex(v, &format!("{} vertex {i}", mesh.name));
        }
    }
}

//! The harness library: image comparison, cross-backend checks, and (growing) goldens, bless and
//! reports. The `harness` binary is a thin command line over it.

pub mod bench;
pub mod check;
pub mod compare;
pub mod first_scene;
pub mod golden;
pub mod images;
pub mod inspect;
pub mod metrics;
pub mod reference;
pub mod report;
pub mod selftest;
pub mod shadow_reference;
pub mod suite;
pub mod sweep;
pub mod test_scenes;
pub mod tolerance;

/// The workspace root (the folder holding `scenes/` and `golden/`). `HARNESS_ROOT` overrides the
/// location compiled in, for running an installed binary against another checkout.
pub fn workspace_root() -> std::path::PathBuf {
    std::env::var_os("HARNESS_ROOT")
        .map(std::path::PathBuf::from)
        .unwrap_or_else(|| {
            let root = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("..");
            root.canonicalize().unwrap_or(root)
        })
}

/// The canonical scenes' folder, `<workspace>/scenes`.
pub fn scenes_dir() -> std::path::PathBuf {
    workspace_root().join("scenes")
}

/// Loads a scene by canonical name (`chess`) or path (`scenes/chess.toml`).
pub fn load_scene(
    name_or_path: &str,
) -> Result<engine::scene_file::LoadedScene, engine::scene_file::SceneFileError> {
    let path = engine::scene_file::resolve(name_or_path, &scenes_dir())?;
    engine::scene_file::load(&path)
}

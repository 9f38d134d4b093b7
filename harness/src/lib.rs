//! The harness library: renders the canonical scenes, compares every pass with its golden within
//! measured tolerances, blesses, measures speed against error, and writes the review page. The
//! `harness` binary is a thin command line over it.
//!
//! Rooms: [`golden`] (store, tolerances, metrics, suite, check, noise model, self-test),
//! [`reference`] (CPU references in f64), [`measure`] (bench, sweeps, hard cases) and
//! [`report`] (the HTML review page); beside them the small shared helpers ([`html`],
//! [`images`], [`stats`]) and the scenes built in code ([`test_scenes`], [`first_scene`]).

pub mod ci_report;
pub mod faults;
pub mod first_scene;
pub mod golden;
pub mod html;
pub mod images;
pub mod inspect;
pub mod measure;
pub mod reference;
pub mod report;
pub mod review;
pub mod test_scenes;
pub mod url;

/// Order statistics (one nearest-rank rule), shared with the engine's tests.
pub use engine::stats;

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

/// Where the harness caches precomputed IBL maps: `<workspace>/target/harness/ibl-cache`
/// (`HARNESS_IBL_CACHE` overrides it; an empty value turns the disk cache off).
pub fn ibl_cache_dir() -> Option<std::path::PathBuf> {
    match std::env::var_os("HARNESS_IBL_CACHE") {
        Some(dir) if dir.is_empty() => None,
        Some(dir) => Some(dir.into()),
        None => Some(workspace_root().join("target/harness/ibl-cache")),
    }
}

/// Points the engine's IBL disk cache at [`ibl_cache_dir`] (the CLI and the golden suite do
/// this at start-up, so a second run skips the precompute).
pub fn use_ibl_cache() {
    engine::ibl::cache::set_directory(ibl_cache_dir());
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

/// An error and its causes on one line, each cause once: a cause whose text the message so far
/// already contains (the loaders' errors quote their sources) is not repeated.
pub fn error_text(error: &(dyn std::error::Error + 'static)) -> String {
    let mut text = error.to_string();
    let mut cause = error.source();
    while let Some(next) = cause {
        let more = next.to_string();
        if !text.contains(&more) {
            text.push_str(": ");
            text.push_str(&more);
        }
        cause = next.source();
    }
    text
}

/// Identities' names, comma-separated, for messages.
pub fn names<T: std::fmt::Display>(ids: &[T]) -> String {
    let names: Vec<String> = ids.iter().map(ToString::to_string).collect();
    names.join(", ")
}

/// Serializes a backend as its name, or `-` for none (a source of renders that has no backend
/// of its own, such as synthetic rounding).
pub fn backend_or_dash<S: serde::Serializer>(
    backend: &Option<engine::backend::BackendKind>,
    s: S,
) -> Result<S::Ok, S::Error> {
    s.serialize_str(backend.map_or("-", engine::backend::BackendKind::name))
}

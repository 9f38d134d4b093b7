//! The harness library: image comparison, cross-backend checks, and (growing) goldens, bless and
//! reports. The `harness` binary is a thin command line over it.

pub mod compare;
pub mod first_scene;
pub mod golden;
pub mod images;
pub mod metrics;
pub mod reference;
pub mod test_scenes;
pub mod tolerance;

/// The workspace root (the folder holding `scenes/` and `golden/`). `HARNESS_ROOT` overrides the
/// location compiled in, for running an installed binary against another checkout.
pub fn workspace_root() -> std::path::PathBuf {
    std::env::var_os("HARNESS_ROOT")
        .map(std::path::PathBuf::from)
        .unwrap_or_else(|| std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join(".."))
}

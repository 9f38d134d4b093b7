//! Verifications kept across processes: a verification's outcome is a function of what its child
//! checks read (the scene and its assets, the candidates and the limits in the temporary golden
//! folder, the harness executable, the drivers and the environment they run under), so the same
//! candidates of the same scene need not be rendered again under every source. Off unless
//! [`CACHE_ENV`] names a folder: the test suite sets it, where the same change (arrow's light
//! brightened) is checked, blessed and accepted by several tests.
//!
//! The key covers every input a child check reads; where one cannot be read or named with
//! certainty (no driver library mapped in this process, a scene file changed since it was
//! loaded, a golden folder too large to hash), the verification is neither looked up nor kept.
//! Only outcomes every source gave are kept (a child that could not run says nothing about
//! the candidates).

use std::collections::hash_map::DefaultHasher;
use std::hash::{Hash, Hasher};
use std::path::{Path, PathBuf};

use engine::plan::TargetId;

use super::suite::Case;
use super::verify::Disagreement;

/// The environment variable naming the folder that keeps verifications.
pub const CACHE_ENV: &str = "HARNESS_VERIFY_CACHE";

/// Environment variables that can change what a child check renders or reads, by prefix (the
/// drivers' own, the loader's, the harness's), less [`NOT_IN_THE_KEY`].
const ENV_PREFIXES: [&str; 12] = [
    "GALLIUM_", "LP_", "LIBGL_", "MESA_", "VK_", "EGL_", "__EGL", "__GLX", "DRI_", "WGPU_", "LD_",
    "HARNESS_",
];
/// `HARNESS_ROOT` and `HARNESS_IBL_CACHE` are set for the children by the verification itself
/// (the IBL maps' own key covers their inputs); the cache's folder changes no outcome.
const NOT_IN_THE_KEY: [&str; 3] = ["HARNESS_ROOT", "HARNESS_IBL_CACHE", CACHE_ENV];

/// A golden folder larger than this is not hashed (and its scene's verifications not kept).
const MAX_HASHED_BYTES: u64 = 256 << 20;

/// The folder verifications are kept in, when [`CACHE_ENV`] names one.
pub fn folder() -> Option<PathBuf> {
    std::env::var_os(CACHE_ENV)
        .filter(|v| !v.is_empty())
        .map(PathBuf::from)
}

/// The key of verifying `candidates` of `case`, whose inputs digest is `inputs`
/// ([`super::verify::inputs_digest`]: every file the scene was loaded from, the noise model,
/// the executable),
/// against the temporary golden folder `golden` (which holds them and the limits); None when an
/// input cannot be hashed with certainty.
pub fn key(inputs: &str, case: &Case, golden: &Path, candidates: &[TargetId]) -> Option<String> {
    let mut hasher = DefaultHasher::new();
    "verification 2".hash(&mut hasher);
    inputs.hash(&mut hasher);
    candidates.hash(&mut hasher);
    hash_tree(golden, &mut hasher)?;
    // The scene's files are in `inputs`, digested when the scene was loaded; the children read
    // them as they are now, so a file edited since gives no key (their outcome would be the
    // edited scene's).
    if !case
        .inputs
        .changed_on_disk(&crate::workspace_root())
        .is_empty()
    {
        return None;
    }
    // The environment the children inherit.
    let mut vars: Vec<(String, String)> = std::env::vars()
        .filter(|(k, _)| {
            ENV_PREFIXES.iter().any(|p| k.starts_with(p)) && !NOT_IN_THE_KEY.contains(&k.as_str())
        })
        .collect();
    vars.sort();
    vars.hash(&mut hasher);
    // The drivers: Mesa's libraries this process has mapped, by path, size and time (it rendered
    // the scene, so they are the ones the children load; a process that rendered nothing does
    // not know which drivers the children would load, and keeps nothing).
    let drivers: Vec<_> = mapped_libraries()?
        .into_iter()
        .filter(|(path, _, _)| is_driver(path))
        .collect();
    if drivers.is_empty() {
        return None;
    }
    drivers.hash(&mut hasher);
    Some(format!("{:016x}", hasher.finish()))
}

/// The outcome kept under `key`, if any (an unreadable entry is a miss).
pub fn lookup(folder: &Path, key: &str) -> Option<Vec<Disagreement>> {
    let bytes = std::fs::read(folder.join(format!("{key}.json"))).ok()?;
    serde_json::from_slice(&bytes).ok()
}

/// Keeps `disagreements` under `key` (atomically; a failure to write is only a lost shortcut).
pub fn keep(folder: &Path, key: &str, disagreements: &[Disagreement]) {
    if disagreements.iter().any(|d| d.backend.is_none()) {
        return;
    }
    if let Ok(bytes) = serde_json::to_vec_pretty(disagreements) {
        let _ = engine::files::write_atomically(&folder.join(format!("{key}.json")), &bytes);
    }
}

/// Hashes every file under `root` (relative path and bytes, in name order); None when it is
/// larger than [`MAX_HASHED_BYTES`] or a file cannot be read. A missing folder hashes as empty.
fn hash_tree(root: &Path, hasher: &mut DefaultHasher) -> Option<()> {
    let mut files = Vec::new();
    let mut pending = vec![root.to_path_buf()];
    while let Some(dir) = pending.pop() {
        let Ok(entries) = std::fs::read_dir(&dir) else {
            continue;
        };
        for entry in entries.flatten() {
            let path = entry.path();
            match entry.file_type() {
                Ok(t) if t.is_dir() => pending.push(path),
                Ok(_) => files.push(path),
                Err(_) => return None,
            }
        }
    }
    files.sort();
    let mut total = 0u64;
    for file in files {
        let bytes = std::fs::read(&file).ok()?;
        total += bytes.len() as u64;
        if total > MAX_HASHED_BYTES {
            return None;
        }
        file.strip_prefix(root).ok()?.hash(hasher);
        bytes.hash(hasher);
    }
    Some(())
}

/// The shared libraries mapped into this process: path, size, modification time, in path order
/// (Linux `/proc/self/maps`; None elsewhere).
fn mapped_libraries() -> Option<Vec<(String, u64, Option<std::time::SystemTime>)>> {
    let maps = std::fs::read_to_string("/proc/self/maps").ok()?;
    let mut paths: Vec<&str> = maps
        .lines()
        .filter_map(|line| line.split_whitespace().nth(5))
        .filter(|path| path.starts_with('/') && path.contains(".so"))
        .collect();
    paths.sort_unstable();
    paths.dedup();
    Some(
        paths
            .into_iter()
            .filter_map(|path| {
                let meta = std::fs::metadata(path).ok()?;
                Some((path.to_owned(), meta.len(), meta.modified().ok()))
            })
            .collect(),
    )
}

/// Whether a library path is one of Mesa's drivers or what they are built on (llvmpipe,
/// lavapipe, their EGL and GLX front ends, LLVM).
fn is_driver(path: &str) -> bool {
    [
        "swrast_dri",
        "libgallium",
        "libvulkan_lvp",
        "libEGL_mesa",
        "libGLX_mesa",
        "libglapi",
        "libLLVM",
    ]
    .iter()
    .any(|name| path.contains(name))
}

//! FLIP maps kept for the images they were computed from. FLIP is a pure function of its two
//! images (and the viewing distance), and the costliest metric (about 0.12 CPU-s for a 512x512
//! pair here): a `check` evaluates it for every backend whose final differs from the golden, and
//! backends often render the same final (gl and wgpu-gl), so the same pair is evaluated again.
//!
//! - Within a process, the last [`KEPT_IN_MEMORY`] maps are kept, by a SHA-256 of both images.
//! - Across processes, maps are kept in the folder of [`super::super::verify_cache::CACHE_ENV`]
//!   when it names one (the test suite sets it: its `harness` children check the same unchanged
//!   finals of a host that rounds unlike the blessing one, and computed each of 51 distinct maps
//!   twice on average). A file that cannot be read as a whole map is computed again; a map that
//!   cannot be written is only not kept.

use std::collections::VecDeque;
use std::path::{Path, PathBuf};
use std::sync::{Arc, Mutex};

use sha2::{Digest, Sha256};

/// How many maps a process keeps (1 MiB each at 512x512).
const KEPT_IN_MEMORY: usize = 8;

/// The key of a FLIP map: what it was computed from, hashed.
pub type Key = [u8; 32];

/// Maps computed in this process, the newest last.
static MEMORY: Mutex<VecDeque<(Key, Arc<Vec<f32>>)>> = Mutex::new(VecDeque::new());

/// The key of FLIP of `test` against `reference` (RGB bytes, `width` x `height`) at
/// `pixels_per_degree`.
pub fn key(reference: &[u8], test: &[u8], width: u32, height: u32, pixels_per_degree: f32) -> Key {
    let mut hash = Sha256::new();
    // The implementation's name: a FLIP of another version would be another function.
    hash.update(b"nv-flip 0.1 LDR");
    hash.update(width.to_le_bytes());
    hash.update(height.to_le_bytes());
    hash.update(pixels_per_degree.to_le_bytes());
    hash.update((reference.len() as u64).to_le_bytes());
    hash.update(reference);
    hash.update(test);
    hash.finalize().into()
}

/// The map kept for `key` (`len` values), from memory or the shared folder.
pub(super) fn get(key: &Key, len: usize) -> Option<Arc<Vec<f32>>> {
    if let Ok(memory) = MEMORY.lock() {
        if let Some((_, map)) = memory.iter().find(|(k, _)| k == key) {
            return Some(Arc::clone(map));
        }
    }
    let map = Arc::new(read(&shared_folder()?, key, len)?);
    remember(*key, Arc::clone(&map));
    Some(map)
}

/// Keeps `map` for `key`: in memory, and in the shared folder when there is one.
pub(super) fn put(key: Key, map: Arc<Vec<f32>>) {
    if let Some(folder) = shared_folder() {
        if let Err(e) = write(&folder, &key, &map) {
            log::debug!("FLIP map not kept in {}: {e}", folder.display());
        }
    }
    remember(key, map);
}

/// The map of `key` in `folder`, if a whole one of `len` values is there.
pub fn read(folder: &Path, key: &Key, len: usize) -> Option<Vec<f32>> {
    let bytes = std::fs::read(file(folder, key)).ok()?;
    (bytes.len() == len * 4).then(|| {
        bytes
            .chunks_exact(4)
            .map(|b| f32::from_le_bytes([b[0], b[1], b[2], b[3]]))
            .collect()
    })
}

/// Writes the map of `key` into `folder` (whole or not at all; the folder is made if missing).
pub fn write(folder: &Path, key: &Key, map: &[f32]) -> Result<(), crate::images::ImageFileError> {
    let bytes: Vec<u8> = map.iter().flat_map(|v| v.to_le_bytes()).collect();
    crate::images::write_atomically(&file(folder, key), &bytes)
}

/// Adds a map to this process's memory, dropping the oldest beyond [`KEPT_IN_MEMORY`].
fn remember(key: Key, map: Arc<Vec<f32>>) {
    if let Ok(mut memory) = MEMORY.lock() {
        if memory.iter().any(|(k, _)| *k == key) {
            return;
        }
        if memory.len() == KEPT_IN_MEMORY {
            memory.pop_front();
        }
        memory.push_back((key, map));
    }
}

/// The folder shared by processes, when [`super::super::verify_cache::CACHE_ENV`] names one.
fn shared_folder() -> Option<PathBuf> {
    Some(super::super::verify_cache::folder()?.join("flip"))
}

/// The file of `key` in `folder`.
pub fn file(folder: &Path, key: &Key) -> PathBuf {
    let hex: String = key.iter().map(|b| format!("{b:02x}")).collect();
    folder.join(format!("{hex}.f32"))
}

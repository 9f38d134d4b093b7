//! Caches of precomputed IBL maps: one in memory per process, and optionally one on disk.
//!
//! Disk entries are named by the SHA-256 of the environment's texels, its size, the
//! [`IblSettings`], [`FORMAT_VERSION`] and the source text of this folder's code (so any edit
//! to the algorithm misses, without anyone having to remember a version bump). An
//! entry is written to a temporary file in the same directory and renamed into place, so a
//! reader never sees half of one. Each entry ends with the SHA-256 of its payload: an entry
//! that is truncated, corrupt or from another version is rebuilt (with a warning), never
//! trusted. A folder keeps at most [`MAX_DIRECTORY_BYTES`] of entries: each write removes the
//! entries used longest ago past that (a hit marks its entry used), since every edit of this
//! folder's code makes new keys and the old entries would otherwise stay forever.

use std::collections::VecDeque;
use std::path::{Path, PathBuf};
use std::sync::{Arc, Mutex, RwLock, Weak};

use sha2::{Digest, Sha256};

use super::{CubeLevel, CubeMap, IblMaps, IblSettings};
use crate::scene::EnvironmentImage;

/// Bump when the entry layout changes (an algorithm change already changes the key through
/// [`ALGORITHM_SOURCES`]).
pub const FORMAT_VERSION: u32 = 4;

/// The source of every file of the IBL precompute (this folder), part of every key: the maps
/// are a function of the image, the settings and this code. A test checks the list covers the
/// folder.
pub const ALGORITHM_SOURCES: [(&str, &str); 7] = [
    ("cache.rs", include_str!("cache.rs")),
    ("cube.rs", include_str!("cube.rs")),
    ("dfg.rs", include_str!("dfg.rs")),
    ("irradiance.rs", include_str!("irradiance.rs")),
    ("mod.rs", include_str!("mod.rs")),
    ("specular.rs", include_str!("specular.rs")),
    ("sun.rs", include_str!("sun.rs")),
];

const MAGIC: &[u8; 8] = b"IBLMAPS\0";

/// The most bytes of entries one cache folder keeps (see [`evict`]): the maps of every scene,
/// sweep setting and sky the tests and sweeps use (about 60 entries of 1.7 to 8 MB) fit.
pub const MAX_DIRECTORY_BYTES: u64 = 512 << 20;

/// Maps kept in memory per process (most recent first out last).
const MEMORY_ENTRIES: usize = 8;

/// A cache entry's name: SHA-256 of everything the maps depend on.
pub type Key = [u8; 32];

/// Why the disk cache could not be written.
#[derive(Debug, thiserror::Error)]
#[error("IBL cache `{}`: {source}", path.display())]
pub struct CacheError {
    /// The file or directory.
    pub path: PathBuf,
    /// What failed.
    pub source: std::io::Error,
}

static DIRECTORY: RwLock<Option<PathBuf>> = RwLock::new(None);
static MEMORY: Mutex<VecDeque<(Key, Arc<IblMaps>)>> = Mutex::new(VecDeque::new());
/// Keys already computed for images still alive: hashing megabytes of texels again for every
/// frame would make a memory hit cost tens of milliseconds.
static KNOWN_KEYS: Mutex<Vec<(Weak<EnvironmentImage>, IblSettings, Key)>> = Mutex::new(Vec::new());

/// Sets (or with `None` clears) the directory [`super::prepare`] caches maps in. Without one,
/// maps are only kept in memory.
pub fn set_directory(directory: Option<PathBuf>) {
    *DIRECTORY.write().unwrap_or_else(|e| e.into_inner()) = directory;
}

/// The directory set with [`set_directory`].
pub fn directory() -> Option<PathBuf> {
    DIRECTORY.read().unwrap_or_else(|e| e.into_inner()).clone()
}

/// The key of an environment and settings.
pub fn key(image: &EnvironmentImage, settings: &IblSettings) -> Key {
    let mut hash = Sha256::new();
    hash.update(MAGIC);
    hash.update(FORMAT_VERSION.to_le_bytes());
    for (name, source) in ALGORITHM_SOURCES {
        hash.update(name.as_bytes());
        hash.update(source.as_bytes());
    }
    hash.update(image.width.to_le_bytes());
    hash.update(image.height.to_le_bytes());
    for texel in &image.texels {
        for c in texel {
            hash.update(c.to_bits().to_le_bytes());
        }
    }
    // The render-time knobs change no map: maps are shared across them.
    let maps_settings = settings.precomputed_part();
    hash.update(
        serde_json::to_vec(&maps_settings).expect("IBL settings serialise"), // plain struct
    );
    hash.finalize().into()
}

/// [`key`], remembered per image object while it lives (so a second frame of the same scene
/// does not hash its texels again).
pub fn key_of_shared(image: &Arc<EnvironmentImage>, settings: &IblSettings) -> Key {
    // Keyed by the precomputed part: settings that differ only in render-time knobs have the
    // same key, so the image is not hashed again for each of them.
    let settings = &settings.precomputed_part();
    let mut known = KNOWN_KEYS.lock().unwrap_or_else(|e| e.into_inner());
    known.retain(|(weak, _, _)| weak.strong_count() > 0);
    if let Some((_, _, key)) = known.iter().find(|(weak, s, _)| {
        s == settings && weak.upgrade().is_some_and(|live| Arc::ptr_eq(&live, image))
    }) {
        return *key;
    }
    drop(known);
    let computed = key(image, settings);
    KNOWN_KEYS.lock().unwrap_or_else(|e| e.into_inner()).push((
        Arc::downgrade(image),
        settings.clone(),
        computed,
    ));
    computed
}

/// Entry file name of a key.
pub fn file_name(key: &Key) -> String {
    let hex: String = key.iter().map(|b| format!("{b:02x}")).collect();
    format!("ibl-{hex}.bin")
}

pub(super) fn memory_get(key: &Key) -> Option<Arc<IblMaps>> {
    let memory = MEMORY.lock().unwrap_or_else(|e| e.into_inner());
    memory
        .iter()
        .find(|(k, _)| k == key)
        .map(|(_, m)| m.clone())
}

pub(super) fn memory_put(key: Key, maps: Arc<IblMaps>) {
    let mut memory = MEMORY.lock().unwrap_or_else(|e| e.into_inner());
    memory.retain(|(k, _)| *k != key);
    memory.push_back((key, maps));
    while memory.len() > MEMORY_ENTRIES {
        memory.pop_front();
    }
}

/// One lock per key being prepared, so that threads asking for the same maps at once build them
/// once: the first builds (or reads the disk), the others wait and then find them in memory.
static PREPARING: Mutex<Vec<(Key, Arc<Mutex<()>>)>> = Mutex::new(Vec::new());

/// The lock [`super::prepare`] holds while it reads or builds `key`'s maps (entries are dropped
/// once no thread holds or waits for them).
pub(super) fn preparing(key: &Key) -> Arc<Mutex<()>> {
    let mut locks = PREPARING.lock().unwrap_or_else(|e| e.into_inner());
    locks.retain(|(_, lock)| Arc::strong_count(lock) > 1);
    if let Some((_, lock)) = locks.iter().find(|(k, _)| k == key) {
        return lock.clone();
    }
    let lock = Arc::new(Mutex::new(()));
    locks.push((*key, lock.clone()));
    lock
}

/// Forgets the maps kept in memory (for tests and timing the disk cache).
pub fn clear_memory() {
    MEMORY.lock().unwrap_or_else(|e| e.into_inner()).clear();
}

fn push_level(out: &mut Vec<u8>, level: &CubeLevel) {
    out.extend_from_slice(&level.size.to_le_bytes());
    for t in &level.texels {
        for c in t {
            out.extend_from_slice(&c.to_le_bytes());
        }
    }
}

/// The bytes of an entry: header, payload, SHA-256 of the payload.
pub fn encode(key: &Key, maps: &IblMaps) -> Vec<u8> {
    let mut payload = Vec::new();
    for chain in [&maps.specular, &maps.radiance] {
        payload.extend_from_slice(&(chain.levels.len() as u32).to_le_bytes());
        for level in &chain.levels {
            push_level(&mut payload, level);
        }
    }
    push_level(&mut payload, &maps.irradiance);
    payload.extend_from_slice(&(maps.dfg.len() as u32).to_le_bytes());
    for t in &maps.dfg {
        payload.extend_from_slice(&t[0].to_le_bytes());
        payload.extend_from_slice(&t[1].to_le_bytes());
    }
    // The extracted suns: how many, then each one's texel count, direction, irradiance and
    // solid angle.
    payload.extend_from_slice(&(maps.suns.len() as u32).to_le_bytes());
    for sun in &maps.suns {
        payload.extend_from_slice(&(sun.texels as u32).to_le_bytes());
        let d = sun.direction;
        let [r, g, b] = sun.irradiance;
        for v in [d.x, d.y, d.z, r, g, b, sun.solid_angle] {
            payload.extend_from_slice(&v.to_le_bytes());
        }
    }
    let mut out = Vec::with_capacity(payload.len() + 84);
    out.extend_from_slice(MAGIC);
    out.extend_from_slice(&FORMAT_VERSION.to_le_bytes());
    out.extend_from_slice(key);
    out.extend_from_slice(&(payload.len() as u64).to_le_bytes());
    out.extend_from_slice(&payload);
    out.extend_from_slice(&Sha256::digest(&payload));
    out
}

struct Reader<'a>(&'a [u8]);

impl<'a> Reader<'a> {
    fn take(&mut self, n: usize) -> Result<&'a [u8], String> {
        if self.0.len() < n {
            return Err("truncated".into());
        }
        let (head, rest) = self.0.split_at(n);
        self.0 = rest;
        Ok(head)
    }

    fn u32(&mut self) -> Result<u32, String> {
        Ok(u32::from_le_bytes(
            self.take(4)?.try_into().expect("4 bytes"),
        ))
    }

    fn f32(&mut self) -> Result<f32, String> {
        let v = f32::from_le_bytes(self.take(4)?.try_into().expect("4 bytes"));
        if v.is_finite() {
            Ok(v)
        } else {
            Err("non-finite value".into())
        }
    }

    fn level(&mut self) -> Result<CubeLevel, String> {
        let size = self.u32()?;
        if size == 0 || size > 4096 {
            return Err(format!("bad level size {size}"));
        }
        let count = 6 * (size as usize).pow(2);
        if self.0.len() < count * 12 {
            return Err("truncated".into());
        }
        let texels = (0..count)
            .map(|_| Ok([self.f32()?, self.f32()?, self.f32()?]))
            .collect::<Result<_, String>>()?;
        Ok(CubeLevel { size, texels })
    }

    /// A level count, then the levels of a mip chain.
    fn chain(&mut self) -> Result<CubeMap, String> {
        let levels = self.u32()?;
        if levels == 0 || levels > 16 {
            return Err(format!("bad level count {levels}"));
        }
        Ok(CubeMap {
            levels: (0..levels)
                .map(|_| self.level())
                .collect::<Result<_, _>>()?,
        })
    }
}

/// Parses an entry, checking its header, key and checksum.
pub fn decode(key: &Key, bytes: &[u8]) -> Result<IblMaps, String> {
    let mut r = Reader(bytes);
    if r.take(8)? != MAGIC {
        return Err("not an IBL cache entry".into());
    }
    let version = r.u32()?;
    if version != FORMAT_VERSION {
        return Err(format!(
            "format version {version}, expected {FORMAT_VERSION}"
        ));
    }
    if r.take(32)? != key {
        return Err("key mismatch".into());
    }
    let length = u64::from_le_bytes(r.take(8)?.try_into().expect("8 bytes")) as usize;
    let payload = r.take(length)?;
    let checksum = r.take(32)?;
    if !r.0.is_empty() {
        return Err("trailing bytes".into());
    }
    if Sha256::digest(payload).as_slice() != checksum {
        return Err("checksum mismatch".into());
    }
    let mut p = Reader(payload);
    let specular = p.chain()?;
    let radiance = p.chain()?;
    let irradiance = p.level()?;
    let dfg_len = p.u32()? as usize;
    if p.0.len() < dfg_len * 8 {
        return Err("bad DFG table length".into());
    }
    let dfg = (0..dfg_len)
        .map(|_| Ok([p.f32()?, p.f32()?]))
        .collect::<Result<_, String>>()?;
    let count = p.u32()?;
    if count > crate::scene::MAX_EXTRACTED_LIGHTS {
        return Err(format!("{count} suns, more than extraction makes"));
    }
    let suns = (0..count)
        .map(|_| {
            let texels = p.u32()? as usize;
            Ok(super::sun::Sun {
                direction: glam::Vec3::new(p.f32()?, p.f32()?, p.f32()?),
                irradiance: [p.f32()?, p.f32()?, p.f32()?],
                solid_angle: p.f32()?,
                texels,
            })
        })
        .collect::<Result<_, String>>()?;
    if !p.0.is_empty() {
        return Err("trailing bytes in the payload".into());
    }
    Ok(IblMaps {
        specular,
        irradiance,
        dfg,
        radiance,
        suns,
    })
}

/// The entry for `key` in `directory`, if there is a valid one. A missing entry is a quiet
/// miss; an unreadable or invalid one is logged as a warning and treated as a miss (it will be
/// rebuilt and replaced).
pub fn read(directory: &Path, key: &Key) -> Option<IblMaps> {
    let path = directory.join(file_name(key));
    let bytes = match std::fs::read(&path) {
        Ok(bytes) => bytes,
        Err(e) if e.kind() == std::io::ErrorKind::NotFound => return None,
        Err(e) => {
            log::warn!(
                "IBL cache `{}` unreadable ({e}); rebuilding",
                path.display()
            );
            return None;
        }
    };
    match decode(key, &bytes) {
        Ok(maps) => {
            // Used now: the last to go when the folder is over its size (best effort).
            let _ = std::fs::File::options()
                .write(true)
                .open(&path)
                .and_then(|f| f.set_modified(std::time::SystemTime::now()));
            Some(maps)
        }
        Err(problem) => {
            log::warn!(
                "IBL cache `{}` is invalid ({problem}); rebuilding",
                path.display()
            );
            None
        }
    }
}

/// Writes the entry for `key` atomically ([`crate::files::write_atomically`]).
pub fn write(directory: &Path, key: &Key, maps: &IblMaps) -> Result<PathBuf, CacheError> {
    let err = |path: &Path| {
        let path = path.to_path_buf();
        move |source| CacheError { path, source }
    };
    std::fs::create_dir_all(directory).map_err(err(directory))?;
    let path = directory.join(file_name(key));
    crate::files::write_atomically(&path, &encode(key, maps)).map_err(err(&path))?;
    evict(directory, MAX_DIRECTORY_BYTES);
    Ok(path)
}

/// Removes the entries of `directory` used longest ago (by modification time: written or last
/// read) until the rest take at most `budget` bytes; the newest entry always stays. Best effort:
/// an entry another process removed first, or one that cannot be removed, is passed over.
/// Returns how many it removed.
pub fn evict(directory: &Path, budget: u64) -> usize {
    let Ok(listing) = std::fs::read_dir(directory) else {
        return 0;
    };
    let mut entries: Vec<(std::time::SystemTime, u64, PathBuf)> = listing
        .filter_map(|e| {
            let e = e.ok()?;
            let name = e.file_name().into_string().ok()?;
            if !(name.starts_with("ibl-") && name.ends_with(".bin")) {
                return None;
            }
            let meta = e.metadata().ok()?;
            Some((meta.modified().ok()?, meta.len(), e.path()))
        })
        .collect();
    entries.sort_by_key(|e| std::cmp::Reverse(e.0));
    let mut kept = 0u64;
    let mut removed = 0;
    for (index, (_, size, path)) in entries.into_iter().enumerate() {
        kept += size;
        if index > 0 && kept > budget && std::fs::remove_file(&path).is_ok() {
            removed += 1;
        }
    }
    removed
}

//! Golden images: where they live, how a pass output is checked against one, and blessing.
//!
//! Layout: `golden/<scene>/<pass>.png` for 8-bit outputs (final image, masks) and
//! `golden/<scene>/<pass>.exr` (fp16, ZIP; depth as f32) for float outputs, one golden per scene
//! and pass for every backend, plus `golden/<scene>/blessed.toml` recording, per pass, when it was
//! blessed, from which backend and driver, and how it differed from the golden it replaced.
//!
//! Blessing refuses images with NaN/Inf, writes atomically (temporary file and rename), and
//! touches only the passes it is asked to.

use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

use engine::backend::{BackendKind, DriverInfo};
use engine::plan::TargetId;
use engine::{Image, ImageData};

use crate::golden::tolerance::{Rule, Verdict};
use crate::images::{self, ImageFileError};

/// Why a golden operation failed.
#[derive(Debug, thiserror::Error)]
pub enum GoldenError {
    /// Reading or writing an image.
    #[error(transparent)]
    File(#[from] ImageFileError),
    /// The image to bless has NaN or infinite values.
    #[error("refusing to bless {scene}/{pass}: {count} NaN/Inf values in the image")]
    NonFinite {
        /// Scene.
        scene: String,
        /// Pass.
        pass: String,
        /// How many.
        count: usize,
    },
    /// A golden holds NaN or infinite values: the file is corrupt (a bless refuses them).
    #[error(
        "{path}: the golden holds {count} NaN/Inf values, which no bless writes: the file is \
         corrupt (restore it from version control, or bless the pass again)"
    )]
    CorruptGolden {
        /// The golden file.
        path: PathBuf,
        /// How many values.
        count: usize,
    },
    /// The scene's bless lock could not be taken.
    #[error("cannot lock {path} for blessing: {error}")]
    Lock {
        /// The lock file.
        path: PathBuf,
        /// Why.
        error: std::io::Error,
    },
    /// blessed.toml could not be read or written.
    #[error("{path}: {message}")]
    Record {
        /// The file.
        path: PathBuf,
        /// What went wrong.
        message: String,
    },
}

/// One bless holding a scene's golden folder, from before its goldens and records are written
/// until they are: two blesses of one scene (two processes, or two threads of the golden
/// suite's `UPDATE_GOLDENS` run) never interleave, and blessed.toml always names the backend of
/// the image beside it. An advisory lock on `golden/<scene>/.bless.lock` (ignored by git),
/// released when dropped or when its process dies. Writing a golden takes one
/// ([`GoldenStore::bless`]).
#[derive(Debug)]
pub struct SceneLock {
    scene: String,
    /// The locked file; None for a dry run's ([`GoldenStore::dry_run_lock`]), which writes
    /// nothing.
    file: Option<std::fs::File>,
}

impl SceneLock {
    /// The scene whose folder is held.
    pub fn scene(&self) -> &str {
        &self.scene
    }

    /// Refuses a write under a dry run's lock (which holds nothing).
    fn writable(&self, store: &GoldenStore) -> Result<(), GoldenError> {
        match self.file {
            Some(_) => Ok(()),
            None => Err(GoldenError::Record {
                path: store.root.join(&self.scene),
                message: "a dry run writes nothing (its lock holds no file)".to_owned(),
            }),
        }
    }
}

/// Where a golden being blessed comes from: what its blessed.toml record says.
#[derive(Clone, Copy, Debug)]
pub struct Provenance<'a> {
    /// The backend that rendered it.
    pub backend: BackendKind,
    /// That backend's driver fingerprint.
    pub driver: &'a str,
    /// The metrics against the golden it replaces, or "new".
    pub previous: &'a str,
    /// Written without verification.
    pub unverified: bool,
    /// Why the picture changed, as the person blessing said it (`harness bless --reason`).
    pub reason: Option<&'a str>,
    /// The scene file, when the scene is not one of scenes/ (None: it is): recorded in
    /// blessed.toml so that `bless --prune` keeps the folder while that file exists.
    pub scene_file: Option<&'a Path>,
}

/// The name of a scene folder's lock file.
pub const LOCK_FILE: &str = ".bless.lock";

/// The golden folder.
#[derive(Clone, Debug)]
pub struct GoldenStore {
    root: PathBuf,
    /// Goldens decoded lately, shared by the clones: a check compares every backend's output
    /// with one golden, which is decoded once.
    decoded: std::sync::Arc<std::sync::Mutex<Decoded>>,
}

/// What identifies one version of a golden file: its length, modification time and inode (a
/// bless writes a new file and renames it over the old, so the inode changes even where the
/// clock is coarse).
type Stamp = (u64, std::time::SystemTime, u64);

/// The most recently decoded goldens, each with the [`Stamp`] of the file it was decoded from (a
/// golden rewritten since is decoded again).
#[derive(Debug, Default)]
struct Decoded {
    images: std::collections::VecDeque<(PathBuf, Stamp, Image)>,
    /// How many goldens were decoded (what the cache saved: [`GoldenStore::decodes`]).
    decodes: usize,
}

impl Decoded {
    /// How many goldens are kept (a scene has at most about a dozen golden passes).
    const KEPT: usize = 16;

    fn get(&self, path: &Path, stamp: Stamp) -> Option<Image> {
        self.images
            .iter()
            .find(|(p, s, _)| p == path && *s == stamp)
            .map(|(_, _, image)| image.clone())
    }

    fn put(&mut self, path: PathBuf, stamp: Stamp, image: Image) {
        self.images.retain(|(p, _, _)| *p != path);
        if self.images.len() == Self::KEPT {
            self.images.pop_front();
        }
        self.images.push_back((path, stamp, image));
        self.decodes += 1;
    }
}

/// What `blessed.toml` holds for one pass.
#[derive(Clone, Debug, serde::Serialize, serde::Deserialize, PartialEq)]
pub struct BlessRecord {
    /// UTC time of the bless (RFC 3339).
    pub blessed: String,
    /// Backend the golden was rendered on.
    pub backend: BackendKind,
    /// Driver fingerprint of that backend.
    pub driver: String,
    /// Metrics against the golden it replaced, or "new".
    pub previous: String,
    /// Written without checking that it reproduces on every backend and CPU code path
    /// (`harness bless --unverified`; see [`crate::golden::verify`]).
    #[serde(default, skip_serializing_if = "std::ops::Not::not")]
    pub unverified: bool,
    /// Why the picture changed (`harness bless --reason`), when the person blessing said.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub reason: Option<String>,
}

#[derive(Debug, Default, serde::Serialize, serde::Deserialize)]
struct BlessFile {
    /// The scene file of a scene outside scenes/ (relative to the workspace when inside it).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    scene_file: Option<PathBuf>,
    #[serde(default)]
    passes: BTreeMap<String, BlessRecord>,
}

/// A one-line driver fingerprint.
pub fn fingerprint(info: &DriverInfo) -> String {
    let mut parts = vec![
        format!("{} {}", info.api, info.api_version),
        info.renderer.clone(),
    ];
    if let Some(mesa) = &info.mesa_version {
        parts.push(format!("Mesa {mesa}"));
    }
    if let Some(llvm) = &info.llvm_version {
        parts.push(format!("LLVM {llvm}"));
    }
    for (k, v) in &info.env {
        parts.push(format!("{k}={v}"));
    }
    parts.join(" | ")
}

/// Whether a pass is stored as 8-bit PNG (otherwise EXR).
pub fn is_eight_bit(image: &Image) -> bool {
    matches!(image.data, ImageData::U8(_))
}

impl GoldenStore {
    /// A store rooted at `root` (usually `<workspace>/golden`).
    pub fn new(root: impl Into<PathBuf>) -> Self {
        Self {
            root: root.into(),
            decoded: Default::default(),
        }
    }

    /// The workspace's `golden/` folder.
    pub fn workspace() -> Self {
        Self::new(crate::workspace_root().join("golden"))
    }

    /// Root folder.
    pub fn root(&self) -> &Path {
        &self.root
    }

    /// Path of a golden; the extension follows the image kind.
    pub fn path(&self, scene: &str, pass: TargetId, eight_bit: bool) -> PathBuf {
        self.root
            .join(scene)
            .join(format!("{pass}.{}", if eight_bit { "png" } else { "exr" }))
    }

    /// Loads a golden; `Ok(None)` when it does not exist. Decoded once while the file is
    /// unchanged (the last 16 goldens are kept).
    pub fn load(
        &self,
        scene: &str,
        pass: TargetId,
        eight_bit: bool,
    ) -> Result<Option<Image>, GoldenError> {
        let path = self.path(scene, pass, eight_bit);
        let stamp = match std::fs::metadata(&path) {
            Err(e) if e.kind() == std::io::ErrorKind::NotFound => return Ok(None),
            // Unreadable: the read below says why.
            Err(_) => None,
            Ok(meta) => meta.modified().ok().map(|modified| {
                #[cfg(unix)]
                let inode = std::os::unix::fs::MetadataExt::ino(&meta);
                #[cfg(not(unix))]
                let inode = 0;
                (meta.len(), modified, inode)
            }),
        };
        let decoded = || self.decoded.lock().unwrap_or_else(|e| e.into_inner());
        if let Some(image) = stamp.and_then(|stamp| decoded().get(&path, stamp)) {
            return Ok(Some(image));
        }
        let image = if eight_bit {
            images::read_png(&path)?
        } else {
            images::read_exr(&path)?
        };
        if let Some(values) = image.as_f32() {
            let count = values.iter().filter(|v| !v.is_finite()).count();
            if count > 0 {
                return Err(GoldenError::CorruptGolden { path, count });
            }
        }
        if let Some(stamp) = stamp {
            decoded().put(path, stamp, image.clone());
        }
        Ok(Some(image))
    }

    /// How many goldens this store and its clones have decoded from their files (a golden read
    /// again while its file is unchanged comes from memory and does not count).
    pub fn decodes(&self) -> usize {
        self.decoded
            .lock()
            .unwrap_or_else(|e| e.into_inner())
            .decodes
    }

    /// `golden/<scene>/blessed.toml`: how each pass of the scene was blessed.
    pub fn record_path(&self, scene: &str) -> PathBuf {
        self.root.join(scene).join("blessed.toml")
    }

    /// What blessed.toml says about each pass of a scene, by the pass's name as the file has it
    /// (a file may name passes no plan has any more).
    pub fn records(&self, scene: &str) -> Result<BTreeMap<String, BlessRecord>, GoldenError> {
        Ok(self.bless_file(scene)?.passes)
    }

    /// The scene file blessed.toml records for a scene outside scenes/ (see
    /// [`Provenance::scene_file`]), as a path from here; None for a scene of scenes/.
    pub fn scene_file(&self, scene: &str) -> Result<Option<PathBuf>, GoldenError> {
        let workspace = self.root.parent().unwrap_or(Path::new(""));
        Ok(self
            .bless_file(scene)?
            .scene_file
            .map(|file| workspace.join(file)))
    }

    /// A scene's blessed.toml as read (empty when there is none).
    fn bless_file(&self, scene: &str) -> Result<BlessFile, GoldenError> {
        let path = self.record_path(scene);
        if !path.exists() {
            return Ok(BlessFile::default());
        }
        let text = std::fs::read_to_string(&path).map_err(|e| GoldenError::Record {
            path: path.clone(),
            message: e.to_string(),
        })?;
        toml::from_str(&text).map_err(|e| GoldenError::Record {
            path: path.clone(),
            message: e.to_string(),
        })
    }

    /// Takes `scene`'s bless lock, waiting while another bless holds it (`on_wait` is called
    /// once, first, with the lock file's path, to say so).
    pub fn lock_scene(
        &self,
        scene: &str,
        on_wait: impl FnOnce(&Path),
    ) -> Result<SceneLock, GoldenError> {
        let dir = self.root.join(scene);
        let path = dir.join(LOCK_FILE);
        let lock_error = |error| GoldenError::Lock {
            path: path.clone(),
            error,
        };
        std::fs::create_dir_all(&dir).map_err(lock_error)?;
        let file = std::fs::OpenOptions::new()
            .create(true)
            .truncate(false)
            .write(true)
            .open(&path)
            .map_err(lock_error)?;
        match file.try_lock() {
            Ok(()) => {}
            Err(std::fs::TryLockError::WouldBlock) => {
                on_wait(&path);
                file.lock().map_err(lock_error)?;
            }
            Err(std::fs::TryLockError::Error(error)) => return Err(lock_error(error)),
        }
        Ok(SceneLock {
            scene: scene.to_owned(),
            file: Some(file),
        })
    }

    /// The lock a dry run holds for `scene`: none at all, as it writes nothing (taking a real
    /// one would make the folder of a scene that has none yet, and leave it behind).
    pub fn dry_run_lock(&self, scene: &str) -> SceneLock {
        SceneLock {
            scene: scene.to_owned(),
            file: None,
        }
    }

    /// Writes `image` as the golden of the locked scene's `pass` and records the bless with
    /// `provenance`. Refuses NaN/Inf.
    pub fn bless(
        &self,
        lock: &SceneLock,
        pass: TargetId,
        image: &Image,
        provenance: Provenance<'_>,
    ) -> Result<PathBuf, GoldenError> {
        let Provenance {
            backend,
            driver,
            previous,
            unverified,
            reason,
            scene_file,
        } = provenance;
        lock.writable(self)?;
        let scene = lock.scene();
        if let Some(values) = image.as_f32() {
            let count = values.iter().filter(|v| !v.is_finite()).count();
            if count > 0 {
                return Err(GoldenError::NonFinite {
                    scene: scene.to_owned(),
                    pass: pass.to_string(),
                    count,
                });
            }
        }
        // Read first: a blessed.toml that does not read must stop the bless before the golden
        // is written, not after (a golden no record says anything of).
        let mut records = self.records(scene)?;
        let eight_bit = is_eight_bit(image);
        let path = self.path(scene, pass, eight_bit);
        images::write_image(image, &path, images::FileCompression::Balanced)?;
        // A pass changing kind (PNG <-> EXR) must not leave the old file behind.
        let stale = self.path(scene, pass, !eight_bit);
        if stale.exists() {
            let _ = std::fs::remove_file(stale);
        }
        records.insert(
            pass.to_string(),
            BlessRecord {
                blessed: humantime::format_rfc3339_seconds(std::time::SystemTime::now())
                    .to_string(),
                backend,
                driver: driver.to_owned(),
                previous: previous.to_owned(),
                unverified,
                reason: reason.map(str::to_owned),
            },
        );
        self.write_records(lock, records, Some(scene_file))?;
        Ok(path)
    }

    /// Drops the record of `pass` (a name as blessed.toml has it) from the locked scene's
    /// blessed.toml: a record whose golden is gone (`harness bless --prune`).
    pub fn forget(&self, lock: &SceneLock, pass: &str) -> Result<(), GoldenError> {
        lock.writable(self)?;
        let mut records = self.records(lock.scene())?;
        if records.remove(pass).is_some() {
            self.write_records(lock, records, None)?;
        }
        Ok(())
    }

    /// Writes the locked scene's blessed.toml, atomically, with `scene_file` as its scene file
    /// (`Some(None)`: a scene of scenes/, none; relative to the workspace when inside it), or
    /// the one it records when None.
    fn write_records(
        &self,
        lock: &SceneLock,
        records: BTreeMap<String, BlessRecord>,
        scene_file: Option<Option<&Path>>,
    ) -> Result<(), GoldenError> {
        let path = self.record_path(lock.scene());
        let workspace = self.root.parent().unwrap_or(Path::new(""));
        let scene_file = match scene_file {
            Some(file) => file.map(|f| super::scene_inputs::input_name(f, workspace)),
            None => self.bless_file(lock.scene())?.scene_file,
        };
        let file = BlessFile {
            scene_file,
            passes: records,
        };
        let text = toml::to_string_pretty(&file).map_err(|e| GoldenError::Record {
            path: path.clone(),
            message: e.to_string(),
        })?;
        let header = "# Written by `harness bless`: when each golden was blessed, from which \
                      backend and driver,\n# and how it differed from the golden it replaced.\n\n";
        images::write_atomically(&path, format!("{header}{text}").as_bytes())?;
        Ok(())
    }
}

/// Outcome of checking one pass output against its golden.
#[derive(Clone, Debug, serde::Serialize, serde::Deserialize)]
pub enum Outcome {
    /// Within tolerance.
    Passed(Verdict),
    /// Outside tolerance (or NaN/Inf).
    Failed(Verdict),
    /// No golden yet.
    MissingGolden,
    /// Golden and output cannot be compared (size or format changed).
    Incomparable(String),
}

impl Outcome {
    /// Whether the check passed.
    pub fn passed(&self) -> bool {
        matches!(self, Outcome::Passed(_))
    }

    /// The outcome as one word, the same in the check table, the test output and the review
    /// page: `ok`, `FAILED`, `MISSING` (no golden) or `INCOMPARABLE` (size or format changed).
    pub fn label(&self) -> &'static str {
        match self {
            Outcome::Passed(_) => "ok",
            Outcome::Failed(_) => "FAILED",
            Outcome::MissingGolden => "MISSING",
            Outcome::Incomparable(_) => "INCOMPARABLE",
        }
    }
}

/// Checks an output against its golden with a rule.
pub fn check(actual: &Image, golden: Option<&Image>, rule: &Rule) -> Outcome {
    let Some(golden) = golden else {
        return Outcome::MissingGolden;
    };
    match rule.evaluate(actual, golden) {
        Ok(verdict) if verdict.passed => Outcome::Passed(verdict),
        Ok(verdict) => Outcome::Failed(verdict),
        Err(e) => Outcome::Incomparable(e.to_string()),
    }
}

/// A diff heatmap: per-pixel largest channel difference, scaled so that `scale` maps to full
/// intensity, on a black-red-yellow-white ramp (RGBA8).
pub fn diff_heatmap(actual: &Image, golden: &Image, scale: f64) -> Option<Image> {
    let pair = crate::golden::metrics::Pair::new(actual, golden).ok()?;
    let differences = pair.pixel_differences();
    let mut data = Vec::with_capacity(differences.len() * 4);
    for d in differences {
        let t = if d.is_finite() {
            (d / scale.max(1e-12)).clamp(0.0, 1.0)
        } else {
            1.0
        };
        let channel = |x: f64| (x.clamp(0.0, 1.0) * 255.0).round() as u8;
        data.extend_from_slice(&[
            channel(t * 3.0),
            channel(t * 3.0 - 1.0),
            channel(t * 3.0 - 2.0),
            255,
        ]);
    }
    Some(Image {
        width: actual.width,
        height: actual.height,
        format: engine::backend::TextureFormat::Rgba8Unorm,
        data: ImageData::U8(data),
    })
}

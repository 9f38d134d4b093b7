//! Files in `golden/` that nothing produces or records any more: a folder of a scene that is no
//! longer in `scenes/`, a golden of a pass the scene's plan lost (or written in the other
//! format), a golden that blessed.toml has no record of (copied in by hand, not blessed), a
//! record of a pass that has no golden, and anything else (a temporary file left by a killed
//! process, a stray folder). `check` lists them as notes; `harness bless --prune` removes them
//! (`--dry-run` lists what it would remove), each scene under its bless lock.

use std::fmt;
use std::path::{Path, PathBuf};

use super::suite::Case;
use super::{GoldenError, GoldenStore, LOCK_FILE};

/// What is wrong with a file in golden/.
#[derive(Clone, Debug, PartialEq, Eq, serde::Serialize, serde::Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum OrphanKind {
    /// A folder of a scene that scenes/ no longer has.
    SceneGone,
    /// A golden of a pass the scene's plan no longer has (or in the other format).
    PassGone,
    /// A golden of a current pass that blessed.toml does not record.
    Unrecorded,
    /// A blessed.toml record of a pass that has no golden (`path` is the blessed.toml).
    RecordWithoutGolden {
        /// The pass the record names.
        pass: String,
    },
    /// Neither a golden nor a file the harness keeps there.
    Stray,
    /// Goldens of current passes in a folder whose blessed.toml is missing or records nothing
    /// (`path` is the blessed.toml): the records were lost, not the goldens made by hand, so
    /// a prune keeps them and says how to restore the records.
    RecordsLost {
        /// How many goldens the folder holds.
        goldens: usize,
    },
}

impl OrphanKind {
    /// Whether `harness bless --prune` removes it ([`OrphanKind::RecordsLost`] it keeps).
    pub fn prunable(&self) -> bool {
        !matches!(self, OrphanKind::RecordsLost { .. })
    }
}

/// A file (or folder) in golden/ that nothing produces or records.
#[derive(Clone, Debug, PartialEq, Eq, serde::Serialize, serde::Deserialize)]
pub struct Orphan {
    /// The file or folder.
    pub path: PathBuf,
    /// Why it is an orphan.
    pub kind: OrphanKind,
    /// The scene folder it is in (None at golden/'s top level).
    pub scene: Option<String>,
}

impl fmt::Display for Orphan {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let scene = self.scene.as_deref().unwrap_or("-");
        let why = match &self.kind {
            OrphanKind::SceneGone => format!(
                "no scene in scenes/ is named {scene}, and its blessed.toml names no scene file \
                 that exists elsewhere"
            ),
            OrphanKind::PassGone => format!("no golden pass of {scene} is written to this file"),
            OrphanKind::Unrecorded => {
                format!("{scene}/blessed.toml does not record it (copied in, not blessed)")
            }
            OrphanKind::RecordWithoutGolden { pass } => {
                format!("records `{pass}`, which has no golden in {scene}")
            }
            OrphanKind::Stray => "not a golden nor a file the harness keeps here".to_owned(),
            OrphanKind::RecordsLost { goldens } => format!(
                "missing or records nothing, beside {goldens} golden(s) of {scene}: restore it \
                 from version control (`git checkout -- {}`), or record them again with `{} \
                 --every-pass`; a prune keeps them",
                self.path.display(),
                crate::golden::command_line::bless_command(scene)
            ),
        };
        write!(f, "{}: {why}", self.path.display())
    }
}

/// Files golden/ keeps at its top level besides the scene folders: no scene may be named as one
/// (its folder would be one of them, and a prune would clear it).
pub(crate) const TOP_LEVEL: [&str; 4] =
    ["README.md", "noise.toml", "timing-noise.toml", "evidence"];
/// Files a scene folder keeps besides its goldens.
const SCENE_FILES: [&str; 3] = ["blessed.toml", "timing.toml", LOCK_FILE];

/// The orphans in `store` for `cases`: in their folders, and, with `canonical` (the names of
/// every scene in scenes/, when the cases are all of them), the folders of scenes that are gone.
pub fn find(
    store: &GoldenStore,
    cases: &[Case],
    canonical: Option<&[String]>,
) -> Result<Vec<Orphan>, GoldenError> {
    let mut orphans = Vec::new();
    if let Some(canonical) = canonical {
        for (name, path, is_dir) in entries(store.root())? {
            let known = TOP_LEVEL.contains(&name.as_str()) || canonical.contains(&name);
            // A scene file outside scenes/ keeps its folder while the file blessed.toml
            // records for it is there.
            let elsewhere = || {
                is_dir
                    && store
                        .scene_file(&name)
                        .ok()
                        .flatten()
                        .is_some_and(|file| file.is_file())
            };
            if !known && !elsewhere() {
                let kind = if is_dir {
                    OrphanKind::SceneGone
                } else {
                    OrphanKind::Stray
                };
                let scene = is_dir.then(|| name.clone());
                orphans.push(Orphan { path, kind, scene });
            }
        }
    }
    for case in cases {
        orphans.extend(in_scene(store, case)?);
    }
    Ok(orphans)
}

/// The orphans in one scene's folder.
fn in_scene(store: &GoldenStore, case: &Case) -> Result<Vec<Orphan>, GoldenError> {
    let scene = case.name();
    let dir = store.root().join(scene);
    if !dir.is_dir() {
        return Ok(Vec::new());
    }
    let records = store.records(scene)?;
    let orphan = |path: PathBuf, kind| Orphan {
        path,
        kind,
        scene: Some(scene.to_owned()),
    };
    let mut orphans = Vec::new();
    let mut unrecorded_goldens = 0;
    for (name, path, is_dir) in entries(&dir)? {
        if SCENE_FILES.contains(&name.as_str()) {
            continue;
        }
        let golden_pass = case
            .passes
            .iter()
            .find(|&&pass| store.path(scene, pass, case.is_eight_bit(pass)) == path);
        let kind = match golden_pass {
            Some(pass) if records.contains_key(&pass.to_string()) => continue,
            // No record at all: counted, and said once below.
            Some(_) if records.is_empty() => {
                unrecorded_goldens += 1;
                continue;
            }
            Some(_) => OrphanKind::Unrecorded,
            None if !is_dir && is_image(&path) => OrphanKind::PassGone,
            None => OrphanKind::Stray,
        };
        orphans.push(orphan(path, kind));
    }
    for pass in records.keys() {
        let has_golden = case.passes.iter().any(|p| {
            p.to_string() == *pass && store.path(scene, *p, case.is_eight_bit(*p)).exists()
        });
        if !has_golden {
            orphans.push(orphan(
                dir.join("blessed.toml"),
                OrphanKind::RecordWithoutGolden { pass: pass.clone() },
            ));
        }
    }
    if unrecorded_goldens > 0 {
        orphans.push(orphan(
            store.record_path(scene),
            OrphanKind::RecordsLost {
                goldens: unrecorded_goldens,
            },
        ));
    }
    Ok(orphans)
}

/// Whether `path` is a golden image by its extension.
fn is_image(path: &Path) -> bool {
    path.extension().is_some_and(|x| x == "png" || x == "exr")
}

/// `dir`'s entries: name, path, whether a folder; sorted by name.
fn entries(dir: &Path) -> Result<Vec<(String, PathBuf, bool)>, GoldenError> {
    let read_error = |e: std::io::Error| GoldenError::Record {
        path: dir.to_owned(),
        message: e.to_string(),
    };
    let mut out = Vec::new();
    for entry in std::fs::read_dir(dir).map_err(read_error)? {
        let entry = entry.map_err(read_error)?;
        let is_dir = entry.file_type().map_err(read_error)?.is_dir();
        out.push((
            entry.file_name().to_string_lossy().into_owned(),
            entry.path(),
            is_dir,
        ));
    }
    out.sort();
    Ok(out)
}

/// Removes `orphans` (nothing with `dry_run`): files and folders, and the records of passes
/// without a golden from blessed.toml, each scene's under its bless lock (`on_wait` as for
/// [`GoldenStore::lock_scene`]). Returns a line per orphan saying what was (or would be) done.
pub fn prune(
    store: &GoldenStore,
    orphans: &[Orphan],
    dry_run: bool,
    on_wait: impl Fn(&Path),
) -> Result<Vec<String>, GoldenError> {
    let verb = if dry_run { "would remove" } else { "removed" };
    let mut lines = Vec::new();
    let mut scenes: Vec<Option<&str>> = orphans.iter().map(|o| o.scene.as_deref()).collect();
    scenes.sort_unstable();
    scenes.dedup();
    for scene in scenes {
        let _lock = match scene {
            Some(scene) if !dry_run => Some(store.lock_scene(scene, &on_wait)?),
            _ => None,
        };
        for orphan in orphans.iter().filter(|o| o.scene.as_deref() == scene) {
            let remove_error = |e: std::io::Error| GoldenError::Record {
                path: orphan.path.clone(),
                message: format!("cannot remove: {e}"),
            };
            match &orphan.kind {
                OrphanKind::RecordWithoutGolden { pass } => {
                    if !dry_run {
                        if let Some(lock) = &_lock {
                            store.forget(lock, pass)?;
                        }
                    }
                    lines.push(format!(
                        "{}: {} the record of `{pass}`",
                        orphan.path.display(),
                        if dry_run { "would drop" } else { "dropped" }
                    ));
                }
                OrphanKind::SceneGone => {
                    if !dry_run {
                        std::fs::remove_dir_all(&orphan.path).map_err(remove_error)?;
                    }
                    lines.push(format!("{} {}", verb, orphan.path.display()));
                }
                OrphanKind::RecordsLost { .. } => lines.push(format!("kept: {orphan}")),
                OrphanKind::PassGone | OrphanKind::Unrecorded | OrphanKind::Stray => {
                    if !dry_run {
                        if orphan.path.is_dir() {
                            std::fs::remove_dir_all(&orphan.path).map_err(remove_error)?;
                        } else {
                            std::fs::remove_file(&orphan.path).map_err(remove_error)?;
                        }
                    }
                    lines.push(format!("{} {}", verb, orphan.path.display()));
                }
            }
        }
    }
    Ok(lines)
}

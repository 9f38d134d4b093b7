//! What a check rendered a scene from: every file the scene's load read (the scene file, its
//! environment, meshes, material libraries and textures), each with a digest of its bytes taken
//! when the scene was loaded, kept in last-check.json. Accepting the check's outputs or timings
//! compares them with the files as they are now: outputs rendered from a scene that has changed
//! since are not that scene's pictures any more, verified or not, so they are refused with the
//! files that changed. The load's warnings are kept beside them: a material library or map the
//! scene lost changes its picture, which a failing check's advice must say before it says bless.

use std::path::{Path, PathBuf};

use engine::scene_file::LoadedScene;

/// The files a scene was loaded from when it was checked.
#[derive(Clone, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct SceneInputs {
    /// The scene.
    pub scene: String,
    /// Each file the load read ([`input_name`] in the workspace), with a digest of its bytes
    /// ([`file_digest`]; None: unreadable when digested).
    pub files: Vec<(PathBuf, Option<String>)>,
    /// What the load noted about untidy assets (a material library that cannot be read, a
    /// material no library defines, generated normals, ...).
    #[serde(default)]
    pub warnings: Vec<String>,
}

impl SceneInputs {
    /// The files `loaded` was read from, digested now (right after the load, so that an edit
    /// while a long check renders is not taken for what it rendered).
    pub fn of(loaded: &LoadedScene) -> Self {
        let workspace = crate::workspace_root();
        Self {
            scene: loaded.scene.name.clone(),
            files: loaded
                .files
                .iter()
                .map(|file| (input_name(file, &workspace), file_digest(file)))
                .collect(),
            warnings: loaded.warnings.clone(),
        }
    }

    /// One digest of every file and its digest (SHA-256, hex): equal exactly when the scene was
    /// loaded from the same bytes.
    pub fn digest(&self) -> String {
        use sha2::Digest as _;
        let mut files = self.files.clone();
        files.sort();
        let mut hasher = sha2::Sha256::new();
        for (file, digest) in &files {
            hasher.update(file.to_string_lossy().as_bytes());
            hasher.update([0]);
            hasher.update(digest.as_deref().unwrap_or("unreadable").as_bytes());
            hasher.update([b'\n']);
        }
        hasher
            .finalize()
            .iter()
            .map(|b| format!("{b:02x}"))
            .collect()
    }

    /// The files that differ between these inputs and `now`'s: changed, gone, or read by only
    /// one of the two loads.
    pub fn changed(&self, now: &SceneInputs) -> Vec<PathBuf> {
        let mut changed: Vec<PathBuf> = self
            .files
            .iter()
            .filter(|(file, digest)| {
                now.files
                    .iter()
                    .find(|(f, _)| f == file)
                    .is_none_or(|(_, d)| d != digest || d.is_none())
            })
            .map(|(file, _)| file.clone())
            .collect();
        for (file, _) in &now.files {
            if !self.files.iter().any(|(f, _)| f == file) {
                changed.push(file.clone());
            }
        }
        changed
    }

    /// The recorded files whose bytes differ on disk now, in `workspace` (without loading the
    /// scene again: a file the scene would read now and did not then is not seen;
    /// [`Self::changed`] sees it).
    pub fn changed_on_disk(&self, workspace: &Path) -> Vec<PathBuf> {
        self.files
            .iter()
            .filter(|(file, digest)| {
                let now = file_digest(&workspace.join(file));
                now.is_none() || &now != digest
            })
            .map(|(file, _)| file.clone())
            .collect()
    }

    /// Why outputs or timings of these inputs may not be accepted, where `changed` files
    /// ([`Self::changed`], [`Self::changed_on_disk`]) differ: None when none does. `argument`
    /// is the scene as the check was given it and `out` the check's folder, named in the check
    /// to run again (the accept reads that folder).
    pub fn refusal(
        &self,
        changed: &[PathBuf],
        argument: &str,
        out: Option<&Path>,
    ) -> Option<String> {
        (!changed.is_empty()).then(|| {
            let files: Vec<String> = changed.iter().map(|f| f.display().to_string()).collect();
            format!(
                "{} changed since the check ({}): the outputs it kept show the scene as it \
                 was, not as it is. Check it again (`{}`), then accept",
                self.scene,
                files.join(", "),
                super::command_line::check_command(argument, out)
            )
        })
    }
}

/// Each scene's [`SceneInputs::digest`], by scene name: what a speed history line keeps of the
/// scenes it timed.
pub fn digests<'a>(
    inputs: impl IntoIterator<Item = &'a SceneInputs>,
) -> std::collections::BTreeMap<String, String> {
    inputs
        .into_iter()
        .map(|i| (i.scene.clone(), i.digest()))
        .collect()
}

/// `file` as a check records it: relative to `workspace` when it lies inside (so that a check
/// made in another checkout, a CI job's, compares with this checkout's files, and two
/// workspaces share a verification), else absolute; symbolic links and `..` resolved.
pub fn input_name(file: &Path, workspace: &Path) -> PathBuf {
    let workspace = workspace
        .canonicalize()
        .unwrap_or_else(|_| workspace.to_owned());
    let file = file.canonicalize().unwrap_or_else(|_| {
        // A file gone: `..` and `.` resolved by their names.
        let absolute = std::path::absolute(file).unwrap_or_else(|_| file.to_owned());
        let mut resolved = PathBuf::new();
        for part in absolute.components() {
            match part {
                std::path::Component::ParentDir => {
                    resolved.pop();
                }
                std::path::Component::CurDir => {}
                other => resolved.push(other),
            }
        }
        resolved
    });
    file.strip_prefix(&workspace)
        .map_or_else(|_| file.clone(), Path::to_path_buf)
}

/// A digest of a file's bytes, the same on every machine and Rust release (SHA-256, hex; None
/// when it cannot be read).
pub fn file_digest(path: &Path) -> Option<String> {
    use sha2::Digest as _;
    let bytes = std::fs::read(path).ok()?;
    let digest = sha2::Sha256::digest(&bytes);
    Some(digest.iter().map(|b| format!("{b:02x}")).collect())
}

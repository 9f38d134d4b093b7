//! What a check rendered a scene from: every file the scene's load read (the scene file, its
//! environment, meshes, material libraries and textures), each with a digest of its bytes, kept
//! in last-check.json. Accepting the check's outputs compares them with the files as they are
//! now: outputs rendered from a scene that has changed since are not that scene's pictures any
//! more, verified or not, so they are refused with the files that changed. The load's warnings
//! are kept beside them: a material library or map the scene lost changes its picture, which a
//! failing check's advice must say before it says bless.

use std::path::{Path, PathBuf};

use super::suite::Case;

/// The files a scene was loaded from when it was checked.
#[derive(Clone, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct SceneInputs {
    /// The scene.
    pub scene: String,
    /// Each file the load read ([`input_name`]), with a digest of its bytes (None: unreadable
    /// when digested).
    pub files: Vec<(PathBuf, Option<String>)>,
    /// What the load noted about untidy assets (a material library that cannot be read, a
    /// material no library defines, generated normals, ...).
    #[serde(default)]
    pub warnings: Vec<String>,
}

impl SceneInputs {
    /// The files `case` was loaded from, digested as they are now.
    pub fn of(case: &Case) -> Self {
        Self {
            scene: case.name().to_owned(),
            files: case
                .loaded
                .files
                .iter()
                .map(|file| (input_name(file), super::verify::file_digest(file)))
                .collect(),
            warnings: case.loaded.warnings.clone(),
        }
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

    /// Why outputs rendered from these inputs may not be accepted as `now`'s scene's goldens
    /// (`argument`: the scene as the check was given it): None when no file changed.
    pub fn refusal(&self, now: &SceneInputs, argument: &str) -> Option<String> {
        let changed = self.changed(now);
        (!changed.is_empty()).then(|| {
            let files: Vec<String> = changed.iter().map(|f| f.display().to_string()).collect();
            format!(
                "{} changed since the check ({}): the outputs it kept show the scene as it \
                 was, not as it is. Check it again (`{}`), then accept",
                self.scene,
                files.join(", "),
                super::command_line::check_command(argument)
            )
        })
    }
}

/// A file a scene was loaded from as the check records it: relative to the workspace when it
/// lies inside (so that a check made in another checkout, a CI job's, compares with this
/// checkout's files, and two workspaces share a verification), else absolute.
pub fn input_name(file: &Path) -> PathBuf {
    let root = crate::workspace_root();
    let root = root.canonicalize().unwrap_or(root);
    let file = file
        .canonicalize()
        .unwrap_or_else(|_| std::path::absolute(file).unwrap_or_else(|_| file.to_owned()));
    file.strip_prefix(&root)
        .map_or_else(|_| file.clone(), Path::to_path_buf)
}

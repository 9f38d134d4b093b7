//! Scene files: TOML, parsed with serde into [`SceneFile`], then resolved into a [`Scene`] by
//! loading the meshes, textures and environment they name. Paths are relative to the scene
//! file. Unknown keys are errors that name the key, the file and the line.
//!
//! The `[tolerances]` table belongs to the golden harness; the engine keeps it as raw TOML
//! ([`SceneFile::tolerances`]) for the harness to parse.
//!
//! The format is documented with a full example in the README ("Scene files").
//!
//! The schema is in `schema`, the loading of what a file names in `resolver`, and the location
//! of parse errors in `error_location`.

use std::path::{Path, PathBuf};

use crate::assets::{self, AssetError};
use crate::scene::Scene;

mod error_location;
mod resolver;
mod schema;

use error_location::{light_error, line_column};
use resolver::Resolver;
pub use schema::{
    CameraSpec, DirectionalLightSpec, EnvironmentSpec, LightSpec, MaterialSpec, ObjectSpec,
    PointLightSpec, QualitySpec, ScaleSpec, SceneFile, ShadowSpec,
};

/// Why a scene file could not be loaded.
#[derive(Debug, thiserror::Error)]
pub enum SceneFileError {
    /// The file could not be read.
    #[error("{path}: cannot read scene file: {source}")]
    Io {
        /// Scene file.
        path: PathBuf,
        /// OS error.
        source: std::io::Error,
    },
    /// TOML syntax error, wrong type or unknown key.
    #[error("{path}:{line}:{column}: {message}")]
    Parse {
        /// Scene file.
        path: PathBuf,
        /// 1-based line.
        line: usize,
        /// 1-based column.
        column: usize,
        /// What is wrong (names the key for unknown keys).
        message: String,
    },
    /// Parsed, but the values make no sense (NaN, negative radius, ...).
    #[error("{path}: {message}")]
    Invalid {
        /// Scene file.
        path: PathBuf,
        /// What is wrong and where.
        message: String,
    },
    /// A mesh, texture or environment it names failed to load.
    #[error("{path}: {source}")]
    Asset {
        /// Scene file.
        path: PathBuf,
        /// The asset error (names the asset file).
        source: AssetError,
    },
    /// `--scene NAME` named no canonical scene.
    #[error("no scene `{name}`: not a file, and not one of the scenes in {dir} ({known})")]
    UnknownScene {
        /// What was asked for.
        name: String,
        /// Where canonical scenes were looked for.
        dir: String,
        /// Scenes found there.
        known: String,
    },
}

/// A loaded scene with what the harness needs from its file.
#[derive(Clone)]
pub struct LoadedScene {
    /// The scene.
    pub scene: Scene,
    /// Where it was loaded from.
    pub path: PathBuf,
    /// The description line.
    pub description: Option<String>,
    /// Raw `[tolerances]` table.
    pub tolerances: toml::Table,
    /// Texture files decoded while loading (each at most once).
    pub textures_decoded: usize,
    /// Every file the load read, each once, in the order first read: the scene file, the
    /// environment, the meshes, their material libraries and the textures. A digest of their
    /// bytes says whether the scene is still what it was.
    pub files: Vec<PathBuf>,
    /// What the loaders noted about untidy but usable assets (text that is not UTF-8, a
    /// missing material library, unknown material names, generated normals, ...), each
    /// asset's once, each naming its file and line.
    pub warnings: Vec<String>,
}

/// Parses scene-file text (no assets are loaded).
pub fn parse(path: &Path, text: &str) -> Result<SceneFile, SceneFileError> {
    toml::from_str(text).map_err(|e| {
        let start = e.span().map_or(0, |span| span.start);
        let (start, message) =
            light_error(text, start).unwrap_or_else(|| (start, e.message().trim().to_owned()));
        let (line, column) = line_column(text, start);
        SceneFileError::Parse {
            path: path.to_owned(),
            line,
            column,
            message,
        }
    })
}

/// Finds a scene by canonical name (`chess`) or path (`scenes/chess.toml`). Names are looked
/// up in `scenes_dir`.
pub fn resolve(name_or_path: &str, scenes_dir: &Path) -> Result<PathBuf, SceneFileError> {
    let as_path = Path::new(name_or_path);
    if as_path.is_file() {
        return Ok(as_path.to_owned());
    }
    let candidate = scenes_dir.join(format!("{name_or_path}.toml"));
    // There but no file (a folder, a link to nothing): loading it says why, where "no scene"
    // beside a list that names it would contradict itself.
    if std::fs::symlink_metadata(&candidate).is_ok() {
        return Ok(candidate);
    }
    Err(SceneFileError::UnknownScene {
        name: name_or_path.to_owned(),
        dir: scenes_dir.display().to_string(),
        known: canonical_scenes(scenes_dir).join(", "),
    })
}

/// Scene files directly in `scenes_dir` whose names are not UTF-8, which no command line can
/// name as a scene ([`canonical_scenes`] leaves them out): their paths, shown lossily, sorted.
pub fn unnamed_scene_files(scenes_dir: &Path) -> Vec<String> {
    let mut paths: Vec<String> = std::fs::read_dir(scenes_dir)
        .into_iter()
        .flatten()
        .flatten()
        .map(|e| e.path())
        .filter(|p| p.extension().is_some_and(|x| x == "toml"))
        .filter(|p| p.file_stem().is_some_and(|s| s.to_str().is_none()))
        .map(|p| p.to_string_lossy().into_owned())
        .collect();
    paths.sort();
    paths
}

/// Names of the scene files directly in `scenes_dir`, sorted.
pub fn canonical_scenes(scenes_dir: &Path) -> Vec<String> {
    let mut names: Vec<String> = std::fs::read_dir(scenes_dir)
        .into_iter()
        .flatten()
        .flatten()
        .filter_map(|e| {
            let path = e.path();
            (path.extension().is_some_and(|x| x == "toml"))
                .then(|| path.file_stem()?.to_str().map(str::to_owned))
                .flatten()
        })
        .collect();
    names.sort();
    names
}

/// A scene file that is not UTF-8 (TOML's encoding), refused where its first such byte is.
fn not_utf8(path: &Path, error: &std::string::FromUtf8Error) -> SceneFileError {
    let bytes = error.as_bytes();
    let at = error.utf8_error().valid_up_to();
    let before = &bytes[..at];
    let line_start = before
        .iter()
        .rposition(|&b| b == b'\n')
        .map_or(0, |i| i + 1);
    SceneFileError::Parse {
        path: path.to_owned(),
        line: before.iter().filter(|&&b| b == b'\n').count() + 1,
        column: at - line_start + 1,
        message: format!(
            "byte 0x{:02x} is not UTF-8: a scene file is TOML, which must be UTF-8 (a file saved \
             as UTF-16 or Latin-1 reads like this; save it as UTF-8)",
            bytes[at]
        ),
    }
}

/// Reads, parses and resolves a scene file, loading every asset it names within the default
/// [`assets::Limits`].
pub fn load(path: &Path) -> Result<LoadedScene, SceneFileError> {
    load_with_limits(path, assets::Limits::DEFAULT)
}

/// [`load`] with other limits ([`assets::Limits::NONE`] for none): an asset above them is
/// refused, naming its file, before it is decoded.
pub fn load_with_limits(
    path: &Path,
    limits: assets::Limits,
) -> Result<LoadedScene, SceneFileError> {
    let bytes = std::fs::read(path).map_err(|source| SceneFileError::Io {
        path: path.to_owned(),
        source,
    })?;
    let text = String::from_utf8(bytes).map_err(|e| not_utf8(path, &e))?;
    let file = parse(path, &text)?;
    Resolver::new(path, limits).resolve(file)
}

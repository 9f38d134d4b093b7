//! Error type shared by every loader in the asset module.
//!
//! Every variant carries the path of the file at fault and, where the problem
//! can be pinned to a line of a text file, the 1-based line number. The
//! `Display` form reads `path:line: problem` (or `path: problem` when no line
//! is known), e.g. `scenes/x.obj:12: face index 9 out of range (8 positions)`.

use std::fmt;
use std::path::{Path, PathBuf};

/// Anything that can go wrong while loading meshes, materials, textures or
/// environment maps.
#[derive(thiserror::Error, Debug)]
pub enum AssetError {
    /// A file could not be opened or read (missing, permissions, ...).
    #[error("{}: cannot read file: {source}", Loc(.path, .line))]
    Io {
        /// File that could not be read.
        path: PathBuf,
        /// Line of the referencing statement, if any.
        line: Option<usize>,
        /// Underlying I/O error.
        #[source]
        source: std::io::Error,
    },

    /// Malformed or semantically invalid text in an OBJ or MTL file.
    #[error("{}: {message}", Loc(.path, .line))]
    Parse {
        /// OBJ or MTL file.
        path: PathBuf,
        /// 1-based line number, when known.
        line: Option<usize>,
        /// What is wrong.
        message: String,
    },

    /// The asset is above a loading limit ([`crate::assets::Limits`]); nothing was decoded.
    #[error("{}: {what} {value} is above the limit of {limit}", .path.display())]
    LimitExceeded {
        /// The file.
        path: PathBuf,
        /// What was measured.
        what: String,
        /// Its value.
        value: u64,
        /// The limit.
        limit: u64,
    },

    /// The OBJ file contains no triangles or polygons.
    #[error("{}: no geometry: {detail}", .path.display())]
    NoGeometry {
        /// OBJ file.
        path: PathBuf,
        /// What was found instead.
        detail: String,
    },

    /// A material library named by `mtllib` could not be read.
    #[error("{}: material library referenced from {}: {source}", .path.display(), Loc(.obj, .line))]
    MissingMtl {
        /// The MTL file path (resolved against the OBJ's directory).
        path: PathBuf,
        /// The OBJ file that referenced it.
        obj: PathBuf,
        /// Line of the `mtllib` statement in the OBJ file.
        line: Option<usize>,
        /// Underlying I/O error.
        #[source]
        source: std::io::Error,
    },

    /// A texture referenced by a material could not be loaded.
    #[error("{}: `{key}` texture failed to load: {source}", Loc(.mtl, .line))]
    Texture {
        /// Texture path (resolved against the MTL's directory).
        path: PathBuf,
        /// The MTL file that referenced it.
        mtl: PathBuf,
        /// Line of the referencing statement in the MTL file.
        line: Option<usize>,
        /// MTL key, e.g. `map_Kd`.
        key: String,
        /// Why loading failed (an [`AssetError::Io`] or [`AssetError::ImageDecode`]).
        #[source]
        source: Box<AssetError>,
    },

    /// An image file could not be decoded.
    #[error("{}: cannot decode image: {source}", .path.display())]
    ImageDecode {
        /// Image file.
        path: PathBuf,
        /// Decoder error.
        #[source]
        source: image::ImageError,
    },

    /// An OpenEXR file could not be decoded.
    #[error("{}: cannot decode EXR: {source}", .path.display())]
    Exr {
        /// EXR file.
        path: PathBuf,
        /// Decoder error.
        #[source]
        source: exr::error::Error,
    },

    /// A decoded image is unusable (zero size, too large, non-finite texels, ...).
    #[error("{}: {message}", .path.display())]
    InvalidImage {
        /// Image file.
        path: PathBuf,
        /// What is wrong.
        message: String,
    },

    /// `tobj` rejected the file for a reason the pre-scan did not catch.
    #[error("{}: OBJ loader error: {source}", .path.display())]
    Obj {
        /// OBJ file.
        path: PathBuf,
        /// The `tobj` error.
        #[source]
        source: tobj::LoadError,
    },
}

impl AssetError {
    /// The file this error is about (for [`AssetError::Texture`], the texture).
    pub fn path(&self) -> &Path {
        match self {
            Self::Io { path, .. }
            | Self::Parse { path, .. }
            | Self::NoGeometry { path, .. }
            | Self::MissingMtl { path, .. }
            | Self::Texture { path, .. }
            | Self::ImageDecode { path, .. }
            | Self::Exr { path, .. }
            | Self::InvalidImage { path, .. }
            | Self::LimitExceeded { path, .. }
            | Self::Obj { path, .. } => path,
        }
    }

    /// The 1-based line number the error refers to, when known.
    pub fn line(&self) -> Option<usize> {
        match self {
            Self::Io { line, .. }
            | Self::Parse { line, .. }
            | Self::MissingMtl { line, .. }
            | Self::Texture { line, .. } => *line,
            _ => None,
        }
    }

    pub(super) fn parse(path: &Path, line: usize, message: impl Into<String>) -> Self {
        Self::Parse {
            path: path.to_path_buf(),
            line: Some(line),
            message: message.into(),
        }
    }

    pub(super) fn io(path: &Path, source: std::io::Error) -> Self {
        Self::Io {
            path: path.to_path_buf(),
            line: None,
            source,
        }
    }

    pub(super) fn invalid_image(path: &Path, message: impl Into<String>) -> Self {
        Self::InvalidImage {
            path: path.to_path_buf(),
            message: message.into(),
        }
    }
}

/// Formats `path` or `path:line`.
struct Loc<'a>(&'a Path, &'a Option<usize>);

impl fmt::Display for Loc<'_> {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self.1 {
            Some(line) => write!(f, "{}:{}", self.0.display(), line),
            None => write!(f, "{}", self.0.display()),
        }
    }
}

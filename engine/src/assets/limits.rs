//! Resource limits for loading: a mesh, texture or scene above them is refused with an error
//! naming the file, checked from counts and headers before its data is decoded or allocated.

use std::path::Path;

use super::AssetError;

/// What one load (a scene with its meshes, textures and environment) may take.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Limits {
    /// Most vertex positions (`v` lines) in one OBJ file, counted before it is parsed.
    pub max_vertices: usize,
    /// Longest side of a texture or environment image in texels, read from its header.
    pub max_texture_side: u32,
    /// Most bytes the decoded assets of one load may take together: meshes (48-byte vertices
    /// and indices, estimated from the OBJ's counts), textures with their mips, environments.
    pub max_total_bytes: u64,
}

impl Limits {
    /// Generous defaults: 16 M vertices per OBJ, 16384-texel sides, 4 GiB in all.
    pub const DEFAULT: Limits = Limits {
        max_vertices: 16 << 20,
        max_texture_side: 16384,
        max_total_bytes: 4 << 30,
    };
    /// No limits.
    pub const NONE: Limits = Limits {
        max_vertices: usize::MAX,
        max_texture_side: u32::MAX,
        max_total_bytes: u64::MAX,
    };
}

impl Default for Limits {
    fn default() -> Self {
        Self::DEFAULT
    }
}

/// The limits of one load and the bytes reserved against them so far.
#[derive(Clone, Debug, Default)]
pub struct Budget {
    limits: Limits,
    reserved: u64,
}

impl Budget {
    /// A fresh budget.
    pub fn new(limits: Limits) -> Self {
        Self {
            limits,
            reserved: 0,
        }
    }

    /// The limits.
    pub fn limits(&self) -> Limits {
        self.limits
    }

    /// Bytes reserved so far.
    pub fn reserved(&self) -> u64 {
        self.reserved
    }

    fn exceeded(path: &Path, what: String, value: u64, limit: u64) -> AssetError {
        AssetError::LimitExceeded {
            path: path.to_path_buf(),
            what,
            value,
            limit,
        }
    }

    /// Checks an OBJ's vertex count.
    pub fn check_vertices(&self, path: &Path, vertices: usize) -> Result<(), AssetError> {
        if vertices > self.limits.max_vertices {
            return Err(Self::exceeded(
                path,
                "vertex count".to_owned(),
                vertices as u64,
                self.limits.max_vertices as u64,
            ));
        }
        Ok(())
    }

    /// Checks an image's size against the side limit.
    pub fn check_image(&self, path: &Path, width: u32, height: u32) -> Result<(), AssetError> {
        let side = width.max(height);
        if side > self.limits.max_texture_side {
            return Err(Self::exceeded(
                path,
                format!("image side ({width}x{height})"),
                u64::from(side),
                u64::from(self.limits.max_texture_side),
            ));
        }
        Ok(())
    }

    /// Reserves `bytes` for the asset at `path`, or says the load would exceed its total.
    pub fn reserve(&mut self, path: &Path, bytes: u64) -> Result<(), AssetError> {
        let total = self.reserved.saturating_add(bytes);
        if total > self.limits.max_total_bytes {
            return Err(Self::exceeded(
                path,
                format!(
                    "total decoded bytes ({} reserved before this file)",
                    self.reserved
                ),
                total,
                self.limits.max_total_bytes,
            ));
        }
        self.reserved = total;
        Ok(())
    }
}

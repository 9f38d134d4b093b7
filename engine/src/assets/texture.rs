//! Texture loading: decode with `image`, convert to RGBA8, build a CPU mip
//! chain, and deduplicate decodes through [`TextureCache`].
//!
//! Mip levels follow the GPU convention: level `k` is
//! `max(1, width >> k) x max(1, height >> k)`, down to 1x1. Each texel of a
//! level is the 2x2 box average of the level above; sample coordinates are
//! clamped to the source edge (so a 1-texel-wide source repeats its column,
//! and for an odd source size the last row/column is not sampled). sRGB
//! textures average RGB in linear light and re-encode; alpha and `Linear`
//! textures average the stored values with round-half-up integer math.

use std::collections::HashMap;
use std::path::{Path, PathBuf};
use std::sync::OnceLock;

use serde::Serialize;

use super::error::AssetError;
use super::limits::{Budget, Limits};

/// How the colour channels of a texture are encoded.
#[derive(Copy, Clone, PartialEq, Eq, Hash, Debug, Serialize)]
pub enum ColorSpace {
    /// sRGB transfer function on RGB (alpha is linear). Used for `map_Kd`.
    Srgb,
    /// Values stored as-is (normal, specular, roughness, metallic, clearcoat maps).
    Linear,
}

/// Handle of a texture inside a [`TextureCache`].
#[derive(Copy, Clone, PartialEq, Eq, Hash, Debug, Serialize)]
pub struct TextureId(pub u32);

/// A decoded RGBA8 texture with its full mip chain.
#[derive(Clone, Debug)]
pub struct TextureData {
    /// Path the texture was loaded from (as given to the loader).
    pub path: PathBuf,
    /// Colour space the texture should be sampled in.
    pub color_space: ColorSpace,
    /// Width of mip level 0.
    pub width: u32,
    /// Height of mip level 0.
    pub height: u32,
    /// RGBA8 texels, tightly packed, top row first; `mips[0]` is full size,
    /// the last level is 1x1.
    pub mips: Vec<Vec<u8>>,
}

impl TextureData {
    /// Size of mip level `level` (`max(1, size >> level)` per axis).
    pub fn mip_size(&self, level: usize) -> (u32, u32) {
        let shift = u32::try_from(level).unwrap_or(u32::MAX);
        (
            self.width.checked_shr(shift).unwrap_or(0).max(1),
            self.height.checked_shr(shift).unwrap_or(0).max(1),
        )
    }
}

/// Decodes an image file into RGBA8 and builds its mip chain.
///
/// The format is detected from the file contents (this build supports PNG).
pub fn load_texture(path: &Path, color_space: ColorSpace) -> Result<TextureData, AssetError> {
    let bytes = std::fs::read(path).map_err(|e| AssetError::io(path, e))?;
    let image = image::load_from_memory(&bytes).map_err(|source| AssetError::ImageDecode {
        path: path.to_path_buf(),
        source,
    })?;
    let rgba = image.into_rgba8();
    let (width, height) = rgba.dimensions();
    if width == 0 || height == 0 {
        return Err(AssetError::invalid_image(
            path,
            format!("image has zero size ({width}x{height})"),
        ));
    }
    let mips = generate_mips(width, height, &rgba.into_raw(), color_space);
    Ok(TextureData {
        path: path.to_path_buf(),
        color_space,
        width,
        height,
        mips,
    })
}

/// Builds the full mip chain (level 0 included) of a tightly packed RGBA8
/// image. Texels missing from a short `level0` slice read as zero.
pub fn generate_mips(
    width: u32,
    height: u32,
    level0: &[u8],
    color_space: ColorSpace,
) -> Vec<Vec<u8>> {
    let (mut w, mut h) = (width.max(1), height.max(1));
    let len = texel_bytes(w, h);
    let mut first = vec![0u8; len];
    for (dst, src) in first.iter_mut().zip(level0) {
        *dst = *src;
    }
    let mut mips = vec![first];
    while w > 1 || h > 1 {
        let Some(src) = mips.last() else { break };
        let (next, nw, nh) = downsample(src, w, h, color_space);
        mips.push(next);
        w = nw;
        h = nh;
    }
    mips
}

fn texel_bytes(w: u32, h: u32) -> usize {
    (w as usize).saturating_mul(h as usize).saturating_mul(4)
}

fn downsample(src: &[u8], sw: u32, sh: u32, cs: ColorSpace) -> (Vec<u8>, u32, u32) {
    let (dw, dh) = ((sw / 2).max(1), (sh / 2).max(1));
    let lut = srgb_to_linear_lut();
    let mut dst = Vec::with_capacity(texel_bytes(dw, dh));
    let at = |x: u32, y: u32, c: usize| -> u8 {
        let i = (y as usize * sw as usize + x as usize) * 4 + c;
        src.get(i).copied().unwrap_or(0)
    };
    for y in 0..dh {
        let (y0, y1) = ((2 * y).min(sh - 1), (2 * y + 1).min(sh - 1));
        for x in 0..dw {
            let (x0, x1) = ((2 * x).min(sw - 1), (2 * x + 1).min(sw - 1));
            for c in 0..4 {
                let s = [at(x0, y0, c), at(x1, y0, c), at(x0, y1, c), at(x1, y1, c)];
                let v = if cs == ColorSpace::Srgb && c < 3 {
                    let sum: f64 = s
                        .iter()
                        .map(|&v| lut.get(v as usize).copied().unwrap_or(0.0))
                        .sum();
                    linear_to_srgb_u8(sum / 4.0)
                } else {
                    let sum: u32 = s.iter().map(|&v| u32::from(v)).sum();
                    ((sum + 2) / 4) as u8
                };
                dst.push(v);
            }
        }
    }
    (dst, dw, dh)
}

/// Exact sRGB decode of every 8-bit value.
fn srgb_to_linear_lut() -> &'static [f64; 256] {
    static LUT: OnceLock<[f64; 256]> = OnceLock::new();
    LUT.get_or_init(|| {
        let mut lut = [0.0; 256];
        for (i, v) in lut.iter_mut().enumerate() {
            *v = srgb_to_linear(i as f64 / 255.0);
        }
        lut
    })
}

/// sRGB electro-optical transfer function (encoded 0..1 -> linear 0..1).
pub fn srgb_to_linear(s: f64) -> f64 {
    if s <= 0.04045 {
        s / 12.92
    } else {
        ((s + 0.055) / 1.055).powf(2.4)
    }
}

/// Inverse of [`srgb_to_linear`], rounded to the nearest 8-bit value.
pub fn linear_to_srgb_u8(l: f64) -> u8 {
    let l = if l.is_finite() {
        l.clamp(0.0, 1.0)
    } else {
        0.0
    };
    let s = if l <= 0.003_130_8 {
        12.92 * l
    } else {
        1.055 * l.powf(1.0 / 2.4) - 0.055
    };
    (s * 255.0 + 0.5).floor().clamp(0.0, 255.0) as u8
}

/// Deduplicating texture store, keyed by (canonical path, colour space).
///
/// A file referenced by several materials in the same colour space is decoded
/// once and shares one [`TextureId`]. Failed loads are not cached.
/// It also carries the load's [`Budget`]: the limits every asset of one load (textures here,
/// meshes in `load_obj`, the environment in scene files) is checked against before decoding.
#[derive(Debug, Default)]
pub struct TextureCache {
    textures: Vec<TextureData>,
    by_key: HashMap<(PathBuf, ColorSpace), TextureId>,
    decodes: usize,
    budget: Budget,
}

impl TextureCache {
    /// An empty cache with the default [`Limits`].
    pub fn new() -> Self {
        Self::default()
    }

    /// An empty cache whose load is held to `limits`.
    pub fn with_limits(limits: Limits) -> Self {
        Self {
            budget: Budget::new(limits),
            ..Self::default()
        }
    }

    /// The load's limits and what is reserved against them.
    pub fn budget(&mut self) -> &mut Budget {
        &mut self.budget
    }

    /// Returns the id of `path` in `color_space`, decoding it on first use.
    pub fn load(&mut self, path: &Path, color_space: ColorSpace) -> Result<TextureId, AssetError> {
        let canonical = std::fs::canonicalize(path).map_err(|e| AssetError::io(path, e))?;
        let key = (canonical, color_space);
        if let Some(id) = self.by_key.get(&key) {
            log::debug!("texture cache hit: {}", path.display());
            return Ok(*id);
        }
        let id = u32::try_from(self.textures.len())
            .map(TextureId)
            .map_err(|_| AssetError::invalid_image(path, "texture cache is full"))?;
        // Size from the header only, checked and reserved (RGBA8 with a full mip chain, 4/3 of
        // level 0) before anything is decoded.
        let (width, height) = image::ImageReader::open(path)
            .map_err(|e| AssetError::io(path, e))?
            .with_guessed_format()
            .map_err(|e| AssetError::io(path, e))?
            .into_dimensions()
            .map_err(|source| AssetError::ImageDecode {
                path: path.to_path_buf(),
                source,
            })?;
        self.budget.check_image(path, width, height)?;
        self.budget
            .reserve(path, u64::from(width) * u64::from(height) * 4 * 4 / 3)?;
        self.decodes += 1;
        let texture = load_texture(path, color_space)?;
        log::info!(
            "decoded texture {} ({}x{}, {} mips, {:?})",
            path.display(),
            texture.width,
            texture.height,
            texture.mips.len(),
            color_space
        );
        self.textures.push(texture);
        self.by_key.insert(key, id);
        Ok(id)
    }

    /// The texture behind `id`, if it belongs to this cache.
    pub fn get(&self, id: TextureId) -> Option<&TextureData> {
        self.textures.get(id.0 as usize)
    }

    /// Number of textures held.
    pub fn len(&self) -> usize {
        self.textures.len()
    }

    /// Whether the cache holds no texture.
    pub fn is_empty(&self) -> bool {
        self.textures.is_empty()
    }

    /// How many decodes were attempted (cache misses), successful or not.
    pub fn decode_count(&self) -> usize {
        self.decodes
    }

    /// All textures with their ids, in load order.
    pub fn iter(&self) -> impl Iterator<Item = (TextureId, &TextureData)> {
        self.textures
            .iter()
            .enumerate()
            .map(|(i, t)| (TextureId(i as u32), t))
    }
}

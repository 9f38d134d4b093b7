//! Texture loading: decode with `image` (PNG, JPEG, TGA, BMP), build a CPU mip
//! chain, and deduplicate decodes through [`TextureCache`].
//!
//! 8-bit files become RGBA8 textures. 16-bit files (16-bit PNG, the usual form of precise
//! normal maps) are not truncated to 8 bits: they become RGBA16F textures, which keep 11
//! significant bits (a step of at most 1/2048 of a value, against 1/255 for 8 bits) and which
//! every backend can filter; an sRGB 16-bit map is decoded to linear before it is stored, so
//! sampling returns linear values either way.
//!
//! Mip levels follow the GPU convention: level `k` is
//! `max(1, width >> k) x max(1, height >> k)`, down to 1x1. Each texel of a
//! level is the box-filtered average of the area of the level above that it
//! covers: the 2x2 texels below it where a size is even, and three texels per
//! axis, weighted by how much of each the texel covers, where a size is odd
//! (so no row or column of an odd-sized texture is dropped). sRGB textures
//! average RGB in linear light and re-encode; alpha and `Linear` textures
//! average the stored values, rounding half up.

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

/// How a decoded texture's texels are stored.
#[derive(Copy, Clone, PartialEq, Eq, Hash, Debug, Serialize)]
pub enum TexelFormat {
    /// Four bytes per texel, in the texture's colour space.
    Rgba8,
    /// Four little-endian IEEE half floats per texel, linear (from 16-bit files).
    Rgba16Float,
}

/// A decoded texture with its full mip chain.
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
    /// How each level's texels are stored.
    pub format: TexelFormat,
    /// Texels, tightly packed in `format`, top row first; `mips[0]` is full size,
    /// the last level is 1x1.
    pub mips: Vec<Vec<u8>>,
}

impl TextureData {
    /// Bits per channel of the file the texture came from (8 or 16).
    pub fn bits(&self) -> u8 {
        match self.format {
            TexelFormat::Rgba8 => 8,
            TexelFormat::Rgba16Float => 16,
        }
    }

    /// Size of mip level `level` (`max(1, size >> level)` per axis).
    pub fn mip_size(&self, level: usize) -> (u32, u32) {
        let shift = u32::try_from(level).unwrap_or(u32::MAX);
        (
            self.width.checked_shr(shift).unwrap_or(0).max(1),
            self.height.checked_shr(shift).unwrap_or(0).max(1),
        )
    }
}

/// Decodes an image file and builds its mip chain: RGBA8 for 8-bit files, RGBA16F for 16-bit
/// ones (see the module docs), within the default [`Limits`].
///
/// The format is detected from the file contents: PNG, JPEG, TGA or BMP.
pub fn load_texture(path: &Path, color_space: ColorSpace) -> Result<TextureData, AssetError> {
    load_texture_with_limits(path, color_space, Limits::DEFAULT)
}

/// [`load_texture`] held to `limits`: the image's sides (from its header, before decoding) and
/// its decoded bytes with mips are checked against them. The decoder's own allocation cap
/// follows the image's size (the `image` crate's default of 512 MiB would refuse a texture the
/// limits allow, without saying which limit).
pub fn load_texture_with_limits(
    path: &Path,
    color_space: ColorSpace,
    limits: Limits,
) -> Result<TextureData, AssetError> {
    let header = header(path)?;
    let (width, height, texel_bytes) = header;
    let mut budget = Budget::new(limits);
    budget.check_image(path, width, height)?;
    budget.reserve(path, decoded_bytes(width, height, texel_bytes))?;
    decode(path, color_space, limits, header)
}

/// Decodes a texture whose header has been checked against `limits`.
fn decode(
    path: &Path,
    color_space: ColorSpace,
    limits: Limits,
    (width, height, texel_bytes): (u32, u32, u64),
) -> Result<TextureData, AssetError> {
    // The decoder allocates its output (at most `texel_bytes` a texel) before reading the
    // pixels, and an allocation that fails aborts the process: with the limits off, a header
    // may claim any size, so a size this process cannot allocate is an error here.
    let output = u64::from(width) * u64::from(height) * texel_bytes;
    let allocatable = usize::try_from(output)
        .is_ok_and(|bytes| Vec::<u8>::new().try_reserve_exact(bytes).is_ok());
    if !allocatable {
        return Err(AssetError::invalid_image(
            path,
            format!("{width}x{height} decodes to {output} bytes, more than can be allocated"),
        ));
    }
    let mut decoder_limits = image::Limits::no_limits();
    decoder_limits.max_image_width = Some(limits.max_texture_side);
    decoder_limits.max_image_height = Some(limits.max_texture_side);
    // The decoder's own buffers on top of its output: a generous margin, so that only a file
    // whose decoder misbehaves meets it.
    decoder_limits.max_alloc = Some(output.saturating_mul(2).saturating_add(64 << 20));
    let bytes = std::fs::read(path).map_err(|e| AssetError::io(path, e))?;
    let mut reader = image::ImageReader::new(std::io::Cursor::new(bytes));
    reader.limits(decoder_limits);
    // The format from the contents where they tell it, else from the extension (TGA has no
    // signature).
    if let Ok(format) = image::ImageFormat::from_path(path) {
        reader.set_format(format);
    }
    let image = reader
        .with_guessed_format()
        .map_err(|e| AssetError::io(path, e))?
        .decode()
        .map_err(|source| AssetError::ImageDecode {
            path: path.to_path_buf(),
            source,
        })?;
    let (width, height) = (image.width(), image.height());
    if width == 0 || height == 0 {
        return Err(AssetError::invalid_image(
            path,
            format!("image has zero size ({width}x{height})"),
        ));
    }
    let (format, mips) = if is_sixteen_bit(image.color()) {
        let level0: Vec<[f32; 4]> = image
            .into_rgba16()
            .pixels()
            .map(|p| {
                let value = |c: usize| f64::from(p[c]) / 65535.0;
                let color = |c: usize| match color_space {
                    ColorSpace::Srgb => srgb_to_linear(value(c)),
                    ColorSpace::Linear => value(c),
                };
                [color(0), color(1), color(2), value(3)].map(|v| v as f32)
            })
            .collect();
        let mips = generate_mips_f32(width, height, level0)
            .iter()
            .map(|level| {
                level
                    .iter()
                    .flatten()
                    .flat_map(|&v| half::f16::from_f32(v).to_le_bytes())
                    .collect()
            })
            .collect();
        (TexelFormat::Rgba16Float, mips)
    } else {
        let rgba = image.into_rgba8();
        (
            TexelFormat::Rgba8,
            generate_mips(width, height, &rgba.into_raw(), color_space),
        )
    };
    Ok(TextureData {
        path: path.to_path_buf(),
        color_space,
        width,
        height,
        format,
        mips,
    })
}

/// Whether a decoded color type has 16 bits per channel (and so becomes RGBA16F).
fn is_sixteen_bit(color: image::ColorType) -> bool {
    color.bytes_per_pixel() / color.channel_count() == 2
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

/// Builds the full mip chain (level 0 included) of a linear float RGBA image with the same
/// box filter as [`generate_mips`] (every channel averaged as stored, no rounding).
pub fn generate_mips_f32(width: u32, height: u32, level0: Vec<[f32; 4]>) -> Vec<Vec<[f32; 4]>> {
    let (mut w, mut h) = (width.max(1), height.max(1));
    let mut first = level0;
    first.resize(w as usize * h as usize, [0.0; 4]);
    let mut mips = vec![first];
    while w > 1 || h > 1 {
        let Some(src) = mips.last() else { break };
        let (dw, dh) = ((w / 2).max(1), (h / 2).max(1));
        let (xs, ys) = (box_taps(w, dw), box_taps(h, dh));
        let mut next = Vec::with_capacity(dw as usize * dh as usize);
        for y_taps in &ys {
            for x_taps in &xs {
                let mut sum = [0.0f64; 4];
                for &(sy, wy) in y_taps {
                    for &(sx, wx) in x_taps {
                        let texel = src
                            .get(sy as usize * w as usize + sx as usize)
                            .copied()
                            .unwrap_or([0.0; 4]);
                        for (total, v) in sum.iter_mut().zip(texel) {
                            *total += wx * wy * f64::from(v);
                        }
                    }
                }
                next.push(sum.map(|v| v as f32));
            }
        }
        mips.push(next);
        w = dw;
        h = dh;
    }
    mips
}

/// The source texels of one axis under each destination texel when `source` texels shrink to
/// `destination` (a box filter): destination texel `i` covers `[i, i + 1) * source /
/// destination`, and each source texel weighs the fraction of that span it covers. An even
/// size gives two taps of 1/2; an odd size three taps (for 5 -> 2: 0.4, 0.4, 0.2 and 0.2, 0.4,
/// 0.4); a size of 1 one tap of 1.
fn box_taps(source: u32, destination: u32) -> Vec<Vec<(u32, f64)>> {
    let (source, destination) = (u64::from(source.max(1)), u64::from(destination.max(1)));
    (0..destination)
        .map(|i| {
            // In units of 1/destination source texels: the span is [lo, hi).
            let (lo, hi) = (i * source, (i + 1) * source);
            let first = lo / destination;
            let last = (hi - 1) / destination;
            (first..=last)
                .filter_map(|j| {
                    let covered = hi.min((j + 1) * destination) - lo.max(j * destination);
                    (covered > 0).then(|| (j as u32, covered as f64 / source as f64))
                })
                .collect()
        })
        .collect()
}

fn texel_bytes(w: u32, h: u32) -> usize {
    (w as usize).saturating_mul(h as usize).saturating_mul(4)
}

fn downsample(src: &[u8], sw: u32, sh: u32, cs: ColorSpace) -> (Vec<u8>, u32, u32) {
    let (dw, dh) = ((sw / 2).max(1), (sh / 2).max(1));
    let lut = srgb_to_linear_lut();
    let at = |x: u32, y: u32, c: usize| -> u8 {
        let i = (y as usize * sw as usize + x as usize) * 4 + c;
        src.get(i).copied().unwrap_or(0)
    };
    let odd = |size: u32| size > 1 && size % 2 == 1;
    if odd(sw) || odd(sh) {
        return (downsample_weighted(sw, sh, dw, dh, cs, &at), dw, dh);
    }
    // Even sizes (or 1): the 2x2 texels below, edge-clamped where a size is 1. Kept apart from
    // the weighted path so that these levels stay bit for bit what they have always been.
    let mut dst = Vec::with_capacity(texel_bytes(dw, dh));
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

/// One level down where a size is odd: each texel the [`box_taps`]-weighted mean of the texels
/// it covers.
fn downsample_weighted(
    sw: u32,
    sh: u32,
    dw: u32,
    dh: u32,
    cs: ColorSpace,
    at: &dyn Fn(u32, u32, usize) -> u8,
) -> Vec<u8> {
    let lut = srgb_to_linear_lut();
    let (xs, ys) = (box_taps(sw, dw), box_taps(sh, dh));
    let mut dst = Vec::with_capacity(texel_bytes(dw, dh));
    for y_taps in &ys {
        for x_taps in &xs {
            for c in 0..4 {
                let srgb = cs == ColorSpace::Srgb && c < 3;
                let mut sum = 0.0f64;
                for &(sy, wy) in y_taps {
                    for &(sx, wx) in x_taps {
                        let v = at(sx, sy, c);
                        let v = if srgb {
                            lut.get(v as usize).copied().unwrap_or(0.0)
                        } else {
                            f64::from(v)
                        };
                        sum += wx * wy * v;
                    }
                }
                dst.push(if srgb {
                    linear_to_srgb_u8(sum)
                } else {
                    (sum + 0.5).floor().clamp(0.0, 255.0) as u8
                });
            }
        }
    }
    dst
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

/// An image file's size and the bytes per texel it decodes to (RGBA8 or RGBA16F), from its
/// header only.
fn header(path: &Path) -> Result<(u32, u32, u64), AssetError> {
    let decoder = image::ImageReader::open(path)
        .map_err(|e| AssetError::io(path, e))?
        .with_guessed_format()
        .map_err(|e| AssetError::io(path, e))?
        .into_decoder()
        .map_err(|source| AssetError::ImageDecode {
            path: path.to_path_buf(),
            source,
        })?;
    let (width, height) = image::ImageDecoder::dimensions(&decoder);
    let color = image::ImageDecoder::color_type(&decoder);
    Ok((width, height, if is_sixteen_bit(color) { 8 } else { 4 }))
}

/// The bytes a decoded texture takes with its full mip chain (4/3 of level 0).
fn decoded_bytes(width: u32, height: u32, texel_bytes: u64) -> u64 {
    u64::from(width) * u64::from(height) * texel_bytes * 4 / 3
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
        // Size and bit depth from the header only, checked and reserved against the whole
        // load's budget before anything is decoded.
        let header = header(path)?;
        let (width, height, texel_bytes) = header;
        self.budget.check_image(path, width, height)?;
        self.budget
            .reserve(path, decoded_bytes(width, height, texel_bytes))?;
        self.decodes += 1;
        let texture = decode(path, color_space, self.budget.limits(), header)?;
        log::info!(
            "decoded texture {} ({}x{}, {} mips, {:?}, {:?})",
            path.display(),
            texture.width,
            texture.height,
            texture.mips.len(),
            color_space,
            texture.format
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

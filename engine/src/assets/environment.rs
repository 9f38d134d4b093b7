//! Equirectangular environment maps from OpenEXR files (via the `exr` crate) and Radiance
//! `.hdr` (RGBE) files (via the `image` crate), the two formats HDRI sites ship. The format is
//! told by the file's first bytes, not its name.
//!
//! EXR: the first layer with `R`, `G` and `B` channels is read at its largest
//! resolution level; `A` is optional (defaults to 1). Samples of any type
//! (f16, f32, u32) are converted to f32. Radiance: RGB, alpha 1. Texels are RGBA, linear, top
//! row first. "Radiance" here is the **maximum of the R, G and B channels** of a
//! texel (not luminance).

use std::io::Cursor;

use exr::image::read::image::ReadLayers as _;
use exr::image::read::layers::ReadChannels as _;
use std::path::{Path, PathBuf};

use super::error::AssetError;

/// Largest environment accepted, in texels (8192 x 8192; 1 GiB as f32 RGBA).
pub const MAX_ENVIRONMENT_TEXELS: usize = 1 << 26;

/// A decoded equirectangular environment map.
#[derive(Clone, Debug)]
pub struct Environment {
    /// The environment file (EXR or Radiance .hdr).
    pub path: PathBuf,
    /// Width in texels.
    pub width: u32,
    /// Height in texels.
    pub height: u32,
    /// RGBA f32 linear texels, row-major, top row first.
    pub texels: Vec<[f32; 4]>,
    /// Smallest per-texel radiance, `max(R, G, B)`.
    pub min_radiance: f32,
    /// Largest per-texel radiance, `max(R, G, B)`.
    pub max_radiance: f32,
}

impl Environment {
    /// Mean per-texel radiance `max(R, G, B)` (computed in f64).
    pub fn mean_radiance(&self) -> f32 {
        if self.texels.is_empty() {
            return 0.0;
        }
        let sum: f64 = self.texels.iter().map(|t| f64::from(radiance(t))).sum();
        (sum / self.texels.len() as f64) as f32
    }
}

/// Radiance measure used throughout: `max(R, G, B)`.
pub fn radiance(texel: &[f32; 4]) -> f32 {
    texel[0].max(texel[1]).max(texel[2])
}

type Pixels = (usize, Vec<[f32; 4]>);

/// The exr crate (1.74.2) trusts the coefficient counts in a DWAA/DWAB block's header and
/// reserves memory for them before decoding: a corrupt file claiming 10^14 coefficients aborts
/// the process (found by fuzzing, input kept in tests/fixtures/fuzz/). So before decoding,
/// every DWA block's counters are checked against the block's own size: no section of a block
/// can hold more than the block's uncompressed bytes.
fn check_dwa_blocks(path: &Path, bytes: &[u8]) -> Result<(), AssetError> {
    use exr::compression::Compression;
    let exr_err = |source| AssetError::Exr {
        path: path.to_path_buf(),
        source,
    };
    let reader = exr::block::read(Cursor::new(bytes), false).map_err(exr_err)?;
    let headers = reader.headers().to_vec();
    let is_dwa = |h: &exr::meta::header::Header| {
        matches!(h.compression, Compression::DWAA(_) | Compression::DWAB(_))
    };
    if !headers.iter().any(is_dwa) {
        return Ok(());
    }
    for chunk in reader.all_chunks(false).map_err(exr_err)? {
        let chunk = chunk.map_err(exr_err)?;
        let Some(header) = headers.get(chunk.layer_index).filter(|h| is_dwa(h)) else {
            continue;
        };
        let data = match &chunk.compressed_block {
            exr::block::chunk::CompressedBlock::ScanLine(b) => &b.compressed_pixels_le,
            exr::block::chunk::CompressedBlock::Tile(b) => &b.compressed_pixels_le,
            _ => continue,
        };
        let block = header
            .get_block_data_indices(&chunk.compressed_block)
            .and_then(|tile| header.get_absolute_block_pixel_coordinates(tile))
            .map_err(exr_err)?;
        let block_bytes = block
            .size
            .area()
            .saturating_mul(header.channels.bytes_per_pixel);
        if data.len() == block_bytes {
            continue; // stored uncompressed
        }
        // The DWA block header: 11 little-endian u64 counters (version, unknown uncompressed
        // and compressed sizes, AC, DC and RLE compressed sizes, RLE uncompressed and raw
        // sizes, AC and DC coefficient counts, AC compression).
        let counter = |i: usize| {
            data.get(i * 8..i * 8 + 8)
                .map(|b| u64::from_le_bytes(b.try_into().unwrap_or([0xff; 8])))
                .unwrap_or(0)
        };
        let sizes = [
            ("unknown section size", counter(1)),
            ("RLE section size", counter(6)),
            ("RLE raw size", counter(7)),
            ("AC coefficient bytes", counter(8).saturating_mul(2)),
            ("DC coefficient bytes", counter(9).saturating_mul(2)),
        ];
        if let Some((what, value)) = sizes.iter().find(|(_, value)| *value > block_bytes as u64) {
            return Err(AssetError::invalid_image(
                path,
                format!(
                    "corrupt DWA block at y {}: {what} {value} exceeds the block's {block_bytes} bytes",
                    block.position.y()
                ),
            ));
        }
    }
    Ok(())
}

/// The first bytes of an OpenEXR file.
const EXR_MAGIC: &[u8] = &[0x76, 0x2f, 0x31, 0x01];

/// The two environment formats.
enum Format {
    Exr,
    Radiance,
}

/// An environment file's format, told by its first bytes (not its name).
fn format(path: &Path, start: &[u8]) -> Result<Format, AssetError> {
    if start.starts_with(EXR_MAGIC) {
        Ok(Format::Exr)
    } else if start.starts_with(b"#?") {
        Ok(Format::Radiance)
    } else {
        Err(AssetError::invalid_image(
            path,
            "not an OpenEXR or Radiance .hdr file (environments must be one of the two)",
        ))
    }
}

/// Loads an EXR or Radiance `.hdr` environment map; rejects missing/corrupt files, other
/// formats, zero or oversized images and any non-finite texel (naming the first bad pixel).
pub fn load_environment(path: &Path) -> Result<Environment, AssetError> {
    let bytes = std::fs::read(path).map_err(|e| AssetError::io(path, e))?;
    let (w, h, texels) = match format(path, &bytes)? {
        Format::Exr => decode_exr(path, &bytes)?,
        Format::Radiance => decode_radiance(path, &bytes)?,
    };
    validated(path, w, h, texels)
}

/// The sizes (width, height) of an environment file's images, from its header alone: every
/// layer of an EXR, the one image of a Radiance `.hdr`. A load checks its limits with them
/// before anything is decoded. The format is told by the first bytes, as in
/// [`load_environment`].
pub fn environment_sizes(path: &Path) -> Result<Vec<(usize, usize)>, AssetError> {
    use std::io::BufRead as _;
    let file = std::fs::File::open(path).map_err(|e| AssetError::io(path, e))?;
    let mut reader = std::io::BufReader::new(file);
    let start = reader.fill_buf().map_err(|e| AssetError::io(path, e))?;
    match format(path, start)? {
        Format::Exr => {
            let meta =
                exr::meta::MetaData::read_from_buffered(reader, false).map_err(|source| {
                    AssetError::Exr {
                        path: path.to_owned(),
                        source,
                    }
                })?;
            Ok(meta
                .headers
                .iter()
                .map(|h| (h.layer_size.width(), h.layer_size.height()))
                .collect())
        }
        Format::Radiance => {
            use image::ImageDecoder as _;
            let decoder = image::codecs::hdr::HdrDecoder::new(reader).map_err(|source| {
                AssetError::ImageDecode {
                    path: path.to_owned(),
                    source,
                }
            })?;
            let (w, h) = decoder.dimensions();
            Ok(vec![(w as usize, h as usize)])
        }
    }
}

/// Checks an environment's size against [`MAX_ENVIRONMENT_TEXELS`] before decoding.
fn check_size(path: &Path, w: usize, h: usize) -> Result<(), AssetError> {
    if w == 0 || h == 0 {
        return Err(AssetError::invalid_image(
            path,
            format!("image has zero size ({w}x{h})"),
        ));
    }
    if w.checked_mul(h).is_none_or(|a| a > MAX_ENVIRONMENT_TEXELS) {
        return Err(AssetError::invalid_image(
            path,
            format!("image too large ({w}x{h}, limit {MAX_ENVIRONMENT_TEXELS} texels)"),
        ));
    }
    Ok(())
}

/// Decodes a Radiance RGBE file (its header is read and its size checked first).
fn decode_radiance(path: &Path, bytes: &[u8]) -> Result<(usize, usize, Vec<[f32; 4]>), AssetError> {
    use image::ImageDecoder as _;
    let decode_err = |source| AssetError::ImageDecode {
        path: path.to_path_buf(),
        source,
    };
    let decoder = image::codecs::hdr::HdrDecoder::new(Cursor::new(bytes)).map_err(decode_err)?;
    let (w, h) = decoder.dimensions();
    check_size(path, w as usize, h as usize)?;
    let image = image::DynamicImage::from_decoder(decoder).map_err(decode_err)?;
    let rgb = image.into_rgb32f();
    let texels = rgb.pixels().map(|p| [p[0], p[1], p[2], 1.0]).collect();
    Ok((w as usize, h as usize, texels))
}

/// Decodes an OpenEXR file.
fn decode_exr(path: &Path, bytes: &[u8]) -> Result<(usize, usize, Vec<[f32; 4]>), AssetError> {
    let exr_err = |source| AssetError::Exr {
        path: path.to_path_buf(),
        source,
    };
    let meta =
        exr::meta::MetaData::read_from_buffered(Cursor::new(bytes), false).map_err(exr_err)?;
    let has = |h: &exr::meta::header::Header, n: &str| h.channels.list.iter().any(|c| c.name.eq(n));
    let rgb_layers: Vec<_> = meta
        .headers
        .iter()
        .filter(|h| !h.deep && has(h, "R") && has(h, "G") && has(h, "B"))
        .collect();
    if rgb_layers.is_empty() {
        return Err(AssetError::invalid_image(
            path,
            "no layer with R, G and B channels",
        ));
    }
    for h in &rgb_layers {
        check_size(path, h.layer_size.width(), h.layer_size.height())?;
    }

    check_dwa_blocks(path, bytes)?;

    let image = exr::prelude::read()
        .no_deep_data()
        .largest_resolution_level()
        .rgba_channels(
            |size, _channels| -> Pixels {
                let area = size.width().saturating_mul(size.height());
                if area > MAX_ENVIRONMENT_TEXELS {
                    (size.width(), Vec::new())
                } else {
                    (size.width(), vec![[0.0; 4]; area])
                }
            },
            |pixels: &mut Pixels, pos, (r, g, b, a): (f32, f32, f32, f32)| {
                let index = pos
                    .y()
                    .checked_mul(pixels.0)
                    .and_then(|i| i.checked_add(pos.x()));
                if let Some(t) = index.and_then(|i| pixels.1.get_mut(i)) {
                    *t = [r, g, b, a];
                }
            },
        )
        .first_valid_layer()
        .all_attributes()
        .from_buffered(Cursor::new(bytes))
        .map_err(exr_err)?;

    let layer = image.layer_data;
    Ok((
        layer.size.width(),
        layer.size.height(),
        layer.channel_data.pixels.1,
    ))
}

/// The decoded texels as an [`Environment`], after checking their count and values.
fn validated(
    path: &Path,
    w: usize,
    h: usize,
    texels: Vec<[f32; 4]>,
) -> Result<Environment, AssetError> {
    if w == 0 || h == 0 || w.checked_mul(h) != Some(texels.len()) {
        return Err(AssetError::invalid_image(
            path,
            format!("unusable image size {w}x{h}"),
        ));
    }
    let (width, height) = match (u32::try_from(w), u32::try_from(h)) {
        (Ok(a), Ok(b)) => (a, b),
        _ => {
            return Err(AssetError::invalid_image(
                path,
                format!("image too large ({w}x{h})"),
            ))
        }
    };
    let (mut min, mut max) = (f32::INFINITY, f32::NEG_INFINITY);
    for (i, t) in texels.iter().enumerate() {
        if !t.iter().all(|c| c.is_finite()) {
            return Err(AssetError::invalid_image(
                path,
                format!("non-finite texel at pixel ({}, {}): {:?}", i % w, i / w, t),
            ));
        }
        let r = radiance(t);
        min = min.min(r);
        max = max.max(r);
    }
    log::info!(
        "loaded environment {} ({width}x{height}, radiance {min}..{max})",
        path.display()
    );
    Ok(Environment {
        path: path.to_path_buf(),
        width,
        height,
        texels,
        min_radiance: min,
        max_radiance: max,
    })
}

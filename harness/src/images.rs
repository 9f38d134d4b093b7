//! Reading and writing pass outputs: PNG for 8-bit images, EXR (fp16, ZIP-compressed) for float
//! images. Every write goes to a temporary file beside the destination and is renamed into place,
//! so a crash or a full disk never leaves a half-written image (or golden) behind.

use std::path::{Path, PathBuf};

use engine::backend::TextureFormat;
use engine::{Image, ImageData};

/// Why an image could not be read or written.
#[derive(Debug, thiserror::Error)]
pub enum ImageFileError {
    /// File system error (the OS error is part of the message, not a separate source, so
    /// `{:#}` chains print it once).
    #[error("{path}: {error}")]
    Io {
        /// The file.
        path: PathBuf,
        /// OS error.
        error: std::io::Error,
    },
    /// PNG encode or decode error.
    #[error("{path}: PNG: {message}")]
    Png {
        /// The file.
        path: PathBuf,
        /// What went wrong.
        message: String,
    },
    /// EXR encode or decode error.
    #[error("{path}: EXR: {message}")]
    Exr {
        /// The file.
        path: PathBuf,
        /// What went wrong.
        message: String,
    },
    /// The image cannot be stored in this format.
    #[error("{path}: {message}")]
    Unsupported {
        /// The file.
        path: PathBuf,
        /// Why.
        message: String,
    },
}

/// Fault injection for tests: milliseconds to wait between writing the temporary file and
/// renaming it over the target, so a test can kill the process mid-write.
pub const WRITE_DELAY_ENV: &str = "HARNESS_FAULT_WRITE_DELAY_MS";

/// Writes `bytes` to `path` atomically ([`engine::files::write_atomically`]): a reader, or a
/// process killed at any moment, sees the old file or the new one, never a part. With
/// [`WRITE_DELAY_ENV`] set, waits that many milliseconds before the rename.
pub fn write_atomically(path: &Path, bytes: &[u8]) -> Result<(), ImageFileError> {
    let fault_delay = || {
        if let Some(ms) = std::env::var(WRITE_DELAY_ENV)
            .ok()
            .and_then(|v| v.parse::<u64>().ok())
        {
            std::thread::sleep(std::time::Duration::from_millis(ms));
        }
    };
    engine::files::write_atomically_with(path, bytes, fault_delay).map_err(|error| {
        ImageFileError::Io {
            path: path.to_owned(),
            error,
        }
    })
}

/// How hard an image file's encoder works (PNG; for EXR, fast is RLE and the others ZIP).
/// Measured on the canonical goldens' PNGs (512x512): the smallest setting took 0.93 s for
/// 727 KB, balanced 0.31 s for 751 KB, fast 0.04 s for 898 KB.
/// - Generated scene assets are written once and must regenerate byte for byte: smallest.
/// - Goldens are kept in the repository and rewritten by every bless that changes them: balanced
///   (3% larger than the smallest for a third of the time; the encoding was half the CPU of
///   blessing one pass).
/// - Outputs for looking at (renders, failure images, report previews) are written on every
///   run: fast.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum FileCompression {
    /// Best compression with adaptive filtering (EXR: ZIP).
    Smallest,
    /// The encoder's default level with adaptive filtering (EXR: ZIP).
    Balanced,
    /// The encoder's fast mode (EXR: RLE).
    Fast,
}

/// PNG bytes of an 8-bit RGBA image.
pub fn encode_png(
    image: &Image,
    path: &Path,
    compression: FileCompression,
) -> Result<Vec<u8>, ImageFileError> {
    let data = image.as_u8().ok_or_else(|| ImageFileError::Unsupported {
        path: path.to_owned(),
        message: format!("{:?} is a float image; write it as .exr", image.format),
    })?;
    png_bytes(
        data,
        image.width,
        image.height,
        image::ExtendedColorType::Rgba8,
        compression,
    )
    .map_err(|e| ImageFileError::Png {
        path: path.to_owned(),
        message: e.to_string(),
    })
}

/// PNG bytes of raw texels of any PNG colour type (`Rgba8`, `Rgb16`, `L8` ...), adaptive
/// filtering: the one PNG encoder of the workspace (goldens, reports, generated assets).
pub fn png_bytes(
    data: &[u8],
    width: u32,
    height: u32,
    colour: image::ExtendedColorType,
    compression: FileCompression,
) -> Result<Vec<u8>, image::ImageError> {
    use image::ImageEncoder;
    let level = match compression {
        FileCompression::Smallest => image::codecs::png::CompressionType::Best,
        FileCompression::Balanced => image::codecs::png::CompressionType::Default,
        FileCompression::Fast => image::codecs::png::CompressionType::Fast,
    };
    let mut out = Vec::new();
    image::codecs::png::PngEncoder::new_with_quality(
        &mut out,
        level,
        image::codecs::png::FilterType::Adaptive,
    )
    .write_image(data, width, height, colour)?;
    Ok(out)
}

/// An 8-bit view of any image for looking at: float channels clamped to 0..1 and scaled
/// (no tone mapping, no sRGB encoding); depth shown as gray.
pub fn display_u8(image: &Image) -> Image {
    match &image.data {
        ImageData::U8(_) => image.clone(),
        ImageData::F32(data) => {
            let channels = image.channels();
            let mut out = Vec::with_capacity((image.width * image.height * 4) as usize);
            for texel in data.chunks_exact(channels) {
                let c = |i: usize| texel.get(i).copied().unwrap_or(texel[0]);
                for i in 0..3 {
                    out.push((c(i).clamp(0.0, 1.0) * 255.0).round() as u8);
                }
                out.push(255);
            }
            Image {
                width: image.width,
                height: image.height,
                format: TextureFormat::Rgba8Unorm,
                data: ImageData::U8(out),
            }
        }
    }
}

/// Writes an image: `.png` needs 8 bits (float images are converted with [`display_u8`]),
/// `.exr` stores float RGBA as fp16 (depth and R32F as f32) with ZIP compression.
pub fn write_image(
    image: &Image,
    path: &Path,
    compression: FileCompression,
) -> Result<(), ImageFileError> {
    let extension = path
        .extension()
        .and_then(|e| e.to_str())
        .unwrap_or("")
        .to_ascii_lowercase();
    match extension.as_str() {
        "png" => write_atomically(path, &encode_png(&display_u8(image), path, compression)?),
        "exr" => write_atomically(path, &encode_exr(image, path, compression)?),
        _ => Err(ImageFileError::Unsupported {
            path: path.to_owned(),
            message: "unknown image extension (use .png or .exr)".to_owned(),
        }),
    }
}

/// EXR bytes of a float image: ZIP-compressed, or with [`FileCompression::Fast`] RLE (an
/// output for looking at: ZIP's deflate was 5% of a failing `check`'s CPU in a profile, RLE's
/// files 40% larger).
pub fn encode_exr(
    image: &Image,
    path: &Path,
    compression: FileCompression,
) -> Result<Vec<u8>, ImageFileError> {
    use exr::prelude::*;
    let data = image.as_f32().ok_or_else(|| ImageFileError::Unsupported {
        path: path.to_owned(),
        message: "EXR output needs a float image; write 8-bit images as .png".to_owned(),
    })?;
    let channels = image.channels();
    let (w, h) = (image.width as usize, image.height as usize);
    let exr_error = |e: exr::error::Error| ImageFileError::Exr {
        path: path.to_owned(),
        message: e.to_string(),
    };
    let mut bytes = std::io::Cursor::new(Vec::new());
    // Blocks in increasing order: the exr crate compresses them in parallel, and with its
    // default (unspecified order) writes them as they finish, so one image gave other bytes
    // each time (a bless rewrote unchanged goldens, an accept could not equal a bless).
    let encoding = Encoding {
        compression: match compression {
            FileCompression::Fast => Compression::RLE,
            FileCompression::Balanced | FileCompression::Smallest => Compression::ZIP16,
        },
        line_order: LineOrder::Increasing,
        ..Encoding::FAST_LOSSLESS
    };
    if channels == 1 {
        // Depth and single-channel data stay f32: fp16 would quantise depth.
        let layer = Layer::new(
            (w, h),
            LayerAttributes::named("main"),
            encoding,
            SpecificChannels::build()
                .with_channel("Y")
                .with_pixel_fn(|p: Vec2<usize>| (data[p.y() * w + p.x()],)),
        );
        exr::image::Image::from_layer(layer)
            .write()
            .to_buffered(&mut bytes)
            .map_err(exr_error)?;
    } else {
        let layer = Layer::new(
            (w, h),
            LayerAttributes::named("main"),
            encoding,
            SpecificChannels::rgba(|p: Vec2<usize>| {
                let t = &data[(p.y() * w + p.x()) * channels..];
                (
                    f16::from_f32(t[0]),
                    f16::from_f32(t[1]),
                    f16::from_f32(t[2]),
                    f16::from_f32(t[3]),
                )
            }),
        );
        exr::image::Image::from_layer(layer)
            .write()
            .to_buffered(&mut bytes)
            .map_err(exr_error)?;
    }
    Ok(bytes.into_inner())
}

/// Reads a PNG as RGBA8 (format `Rgba8Unorm`; the caller knows whether it holds sRGB).
pub fn read_png(path: &Path) -> Result<Image, ImageFileError> {
    let decoded = image::open(path).map_err(|e| ImageFileError::Png {
        path: path.to_owned(),
        message: e.to_string(),
    })?;
    let rgba = decoded.to_rgba8();
    Ok(Image {
        width: rgba.width(),
        height: rgba.height(),
        format: TextureFormat::Rgba8Unorm,
        data: ImageData::U8(rgba.into_raw()),
    })
}

/// Reads the first layer of an EXR written by [`write_image`] (RGBA or single channel).
pub fn read_exr(path: &Path) -> Result<engine::Image, ImageFileError> {
    use exr::prelude::*;
    let exr_error = |e: exr::error::Error| ImageFileError::Exr {
        path: path.to_owned(),
        message: e.to_string(),
    };
    let image = read()
        .no_deep_data()
        .largest_resolution_level()
        .all_channels()
        .first_valid_layer()
        .all_attributes()
        .from_file(path)
        .map_err(exr_error)?;
    let layer = image.layer_data;
    let (w, h) = (layer.size.width(), layer.size.height());
    let channel = |name: &str| {
        layer
            .channel_data
            .list
            .iter()
            .find(|c| c.name.eq_case_insensitive(name))
            .map(|c| c.sample_data.values_as_f32().collect::<Vec<f32>>())
    };
    if let Some(y) = channel("Y") {
        return Ok(engine::Image {
            width: w as u32,
            height: h as u32,
            format: TextureFormat::R32Float,
            data: ImageData::F32(y),
        });
    }
    let (Some(r), Some(g), Some(b)) = (channel("R"), channel("G"), channel("B")) else {
        return Err(ImageFileError::Exr {
            path: path.to_owned(),
            message: "no R, G, B or Y channels".to_owned(),
        });
    };
    let a = channel("A").unwrap_or_else(|| vec![1.0; w * h]);
    let mut data = Vec::with_capacity(w * h * 4);
    for i in 0..w * h {
        data.extend_from_slice(&[r[i], g[i], b[i], a[i]]);
    }
    Ok(engine::Image {
        width: w as u32,
        height: h as u32,
        format: TextureFormat::Rgba32Float,
        data: ImageData::F32(data),
    })
}

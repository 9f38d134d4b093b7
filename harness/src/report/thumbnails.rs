//! Small previews of pass outputs: an 8-bit display mapping of each pass, box-downscaled, and
//! embedded in the page as a PNG data URI with a caption.

use base64::Engine as _;
use engine::plan::TargetId;
use engine::{Image, ImageData};

use super::pixels::{display, Display};

use crate::html::escape;
use crate::images;

/// Largest thumbnail edge in pixels.
const PREVIEW: u32 = 160;

/// An 8-bit thumbnail of a pass output: HDR values Reinhard-mapped, depth stretched over its
/// range, 8-bit images as they are; box-downscaled to at most [`PREVIEW`] pixels.
pub fn preview(image: &Image, pass: TargetId) -> Image {
    // The mapped values in the image's shape (not `..image.clone()`, which copied the pixels
    // only to drop them).
    let mapped = |data: Vec<f32>| Image {
        width: image.width,
        height: image.height,
        format: image.format,
        data: ImageData::F32(data),
    };
    let display = match (&image.data, display(image, pass)) {
        (ImageData::F32(data), Display::Depth) => {
            let finite = data.iter().copied().filter(|v| v.is_finite() && *v < 1.0);
            let (lo, hi) = finite.fold((f32::MAX, f32::MIN), |(lo, hi), v| (lo.min(v), hi.max(v)));
            let span = (hi - lo).max(1e-9);
            let stretched = data
                .iter()
                .map(|&v| if v >= 1.0 { 1.0 } else { (v - lo) / span })
                .collect();
            images::display_u8(&mapped(stretched))
        }
        (ImageData::F32(data), Display::Hdr) => {
            images::display_u8(&mapped(data.iter().map(|&v| v / (1.0 + v.abs())).collect()))
        }
        (ImageData::F32(data), Display::Signed) => {
            images::display_u8(&mapped(data.iter().map(|&v| v * 0.5 + 0.5).collect()))
        }
        _ => images::display_u8(image),
    };
    downscale(&display)
}

/// Box-downscales an 8-bit image by a whole factor, to at most [`PREVIEW`] pixels a side.
fn downscale(image: &Image) -> Image {
    let factor = image.width.max(image.height).div_ceil(PREVIEW).max(1);
    if factor == 1 {
        return image.clone();
    }
    let Some(data) = image.as_u8() else {
        return image.clone();
    };
    let (w, h) = (image.width / factor, image.height / factor);
    let mut out = Vec::with_capacity((w * h * 4) as usize);
    for y in 0..h {
        for x in 0..w {
            for c in 0..4 {
                let mut sum = 0u32;
                for dy in 0..factor {
                    for dx in 0..factor {
                        let i =
                            (((y * factor + dy) * image.width + x * factor + dx) * 4 + c) as usize;
                        sum += u32::from(data[i]);
                    }
                }
                out.push((sum / (factor * factor)) as u8);
            }
        }
    }
    Image {
        width: w,
        height: h,
        format: image.format,
        data: ImageData::U8(out),
    }
}

/// An image as a `data:` URI of a quickly compressed PNG.
fn data_uri(image: &Image) -> String {
    let png = images::encode_png(
        image,
        std::path::Path::new("preview.png"),
        images::FileCompression::Fast,
    )
    .unwrap_or_default();
    format!(
        "data:image/png;base64,{}",
        base64::engine::general_purpose::STANDARD.encode(png)
    )
}

/// A small PNG thumbnail with a caption.
pub(super) fn thumbnail(label: &str, image: &Image, pass: TargetId) -> String {
    format!(
        "<figure><img src=\"{}\" alt=\"{}\"><figcaption>{}</figcaption></figure>",
        data_uri(&preview(image, pass)),
        escape(label),
        escape(label)
    )
}

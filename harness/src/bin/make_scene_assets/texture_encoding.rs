//! Turning sampled texture values into bytes and PNG files.

use harness::images::{self, FileCompression};
use image::ExtendedColorType;

/// A value in 0..=255 from `x` in 0..=255, rounded.
pub(crate) fn byte(x: f64) -> u8 {
    x.round().clamp(0.0, 255.0) as u8
}

/// PNG bytes of 8-bit `data`, compressed with fixed settings.
pub(crate) fn png(size: u32, data: &[u8], colour: ExtendedColorType) -> Vec<u8> {
    images::png_bytes(data, size, size, colour, FileCompression::Smallest)
        .expect("encoding a PNG into memory cannot fail")
}

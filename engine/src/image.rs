//! CPU-side images: what a backend reads back from a texture.

use crate::backend::desc::TextureFormat;

/// Largest value an `Rgba16Float` upload stores (fp16's largest finite value is 65504).
pub const FP16_SAFE_MAX: f32 = 65000.0;

/// `values`, each clamped to `0..=FP16_SAFE_MAX`, as fp16 bit patterns for an `Rgba16Float`
/// upload: round to nearest even, converted a slice at a time (F16C, eight values per
/// instruction, where the CPU has it: the same bits as converting one value at a time).
pub fn fp16_bits(values: impl Iterator<Item = f32>) -> Vec<u16> {
    use half::slice::{HalfBitsSliceExt, HalfFloatSliceExt};
    /// Values clamped into a buffer on the stack and converted together: no list of the
    /// clamped values (an environment has millions) is allocated.
    const CHUNK: usize = 4096;
    let mut values = values.map(|v| v.clamp(0.0, FP16_SAFE_MAX));
    let mut bits = Vec::with_capacity(values.size_hint().0);
    let mut chunk = [0.0f32; CHUNK];
    loop {
        let mut filled = 0;
        // `zip` asks the chunk for a slot first, so no value is taken once the chunk is full.
        for (slot, value) in chunk.iter_mut().zip(&mut values) {
            *slot = value;
            filled += 1;
        }
        let start = bits.len();
        bits.resize(start + filled, 0u16);
        bits[start..]
            .reinterpret_cast_mut::<half::f16>()
            .convert_from_f32_slice(&chunk[..filled]);
        if filled < CHUNK {
            return bits;
        }
    }
}

/// Texel storage: 8-bit formats stay `u8`, everything else (f16 included) is widened to `f32`.
#[derive(Clone, Debug, PartialEq)]
pub enum ImageData {
    /// One byte per channel.
    U8(Vec<u8>),
    /// One f32 per channel (f16 converted exactly).
    F32(Vec<f32>),
}

/// A tightly packed image, top row first, `format.channels()` values per pixel.
#[derive(Clone, Debug, PartialEq)]
pub struct Image {
    /// Width in pixels.
    pub width: u32,
    /// Height in pixels.
    pub height: u32,
    /// Format of the texture it came from.
    pub format: TextureFormat,
    /// Texel values.
    pub data: ImageData,
}

impl Image {
    /// Channels per pixel.
    pub fn channels(&self) -> usize {
        self.format.channels()
    }

    /// Channel values of pixel (x, y) (y = 0 is the top row), as f32 (8-bit values stay 0..255).
    pub fn pixel(&self, x: u32, y: u32) -> Vec<f32> {
        let c = self.channels();
        let start = (y as usize * self.width as usize + x as usize) * c;
        match &self.data {
            ImageData::U8(v) => v[start..start + c].iter().map(|&b| b as f32).collect(),
            ImageData::F32(v) => v[start..start + c].to_vec(),
        }
    }

    /// The 8-bit data, if this is an 8-bit image.
    pub fn as_u8(&self) -> Option<&[u8]> {
        match &self.data {
            ImageData::U8(v) => Some(v),
            ImageData::F32(_) => None,
        }
    }

    /// The float data, if this is a float image.
    pub fn as_f32(&self) -> Option<&[f32]> {
        match &self.data {
            ImageData::F32(v) => Some(v),
            ImageData::U8(_) => None,
        }
    }

    /// Converts raw texel bytes of `format` (tightly packed, top row first) into an image.
    pub fn from_texel_bytes(width: u32, height: u32, format: TextureFormat, bytes: &[u8]) -> Self {
        let data = match format {
            TextureFormat::Rgba8Unorm | TextureFormat::Rgba8UnormSrgb => {
                ImageData::U8(bytes.to_vec())
            }
            TextureFormat::Rgba16Float => {
                use half::slice::HalfFloatSliceExt;
                let halves: Vec<half::f16> = bytes
                    .chunks_exact(2)
                    .map(|b| half::f16::from_le_bytes([b[0], b[1]]))
                    .collect();
                // The slice conversion uses F16C on whole vectors (exact, as per value).
                let mut values = vec![0.0f32; halves.len()];
                halves.convert_to_f32_slice(&mut values);
                ImageData::F32(values)
            }
            TextureFormat::Rgba32Float | TextureFormat::R32Float | TextureFormat::Depth32Float => {
                ImageData::F32(
                    bytes
                        .chunks_exact(4)
                        .map(|b| f32::from_le_bytes([b[0], b[1], b[2], b[3]]))
                        .collect(),
                )
            }
        };
        Self {
            width,
            height,
            format,
            data,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn fp16_bits_are_the_one_at_a_time_conversion() {
        let values: Vec<f32> = (0..100_000)
            .map(|i| (i as f32 * 0.618_034).sin() * 10f32.powi(i % 9 - 3))
            .chain([
                0.0,
                -0.0,
                1e-8,
                6e-5,
                65504.0,
                65519.0,
                7e4,
                f32::INFINITY,
                -5.0,
            ])
            .collect();
        let one_at_a_time: Vec<u16> = values
            .iter()
            .map(|&v| half::f16::from_f32(v.clamp(0.0, FP16_SAFE_MAX)).to_bits())
            .collect();
        assert_eq!(fp16_bits(values.iter().copied()), one_at_a_time);
        // Whole chunks only, and nothing.
        assert_eq!(
            fp16_bits(values[..8192].iter().copied()),
            one_at_a_time[..8192]
        );
        assert_eq!(fp16_bits(std::iter::empty()), Vec::<u16>::new());
    }
}

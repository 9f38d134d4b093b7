//! Synthetic host rounding: 8-bit outputs re-quantized from an exact f64 tone mapping of the
//! light buffer, float outputs moved by ±1 ulp of their storage, as another host's arithmetic
//! could round them.

use std::collections::BTreeMap;

use engine::assets::linear_to_srgb_u8;
use engine::ibl::splitmix64;
use engine::plan::TargetId;
use engine::scene::ToneMap;
use engine::{Image, ImageData};

use crate::golden::suite::Case;

/// Synthetic host rounding of a frame's golden outputs (see
/// [`SourceKind::SyntheticRounding`](super::SourceKind::SyntheticRounding)):
/// 8-bit outputs that are a tone mapping of the light buffer are re-quantized from an f64
/// evaluation of it; float outputs move by ±1 ulp of their storage. The mask (exact one-hot
/// values, no arithmetic to round) and outputs drawn over by gizmos are left out.
pub fn synthetic_rounding(
    case: &Case,
    outputs: &BTreeMap<TargetId, Image>,
) -> BTreeMap<TargetId, Image> {
    let quality = &case.loaded.scene.quality;
    let mut out = BTreeMap::new();
    for (seed, (pass, image)) in outputs.iter().enumerate() {
        match &image.data {
            ImageData::F32(_) => {
                out.insert(*pass, ulp_noise(image, seed as u64));
            }
            ImageData::U8(_) if *pass == TargetId::Final && !quality.gizmos => {
                if let Some(light) = outputs.get(&TargetId::Light) {
                    out.insert(*pass, requantize_final(light, quality.tone_map));
                }
            }
            ImageData::U8(_) => {}
        }
    }
    out
}

/// The tone-mapping pass's curve, in f64 (engine/shaders/tonemap.wgsl).
pub fn tone_map(x: f64, operator: ToneMap) -> f64 {
    let x = x.max(0.0);
    match operator {
        ToneMap::Aces => (x * (2.51 * x + 0.03)) / (x * (2.43 * x + 0.59) + 0.14),
        ToneMap::Reinhard => x / (1.0 + x),
        ToneMap::Clamp => x,
    }
    .clamp(0.0, 1.0)
}

/// The final image as an exact f64 evaluation of the tone mapping and sRGB encoding of `light`,
/// rounded to 8 bits: where the GPU's f32 arithmetic lands near a rounding boundary, this rounds
/// the other way, as another host's would.
pub fn requantize_final(light: &Image, operator: ToneMap) -> Image {
    let values = light.as_f32().unwrap_or(&[]);
    let channels = light.channels();
    let mut data = Vec::with_capacity(light.width as usize * light.height as usize * 4);
    for pixel in values.chunks_exact(channels) {
        for c in 0..3 {
            let v = f64::from(pixel[c.min(channels - 1)]);
            data.push(linear_to_srgb_u8(tone_map(v, operator)));
        }
        data.push(255);
    }
    Image {
        width: light.width,
        height: light.height,
        format: engine::backend::TextureFormat::Rgba8UnormSrgb,
        data: ImageData::U8(data),
    }
}

/// Moves `x` by `steps` representable values of its storage: fp16 for RGBA16F outputs, f32
/// otherwise. Infinities and NaN stay as they are; zero moves to the smallest subnormal.
pub fn step_ulps(x: f32, steps: i32, fp16: bool) -> f32 {
    if !x.is_finite() {
        return x;
    }
    // Map the bits to integers that order like the values (negative values below zero).
    if fp16 {
        let bits = i32::from(half::f16::from_f32(x).to_bits());
        let ordered = if bits & 0x8000 != 0 {
            -(bits & 0x7fff)
        } else {
            bits
        };
        let moved = (ordered + steps).clamp(-0x7bff, 0x7bff);
        let bits = if moved < 0 { (-moved) | 0x8000 } else { moved };
        half::f16::from_bits(bits as u16).to_f32()
    } else {
        let bits = i64::from(x.to_bits());
        let ordered = if bits & 0x8000_0000 != 0 {
            -(bits & 0x7fff_ffff)
        } else {
            bits
        };
        let moved = (ordered + i64::from(steps)).clamp(-0x7f7f_ffff, 0x7f7f_ffff);
        let bits = if moved < 0 {
            (-moved) | 0x8000_0000
        } else {
            moved
        };
        f32::from_bits(bits as u32)
    }
}

/// Every value moved by -1, 0 or +1 ulp of its storage, chosen by a hash of `seed` and its index.
pub fn ulp_noise(image: &Image, seed: u64) -> Image {
    let fp16 = image.format == engine::backend::TextureFormat::Rgba16Float;
    let mut out = image.clone();
    if let ImageData::F32(values) = &mut out.data {
        for (i, v) in values.iter_mut().enumerate() {
            let step = (splitmix64(seed.wrapping_mul(0x1_0000_0001) ^ i as u64) % 3) as i32 - 1;
            *v = step_ulps(*v, step, fp16);
        }
    }
    out
}

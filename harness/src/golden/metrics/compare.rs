//! Symmetric difference statistics of two read-back renders of the same size and format, neither
//! of them a golden (one backend against another, a render against a moved copy of its scene).

use engine::image::{Image, ImageData};

/// Why two images cannot be compared.
#[derive(Debug, thiserror::Error, PartialEq)]
pub enum CompareError {
    /// Different sizes or formats.
    #[error("images differ in shape: {a} vs {b}")]
    Shape {
        /// First image's shape.
        a: String,
        /// Second image's shape.
        b: String,
    },
    /// 8-bit statistics asked of float images or the reverse.
    #[error("{0}")]
    Kind(&'static str),
}

fn shape(image: &Image) -> String {
    format!("{}x{} {:?}", image.width, image.height, image.format)
}

fn check_shape(a: &Image, b: &Image) -> Result<(), CompareError> {
    if a.width != b.width || a.height != b.height || a.format != b.format {
        return Err(CompareError::Shape {
            a: shape(a),
            b: shape(b),
        });
    }
    Ok(())
}

/// Statistics of an 8-bit comparison.
#[derive(Clone, Debug, PartialEq, serde::Serialize)]
pub struct U8Difference {
    /// Largest per-channel absolute difference (0..255).
    pub max_abs: u8,
    /// Fraction of pixels whose every channel differs by at most the tolerance.
    pub fraction_within: f64,
    /// Pixels with some channel over the tolerance.
    pub pixels_over: usize,
}

/// Compares 8-bit images pixel by pixel with a per-channel tolerance.
pub fn u8_difference(a: &Image, b: &Image, tolerance: u8) -> Result<U8Difference, CompareError> {
    check_shape(a, b)?;
    let (ImageData::U8(x), ImageData::U8(y)) = (&a.data, &b.data) else {
        return Err(CompareError::Kind("u8_difference needs 8-bit images"));
    };
    let channels = a.channels();
    let mut max_abs = 0u8;
    let mut pixels_over = 0usize;
    for (p, q) in x.chunks_exact(channels).zip(y.chunks_exact(channels)) {
        let worst = p
            .iter()
            .zip(q)
            .map(|(s, t)| s.abs_diff(*t))
            .max()
            .unwrap_or(0);
        max_abs = max_abs.max(worst);
        pixels_over += usize::from(worst > tolerance);
    }
    let pixels = (a.width as usize * a.height as usize).max(1);
    Ok(U8Difference {
        max_abs,
        fraction_within: 1.0 - pixels_over as f64 / pixels as f64,
        pixels_over,
    })
}

/// Statistics of a float comparison.
#[derive(Clone, Debug, PartialEq, serde::Serialize)]
pub struct RelativeDifference {
    /// Largest per-channel relative difference `|a-b| / max(|a|, |b|, floor)`.
    pub max_relative: f64,
    /// Largest absolute difference.
    pub max_abs: f64,
    /// Pixel (x, y) of the largest relative difference.
    pub worst_pixel: (u32, u32),
    /// Pixels with some channel over `limit`.
    pub pixels_over: usize,
    /// Fraction of pixels with every channel within `limit`.
    pub fraction_within: f64,
    /// Whether either image holds NaN or infinity.
    pub non_finite: bool,
}

/// Compares float images channel by channel. `floor` keeps values near zero from inflating the
/// relative error; `limit` is the threshold counted in `pixels_over`.
pub fn relative_difference(
    a: &Image,
    b: &Image,
    floor: f64,
    limit: f64,
) -> Result<RelativeDifference, CompareError> {
    check_shape(a, b)?;
    let (ImageData::F32(x), ImageData::F32(y)) = (&a.data, &b.data) else {
        return Err(CompareError::Kind("relative_difference needs float images"));
    };
    let channels = a.channels();
    let mut result = RelativeDifference {
        max_relative: 0.0,
        max_abs: 0.0,
        worst_pixel: (0, 0),
        pixels_over: 0,
        fraction_within: 1.0,
        non_finite: false,
    };
    for (index, (p, q)) in x
        .chunks_exact(channels)
        .zip(y.chunks_exact(channels))
        .enumerate()
    {
        let mut worst = 0.0f64;
        for (&s, &t) in p.iter().zip(q) {
            if !s.is_finite() || !t.is_finite() {
                result.non_finite = true;
                worst = f64::INFINITY;
                continue;
            }
            let (s, t) = (s as f64, t as f64);
            let abs = (s - t).abs();
            result.max_abs = result.max_abs.max(abs);
            worst = worst.max(abs / s.abs().max(t.abs()).max(floor));
        }
        if worst > result.max_relative {
            result.max_relative = worst;
            result.worst_pixel = (
                (index % a.width as usize) as u32,
                (index / a.width as usize) as u32,
            );
        }
        result.pixels_over += usize::from(worst > limit);
    }
    let pixels = (a.width as usize * a.height as usize).max(1);
    result.fraction_within = 1.0 - result.pixels_over as f64 / pixels as f64;
    Ok(result)
}

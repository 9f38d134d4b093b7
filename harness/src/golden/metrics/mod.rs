//! Image-difference metrics, written once and used by tolerances, the noise model, the report
//! and bless; [`compare`] holds the symmetric comparisons of two renders with no golden between
//! them (one backend against another).
//!
//! Every metric compares an `actual` image with a `golden` (expected) one of the same size and
//! channel count. 8-bit images are compared in 0..1 units (1/255 per step); float images in their
//! own units. Each metric is tested on synthetic images with known answers.
//!
//! - a per-value *error* is the absolute difference `|a - g|`, or, given an absolute `floor` (in
//!   the image's units), the relative difference `|a - g| / max(|g|, floor)`: relative where the
//!   golden is bright, absolute (scaled by `1 / floor`) where it is darker than the floor. The
//!   floor is a fixed level, not a fraction of the image's maximum, so a sun in the frame does
//!   not make every other pixel's error vanish;
//! - [`Channels`] picks the channels compared: `rgb` (the first three) or `all`;
//! - `max_abs`: largest per-channel absolute difference (per channel and overall).
//! - `fraction_over(t)`: fraction of pixels whose largest channel error is over `t`.
//! - `rmse` and `psnr` (peak 1 for 8-bit images, the golden's largest value for float images).
//! - `relative`: a percentile of the per-value relative error (RGB by default).
//! - `flip_mean` / `flip_percentile`: NVIDIA FLIP (LDR) via `nv-flip`, for sRGB 8-bit images.
//! - a shift radius `r` makes `max_abs` and `fraction_over` forgiving of edge jitter: each actual
//!   pixel is compared with the best-matching golden pixel within `r` pixels.
//!
//! Non-finite values are counted separately and always fail (see [`crate::golden::tolerance`]).

use std::borrow::Cow;

pub mod compare;
pub mod flip_memo;

use engine::{Image, ImageData};

/// Which channels a metric compares.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, serde::Serialize, serde::Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum Channels {
    /// Every channel of the image.
    #[default]
    All,
    /// The first three (color without alpha; all of a one- or two-channel image).
    Rgb,
}

impl Channels {
    /// How many leading channels of a `channels`-channel image are compared.
    pub fn count(self, channels: usize) -> usize {
        match self {
            Channels::All => channels,
            Channels::Rgb => channels.min(3),
        }
    }

    /// The name used in tolerance tables (`rgb`, `all`).
    pub fn name(self) -> &'static str {
        match self {
            Channels::All => "all",
            Channels::Rgb => "rgb",
        }
    }
}

/// The error of one value against its golden: absolute, or relative above an absolute floor.
fn value_error(actual: f32, golden: f32, floor: Option<f64>) -> f64 {
    let (a, g) = (f64::from(actual), f64::from(golden));
    let e = match floor {
        None => (a - g).abs(),
        Some(floor) => (a - g).abs() / g.abs().max(floor).max(f64::MIN_POSITIVE),
    };
    if e.is_nan() {
        f64::INFINITY
    } else {
        e
    }
}

/// Why two images cannot be compared.
#[derive(Debug, thiserror::Error)]
pub enum MetricError {
    /// Different sizes or channel counts.
    #[error("size or layout differs: actual {actual}, golden {golden}")]
    Mismatch {
        /// Actual image shape.
        actual: String,
        /// Golden image shape.
        golden: String,
    },
    /// FLIP needs 8-bit RGBA images.
    #[error("FLIP needs 8-bit images")]
    FlipNeedsU8,
}

/// Where two images differ most: the pixel (top row 0) with the largest absolute channel
/// difference (infinite for NaN), and how many pixels differ at all.
#[derive(Clone, Copy, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct LargestDifference {
    /// Column.
    pub x: u32,
    /// Row, from the top.
    pub y: u32,
    /// The largest absolute channel difference (8-bit images in 0..1 units).
    pub difference: f64,
    /// Pixels with any channel different.
    pub differing_pixels: usize,
    /// The golden's value in that channel (None in results from before it was kept): how
    /// large the difference is against what it differs from.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub golden: Option<f64>,
}

impl std::fmt::Display for LargestDifference {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(
            f,
            "{} px differ, the most {:.4e}",
            self.differing_pixels, self.difference
        )?;
        // As a share of the golden's value too: a difference of 3.1 in a light buffer of 78
        // is 4%, not what the bare number suggests beside a relative limit.
        if let Some(golden) = self.golden.filter(|g| *g != 0.0 && g.is_finite()) {
            let percent = 100.0 * self.difference / golden.abs();
            write!(f, " ({percent:.3}% of the golden's {golden:.4e})")?;
        }
        write!(f, " at ({}, {})", self.x, self.y)
    }
}

/// Both images as f32 values (8-bit scaled to 0..1) with their channel count.
pub struct Pair<'a> {
    actual: Cow<'a, [f32]>,
    golden: Cow<'a, [f32]>,
    /// Same values bit for bit, all finite: every error is exactly 0.
    identical: bool,
    width: usize,
    height: usize,
    channels: usize,
    eight_bit: bool,
}

fn shape(image: &Image) -> String {
    format!(
        "{}x{} {:?} ({} channels)",
        image.width,
        image.height,
        image.format,
        image.channels()
    )
}

/// An image's values in metric units: float images borrowed, 8-bit ones scaled to 0..1.
fn values(image: &Image) -> Cow<'_, [f32]> {
    match &image.data {
        ImageData::U8(d) => Cow::Owned(d.iter().map(|&v| f32::from(v) / 255.0).collect()),
        ImageData::F32(d) => Cow::Borrowed(d),
    }
}

/// Whether two images hold the same values bit for bit (float images compared by bit pattern,
/// so a NaN matches only the same NaN, and -0 not 0).
pub fn bitwise_equal(actual: &Image, golden: &Image) -> bool {
    match (&actual.data, &golden.data) {
        (ImageData::U8(a), ImageData::U8(g)) => a == g,
        (ImageData::F32(a), ImageData::F32(g)) => {
            a.len() == g.len() && a.iter().zip(g).all(|(a, g)| a.to_bits() == g.to_bits())
        }
        _ => false,
    }
}

impl<'a> Pair<'a> {
    /// Prepares two images for comparison.
    pub fn new(actual: &'a Image, golden: &'a Image) -> Result<Self, MetricError> {
        let same = actual.width == golden.width
            && actual.height == golden.height
            && actual.channels() == golden.channels()
            && matches!(actual.data, ImageData::U8(_)) == matches!(golden.data, ImageData::U8(_));
        if !same {
            return Err(MetricError::Mismatch {
                actual: shape(actual),
                golden: shape(golden),
            });
        }
        let actual_values = values(actual);
        let identical =
            bitwise_equal(actual, golden) && actual_values.iter().all(|v| v.is_finite());
        Ok(Self {
            actual: actual_values,
            golden: values(golden),
            identical,
            width: actual.width as usize,
            height: actual.height as usize,
            channels: actual.channels(),
            eight_bit: matches!(actual.data, ImageData::U8(_)),
        })
    }

    /// Number of pixels.
    pub fn pixels(&self) -> usize {
        self.width * self.height
    }

    /// Whether the images are equal bit for bit with only finite values, so that every metric
    /// is exactly zero (PSNR infinite) and need not be computed.
    pub fn identical(&self) -> bool {
        self.identical
    }

    /// Non-finite values in the actual image.
    pub fn non_finite(&self) -> usize {
        self.actual.iter().filter(|v| !v.is_finite()).count()
    }

    /// Per-pixel largest channel error (absolute, or relative above `floor`; see the module
    /// docs) over `channels`, comparing each actual pixel with the closest golden pixel within
    /// `shift` pixels (0: the same pixel).
    pub fn pixel_errors(&self, shift: u32, floor: Option<f64>, channels: Channels) -> Vec<f64> {
        if shift == 0 {
            return self.unshifted_errors(floor, channels).collect();
        }
        let c = self.channels;
        let used = channels.count(c);
        let r = shift as isize;
        let mut out = Vec::with_capacity(self.pixels());
        for y in 0..self.height {
            for x in 0..self.width {
                let a = &self.actual[(y * self.width + x) * c..][..used];
                let mut best = f64::INFINITY;
                for dy in -r..=r {
                    for dx in -r..=r {
                        let (gx, gy) = (x as isize + dx, y as isize + dy);
                        if gx < 0
                            || gy < 0
                            || gx >= self.width as isize
                            || gy >= self.height as isize
                        {
                            continue;
                        }
                        let g =
                            &self.golden[(gy as usize * self.width + gx as usize) * c..][..used];
                        let e = a
                            .iter()
                            .zip(g)
                            .map(|(&a, &g)| value_error(a, g, floor))
                            .fold(0.0f64, f64::max);
                        best = best.min(e);
                    }
                }
                out.push(best);
            }
        }
        out
    }

    /// Per-pixel largest channel error over `channels` against the same golden pixel, in pixel
    /// order (the no-shift case of [`Pair::pixel_errors`], without a list).
    fn unshifted_errors(
        &self,
        floor: Option<f64>,
        channels: Channels,
    ) -> impl Iterator<Item = f64> + '_ {
        let c = self.channels;
        let used = channels.count(c);
        self.actual
            .chunks_exact(c)
            .zip(self.golden.chunks_exact(c))
            .map(move |(a, g)| {
                a[..used]
                    .iter()
                    .zip(&g[..used])
                    .map(|(&a, &g)| value_error(a, g, floor))
                    .fold(0.0f64, f64::max)
            })
    }

    /// Per-pixel largest absolute channel difference over every channel, no shift (for diff
    /// images).
    pub fn pixel_differences(&self) -> Vec<f64> {
        self.pixel_errors(0, None, Channels::All)
    }

    /// The pixel with the largest absolute channel difference (no shift), and how many pixels
    /// differ at all; `None` when nothing differs.
    pub fn largest_difference(&self) -> Option<LargestDifference> {
        let mut differing = 0usize;
        let mut worst: Option<(usize, f64)> = None;
        for (i, d) in self.unshifted_errors(None, Channels::All).enumerate() {
            if d > 0.0 {
                differing += 1;
                if worst.is_none_or(|(_, w)| d > w) {
                    worst = Some((i, d));
                }
            }
        }
        let (index, difference) = worst?;
        // The channel that differs most there, and the golden's value in it.
        let at = index * self.channels..(index + 1) * self.channels;
        let golden = self.actual[at.clone()]
            .iter()
            .zip(&self.golden[at])
            .max_by(|(a, g), (b, h)| (*a - *g).abs().total_cmp(&(*b - *h).abs()))
            .map(|(_, g)| f64::from(*g));
        Some(LargestDifference {
            x: (index % self.width) as u32,
            y: (index / self.width) as u32,
            difference,
            differing_pixels: differing,
            golden,
        })
    }

    /// Largest absolute difference per channel (no shift).
    pub fn max_abs_per_channel(&self) -> Vec<f64> {
        let mut max = vec![0.0f64; self.channels];
        for (i, (a, g)) in self.actual.iter().zip(self.golden.iter()).enumerate() {
            let d = f64::from((a - g).abs());
            let slot = &mut max[i % self.channels];
            *slot = if d.is_nan() {
                f64::INFINITY
            } else {
                slot.max(d)
            };
        }
        max
    }

    /// Largest absolute difference over `channels`, with a shift radius.
    pub fn max_abs(&self, shift: u32, channels: Channels) -> f64 {
        self.pixel_errors(shift, None, channels)
            .into_iter()
            .fold(0.0f64, f64::max)
    }

    /// Fraction of pixels whose largest error over `channels` (absolute, or relative above
    /// `floor`) is more than `threshold`, with a shift radius.
    pub fn fraction_over(
        &self,
        threshold: f64,
        shift: u32,
        floor: Option<f64>,
        channels: Channels,
    ) -> f64 {
        let over = if shift == 0 {
            // The common case, counted without a per-pixel error list.
            self.unshifted_errors(floor, channels)
                .filter(|&e| e > threshold)
                .count()
        } else {
            self.pixel_errors(shift, floor, channels)
                .into_iter()
                .filter(|&e| e > threshold)
                .count()
        };
        over as f64 / self.pixels().max(1) as f64
    }

    /// Root-mean-square difference over all channels.
    pub fn rmse(&self) -> f64 {
        let sum: f64 = self
            .actual
            .iter()
            .zip(self.golden.iter())
            .map(|(a, g)| f64::from(a - g).powi(2))
            .sum();
        (sum / self.actual.len().max(1) as f64).sqrt()
    }

    /// Peak signal-to-noise ratio in dB (infinite for identical images).
    pub fn psnr(&self) -> f64 {
        let peak = if self.eight_bit {
            1.0
        } else {
            self.golden
                .iter()
                .filter(|v| v.is_finite())
                .fold(0.0f64, |m, &v| m.max(f64::from(v).abs()))
                .max(1e-12)
        };
        let rmse = self.rmse();
        if rmse == 0.0 {
            f64::INFINITY
        } else {
            20.0 * (peak / rmse).log10()
        }
    }

    /// Relative error of every value of `channels`, `|a - g| / max(|g|, floor)` with `floor`
    /// absolute (in the image's units), sorted ascending.
    pub fn relative_errors(&self, floor: f64, channels: Channels) -> Vec<f64> {
        let c = self.channels;
        let used = channels.count(c);
        let mut errors: Vec<f64> = self
            .actual
            .chunks_exact(c)
            .zip(self.golden.chunks_exact(c))
            .flat_map(|(a, g)| {
                a[..used]
                    .iter()
                    .zip(&g[..used])
                    .map(|(&a, &g)| value_error(a, g, Some(floor)))
            })
            .collect();
        errors.sort_by(f64::total_cmp);
        errors
    }

    /// The `percentile` (0..1) of the relative error over `channels` (see
    /// [`Pair::relative_errors`]).
    pub fn relative_percentile(&self, percentile: f64, floor: f64, channels: Channels) -> f64 {
        engine::stats::percentile_of_sorted(&self.relative_errors(floor, channels), percentile)
    }

    /// FLIP error map of two 8-bit images (values 0..1 per pixel).
    pub fn flip_map(actual: &Image, golden: &Image) -> Result<Vec<f32>, MetricError> {
        let (ImageData::U8(a), ImageData::U8(g)) = (&actual.data, &golden.data) else {
            return Err(MetricError::FlipNeedsU8);
        };
        let rgb =
            |d: &[u8]| -> Vec<u8> { d.chunks_exact(4).flat_map(|p| [p[0], p[1], p[2]]).collect() };
        let (reference, test) = (rgb(g), rgb(a));
        let ppd = nv_flip::DEFAULT_PIXELS_PER_DEGREE;
        let key = flip_memo::key(&reference, &test, golden.width, golden.height, ppd);
        let len = golden.width as usize * golden.height as usize;
        if let Some(map) = flip_memo::get(&key, len) {
            return Ok(map.as_ref().clone());
        }
        let reference = nv_flip::FlipImageRgb8::with_data(golden.width, golden.height, &reference);
        let test = nv_flip::FlipImageRgb8::with_data(actual.width, actual.height, &test);
        let map = nv_flip::flip(reference, test, ppd).to_vec();
        flip_memo::put(key, std::sync::Arc::new(map.clone()));
        Ok(map)
    }
}

/// Mean of a FLIP error map.
pub fn flip_mean(map: &[f32]) -> f64 {
    map.iter().map(|&v| f64::from(v)).sum::<f64>() / map.len().max(1) as f64
}

/// Mean and percentile of a FLIP error map.
pub fn flip_stats(map: &[f32], percentile: f64) -> (f64, f64) {
    let mean = flip_mean(map);
    let mut sorted: Vec<f64> = map.iter().map(|&v| f64::from(v)).collect();
    sorted.sort_by(f64::total_cmp);
    (
        mean,
        engine::stats::percentile_of_sorted(&sorted, percentile),
    )
}

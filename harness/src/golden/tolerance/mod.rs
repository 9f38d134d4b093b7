//! Tolerances: a small tree of rules over [`crate::golden::metrics`], read from a scene file's
//! `[tolerances.<pass>]` table.
//!
//! A rule is a TOML table with exactly one of:
//! - `all = [rule, ...]`: passes when every rule passes;
//! - `any = [rule, ...]`: passes when some rule passes;
//! - `metric = "<name>"` with its limit (`max`, or `min` for `psnr`) and parameters:
//!
//! | metric | parameters | passes when |
//! |---|---|---|
//! | `max_abs` | `shift` (px, default 0), `channels` | largest channel difference <= `max` |
//! | `fraction_over` | `threshold`, `floor` (absent: absolute), `shift`, `channels` | fraction of pixels whose largest channel error is over `threshold` <= `max` |
//! | `rmse` | | RMSE <= `max` |
//! | `psnr` | | PSNR >= `min` (dB) |
//! | `relative` | `percentile` (default 1), `floor` (default 1e-3), `channels` (default `rgb`) | that percentile of the relative error <= `max` |
//! | `flip_mean` | | mean FLIP error <= `max` (8-bit images) |
//! | `flip_percentile` | `percentile` | that percentile of FLIP <= `max` |
//!
//! 8-bit differences are in 0..1 units (one step is 1/255 = 0.00392). `floor` is absolute, in the
//! image's units: an error is `|a - g| / max(|g|, floor)` (see [`crate::golden::metrics`]). `channels` is
//! `"all"` (default, but `rgb` for `relative`) or `"rgb"` (alpha left out). Any NaN or infinity
//! in the actual image fails every rule, whatever the tree says.
//!
//! A verdict also carries the rule's *ratio*: how far the image is from failing, `value / limit`
//! for one check (`limit / value` for `psnr`), the largest over an `all`, the smallest over an
//! `any`. It passes at ratio <= 1; the mutation self-test and the noise model read margins from
//! it.

use std::fmt;

use engine::Image;

use crate::golden::metrics::{flip_mean, flip_stats, Channels, MetricError, Pair};

mod parse;

pub use parse::RuleError;

/// A metric with its parameters.
#[derive(Clone, Debug, PartialEq)]
pub enum Metric {
    /// Largest channel difference.
    MaxAbs {
        /// Shift radius in pixels.
        shift: u32,
        /// Channels compared.
        channels: Channels,
    },
    /// Fraction of pixels over a threshold.
    FractionOver {
        /// Per-channel error that counts a pixel as over.
        threshold: f64,
        /// Absolute floor: with one, the error is relative (see [`crate::golden::metrics`]).
        floor: Option<f64>,
        /// Shift radius in pixels.
        shift: u32,
        /// Channels compared.
        channels: Channels,
    },
    /// Root-mean-square difference.
    Rmse,
    /// Peak signal-to-noise ratio (a lower bound).
    Psnr,
    /// Relative error percentile.
    Relative {
        /// Percentile, 0..1.
        percentile: f64,
        /// Absolute denominator floor, in the image's units.
        floor: f64,
        /// Channels compared.
        channels: Channels,
    },
    /// Mean FLIP.
    FlipMean,
    /// FLIP percentile.
    FlipPercentile {
        /// Percentile, 0..1.
        percentile: f64,
    },
}

impl fmt::Display for Metric {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let extras = |shift: u32, channels: Channels, default: Channels| {
            let mut s = String::new();
            if channels != default {
                s.push_str(&format!(", {}", channels.name()));
            }
            if shift > 0 {
                s.push_str(&format!(", shift {shift}px"));
            }
            s
        };
        match self {
            Metric::MaxAbs { shift, channels } => {
                let e = extras(*shift, *channels, Channels::All);
                if e.is_empty() {
                    write!(f, "max_abs")
                } else {
                    write!(f, "max_abs({})", &e[2..])
                }
            }
            Metric::FractionOver {
                threshold,
                floor,
                shift,
                channels,
            } => {
                let relative = floor.map_or(String::new(), |fl| format!(" rel, floor {fl}"));
                write!(
                    f,
                    "fraction_over(> {threshold}{relative}{})",
                    extras(*shift, *channels, Channels::All)
                )
            }
            Metric::Rmse => write!(f, "rmse"),
            Metric::Psnr => write!(f, "psnr"),
            Metric::Relative {
                percentile,
                floor,
                channels,
            } => write!(
                f,
                "relative(p{}, floor {floor}{})",
                percentile * 100.0,
                extras(0, *channels, Channels::Rgb)
            ),
            Metric::FlipMean => write!(f, "flip_mean"),
            Metric::FlipPercentile { percentile } => write!(f, "flip(p{})", percentile * 100.0),
        }
    }
}

/// A tolerance rule tree.
#[derive(Clone, Debug, PartialEq)]
pub enum Rule {
    /// Every rule must pass.
    All(Vec<Rule>),
    /// Some rule must pass.
    Any(Vec<Rule>),
    /// `metric <= limit` (or `>=` for PSNR).
    Check {
        /// What to measure.
        metric: Metric,
        /// The limit.
        limit: f64,
    },
}

/// The per-pixel criterion of a rule, for showing differences in units of the tolerance: a
/// pixel's error is its largest channel difference, divided by `max(|golden|, floor)` when the
/// criterion is relative, and the pixel counts as over at `error > threshold`.
#[derive(Clone, Copy, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct PixelCriterion {
    /// The error at which a pixel counts as over.
    pub threshold: f64,
    /// Denominator floor of a relative criterion; `None` for an absolute one.
    pub floor: Option<f64>,
    /// Which channels count.
    pub channels: Channels,
}

impl Rule {
    /// The first per-pixel criterion of the rule: a `fraction_over` threshold, or a `max_abs`
    /// limit. `None` when the rule only has whole-image metrics (RMSE, PSNR, FLIP).
    pub fn pixel_criterion(&self) -> Option<PixelCriterion> {
        match self {
            Rule::All(rules) | Rule::Any(rules) => rules.iter().find_map(Rule::pixel_criterion),
            Rule::Check {
                metric:
                    Metric::FractionOver {
                        threshold,
                        floor,
                        channels,
                        ..
                    },
                ..
            } => Some(PixelCriterion {
                threshold: *threshold,
                floor: *floor,
                channels: *channels,
            }),
            Rule::Check {
                metric: Metric::MaxAbs { channels, .. },
                limit,
            } => Some(PixelCriterion {
                threshold: *limit,
                floor: None,
                channels: *channels,
            }),
            Rule::Check { .. } => None,
        }
    }

    /// The first FLIP metric in the rule, if any: FLIP compares 8-bit images only, so such a
    /// rule cannot judge a float pass.
    pub fn flip_metric(&self) -> Option<&Metric> {
        match self {
            Rule::All(rules) | Rule::Any(rules) => rules.iter().find_map(Rule::flip_metric),
            Rule::Check { metric, .. } => {
                matches!(metric, Metric::FlipMean | Metric::FlipPercentile { .. }).then_some(metric)
            }
        }
    }

    /// Evaluates the rule on `actual` against `golden`.
    pub fn evaluate(&self, actual: &Image, golden: &Image) -> Result<Verdict, MetricError> {
        let pair = Pair::new(actual, golden)?;
        let mut flip = None;
        let mut checks = Vec::new();
        let ratio = self.evaluate_with(&pair, actual, golden, &mut flip, &mut checks)?;
        let non_finite = pair.non_finite();
        let passed = ratio <= 1.0 && non_finite == 0;
        Ok(Verdict {
            passed,
            ratio: if non_finite > 0 { f64::INFINITY } else { ratio },
            non_finite,
            checks,
            // Where to look, for a failure only (it costs a pass over the pixels).
            largest_difference: (!passed).then(|| pair.largest_difference()).flatten(),
        })
    }

    /// The checks of the tree, in tree order.
    pub fn checks(&self) -> Vec<(&Metric, f64)> {
        match self {
            Rule::All(rules) | Rule::Any(rules) => rules.iter().flat_map(Rule::checks).collect(),
            Rule::Check { metric, limit } => vec![(metric, *limit)],
        }
    }

    /// Evaluates the tree and returns its ratio (passes at <= 1), pushing every check.
    fn evaluate_with(
        &self,
        pair: &Pair,
        actual: &Image,
        golden: &Image,
        flip: &mut Option<Vec<f32>>,
        checks: &mut Vec<CheckResult>,
    ) -> Result<f64, MetricError> {
        match self {
            Rule::All(rules) => {
                let mut worst = 0.0f64;
                for rule in rules {
                    worst = worst.max(rule.evaluate_with(pair, actual, golden, flip, checks)?);
                }
                Ok(worst)
            }
            Rule::Any(rules) => {
                let mut best = f64::INFINITY;
                for rule in rules {
                    best = best.min(rule.evaluate_with(pair, actual, golden, flip, checks)?);
                }
                Ok(best)
            }
            Rule::Check { metric, limit } => {
                let value = metric_value(metric, pair, actual, golden, flip)?;
                let at_least = *metric == Metric::Psnr;
                let ratio = ratio(value, *limit, at_least);
                let pixels_over = matches!(metric, Metric::FractionOver { .. })
                    .then(|| (value * pair.pixels() as f64).round() as u64);
                checks.push(CheckResult {
                    metric: metric.to_string(),
                    value,
                    limit: *limit,
                    at_least,
                    passed: ratio <= 1.0,
                    pixels_over,
                });
                Ok(ratio)
            }
        }
    }
}

/// `value / limit` (`limit / value` for a lower bound); 0 when both are 0, infinite for NaN.
pub fn ratio(value: f64, limit: f64, at_least: bool) -> f64 {
    let (num, den) = if at_least {
        (limit, value)
    } else {
        (value, limit)
    };
    if num.is_nan() || den.is_nan() {
        f64::INFINITY
    } else if num <= 0.0 {
        0.0
    } else if den <= 0.0 {
        f64::INFINITY
    } else {
        num / den
    }
}

/// Measures one metric (the FLIP map is computed once per evaluation and shared).
pub fn metric_value(
    metric: &Metric,
    pair: &Pair,
    actual: &Image,
    golden: &Image,
    flip: &mut Option<Vec<f32>>,
) -> Result<f64, MetricError> {
    if pair.identical() {
        // Equal bit for bit: every error is exactly 0, which is what each metric below would
        // compute (FLIP of an image against itself included), without the cost.
        return Ok(match metric {
            Metric::Psnr => f64::INFINITY,
            Metric::FractionOver { threshold, .. } if *threshold < 0.0 => 1.0,
            _ => 0.0,
        });
    }
    if matches!(metric, Metric::FlipMean | Metric::FlipPercentile { .. }) && flip.is_none() {
        *flip = Some(Pair::flip_map(actual, golden)?);
    }
    let flip_map = flip.as_deref().unwrap_or(&[]);
    Ok(match metric {
        Metric::MaxAbs { shift, channels } => pair.max_abs(*shift, *channels),
        Metric::FractionOver {
            threshold,
            floor,
            shift,
            channels,
        } => pair.fraction_over(*threshold, *shift, *floor, *channels),
        Metric::Rmse => pair.rmse(),
        Metric::Psnr => pair.psnr(),
        Metric::Relative {
            percentile,
            floor,
            channels,
        } => pair.relative_percentile(*percentile, *floor, *channels),
        Metric::FlipMean => flip_mean(flip_map),
        Metric::FlipPercentile { percentile } => flip_stats(flip_map, *percentile).1,
    })
}

/// Reads a number that JSON wrote as `null` (serde_json writes infinities and NaN so) as
/// infinity.
pub(crate) fn null_as_infinity<'de, D: serde::Deserializer<'de>>(d: D) -> Result<f64, D::Error> {
    use serde::Deserialize;
    Ok(Option::<f64>::deserialize(d)?.unwrap_or(f64::INFINITY))
}

/// One metric measured against its limit.
#[derive(Clone, Debug, serde::Serialize, serde::Deserialize)]
pub struct CheckResult {
    /// Metric and parameters.
    pub metric: String,
    /// Measured value.
    #[serde(deserialize_with = "null_as_infinity")]
    pub value: f64,
    /// The limit.
    pub limit: f64,
    /// The value must be at least the limit (PSNR) rather than at most.
    pub at_least: bool,
    /// Whether it passed.
    pub passed: bool,
    /// For `fraction_over`: how many pixels are over the threshold.
    #[serde(default)]
    pub pixels_over: Option<u64>,
}

impl CheckResult {
    /// `value / limit` (`limit / value` for a lower bound): passes at <= 1.
    pub fn ratio(&self) -> f64 {
        ratio(self.value, self.limit, self.at_least)
    }
}

impl fmt::Display for CheckResult {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(
            f,
            "{} = {:.4e} ({} {:.4e}, {:.2}x) {}",
            self.metric,
            self.value,
            if self.at_least { "min" } else { "max" },
            self.limit,
            self.ratio(),
            if self.passed { "ok" } else { "FAILED" }
        )?;
        match self.pixels_over {
            Some(n) => write!(f, ", {n} px over"),
            None => Ok(()),
        }
    }
}

/// The outcome of a tolerance check.
#[derive(Clone, Debug, serde::Serialize, serde::Deserialize)]
pub struct Verdict {
    /// Whether the rule tree passed and the image is finite.
    pub passed: bool,
    /// How far from failing: passes at <= 1 (see the module docs); infinite with NaN/Inf.
    #[serde(deserialize_with = "null_as_infinity")]
    pub ratio: f64,
    /// NaN/Inf values in the actual image.
    pub non_finite: usize,
    /// Every metric evaluated, in tree order.
    pub checks: Vec<CheckResult>,
    /// For a failure: the largest difference and where it is.
    #[serde(default)]
    pub largest_difference: Option<crate::golden::metrics::LargestDifference>,
}

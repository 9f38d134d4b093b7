//! Tolerances: a small tree of rules over [`crate::metrics`], read from a scene file's
//! `[tolerances.<pass>]` table.
//!
//! A rule is a TOML table with exactly one of:
//! - `all = [rule, ...]`: passes when every rule passes;
//! - `any = [rule, ...]`: passes when some rule passes;
//! - `metric = "<name>"` with its limit (`max`, or `min` for `psnr`) and parameters:
//!
//! | metric | parameters | passes when |
//! |---|---|---|
//! | `max_abs` | `shift` (px, default 0) | largest channel difference <= `max` |
//! | `fraction_over` | `threshold`, `shift` | fraction of pixels over `threshold` <= `max` |
//! | `rmse` | | RMSE <= `max` |
//! | `psnr` | | PSNR >= `min` (dB) |
//! | `relative` | `percentile` (default 1), `floor` (default 1e-3) | that percentile of the relative error <= `max` |
//! | `flip_mean` | | mean FLIP error <= `max` (8-bit images) |
//! | `flip_percentile` | `percentile` | that percentile of FLIP <= `max` |
//!
//! 8-bit differences are in 0..1 units (one step is 1/255 = 0.00392). Any NaN or infinity in the
//! actual image fails every rule, whatever the tree says.

use std::fmt;

use engine::Image;

use crate::metrics::{flip_stats, MetricError, Pair};

/// A metric with its parameters.
#[derive(Clone, Debug, PartialEq)]
pub enum Metric {
    /// Largest channel difference.
    MaxAbs {
        /// Shift radius in pixels.
        shift: u32,
    },
    /// Fraction of pixels over a threshold.
    FractionOver {
        /// Per-channel difference that counts a pixel as over.
        threshold: f64,
        /// Shift radius in pixels.
        shift: u32,
    },
    /// Root-mean-square difference.
    Rmse,
    /// Peak signal-to-noise ratio (a lower bound).
    Psnr,
    /// Relative error percentile.
    Relative {
        /// Percentile, 0..1.
        percentile: f64,
        /// Denominator floor as a fraction of the golden's maximum.
        floor: f64,
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
        let shift = |s: &u32| {
            if *s > 0 {
                format!(", shift {s}px")
            } else {
                String::new()
            }
        };
        match self {
            Metric::MaxAbs { shift: s } => write!(f, "max_abs{}", shift(s)),
            Metric::FractionOver {
                threshold,
                shift: s,
            } => write!(f, "fraction_over({threshold:.4}{})", shift(s)),
            Metric::Rmse => write!(f, "rmse"),
            Metric::Psnr => write!(f, "psnr"),
            Metric::Relative { percentile, floor } => {
                write!(f, "relative(p{}, floor {floor})", percentile * 100.0)
            }
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

/// A rule that could not be read.
#[derive(Debug, thiserror::Error)]
#[error("tolerance `{path}`: {message}")]
pub struct RuleError {
    /// Where in the table (e.g. `final.all[1]`).
    pub path: String,
    /// What is wrong.
    pub message: String,
}

fn number(table: &toml::Table, key: &str, path: &str) -> Result<Option<f64>, RuleError> {
    match table.get(key) {
        None => Ok(None),
        Some(toml::Value::Float(v)) if v.is_finite() => Ok(Some(*v)),
        Some(toml::Value::Integer(v)) => Ok(Some(*v as f64)),
        Some(other) => Err(RuleError {
            path: path.to_owned(),
            message: format!("`{key}` must be a finite number, not {other}"),
        }),
    }
}

impl Rule {
    /// Reads a rule from its TOML table; `path` names it in errors.
    pub fn from_toml(value: &toml::Value, path: &str) -> Result<Rule, RuleError> {
        let err = |message: String| RuleError {
            path: path.to_owned(),
            message,
        };
        let table = value
            .as_table()
            .ok_or_else(|| err("a rule must be a table".to_owned()))?;
        for (key, kind) in [("all", 0), ("any", 1)] {
            if let Some(list) = table.get(key) {
                if table.len() != 1 {
                    return Err(err(format!("`{key}` cannot be mixed with other keys")));
                }
                let items = list
                    .as_array()
                    .ok_or_else(|| err(format!("`{key}` must be an array of rules")))?;
                if items.is_empty() {
                    return Err(err(format!("`{key}` is empty")));
                }
                let rules = items
                    .iter()
                    .enumerate()
                    .map(|(i, v)| Rule::from_toml(v, &format!("{path}.{key}[{i}]")))
                    .collect::<Result<Vec<_>, _>>()?;
                return Ok(if kind == 0 {
                    Rule::All(rules)
                } else {
                    Rule::Any(rules)
                });
            }
        }
        let name = table
            .get("metric")
            .and_then(|v| v.as_str())
            .ok_or_else(|| err("expected `all`, `any` or `metric = \"...\"`".to_owned()))?;
        let allowed: &[&str] = match name {
            "max_abs" => &["shift", "max"],
            "fraction_over" => &["threshold", "shift", "max"],
            "rmse" | "flip_mean" => &["max"],
            "psnr" => &["min"],
            "relative" => &["percentile", "floor", "max"],
            "flip_percentile" => &["percentile", "max"],
            other => {
                return Err(err(format!(
                    "unknown metric `{other}` (expected max_abs, fraction_over, rmse, psnr, \
                     relative, flip_mean or flip_percentile)"
                )))
            }
        };
        for key in table.keys() {
            if key != "metric" && !allowed.contains(&key.as_str()) {
                return Err(err(format!(
                    "unknown key `{key}` for metric `{name}` (allowed: {})",
                    allowed.join(", ")
                )));
            }
        }
        let shift = number(table, "shift", path)?.unwrap_or(0.0);
        if !(0.0..=8.0).contains(&shift) || shift.fract() != 0.0 {
            return Err(err(
                "`shift` must be a whole number of pixels, 0..8".to_owned()
            ));
        }
        let shift = shift as u32;
        let percentile = number(table, "percentile", path)?.unwrap_or(1.0);
        if !(0.0..=1.0).contains(&percentile) || percentile == 0.0 {
            return Err(err(
                "`percentile` must be in (0, 1] (0.999 = 99.9th)".to_owned()
            ));
        }
        let metric = match name {
            "max_abs" => Metric::MaxAbs { shift },
            "fraction_over" => Metric::FractionOver {
                threshold: number(table, "threshold", path)?
                    .ok_or_else(|| err("fraction_over needs `threshold`".to_owned()))?,
                shift,
            },
            "rmse" => Metric::Rmse,
            "psnr" => Metric::Psnr,
            "relative" => Metric::Relative {
                percentile,
                floor: number(table, "floor", path)?.unwrap_or(1e-3),
            },
            "flip_mean" => Metric::FlipMean,
            _ => Metric::FlipPercentile { percentile },
        };
        let limit_key = if metric == Metric::Psnr { "min" } else { "max" };
        let limit = number(table, limit_key, path)?
            .ok_or_else(|| err(format!("metric `{name}` needs `{limit_key}`")))?;
        Ok(Rule::Check { metric, limit })
    }

    /// Evaluates the rule on `actual` against `golden`.
    pub fn evaluate(&self, actual: &Image, golden: &Image) -> Result<Verdict, MetricError> {
        let pair = Pair::new(actual, golden)?;
        let mut flip = None;
        let mut checks = Vec::new();
        let passed = self.evaluate_with(&pair, actual, golden, &mut flip, &mut checks)?;
        let non_finite = pair.non_finite();
        Ok(Verdict {
            passed: passed && non_finite == 0,
            non_finite,
            checks,
        })
    }

    fn evaluate_with(
        &self,
        pair: &Pair,
        actual: &Image,
        golden: &Image,
        flip: &mut Option<Vec<f32>>,
        checks: &mut Vec<CheckResult>,
    ) -> Result<bool, MetricError> {
        match self {
            Rule::All(rules) => {
                let mut all = true;
                for rule in rules {
                    all &= rule.evaluate_with(pair, actual, golden, flip, checks)?;
                }
                Ok(all)
            }
            Rule::Any(rules) => {
                let mut any = false;
                for rule in rules {
                    any |= rule.evaluate_with(pair, actual, golden, flip, checks)?;
                }
                Ok(any)
            }
            Rule::Check { metric, limit } => {
                let mut flip_map = || -> Result<Vec<f32>, MetricError> {
                    if flip.is_none() {
                        *flip = Some(Pair::flip_map(actual, golden)?);
                    }
                    Ok(flip.clone().unwrap_or_default())
                };
                let value = match metric {
                    Metric::MaxAbs { shift } => pair.max_abs(*shift),
                    Metric::FractionOver { threshold, shift } => {
                        pair.fraction_over(*threshold, *shift)
                    }
                    Metric::Rmse => pair.rmse(),
                    Metric::Psnr => pair.psnr(),
                    Metric::Relative { percentile, floor } => {
                        pair.relative_percentile(*percentile, *floor)
                    }
                    Metric::FlipMean => flip_stats(&flip_map()?, 0.5).0,
                    Metric::FlipPercentile { percentile } => {
                        flip_stats(&flip_map()?, *percentile).1
                    }
                };
                let passed = if *metric == Metric::Psnr {
                    value >= *limit
                } else {
                    value <= *limit
                };
                checks.push(CheckResult {
                    metric: metric.to_string(),
                    value,
                    limit: *limit,
                    at_least: *metric == Metric::Psnr,
                    passed,
                });
                Ok(passed)
            }
        }
    }
}

/// One metric measured against its limit.
#[derive(Clone, Debug, serde::Serialize)]
pub struct CheckResult {
    /// Metric and parameters.
    pub metric: String,
    /// Measured value.
    pub value: f64,
    /// The limit.
    pub limit: f64,
    /// The value must be at least the limit (PSNR) rather than at most.
    pub at_least: bool,
    /// Whether it passed.
    pub passed: bool,
}

impl fmt::Display for CheckResult {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(
            f,
            "{} = {:.4e} ({} {:.4e}) {}",
            self.metric,
            self.value,
            if self.at_least { "min" } else { "max" },
            self.limit,
            if self.passed { "ok" } else { "FAILED" }
        )
    }
}

/// The outcome of a tolerance check.
#[derive(Clone, Debug, serde::Serialize)]
pub struct Verdict {
    /// Whether the rule tree passed and the image is finite.
    pub passed: bool,
    /// NaN/Inf values in the actual image.
    pub non_finite: usize,
    /// Every metric evaluated, in tree order.
    pub checks: Vec<CheckResult>,
}

#[cfg(test)]
mod tests {
    use super::*;
    use engine::backend::TextureFormat;
    use engine::ImageData;

    fn rule(text: &str) -> Result<Rule, RuleError> {
        let value: toml::Value = toml::from_str::<toml::Table>(text).unwrap().into();
        Rule::from_toml(&value, "final")
    }

    fn gray(values: &[u8]) -> Image {
        Image {
            width: values.len() as u32,
            height: 1,
            format: TextureFormat::Rgba8UnormSrgb,
            data: ImageData::U8(values.iter().flat_map(|&v| [v, v, v, 255]).collect()),
        }
    }

    #[test]
    fn all_and_any_combine_checks() {
        let golden = gray(&[10, 10, 10, 10]);
        let actual = gray(&[10, 10, 10, 30]);
        let strict = rule(
            r#"all = [{ metric = "max_abs", max = 0.01 }, { metric = "fraction_over", threshold = 0.01, max = 0.5 }]"#,
        )
        .unwrap();
        let verdict = strict.evaluate(&actual, &golden).unwrap();
        assert!(!verdict.passed);
        assert_eq!(verdict.checks.len(), 2);
        assert!(!verdict.checks[0].passed && verdict.checks[1].passed);
        let lenient = rule(
            r#"any = [{ metric = "max_abs", max = 0.01 }, { metric = "fraction_over", threshold = 0.01, max = 0.5 }]"#,
        )
        .unwrap();
        assert!(lenient.evaluate(&actual, &golden).unwrap().passed);
    }

    #[test]
    fn psnr_is_a_lower_bound() {
        let golden = gray(&[10, 10]);
        let actual = gray(&[10, 11]);
        assert!(
            rule(
                r#"metric = "psnr"
min = 40"#
            )
            .unwrap()
            .evaluate(&actual, &golden)
            .unwrap()
            .passed
        );
        assert!(
            !rule(
                r#"metric = "psnr"
min = 60"#
            )
            .unwrap()
            .evaluate(&actual, &golden)
            .unwrap()
            .passed
        );
    }

    #[test]
    fn bad_rules_are_named() {
        let e = rule(r#"metric = "max_abs""#).unwrap_err();
        assert!(e.to_string().contains("needs `max`"), "{e}");
        let e = rule(r#"metric = "fliip""#).unwrap_err();
        assert!(e.to_string().contains("unknown metric `fliip`"), "{e}");
        let e = rule(
            r#"metric = "rmse"
max = 1
shift = 1"#,
        )
        .unwrap_err();
        assert!(e.to_string().contains("unknown key `shift`"), "{e}");
        let e = rule(r#"all = [{ metric = "rmse" }]"#).unwrap_err();
        assert!(e.to_string().contains("final.all[0]"), "{e}");
    }
}

//! Reading a tolerance rule from its TOML table (the format is in the parent module's docs),
//! with errors that name where in the table a rule is wrong.

use super::{Metric, Rule};
use crate::golden::metrics::Channels;

/// A rule that could not be read.
#[derive(Debug, thiserror::Error)]
#[error("tolerance `{path}`: {message}")]
pub struct RuleError {
    /// Where in the table (e.g. `final.all[1]`).
    pub path: String,
    /// What is wrong.
    pub message: String,
}

/// The number under `key` (an integer or a finite float), `None` when absent.
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
            "max_abs" => &["shift", "channels", "max"],
            "fraction_over" => &["threshold", "floor", "shift", "channels", "max"],
            "rmse" | "flip_mean" => &["max"],
            "psnr" => &["min"],
            "relative" => &["percentile", "floor", "channels", "max"],
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
        let channels = match table.get("channels") {
            None => None,
            Some(toml::Value::String(c)) if c == "all" => Some(Channels::All),
            Some(toml::Value::String(c)) if c == "rgb" => Some(Channels::Rgb),
            Some(other) => {
                return Err(err(format!(
                    "`channels` must be \"all\" or \"rgb\", not {other}"
                )))
            }
        };
        let floor = number(table, "floor", path)?;
        if floor.is_some_and(|f| f <= 0.0) {
            return Err(err("`floor` must be positive".to_owned()));
        }
        let metric = match name {
            "max_abs" => Metric::MaxAbs {
                shift,
                channels: channels.unwrap_or_default(),
            },
            "fraction_over" => Metric::FractionOver {
                threshold: number(table, "threshold", path)?
                    .ok_or_else(|| err("fraction_over needs `threshold`".to_owned()))?,
                floor,
                shift,
                channels: channels.unwrap_or_default(),
            },
            "rmse" => Metric::Rmse,
            "psnr" => Metric::Psnr,
            "relative" => Metric::Relative {
                percentile,
                floor: floor.unwrap_or(1e-3),
                channels: channels.unwrap_or(Channels::Rgb),
            },
            "flip_mean" => Metric::FlipMean,
            _ => Metric::FlipPercentile { percentile },
        };
        let limit_key = if metric == Metric::Psnr { "min" } else { "max" };
        let limit = number(table, limit_key, path)?
            .ok_or_else(|| err(format!("metric `{name}` needs `{limit_key}`")))?;
        if limit_key == "max" && limit < 0.0 {
            return Err(err(format!(
                "`max` {limit} is negative: no render could pass (0 asks for no difference)"
            )));
        }
        // A fraction of pixels and a FLIP error lie in 0..1: a `max` of 1 or more lets every
        // render pass, a check that cannot fire.
        let fraction = matches!(
            metric,
            Metric::FractionOver { .. } | Metric::FlipMean | Metric::FlipPercentile { .. }
        );
        if fraction && limit >= 1.0 {
            return Err(err(format!(
                "`max` {limit} can never be exceeded: {name} lies in 0..1, so every render \
                 would pass (a limit below 1 checks something)"
            )));
        }
        if let Metric::FractionOver { threshold, .. } = metric {
            if threshold < 0.0 {
                return Err(err(format!(
                    "`threshold` {threshold} is negative: every pixel would count as over it"
                )));
            }
        }
        Ok(Rule::Check { metric, limit })
    }
}

impl Rule {
    /// Where a check of this rule can never fail on an 8-bit pass, whose values lie in 0..1 so
    /// that no difference exceeds 1: the first such check and why (a limit the values cannot
    /// reach passes every render, a check that cannot fire). None where each can fail.
    pub fn never_fails_on_eight_bit(&self) -> Option<String> {
        let (metric, limit) = match self {
            Rule::All(rules) | Rule::Any(rules) => {
                return rules.iter().find_map(Rule::never_fails_on_eight_bit)
            }
            Rule::Check { metric, limit } => (metric, *limit),
        };
        // The largest error a value can have: 1, or at most 1 / floor where it is relative (its
        // denominator, max(|golden|, floor), is at least the floor).
        let largest = |floor: Option<f64>| floor.map_or(1.0, |f| 1.0 / f);
        match *metric {
            Metric::MaxAbs { .. } | Metric::Rmse if limit >= 1.0 => Some(format!(
                "`max` {limit} can never be exceeded on an 8-bit pass, whose differences lie \
                 in 0..1"
            )),
            Metric::Psnr if limit <= 0.0 => Some(format!(
                "`min` {limit} can never be undercut on an 8-bit pass, whose PSNR is at least 0"
            )),
            Metric::FractionOver {
                threshold, floor, ..
            } if threshold >= largest(floor) => Some(format!(
                "`threshold` {} can never be exceeded on an 8-bit pass: no pixel's error there \
                 goes beyond {}",
                short(threshold),
                short(largest(floor))
            )),
            Metric::Relative { floor, .. } if limit >= largest(Some(floor)) => Some(format!(
                "`max` {} can never be exceeded on an 8-bit pass: with `floor` {} no relative \
                 error there goes beyond {}",
                short(limit),
                short(floor),
                short(largest(Some(floor)))
            )),
            _ => None,
        }
    }
}

/// `x` for a message: as written where it is of everyday size, else in scientific notation.
fn short(x: f64) -> String {
    if x != 0.0 && !(1e-3..1e6).contains(&x.abs()) {
        format!("{x:.3e}")
    } else {
        format!("{}", (x * 1e6).round() / 1e6)
    }
}

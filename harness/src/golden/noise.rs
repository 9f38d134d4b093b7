//! The noise model: how far an unchanged render moves from its golden under every source of
//! variation a user's machine can bring, and the golden tolerances derived from it.
//!
//! A golden check's limit is not a number that happened to pass on one machine. For every
//! canonical scene, golden pass and metric of the pass's rule, `harness noise` measures the
//! metric on unchanged renders under each source ([`crate::golden::portability`]): the three
//! backends, llvmpipe's other CPU
//! code paths (`GALLIUM_OVERRIDE_CPU_CAPS`, `LP_NATIVE_VECTOR_WIDTH`, `LP_NUM_THREADS`), a second
//! Mesa release (installed privately by `scripts/mesa-backports.sh`), synthetic host rounding, and
//! renders recorded on other hosts (`golden/evidence/<host>/`). `harness noise --write` records
//! every figure in `golden/noise.toml` with the limit derived from them:
//!
//! `limit = margin x max(largest measured noise, the metric's resolution)`
//!
//! The margin (3) leaves an unseen host room for three times the worst noise measured here. The
//! resolution keeps a limit from collapsing to zero where nothing moved: a fraction of pixels is
//! never resolved finer than [`RESOLUTION_PIXELS`] pixels, because no finite set of hosts rules out
//! a few edge pixels rounding the other way on the next one. The mutation self-test
//! ([`crate::golden::selftest`]) proves the limits from both sides: every measured source stays at or
//! below [`MAX_NOISE_RATIO`] of every limit, and every known change fails where it originates by
//! at least [`MIN_MUTATION_RATIO`].

use std::collections::BTreeMap;
use std::path::PathBuf;

use engine::plan::TargetId;

use crate::golden::pass_kind::pass_kind;
use crate::golden::tolerance::Metric;
use crate::golden::GoldenStore;

/// The model's file, in the golden folder.
pub const NOISE_FILE: &str = "noise.toml";
/// limit = margin x max(noise, resolution), for limits written by `harness noise --write`.
pub const DEFAULT_MARGIN: f64 = 3.0;
/// Unchanged renders under every measured source must stay at or below this fraction of every
/// limit (the self-test's noise bound; with a margin of 3 they sit at 1/3 or less).
pub const MAX_NOISE_RATIO: f64 = 0.5;
/// A known change must fail in the pass where it originates by at least this multiple of the
/// limit.
pub const MIN_MUTATION_RATIO: f64 = 3.0;
/// The resolution of a fraction-of-pixels metric, in pixels.
pub const RESOLUTION_PIXELS: f64 = 10.0;
/// The command that regenerates the model.
pub const REGENERATE: &str = "scripts/mesa-backports.sh && cargo run -p harness -- noise --write";

/// Why the noise model could not be read or written.
#[derive(Debug, thiserror::Error)]
pub enum NoiseError {
    /// The file could not be read.
    #[error("{path}: {message}")]
    File {
        /// The file.
        path: PathBuf,
        /// What went wrong.
        message: String,
    },
}

/// One check's recorded figures.
#[derive(Clone, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct CheckFigures {
    /// The limit derived from the figures below.
    pub limit: f64,
    /// The metric's resolution: the smallest noise figure a limit is derived from.
    pub resolution: f64,
    /// Largest value measured per source and backend (`<source>/<backend>`).
    pub noise: BTreeMap<String, f64>,
}

impl CheckFigures {
    /// The largest noise figure and where it was measured.
    pub fn worst(&self) -> (f64, &str) {
        self.noise.iter().fold(
            (0.0, "-"),
            |(w, at), (k, &v)| if v > w { (v, k) } else { (w, at) },
        )
    }
}

/// Checks per metric key, passes per name, scenes per name.
pub type SceneFigures = BTreeMap<String, BTreeMap<String, CheckFigures>>;

/// `golden/noise.toml`.
#[derive(Clone, Debug, Default, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct NoiseModel {
    /// limit = margin x max(noise, resolution).
    pub margin: f64,
    /// How to regenerate the file.
    pub regenerate: String,
    /// What each source was when measured: its description and driver fingerprints.
    #[serde(default)]
    pub sources: BTreeMap<String, String>,
    /// Known driver crashes that left a measurement out: `<source>/<backend>/<scene>` -> why.
    #[serde(default)]
    pub known_crashes: BTreeMap<String, String>,
    /// Figures per scene, pass and metric (the metric as the check tables print it).
    #[serde(default)]
    pub scenes: BTreeMap<String, SceneFigures>,
}

impl NoiseModel {
    /// The model in `store`'s folder; an empty model when the file does not exist.
    pub fn load(store: &GoldenStore) -> Result<NoiseModel, NoiseError> {
        let path = store.root().join(NOISE_FILE);
        if !path.exists() {
            return Ok(NoiseModel::default());
        }
        let text = std::fs::read_to_string(&path).map_err(|e| NoiseError::File {
            path: path.clone(),
            message: e.to_string(),
        })?;
        let model: NoiseModel = toml::from_str(&text).map_err(|e| NoiseError::File {
            path: path.clone(),
            message: e.to_string(),
        })?;
        model
            .problem()
            .map_or(Ok(model), |message| Err(NoiseError::File { path, message }))
    }

    /// The first figure that cannot be a limit or a measurement (a limit of NaN fails every
    /// check, one of infinity passes every one), named by its key.
    fn problem(&self) -> Option<String> {
        if !(self.margin.is_finite() && self.margin > 0.0) {
            return Some(format!(
                "margin {} must be finite and positive",
                self.margin
            ));
        }
        for (scene, passes) in &self.scenes {
            for (pass, checks) in passes {
                for (metric, figures) in checks {
                    let key = format!("scenes.{scene}.{pass}.\"{metric}\"");
                    if !(figures.limit.is_finite() && figures.limit > 0.0) {
                        return Some(format!(
                            "{key}: limit {} must be finite and positive",
                            figures.limit
                        ));
                    }
                    // A fraction of pixels and a FLIP error lie in 0..1: a limit of 1 or more
                    // passes every render, a check that cannot fire.
                    let fraction =
                        metric.starts_with("fraction_over") || metric.starts_with("flip");
                    if fraction && figures.limit >= 1.0 {
                        return Some(format!(
                            "{key}: limit {} can never be exceeded: the metric lies in 0..1",
                            figures.limit
                        ));
                    }
                    let values = std::iter::once(("resolution", &figures.resolution))
                        .chain(figures.noise.iter().map(|(k, v)| (k.as_str(), v)));
                    for (name, value) in values {
                        if !(value.is_finite() && *value >= 0.0) {
                            return Some(format!(
                                "{key}: {name} {value} must be finite and not negative"
                            ));
                        }
                    }
                }
            }
        }
        None
    }

    /// Writes the model atomically into `store`'s folder.
    pub fn save(&self, store: &GoldenStore) -> Result<PathBuf, NoiseError> {
        let path = store.root().join(NOISE_FILE);
        let text = toml::to_string_pretty(self).map_err(|e| NoiseError::File {
            path: path.clone(),
            message: e.to_string(),
        })?;
        let header = "# The noise model of the golden suite, written by `harness noise --write`.\n\
             # For every scene, golden pass and metric: the largest value measured on unchanged\n\
             # renders per source and backend, the metric's resolution, and the limit the suite\n\
             # uses: margin x max(largest noise, resolution). See harness/src/golden/noise.rs and\n\
             # docs/goldens.md.\n\n";
        crate::images::write_atomically(&path, format!("{header}{text}").as_bytes()).map_err(
            |e| NoiseError::File {
                path: path.clone(),
                message: e.to_string(),
            },
        )?;
        Ok(path)
    }

    /// The recorded figures of one check.
    pub fn figures(&self, scene: &str, pass: TargetId, metric: &str) -> Option<&CheckFigures> {
        self.scenes.get(scene)?.get(&pass.to_string())?.get(metric)
    }

    /// The largest limit any scene has for this kind of pass and metric: what a scene without
    /// figures of its own borrows, for a pass of `pixels` pixels. Each limit is borrowed as the
    /// same multiple of the metric's [`resolution`] at the borrowing pass's size: a limit on a
    /// fraction of pixels keeps its number of pixels (a 256x256 scene's 30 pixels are 30 of a
    /// 512x512 image, not the same fraction's 120); the other metrics' resolutions do not
    /// depend on the size, so their limits are borrowed as they are.
    pub fn borrowed_limit(&self, pass: TargetId, metric: &Metric, pixels: usize) -> Option<f64> {
        let kind = pass_kind(pass)?;
        let key = metric.to_string();
        let here = resolution(metric, pixels);
        self.scenes
            .values()
            .flat_map(|passes| passes.iter())
            // The file's keys are names (an edge); one that names no target is no pass.
            .filter(|(p, _)| p.parse().ok().and_then(pass_kind) == Some(kind))
            .filter_map(|(_, checks)| checks.get(&key))
            .map(|f| {
                if f.resolution > 0.0 {
                    f.limit * (here / f.resolution)
                } else {
                    f.limit
                }
            })
            .fold(None, |m: Option<f64>, l| Some(m.map_or(l, |m| m.max(l))))
    }
}

/// The smallest noise figure a metric's limit is derived from (see the module docs): for a
/// fraction of pixels, [`RESOLUTION_PIXELS`] of the image; for FLIP, 1e-3 (a tenth of what ±1 LSB
/// of rounding gives); otherwise one f32 step relative to 1.
pub fn resolution(metric: &Metric, pixels: usize) -> f64 {
    match metric {
        Metric::FractionOver { .. } => RESOLUTION_PIXELS / pixels.max(1) as f64,
        Metric::FlipMean | Metric::FlipPercentile { .. } => 1e-3,
        Metric::MaxAbs { .. } | Metric::Rmse | Metric::Psnr | Metric::Relative { .. } => {
            f64::from(f32::EPSILON)
        }
    }
}

/// Rounds a limit up to three significant digits, so the file reads cleanly and the limit is
/// never below margin x noise.
pub fn round_up(x: f64) -> f64 {
    if x <= 0.0 || !x.is_finite() {
        return x;
    }
    let scale = 10f64.powi(2 - x.log10().floor() as i32);
    (x * scale).ceil() / scale
}

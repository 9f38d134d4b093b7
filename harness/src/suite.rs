//! The golden suite: which scenes and passes are checked, with which tolerances, and what is
//! written when a check fails. Shared by the `cargo test` target (`tests/golden.rs`), `harness
//! check` and `harness bless`.

use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

use engine::backend::{self, BackendKind};
use engine::plan::RenderPlan;
use engine::renderer::{self, Frame, Readback};
use engine::scene_file::LoadedScene;
use engine::Image;

use crate::golden::{self, GoldenStore, Outcome, GOLDEN_PASSES};
use crate::images;
use crate::tolerance::{Metric, Rule, RuleError};

/// The backend goldens are blessed from by default (the others are checked against them).
pub const REFERENCE_BACKEND: BackendKind = BackendKind::Gl;

/// Why the suite could not be set up.
#[derive(Debug, thiserror::Error)]
pub enum SuiteError {
    /// A scene failed to load.
    #[error(transparent)]
    Scene(#[from] engine::scene_file::SceneFileError),
    /// A tolerance in a scene file is malformed.
    #[error("{path}: [tolerances]: {source}")]
    Tolerance {
        /// Scene file.
        path: PathBuf,
        /// The rule error.
        source: RuleError,
    },
    /// `[tolerances]` names a pass the scene has no golden for.
    #[error(
        "{path}: [tolerances.{pass}]: the scene has no golden pass `{pass}` (it has: {known})"
    )]
    UnknownPass {
        /// Scene file.
        path: PathBuf,
        /// The key.
        pass: String,
        /// Golden passes of the scene.
        known: String,
    },
}

/// One scene of the suite with its golden passes and their rules.
pub struct Case {
    /// The loaded scene.
    pub loaded: LoadedScene,
    /// Golden passes, in plan order.
    pub passes: Vec<String>,
    /// Rule per golden pass.
    pub rules: BTreeMap<String, Rule>,
}

impl Case {
    /// Loads a scene (canonical name or path) and its tolerances.
    pub fn load(name_or_path: &str) -> Result<Case, SuiteError> {
        let loaded = crate::load_scene(name_or_path)?;
        let plan = RenderPlan::new(&loaded.scene);
        let passes: Vec<String> = plan
            .target_names()
            .into_iter()
            .filter(|t| GOLDEN_PASSES.contains(t) || t.starts_with("shadow_"))
            .map(str::to_owned)
            .collect();
        let mut rules = BTreeMap::new();
        for (pass, value) in &loaded.tolerances {
            if !passes.contains(pass) {
                return Err(SuiteError::UnknownPass {
                    path: loaded.path.clone(),
                    pass: pass.clone(),
                    known: passes.join(", "),
                });
            }
            let rule = Rule::from_toml(value, pass).map_err(|source| SuiteError::Tolerance {
                path: loaded.path.clone(),
                source,
            })?;
            rules.insert(pass.clone(), rule);
        }
        for pass in &passes {
            rules
                .entry(pass.clone())
                .or_insert_with(|| default_rule(pass));
        }
        Ok(Case {
            loaded,
            passes,
            rules,
        })
    }

    /// Scene name.
    pub fn name(&self) -> &str {
        &self.loaded.scene.name
    }

    /// Renders the golden passes on a new backend of this kind.
    pub fn render(&self, kind: BackendKind) -> Result<Frame, String> {
        let mut backend = backend::create(kind).map_err(|e| e.to_string())?;
        self.render_on(backend.as_mut())
    }

    /// Renders the golden passes on a given backend.
    pub fn render_on(&self, backend: &mut dyn backend::Backend) -> Result<Frame, String> {
        let wanted: Vec<&str> = self.passes.iter().map(String::as_str).collect();
        renderer::render(backend, &self.loaded.scene, Readback::Only(&wanted))
            .map_err(|e| e.to_string())
    }
}

/// Every canonical scene (the `.toml` files directly in `scenes/`).
pub fn canonical_cases() -> Result<Vec<Case>, SuiteError> {
    engine::scene_file::canonical_scenes(&crate::scenes_dir())
        .iter()
        .map(|name| Case::load(name))
        .collect()
}

fn check(metric: Metric, limit: f64) -> Rule {
    Rule::Check { metric, limit }
}

/// The tolerance a pass gets when its scene file gives none. Tight enough that the mutation
/// self-test catches every listed change, loose enough for llvmpipe vs lavapipe (measured; see
/// the README's tolerance table).
pub fn default_rule(pass: &str) -> Rule {
    const STEP: f64 = 1.0 / 255.0;
    match pass {
        // 1e-4 of the pixels is 26 at 512x512: 4x the llvmpipe/lavapipe disagreement measured on
        // chess (6 pixels), 2.5x under the smallest mutation the self-test must catch (shadow
        // bias x4 on chess, 65 pixels).
        "final" => Rule::All(vec![
            check(
                Metric::FractionOver {
                    threshold: 2.0 * STEP,
                    shift: 0,
                },
                1e-4,
            ),
            check(Metric::FlipMean, 0.002),
        ]),
        "mask" | "mask_1" => check(
            Metric::FractionOver {
                threshold: 0.5,
                shift: 0,
            },
            0.001,
        ),
        p if p == "depth" || p.starts_with("shadow_") => check(
            Metric::Relative {
                percentile: 0.999,
                floor: 1e-3,
            },
            1e-5,
        ),
        "light" => Rule::All(vec![
            check(
                Metric::Relative {
                    percentile: 0.5,
                    floor: 1e-3,
                },
                2e-3,
            ),
            check(
                Metric::Relative {
                    percentile: 0.99,
                    floor: 1e-3,
                },
                0.02,
            ),
        ]),
        _ => check(
            Metric::FractionOver {
                threshold: 0.01,
                shift: 0,
            },
            0.002,
        ),
    }
}

/// Files written for a failed (or missing) check, to look at.
#[derive(Clone, Debug, Default, serde::Serialize)]
pub struct Artifacts {
    /// The rendered output.
    pub actual: Option<PathBuf>,
    /// A copy of the golden, as PNG for viewing.
    pub golden: Option<PathBuf>,
    /// Difference heatmap.
    pub diff: Option<PathBuf>,
}

/// Outcome of one scene x pass x backend.
#[derive(Clone, Debug, serde::Serialize)]
pub struct PassCheck {
    /// Scene.
    pub scene: String,
    /// Pass.
    pub pass: String,
    /// Backend.
    pub backend: String,
    /// Result.
    pub outcome: Outcome,
    /// The golden file compared with (or missing).
    pub golden_path: PathBuf,
    /// Files written.
    pub artifacts: Artifacts,
}

/// The `harness bless` command line that would bless this pass.
pub fn bless_command(scene: &str, pass: &str) -> String {
    format!("cargo run --release -p harness -- bless --scene {scene} --pass {pass}")
}

impl PassCheck {
    /// A multi-line explanation for test output.
    pub fn message(&self) -> String {
        let golden = &self.golden_path;
        let mut lines = vec![format!("{}::{}::{}", self.scene, self.pass, self.backend)];
        match &self.outcome {
            Outcome::Passed(v) | Outcome::Failed(v) => {
                if v.non_finite > 0 {
                    lines.push(format!("  {} NaN/Inf values in the output", v.non_finite));
                }
                for c in &v.checks {
                    lines.push(format!("  {c}"));
                }
            }
            Outcome::MissingGolden => lines.push(format!(
                "  no golden at {}; after checking the output, bless it with:\n    {}\n  (or UPDATE_GOLDENS=1 cargo test)",
                golden.display(),
                bless_command(&self.scene, &self.pass)
            )),
            Outcome::Incomparable(why) => lines.push(format!(
                "  cannot compare with {}: {why}\n  if the change is intended, bless with: {}",
                golden.display(),
                bless_command(&self.scene, &self.pass)
            )),
        }
        for (label, path) in [
            ("actual", &self.artifacts.actual),
            ("golden", &self.artifacts.golden),
            ("diff", &self.artifacts.diff),
        ] {
            if let Some(path) = path {
                lines.push(format!("  {label:<6} {}", path.display()));
            }
        }
        lines.join("\n")
    }
}

/// Where failure artifacts go: `target/harness/failures/<scene>/<backend>/`.
pub fn artifacts_dir(scene: &str, backend: &str) -> PathBuf {
    crate::workspace_root()
        .join("target/harness/failures")
        .join(scene)
        .join(backend)
}

/// Checks one pass output against its golden; writes artifacts when it does not pass.
pub fn check_pass(
    store: &GoldenStore,
    case: &Case,
    pass: &str,
    backend: BackendKind,
    actual: &Image,
) -> PassCheck {
    let eight_bit = golden::is_eight_bit(actual);
    let scene = case.name();
    let (golden_image, outcome) = match store.load(scene, pass, eight_bit) {
        Ok(golden_image) => {
            let rule = &case.rules[pass];
            let outcome = golden::check(actual, golden_image.as_ref(), rule);
            (golden_image, outcome)
        }
        Err(e) => (None, Outcome::Incomparable(e.to_string())),
    };
    let mut artifacts = Artifacts::default();
    if !outcome.passed() {
        let dir = artifacts_dir(scene, backend.name());
        artifacts = write_artifacts(&dir, pass, actual, golden_image.as_ref());
    }
    PassCheck {
        scene: scene.to_owned(),
        pass: pass.to_owned(),
        backend: backend.name().to_owned(),
        outcome,
        golden_path: store.path(scene, pass, eight_bit),
        artifacts,
    }
}

/// Writes actual, golden (as PNG) and diff heatmap for a pass into `dir`.
pub fn write_artifacts(
    dir: &Path,
    pass: &str,
    actual: &Image,
    golden: Option<&Image>,
) -> Artifacts {
    let mut artifacts = Artifacts::default();
    let extension = if golden::is_eight_bit(actual) {
        "png"
    } else {
        "exr"
    };
    let actual_path = dir.join(format!("{pass}_actual.{extension}"));
    if images::write_image(actual, &actual_path).is_ok() {
        artifacts.actual = Some(actual_path);
    }
    if let Some(golden) = golden {
        let golden_path = dir.join(format!("{pass}_golden.png"));
        if images::write_image(golden, &golden_path).is_ok() {
            artifacts.golden = Some(golden_path);
        }
        let scale = if golden::is_eight_bit(actual) {
            16.0 / 255.0
        } else {
            0.05
        };
        if let Some(diff) = golden::diff_heatmap(actual, golden, scale) {
            let diff_path = dir.join(format!("{pass}_diff.png"));
            if images::write_image(&diff, &diff_path).is_ok() {
                artifacts.diff = Some(diff_path);
            }
        }
    }
    artifacts
}

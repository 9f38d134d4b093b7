//! The golden suite: which scenes and passes are checked, with which tolerances, and what is
//! written when a check fails. Shared by the `cargo test` target (`tests/golden.rs`), `harness
//! check` and `harness bless`.

use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

use engine::backend::TextureFormat;
use engine::backend::{self, BackendKind};
use engine::plan::{TargetId, TargetSpec};
use engine::renderer::{self, Frame, PreparedFrame, Readback, RenderError};
use engine::scene_file::LoadedScene;
use engine::Image;

use crate::golden::command_line::bless_command;
use crate::golden::noise::{NoiseError, NoiseModel};
use crate::golden::pass_kind::{pass_kind, rule_shape};
use crate::golden::tolerance::{Rule, RuleError};
use crate::golden::{self, GoldenStore, Outcome};
use crate::images::{self, FileCompression};

/// The backend goldens are blessed from by default (the others are checked against them).
pub const REFERENCE_BACKEND: BackendKind = BackendKind::Gl;

/// The backend that stands for `backends` where one must: the reference backend when it is
/// among them, else the first (None when there are none).
pub fn reference_among(backends: &[BackendKind]) -> Option<BackendKind> {
    backends
        .iter()
        .copied()
        .find(|&k| k == REFERENCE_BACKEND)
        .or(backends.first().copied())
}

/// Why the suite could not be set up.
#[derive(Debug, thiserror::Error)]
pub enum SuiteError {
    /// A scene failed to load.
    #[error(transparent)]
    Scene(#[from] engine::scene_file::SceneFileError),
    /// A scene loaded but cannot be drawn (the renderer's validation refused it).
    #[error("{path}: {source}")]
    Unrenderable {
        /// Scene file.
        path: PathBuf,
        /// Why.
        source: Box<RenderError>,
    },
    /// The noise model (golden/noise.toml) cannot be read.
    #[error(transparent)]
    Noise(#[from] NoiseError),
    /// A tolerance in a scene file is malformed.
    #[error("{path}: [tolerances]: {source}")]
    Tolerance {
        /// Scene file.
        path: PathBuf,
        /// The rule error.
        source: RuleError,
    },
    /// The scene's name is one golden/ keeps for itself (`evidence`, `noise.toml`, ...): its
    /// goldens would be written among those files, and a prune would remove them.
    #[error(
        "{path}: the scene is named `{name}`, which golden/ keeps for itself (golden/{name} \
         holds no scene's goldens): give the scene another name (`name = \"...\"` in the file, \
         or rename the file)"
    )]
    ReservedName {
        /// Scene file.
        path: PathBuf,
        /// The name.
        name: String,
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
    /// `[tolerances]` gives a float pass a FLIP metric, which compares 8-bit images only.
    #[error(
        "{path}: [tolerances.{pass}]: `{metric}` compares 8-bit images, and `{pass}` is a float \
         pass: use max_abs, fraction_over, rmse, psnr or relative"
    )]
    FlipOnFloatPass {
        /// Scene file.
        path: PathBuf,
        /// The pass.
        pass: TargetId,
        /// The FLIP metric named.
        metric: String,
    },
}

/// Where a pass's limits came from.
#[derive(Clone, Debug, PartialEq, serde::Serialize)]
pub enum LimitSource {
    /// The scene file's `[tolerances.<pass>]`.
    SceneFile,
    /// The scene's own figures in `golden/noise.toml`.
    NoiseModel,
    /// No figures for this scene: the largest limit of the same kind of pass in other scenes.
    Borrowed,
    /// No figures at all: the rule shape's fallback.
    Fallback,
}

/// One scene of the suite with its golden passes and their rules.
pub struct Case {
    /// The loaded scene (with its shadow terms turned on: they are golden outputs).
    pub loaded: LoadedScene,
    /// The scene as drawn and its plan: every golden pass comes from here, so an extracted
    /// sun's shadow map and shadow term are golden passes too.
    pub frame: PreparedFrame,
    /// Golden passes, in plan order.
    pub passes: Vec<TargetId>,
    /// Rule per golden pass.
    pub rules: BTreeMap<TargetId, Rule>,
    /// Where each pass's limits came from.
    pub limit_sources: BTreeMap<TargetId, LimitSource>,
    /// The files it was loaded from, digested right after the load, and the load's warnings.
    pub inputs: crate::golden::scene_inputs::SceneInputs,
    /// Size and format per pass output.
    targets: BTreeMap<TargetId, TargetSpec>,
}

impl Case {
    /// Loads a scene (canonical name or path), its tolerances, and the limits of the workspace's
    /// noise model.
    pub fn load(name_or_path: &str) -> Result<Case, SuiteError> {
        let model = NoiseModel::load(&GoldenStore::workspace())?;
        Case::load_with(name_or_path, &model)
    }

    /// [`Case::load`] with the limits of `model`.
    pub fn load_with(name_or_path: &str, model: &NoiseModel) -> Result<Case, SuiteError> {
        Case::from_loaded(crate::load_scene(name_or_path)?, model)
    }

    /// [`Case::load_with`] of a scene already loaded.
    pub fn from_loaded(mut loaded: LoadedScene, model: &NoiseModel) -> Result<Case, SuiteError> {
        if crate::golden::orphans::TOP_LEVEL.contains(&loaded.scene.name.as_str()) {
            return Err(SuiteError::ReservedName {
                path: loaded.path.clone(),
                name: loaded.scene.name.clone(),
            });
        }
        let inputs = crate::golden::scene_inputs::SceneInputs::of(&loaded);
        // A shadowed light's shadow term is where a shadow change first shows: golden renders
        // read it back (a full-screen pass per shadowed light).
        loaded.scene.quality.debug_shadow_terms = true;
        let frame =
            PreparedFrame::new(&loaded.scene).map_err(|source| SuiteError::Unrenderable {
                path: loaded.path.clone(),
                source: Box::new(source),
            })?;
        let plan = frame.plan();
        let passes: Vec<TargetId> = plan
            .target_ids()
            .into_iter()
            .filter(|t| pass_kind(*t).is_some())
            .collect();
        let targets: BTreeMap<TargetId, TargetSpec> = passes
            .iter()
            .filter_map(|p| Some((*p, plan.target(*p)?.clone())))
            .collect();
        let mut rules = BTreeMap::new();
        let mut limit_sources = BTreeMap::new();
        for (name, value) in &loaded.tolerances {
            let Some(pass) = name.parse().ok().filter(|p| passes.contains(p)) else {
                return Err(SuiteError::UnknownPass {
                    path: loaded.path.clone(),
                    pass: name.clone(),
                    known: crate::names(&passes),
                });
            };
            let rule = Rule::from_toml(value, name).map_err(|source| SuiteError::Tolerance {
                path: loaded.path.clone(),
                source,
            })?;
            let eight_bit_pass = targets.get(&pass).is_some_and(eight_bit);
            if let Some(message) = rule.never_fails_on_eight_bit().filter(|_| eight_bit_pass) {
                return Err(SuiteError::Tolerance {
                    path: loaded.path.clone(),
                    source: crate::golden::tolerance::RuleError {
                        path: name.clone(),
                        message,
                    },
                });
            }
            if let Some(metric) = rule.flip_metric() {
                if !eight_bit_pass {
                    return Err(SuiteError::FlipOnFloatPass {
                        path: loaded.path.clone(),
                        pass,
                        metric: metric.to_string(),
                    });
                }
            }
            rules.insert(pass, rule);
            limit_sources.insert(pass, LimitSource::SceneFile);
        }
        let scene = loaded.scene.name.clone();
        let pass_pixels = |pass| {
            targets
                .get(&pass)
                .map_or(0, |t| t.width as usize * t.height as usize)
        };
        for &pass in &passes {
            if rules.contains_key(&pass) {
                continue;
            }
            let kind = pass_kind(pass).expect("golden passes have a kind");
            let mut source = LimitSource::NoiseModel;
            let checks = rule_shape(kind)
                .into_iter()
                .map(|(metric, fallback)| {
                    let key = metric.to_string();
                    let limit = match model.figures(&scene, pass, &key) {
                        Some(figures) => figures.limit,
                        None => match model.borrowed_limit(pass, &metric, pass_pixels(pass)) {
                            Some(limit) => {
                                source = LimitSource::Borrowed;
                                limit
                            }
                            None => {
                                source = LimitSource::Fallback;
                                fallback
                            }
                        },
                    };
                    Rule::Check { metric, limit }
                })
                .collect();
            rules.insert(pass, Rule::All(checks));
            limit_sources.insert(pass, source);
        }
        Ok(Case {
            loaded,
            frame,
            passes,
            rules,
            limit_sources,
            inputs,
            targets,
        })
    }

    /// Scene name.
    pub fn name(&self) -> &str {
        &self.loaded.scene.name
    }

    /// How to name this scene on the command line: its file stem when it lives in scenes/ (so
    /// `--scene arrow` finds it again), otherwise the path it was loaded from.
    pub fn argument(&self) -> String {
        scene_argument(&self.loaded.path)
    }

    /// The target a golden pass renders to (None for a pass the scene does not have).
    pub fn target(&self, pass: TargetId) -> Option<&TargetSpec> {
        self.targets.get(&pass)
    }

    /// Pixels of a pass's output (0 for an unknown pass).
    pub fn pixels(&self, pass: TargetId) -> usize {
        self.targets
            .get(&pass)
            .map_or(0, |t| t.width as usize * t.height as usize)
    }

    /// Whether a pass's output is 8-bit (its golden a PNG).
    pub fn is_eight_bit(&self, pass: TargetId) -> bool {
        self.targets.get(&pass).is_some_and(eight_bit)
    }

    /// Renders the golden passes on a new backend of this kind.
    pub fn render(&self, kind: BackendKind) -> Result<Frame, RenderError> {
        let mut backend =
            crate::faults::create_backend(kind).map_err(|source| RenderError::Backend {
                scene: self.name().to_owned(),
                source,
            })?;
        self.render_on(backend.as_mut())
    }

    /// Renders the golden passes on a given backend.
    pub fn render_on(&self, backend: &mut dyn backend::Backend) -> Result<Frame, RenderError> {
        let readback = Readback::Only(&self.passes);
        renderer::render_prepared(backend, &self.frame, readback)
    }
}

/// Whether a target is 8-bit (its golden a PNG, FLIP applicable).
fn eight_bit(target: &TargetSpec) -> bool {
    matches!(
        target.format,
        TextureFormat::Rgba8Unorm | TextureFormat::Rgba8UnormSrgb
    )
}

/// A canonical scene that did not load: one failed case of the run, which goes on with the
/// others.
#[derive(Clone, Debug, serde::Serialize, serde::Deserialize)]
pub struct BrokenScene {
    /// The scene's name (its file stem).
    pub scene: String,
    /// Why it did not load, each cause once.
    pub error: String,
}

/// Every canonical scene that loads, and every one that does not with its error: one broken
/// scene file is one failed case, not the end of the run. Fails only when the noise model
/// (shared by every scene) cannot be read.
pub fn canonical_suite() -> Result<(Vec<Case>, Vec<BrokenScene>), SuiteError> {
    load_suite(&engine::scene_file::canonical_scenes(&crate::scenes_dir()))
}

/// [`canonical_suite`] for the scenes named (canonical names or scene files).
pub fn load_suite(names: &[String]) -> Result<(Vec<Case>, Vec<BrokenScene>), SuiteError> {
    let model = NoiseModel::load(&GoldenStore::workspace())?;
    let mut cases = Vec::new();
    let mut broken = Vec::new();
    for name in names {
        match Case::load_with(name, &model) {
            Ok(case) => cases.push(case),
            Err(e) => broken.push(BrokenScene {
                scene: name.clone(),
                error: crate::error_text(&e),
            }),
        }
    }
    Ok((cases, broken))
}

/// Every canonical scene (the `.toml` files directly in `scenes/`), or the first error (for
/// callers that need them all).
pub fn canonical_cases() -> Result<Vec<Case>, SuiteError> {
    let model = NoiseModel::load(&GoldenStore::workspace())?;
    engine::scene_file::canonical_scenes(&crate::scenes_dir())
        .iter()
        .map(|name| Case::load_with(name, &model))
        .collect()
}

/// Files written for a failed (or missing) check, to look at.
#[derive(Clone, Debug, Default, serde::Serialize, serde::Deserialize)]
pub struct Artifacts {
    /// The rendered output.
    pub actual: Option<PathBuf>,
    /// A copy of the golden, as PNG for viewing.
    pub golden: Option<PathBuf>,
    /// Difference heatmap.
    pub diff: Option<PathBuf>,
}

/// Outcome of one scene x pass x backend.
#[derive(Clone, Debug, serde::Serialize, serde::Deserialize)]
pub struct PassCheck {
    /// Scene.
    pub scene: String,
    /// The scene as the command line names it ([`Case::argument`]).
    pub scene_argument: String,
    /// Pass.
    pub pass: TargetId,
    /// Backend.
    pub backend: BackendKind,
    /// Result.
    pub outcome: Outcome,
    /// The golden file compared with (or missing).
    pub golden_path: PathBuf,
    /// Files written.
    pub artifacts: Artifacts,
    /// The rule's per-pixel criterion, which scales the review page's false-colour diff.
    #[serde(default)]
    pub criterion: Option<crate::golden::tolerance::PixelCriterion>,
    /// The SHA-256 of the golden file a failing pass was compared with (None where it passed
    /// or had none): an accept reads it to tell whether the golden changed since, by content,
    /// which a checkout on another machine, newer than the check, keeps.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub golden_digest: Option<String>,
}

/// How to name the scene file at `path` on the command line: its file stem when it lives in
/// scenes/, otherwise the path (as given: what a user typed, matched again by `--from-last-check
/// --scene`, and relative in a CI job's last-check.json reviewed in another checkout).
pub fn scene_argument(path: &Path) -> String {
    let in_scenes_dir = path
        .parent()
        .and_then(|dir| dir.canonicalize().ok())
        .zip(crate::scenes_dir().canonicalize().ok())
        .is_some_and(|(dir, scenes)| dir == scenes);
    match path.file_stem().and_then(|s| s.to_str()) {
        Some(stem) if in_scenes_dir => stem.to_owned(),
        _ => path.display().to_string(),
    }
}

impl PassCheck {
    /// One line: the check closest to (or furthest past) its limit and, for a failure, where
    /// the largest difference is; or why there was nothing to compare. The check table's last
    /// column, and the message of a JUnit test case.
    pub fn worst(&self) -> String {
        match &self.outcome {
            Outcome::Passed(v) | Outcome::Failed(v) => {
                v.checks
                    .iter()
                    .max_by(|a, b| a.ratio().total_cmp(&b.ratio()))
                    .map(ToString::to_string)
                    .unwrap_or_default()
                    + &v.largest_difference
                        .map(|l| format!("; {l}"))
                        .unwrap_or_default()
            }
            Outcome::MissingGolden => format!("no golden at {}", self.golden_path.display()),
            Outcome::Incomparable(why) => why.clone(),
        }
    }

    /// A multi-line explanation for test output.
    pub fn message(&self) -> String {
        let golden = &self.golden_path;
        let mut lines = vec![format!(
            "{}::{}::{} {}",
            self.scene,
            self.pass,
            self.backend,
            self.outcome.label()
        )];
        match &self.outcome {
            Outcome::Passed(v) | Outcome::Failed(v) => {
                if v.non_finite > 0 {
                    lines.push(format!("  {} NaN/Inf values in the output", v.non_finite));
                }
                for c in &v.checks {
                    lines.push(format!("  {c}"));
                }
                if let Some(largest) = &v.largest_difference {
                    lines.push(format!("  {largest}"));
                }
                if !v.passed {
                    lines.push(format!(
                        "  if the change is intended, bless the scene's changed passes with:\n    {}",
                        bless_command(&self.scene_argument)
                    ));
                }
            }
            Outcome::MissingGolden => lines.push(format!(
                "  no golden at {}; after checking the output, bless the scene's new and changed \
                 passes with:\n    {}\n  (or UPDATE_GOLDENS=1 cargo test)",
                golden.display(),
                bless_command(&self.scene_argument)
            )),
            Outcome::Incomparable(why) => lines.push(format!(
                "  cannot compare with {}: {why}\n  if the change is intended, bless with: {}",
                golden.display(),
                bless_command(&self.scene_argument)
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

/// Where failure artifacts go by default (`harness check` writes `<out>/failures`):
/// `target/harness/failures`.
pub fn default_failures_dir() -> PathBuf {
    crate::workspace_root().join("target/harness/failures")
}

/// Where one scene's failure artifacts on one backend go: `<failures>/<scene>/<backend>/`.
pub fn artifacts_dir(failures: &Path, scene: &str, backend: &str) -> PathBuf {
    failures.join(scene).join(backend)
}

/// Removes a scene's failure artifacts from an earlier run (before this run writes its own), so
/// that what is there after a run is this run's. Other scenes' artifacts are left alone.
pub fn clear_artifacts(failures: &Path, scene: &str) {
    let dir = failures.join(scene);
    if let Err(e) = std::fs::remove_dir_all(&dir) {
        if e.kind() != std::io::ErrorKind::NotFound {
            log::warn!("cannot clear old failure images in {}: {e}", dir.display());
        }
    }
}

/// Checks one pass output against its golden; writes artifacts under `failures` when it does
/// not pass.
pub fn check_pass(
    store: &GoldenStore,
    case: &Case,
    pass: TargetId,
    backend: BackendKind,
    actual: &Image,
    failures: &Path,
) -> PassCheck {
    let eight_bit = golden::is_eight_bit(actual);
    let scene = case.name();
    let (golden_image, outcome) = match store.load(scene, pass, eight_bit) {
        Ok(golden_image) => {
            let rule = &case.rules[&pass];
            let outcome = golden::check(actual, golden_image.as_ref(), rule);
            (golden_image, outcome)
        }
        Err(e) => (None, Outcome::Incomparable(e.to_string())),
    };
    let mut artifacts = Artifacts::default();
    if !outcome.passed() {
        let dir = artifacts_dir(failures, scene, backend.name());
        artifacts = write_artifacts(&dir, pass, actual, golden_image.as_ref());
    }
    let golden_path = store.path(scene, pass, eight_bit);
    PassCheck {
        scene: scene.to_owned(),
        scene_argument: case.argument(),
        pass,
        backend,
        golden_digest: (!outcome.passed())
            .then(|| crate::golden::scene_inputs::file_digest(&golden_path))
            .flatten(),
        outcome,
        golden_path,
        artifacts,
        criterion: case.rules.get(&pass).and_then(Rule::pixel_criterion),
    }
}

/// Writes actual, golden (as PNG) and diff heatmap for a pass into `dir`.
pub fn write_artifacts(
    dir: &Path,
    pass: TargetId,
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
    if images::write_image(actual, &actual_path, FileCompression::Fast).is_ok() {
        artifacts.actual = Some(actual_path);
    }
    if let Some(golden) = golden {
        let golden_path = dir.join(format!("{pass}_golden.png"));
        if images::write_image(golden, &golden_path, FileCompression::Fast).is_ok() {
            artifacts.golden = Some(golden_path);
        }
        let scale = if golden::is_eight_bit(actual) {
            16.0 / 255.0
        } else {
            0.05
        };
        if let Some(diff) = golden::diff_heatmap(actual, golden, scale) {
            let diff_path = dir.join(format!("{pass}_diff.png"));
            if images::write_image(&diff, &diff_path, FileCompression::Fast).is_ok() {
                artifacts.diff = Some(diff_path);
            }
        }
    }
    artifacts
}

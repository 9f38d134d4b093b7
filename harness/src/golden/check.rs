//! `harness check`: every canonical scene on every available backend, every golden pass checked,
//! every pair of backends compared, GPU timings collected. The result feeds the table, the JSON
//! output and the HTML report.

use std::collections::BTreeMap;

use engine::backend::{self, BackendKind};
use engine::plan::{PassId, TargetId};
use engine::renderer::Frame;
use engine::Image;

use crate::golden::command_line::bless_command;
use crate::golden::metrics::Channels;
use crate::golden::suite::{self, Case, PassCheck};
use crate::golden::{self, GoldenStore};

/// Every golden pass output of a run, by (scene, pass, backend), for the review page.
pub type Outputs = BTreeMap<(String, TargetId, BackendKind), Image>;

/// A backend's status in a check run.
#[derive(Clone, Debug, serde::Serialize, serde::Deserialize)]
pub struct BackendRun {
    /// Backend.
    pub backend: BackendKind,
    /// Driver fingerprint, when available.
    pub fingerprint: Option<String>,
    /// Why it was not run.
    pub unavailable: Option<String>,
    /// Asked for by name (`check --backend`): unavailable, it fails the run (not asked for,
    /// it is a note: the check runs on what this machine has).
    #[serde(default)]
    pub required: bool,
}

impl BackendRun {
    /// Asked for and not available: a failure of the run.
    pub fn missing(&self) -> bool {
        self.required && self.unavailable.is_some()
    }
}

/// The largest disagreement between two backends on one pass.
#[derive(Clone, Debug, serde::Serialize, serde::Deserialize)]
pub struct CrossBackend {
    /// Scene.
    pub scene: String,
    /// Pass.
    pub pass: TargetId,
    /// First backend.
    pub a: BackendKind,
    /// Second backend.
    pub b: BackendKind,
    /// Largest channel difference (8-bit in 0..1 units).
    #[serde(deserialize_with = "crate::golden::tolerance::null_as_infinity")]
    pub max_abs: f64,
    /// Fraction of pixels differing by more than 2/255 (8-bit) or 1e-3 relative (float, above an
    /// absolute floor of 1e-3).
    pub fraction_over: f64,
    /// Whether the pair is within the pass's tolerance (one backend taken as the golden).
    pub within_tolerance: bool,
}

/// GPU time of one pass of the plan (a point light's six faces summed).
#[derive(Clone, Debug, serde::Serialize, serde::Deserialize)]
pub struct Timing {
    /// Scene.
    pub scene: String,
    /// Backend.
    pub backend: BackendKind,
    /// Pass.
    pub pass: PassId,
    /// Milliseconds, when the backend has timestamps.
    pub ms: Option<f64>,
}

/// Everything a check run found.
#[derive(Clone, Debug, Default, serde::Serialize, serde::Deserialize)]
pub struct CheckRun {
    /// Backends, available or not.
    pub backends: Vec<BackendRun>,
    /// Scene x pass x backend results.
    pub results: Vec<PassCheck>,
    /// Render failures: (scene, backend, error).
    pub render_errors: Vec<(String, BackendKind, String)>,
    /// Scenes that did not load (each a failed case; the others are checked as usual).
    #[serde(default)]
    pub load_errors: Vec<crate::golden::suite::BrokenScene>,
    /// Cross-backend comparisons.
    pub cross: Vec<CrossBackend>,
    /// GPU timings.
    pub timings: Vec<Timing>,
    /// Information, not failures: where this run's drivers differ from the ones the goldens
    /// were blessed with.
    #[serde(default)]
    pub driver_notes: Vec<String>,
    /// The speed checks (none with `--no-speed`).
    #[serde(default)]
    pub speed: crate::golden::speed::SpeedRun,
    /// Why each failing image check failed: where the change starts, whether the backends
    /// moved alike, what to do.
    #[serde(default)]
    pub diagnoses: Vec<crate::golden::diagnosis::Diagnosis>,
    /// Files in golden/ that nothing produces or records any more (notes, not failures;
    /// `harness bless --prune` removes them).
    #[serde(default)]
    pub orphans: Vec<crate::golden::orphans::Orphan>,
    /// The kept outputs of failing passes verified as the check went (what accepting them
    /// relies on instead of rendering again).
    #[serde(default)]
    pub verifications: Vec<crate::golden::verify::Verification>,
    /// The files each scene was loaded from, digested: accepting this check's outputs refuses
    /// a scene that has changed since.
    #[serde(default)]
    pub inputs: Vec<crate::golden::scene_inputs::SceneInputs>,
    /// The workspace's commit, when it is a git tree: shards of different commits are not one
    /// run (`report --merge` refuses them).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub commit: Option<String>,
}

impl CheckRun {
    /// Whether everything passed.
    pub fn passed(&self) -> bool {
        self.render_errors.is_empty()
            && self.load_errors.is_empty()
            && !self.backends.iter().any(BackendRun::missing)
            && self.results.iter().all(|r| r.outcome.passed())
            && self.speed.passed()
    }

    /// The scene named `scene` as this check was given it (a name in scenes/ or a scene
    /// file's path): what a printed command must name to find it again. The name itself when
    /// the check rendered nothing of it.
    pub fn scene_argument<'a>(&'a self, scene: &'a str) -> &'a str {
        self.results
            .iter()
            .find(|r| r.scene == scene)
            .map_or(scene, |r| r.scene_argument.as_str())
    }

    /// One `harness bless` command per scene with a failing or missing pass, in the order of
    /// the results (each rewrites only its scene's changed passes). A slower pass of a check
    /// with the debug slowdown ([`SpeedRun::is_debug_slowdown`](crate::golden::speed::SpeedRun))
    /// has none: it is the setting's own.
    pub fn bless_commands(&self) -> Vec<String> {
        let mut commands: Vec<String> = Vec::new();
        for r in self.results.iter().filter(|r| !r.outcome.passed()) {
            let command = bless_command(&r.scene_argument);
            if !commands.contains(&command) {
                commands.push(command);
            }
        }
        for c in self
            .speed
            .checks
            .iter()
            .filter(|c| c.failed() && !self.speed.is_debug_slowdown(c))
        {
            let argument = self.scene_argument(&c.scene);
            let command =
                crate::golden::command_line::speed_bless_command(argument, c.bless_writes_here());
            if !commands.contains(&command) && !commands.contains(&bless_command(argument)) {
                commands.push(command);
            }
        }
        commands
    }
}

/// Where the backends of this run differ from the drivers the goldens were blessed with (from
/// each scene's blessed.toml): information, since the noise model's tolerances are there to
/// absorb such differences.
pub fn driver_notes(cases: &[Case], store: &GoldenStore, backends: &[BackendRun]) -> Vec<String> {
    // (backend, blessed driver) -> scenes.
    let mut blessed: BTreeMap<(BackendKind, String), Vec<String>> = BTreeMap::new();
    for case in cases {
        for record in store.records(case.name()).unwrap_or_default().into_values() {
            let scenes = blessed.entry((record.backend, record.driver)).or_default();
            if !scenes.iter().any(|s| s == case.name()) {
                scenes.push(case.name().to_owned());
            }
        }
    }
    let mut notes = Vec::new();
    for ((backend, driver), scenes) in blessed {
        let Some(current) = backends
            .iter()
            .find(|b| b.backend == backend)
            .and_then(|b| b.fingerprint.as_ref())
        else {
            continue;
        };
        if *current != driver {
            notes.push(driver_note(&scenes, backend, &driver, current));
        }
    }
    notes
}

/// Whether a driver fingerprint names one of Mesa's software rasterizers (llvmpipe, which
/// lavapipe reports too, or softpipe): the drivers the noise model is measured over.
pub fn is_software_rasterizer(fingerprint: &str) -> bool {
    fingerprint.contains("llvmpipe") || fingerprint.contains("softpipe")
}

/// The note for `scenes` blessed on `backend` with driver `blessed` and checked with `current`.
pub fn driver_note(
    scenes: &[String],
    backend: BackendKind,
    blessed: &str,
    current: &str,
) -> String {
    let scenes = scenes.join(", ");
    if is_software_rasterizer(blessed) && !is_software_rasterizer(current) {
        return format!(
            "goldens of {scenes} were blessed on {backend} with `{blessed}`, a software \
             rasterizer; {backend} here is `{current}`, which is not one: the noise model \
             (golden/noise.toml) covers Mesa's software drivers, and a GPU differs beyond it in \
             every pass that samples a texture (docs/2026-11-26-nvidia-gpu.md), so a failure \
             here may be the driver's rather than a change's"
        );
    }
    format!(
        "goldens of {scenes} were blessed on {backend} with `{blessed}`; {backend} here is \
         `{current}`: differences within the noise model (golden/noise.toml) are expected, and \
         are not failures"
    )
}

/// How far two backends' outputs of one pass disagree: the largest channel difference and the
/// fraction of pixels over 2/255 (8-bit) or 1e-3 relative above a floor of 1e-3 (float). `None`
/// when the two cannot be compared (sizes or layouts differ).
fn disagreement(a: &Image, b: &Image) -> Option<(f64, f64)> {
    let pair = crate::golden::metrics::Pair::new(a, b).ok()?;
    let fraction = if golden::is_eight_bit(a) {
        pair.fraction_over(2.0 / 255.0, 0, None, Channels::All)
    } else {
        pair.fraction_over(1e-3, 0, Some(1e-3), Channels::All)
    };
    Some((pair.max_abs(0, Channels::All), fraction))
}

/// The pair of backends whose outputs of `scene`'s `pass` disagree most (by fraction over the
/// threshold, then by the largest difference), with its tolerance verdict. Only that pair is
/// reported, so `within_tolerance` (whether `a` passes the pass's rule with `b` as its golden)
/// is called for it alone: the full rule (FLIP, on an 8-bit pass) costs more than the
/// disagreement figures of every pair together.
pub fn worst_pair(
    scene: &str,
    pass: TargetId,
    outputs: &[(BackendKind, &Image)],
    within_tolerance: impl Fn(&Image, &Image) -> bool,
) -> Option<CrossBackend> {
    let mut worst: Option<(usize, usize, f64, f64)> = None;
    for (i, (_, a)) in outputs.iter().enumerate() {
        for (j, (_, b)) in outputs.iter().enumerate().skip(i + 1) {
            let Some((max_abs, fraction_over)) = disagreement(a, b) else {
                continue;
            };
            if worst.is_none_or(|(_, _, worst_max, worst_fraction)| {
                fraction_over > worst_fraction
                    || (fraction_over == worst_fraction && max_abs > worst_max)
            }) {
                worst = Some((i, j, max_abs, fraction_over));
            }
        }
    }
    worst.map(|(i, j, max_abs, fraction_over)| {
        let ((a, image_a), (b, image_b)) = (outputs[i], outputs[j]);
        CrossBackend {
            scene: scene.to_owned(),
            pass,
            a,
            b,
            max_abs,
            fraction_over,
            within_tolerance: within_tolerance(image_a, image_b),
        }
    })
}

/// Runs the check on the backends in `only` (every available one when empty, an unavailable
/// one noted; those named in `only` are asked for, and their absence fails the run), writing
/// failure images under `failures` (each checked scene's old ones there are removed first).
/// `progress` is called before each render with (done, total, what).
/// Returns the run and every golden pass output, for the report.
pub fn run(
    cases: &[Case],
    store: &GoldenStore,
    only: &[BackendKind],
    failures: &std::path::Path,
    progress: impl FnMut(usize, usize, &str),
) -> (CheckRun, Outputs) {
    run_with(
        cases,
        store,
        only,
        failures,
        &crate::faults::create_backend,
        progress,
    )
}

/// Creates the backend for one render of [`run_with`].
pub type BackendFactory<'a> =
    dyn Fn(BackendKind) -> Result<Box<dyn backend::Backend>, backend::BackendError> + 'a;

/// [`run`] with the backends made by `create` (one per scene and backend): a backend that fails
/// to start or fails mid-run fails that scene on that backend, and the run goes on.
pub fn run_with(
    cases: &[Case],
    store: &GoldenStore,
    only: &[BackendKind],
    failures: &std::path::Path,
    create: &BackendFactory<'_>,
    mut progress: impl FnMut(usize, usize, &str),
) -> (CheckRun, Outputs) {
    for case in cases {
        suite::clear_artifacts(failures, case.name());
    }
    let mut outputs = Outputs::new();
    let mut backends = Vec::new();
    let mut available = Vec::new();
    for kind in BackendKind::ALL {
        if !only.is_empty() && !only.contains(&kind) {
            continue;
        }
        let status = backend::probe(kind);
        if status.available {
            available.push(kind);
        }
        backends.push(BackendRun {
            backend: kind,
            fingerprint: status.info.as_ref().map(golden::fingerprint),
            unavailable: (!status.available).then(|| {
                format!(
                    "{} (fix: {})",
                    status.reason.unwrap_or_default(),
                    status.fix.unwrap_or_default()
                )
            }),
            required: only.contains(&kind),
        });
    }
    let total = cases.len() * available.len();
    let mut done = 0;
    let mut results = Vec::new();
    let mut render_errors = Vec::new();
    let mut cross = Vec::new();
    let mut timings = Vec::new();
    for case in cases {
        let mut frames: BTreeMap<BackendKind, Frame> = BTreeMap::new();
        for &kind in &available {
            progress(done, total, &format!("{} on {kind}", case.name()));
            let rendered = create(kind)
                .map_err(|e| e.to_string())
                .and_then(|mut backend| {
                    case.render_on(backend.as_mut()).map_err(|e| e.to_string())
                });
            match rendered {
                Ok(frame) => {
                    for pass in frame.plan.passes.iter().map(|p| p.id) {
                        if frame.timings.ran(pass) {
                            timings.push(Timing {
                                scene: case.name().to_owned(),
                                backend: kind,
                                pass,
                                ms: frame.timings.pass_time(pass).map(|ns| ns / 1e6),
                            });
                        }
                    }
                    for &pass in &case.passes {
                        results.push(suite::check_pass(
                            store,
                            case,
                            pass,
                            kind,
                            &frame.outputs[&pass],
                            failures,
                        ));
                    }
                    frames.insert(kind, frame);
                }
                Err(e) => render_errors.push((case.name().to_owned(), kind, e)),
            }
            done += 1;
        }
        for &pass in &case.passes {
            let outputs: Vec<(BackendKind, &Image)> = frames
                .iter()
                .map(|(&kind, frame)| (kind, &frame.outputs[&pass]))
                .collect();
            cross.extend(worst_pair(case.name(), pass, &outputs, |a, b| {
                golden::check(a, Some(b), &case.rules[&pass]).passed()
            }));
        }
        for (kind, frame) in frames {
            for (pass, image) in frame.outputs {
                outputs.insert((case.name().to_owned(), pass, kind), image);
            }
        }
    }
    progress(done, total, "done");
    let driver_notes = driver_notes(cases, store, &backends);
    let plans = cases
        .iter()
        .map(|case| (case.name().to_owned(), case.frame.plan().clone()))
        .collect();
    let diagnoses = crate::golden::diagnosis::diagnose(&plans, &results, &cross);
    (
        CheckRun {
            diagnoses,
            orphans: Vec::new(),
            verifications: Vec::new(),
            inputs: cases.iter().map(|case| case.inputs.clone()).collect(),
            driver_notes,
            backends,
            results,
            render_errors,
            load_errors: Vec::new(),
            cross,
            timings,
            speed: Default::default(),
            commit: crate::golden::speed::history::commit(),
        },
        outputs,
    )
}

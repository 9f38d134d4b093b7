//! `harness check`: every canonical scene on every available backend, every golden pass checked,
//! every pair of backends compared, GPU timings collected. The result feeds the table, the JSON
//! output and the HTML report.

use std::collections::BTreeMap;

use engine::backend::{self, BackendKind};
use engine::renderer::Frame;
use engine::Image;

use crate::golden::{self, GoldenStore};
use crate::suite::{self, Case, PassCheck};

/// A backend's status in a check run.
#[derive(Clone, Debug, serde::Serialize)]
pub struct BackendRun {
    /// Backend name.
    pub backend: String,
    /// Driver fingerprint, when available.
    pub fingerprint: Option<String>,
    /// Why it was not run.
    pub unavailable: Option<String>,
}

/// The largest disagreement between two backends on one pass.
#[derive(Clone, Debug, serde::Serialize)]
pub struct CrossBackend {
    /// Scene.
    pub scene: String,
    /// Pass.
    pub pass: String,
    /// First backend.
    pub a: String,
    /// Second backend.
    pub b: String,
    /// Largest channel difference (8-bit in 0..1 units).
    pub max_abs: f64,
    /// Fraction of pixels differing by more than 2/255 (8-bit) or 1e-3 relative (float).
    pub fraction_over: f64,
    /// Whether the pair is within the pass's tolerance (one backend taken as the golden).
    pub within_tolerance: bool,
}

/// GPU time of one pass.
#[derive(Clone, Debug, serde::Serialize)]
pub struct Timing {
    /// Scene.
    pub scene: String,
    /// Backend.
    pub backend: String,
    /// Pass.
    pub pass: String,
    /// Milliseconds, when the backend has timestamps.
    pub ms: Option<f64>,
}

/// Everything a check run found.
#[derive(Clone, Debug, serde::Serialize)]
pub struct CheckRun {
    /// Backends, available or not.
    pub backends: Vec<BackendRun>,
    /// Scene x pass x backend results.
    pub results: Vec<PassCheck>,
    /// Render failures: (scene, backend, error).
    pub render_errors: Vec<(String, String, String)>,
    /// Cross-backend comparisons.
    pub cross: Vec<CrossBackend>,
    /// GPU timings.
    pub timings: Vec<Timing>,
}

impl CheckRun {
    /// Whether everything passed.
    pub fn passed(&self) -> bool {
        self.render_errors.is_empty() && self.results.iter().all(|r| r.outcome.passed())
    }
}

/// Compares two backends' outputs of one pass.
pub fn cross_compare(case: &Case, pass: &str, a: &Image, b: &Image) -> Option<(f64, f64, bool)> {
    let pair = crate::metrics::Pair::new(a, b).ok()?;
    let fraction = if golden::is_eight_bit(a) {
        pair.fraction_over(2.0 / 255.0, 0)
    } else {
        let errors = pair.relative_errors(1e-3);
        errors.iter().filter(|&&e| e > 1e-3).count() as f64 / errors.len().max(1) as f64
    };
    let within = golden::check(a, Some(b), &case.rules[pass]).passed();
    Some((pair.max_abs(0), fraction, within))
}

/// Runs the check. `progress` is called before each render with (done, total, what). Returns
/// the run and every golden pass output, for the report.
pub fn run(
    cases: &[Case],
    store: &GoldenStore,
    progress: impl FnMut(usize, usize, &str),
) -> (CheckRun, crate::report::Outputs) {
    run_with(cases, store, &|kind| backend::create(kind), progress)
}

/// Creates the backend for one render of [`run_with`].
pub type BackendFactory<'a> =
    dyn Fn(BackendKind) -> Result<Box<dyn backend::Backend>, backend::BackendError> + 'a;

/// [`run`] with the backends made by `create` (one per scene and backend): a backend that fails
/// to start or fails mid-run fails that scene on that backend, and the run goes on.
pub fn run_with(
    cases: &[Case],
    store: &GoldenStore,
    create: &BackendFactory<'_>,
    mut progress: impl FnMut(usize, usize, &str),
) -> (CheckRun, crate::report::Outputs) {
    let mut outputs = crate::report::Outputs::new();
    let mut backends = Vec::new();
    let mut available = Vec::new();
    for kind in BackendKind::ALL {
        let status = backend::probe(kind);
        if status.available {
            available.push(kind);
        }
        backends.push(BackendRun {
            backend: kind.name().to_owned(),
            fingerprint: status.info.as_ref().map(golden::fingerprint),
            unavailable: (!status.available).then(|| {
                format!(
                    "{} (fix: {})",
                    status.reason.unwrap_or_default(),
                    status.fix.unwrap_or_default()
                )
            }),
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
                .and_then(|mut backend| case.render_on(backend.as_mut()));
            match rendered {
                Ok(frame) => {
                    for t in &frame.timings {
                        timings.push(Timing {
                            scene: case.name().to_owned(),
                            backend: kind.name().to_owned(),
                            pass: t.name.clone(),
                            ms: t.gpu_ns.map(|ns| ns / 1e6),
                        });
                    }
                    for pass in &case.passes {
                        results.push(suite::check_pass(
                            store,
                            case,
                            pass,
                            kind,
                            &frame.outputs[pass],
                        ));
                    }
                    frames.insert(kind, frame);
                }
                Err(e) => render_errors.push((case.name().to_owned(), kind.name().to_owned(), e)),
            }
            done += 1;
        }
        let kinds: Vec<&BackendKind> = frames.keys().collect();
        for pass in &case.passes {
            let mut worst: Option<CrossBackend> = None;
            for (i, a) in kinds.iter().enumerate() {
                for b in &kinds[i + 1..] {
                    let (ia, ib) = (&frames[*a].outputs[pass], &frames[*b].outputs[pass]);
                    if let Some((max_abs, fraction_over, within)) =
                        cross_compare(case, pass, ia, ib)
                    {
                        let entry = CrossBackend {
                            scene: case.name().to_owned(),
                            pass: pass.clone(),
                            a: a.name().to_owned(),
                            b: b.name().to_owned(),
                            max_abs,
                            fraction_over,
                            within_tolerance: within,
                        };
                        if worst.as_ref().is_none_or(|w| {
                            entry.fraction_over > w.fraction_over
                                || (entry.fraction_over == w.fraction_over
                                    && entry.max_abs > w.max_abs)
                        }) {
                            worst = Some(entry);
                        }
                    }
                }
            }
            cross.extend(worst);
        }
        for (kind, frame) in frames {
            for (pass, image) in frame.outputs {
                outputs.insert(
                    (case.name().to_owned(), pass, kind.name().to_owned()),
                    image,
                );
            }
        }
    }
    progress(done, total, "done");
    (
        CheckRun {
            backends,
            results,
            render_errors,
            cross,
            timings,
        },
        outputs,
    )
}

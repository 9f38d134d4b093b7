//! Measuring unchanged renders under a source: environment sources through `harness check
//! --json` in a child process per scene and backend, synthetic rounding of an in-process render,
//! and recorded hosts from their files; each render's checks against the goldens.

use std::collections::BTreeMap;
use std::path::Path;
use std::process::Command;

use engine::backend::BackendKind;
use engine::plan::TargetId;
use engine::Image;

use super::rounding::synthetic_rounding;
use super::sources::{Source, SourceKind};
use crate::golden::check::CheckRun;
use crate::golden::suite::Case;
use crate::golden::{self, GoldenStore, Outcome};

/// The infix of a recorded render's pinned golden (`chess_final_gl.golden.png`): see
/// [`measure_recorded`].
pub const PINNED_GOLDEN: &str = "golden";

/// One measurement: a render of one scene under one source, every golden pass's checks.
#[derive(Clone, Debug, serde::Serialize)]
pub struct Measurement {
    /// Source name.
    pub source: String,
    /// Backend (none, `-` in JSON, for synthetic rounding, which derives from the reference
    /// backend).
    #[serde(serialize_with = "crate::backend_or_dash")]
    pub backend: Option<BackendKind>,
    /// Scene.
    pub scene: String,
    /// Pass.
    pub pass: TargetId,
    /// Metric (as printed) and its value.
    pub values: Vec<(String, f64)>,
}

/// A measurement that could not be made.
#[derive(Clone, Debug, serde::Serialize)]
pub struct Missed {
    /// Source name.
    pub source: String,
    /// Backend.
    pub backend: BackendKind,
    /// Scene.
    pub scene: String,
    /// What happened.
    pub error: String,
    /// A known driver crash (see [`known_driver_crash`]): reported, not a failure.
    pub known: bool,
}

/// Driver crashes that are not the harness's to fix, with the evidence. Measured here: lavapipe
/// with `LP_NATIVE_VECTOR_WIDTH=128` corrupts its heap and aborts (`malloc(): invalid next size`)
/// on valid draws whose vertex count is 1-4 modulo 8, such as the board's 4-vertex quads (Mesa
/// 22.3.6 always at 9-12 vertices, 25.0.7 similarly; the 256-bit default, llvmpipe, and
/// valgrind runs are clean). A scene without such draws renders (ibl), so a render that does
/// is measured; one that aborts is reported as this known crash.
pub fn known_driver_crash(source: &Source, backend: BackendKind) -> Option<String> {
    let SourceKind::Environment(vars) = &source.kind else {
        return None;
    };
    let vector_128 = vars
        .iter()
        .any(|(k, v)| k == "LP_NATIVE_VECTOR_WIDTH" && v == "128");
    (vector_128 && backend == BackendKind::WgpuVulkan).then(|| {
        "lavapipe with LP_NATIVE_VECTOR_WIDTH=128 aborts with heap corruption on draws of 1-4 \
         vertices modulo 8 (Mesa 22.3.6 and 25.0.7): a driver bug"
            .to_owned()
    })
}

fn values_of(outcome: &Outcome) -> Option<Vec<(String, f64)>> {
    match outcome {
        Outcome::Passed(v) | Outcome::Failed(v) => Some(
            v.checks
                .iter()
                .map(|c| (c.metric.clone(), c.value))
                .collect(),
        ),
        Outcome::MissingGolden | Outcome::Incomparable(_) => None,
    }
}

/// What measuring one source gave.
#[derive(Clone, Debug, Default, serde::Serialize)]
pub struct SourceRun {
    /// The measurements.
    pub measurements: Vec<Measurement>,
    /// What could not be measured.
    pub missed: Vec<Missed>,
    /// Driver fingerprint per backend, as the source saw it.
    pub drivers: BTreeMap<BackendKind, String>,
}

/// Measures an environment source: `harness check --json` (the binary `exe`) in a child process
/// per scene and backend.
pub fn measure_environment(
    exe: &Path,
    source: &Source,
    cases: &[Case],
    backends: &[BackendKind],
    mut progress: impl FnMut(&str),
) -> SourceRun {
    let SourceKind::Environment(vars) = &source.kind else {
        return SourceRun::default();
    };
    let mut measurements = Vec::new();
    let mut missed = Vec::new();
    let mut drivers = BTreeMap::new();
    for case in cases {
        for &backend in backends {
            progress(&format!("{} {} on {backend}", source.name, case.name()));
            let out = std::env::temp_dir().join(format!(
                "harness-noise-{}-{}",
                std::process::id(),
                source.name
            ));
            // Images only: the speed checks (the timing model is `noise --timing`'s) and the
            // verification of failing outputs are not this measurement's.
            let output = Command::new(exe)
                .args(["check", "--json", "--no-speed", "--no-verify", "--scene"])
                .arg(&case.loaded.path)
                .args(["--backend", backend.name(), "--out"])
                .arg(&out)
                .envs(vars.iter().map(|(k, v)| (k, v)))
                .output();
            let _ = std::fs::remove_dir_all(&out);
            let mut miss = |error: String| {
                let known = known_driver_crash(source, backend);
                missed.push(Missed {
                    source: source.name.clone(),
                    backend,
                    scene: case.name().to_owned(),
                    error: known.clone().unwrap_or(error),
                    known: known.is_some(),
                });
            };
            let output = match output {
                Ok(output) => output,
                Err(e) => {
                    miss(format!("cannot run {}: {e}", exe.display()));
                    continue;
                }
            };
            let run: CheckRun = match serde_json::from_slice(&output.stdout) {
                Ok(run) => run,
                Err(_) => {
                    let stderr = String::from_utf8_lossy(&output.stderr);
                    let tail: Vec<&str> = stderr
                        .lines()
                        .filter(|l| !l.contains("XDG_RUNTIME_DIR"))
                        .collect();
                    let tail = tail[tail.len().saturating_sub(3)..].join(" / ");
                    miss(format!("the check died ({}): {tail}", output.status));
                    continue;
                }
            };
            for (scene, b, error) in &run.render_errors {
                miss(format!("{scene} on {b}: {error}"));
            }
            for b in &run.backends {
                if let Some(fingerprint) = &b.fingerprint {
                    drivers.insert(b.backend, fingerprint.clone());
                }
            }
            for result in &run.results {
                if let Some(values) = values_of(&result.outcome) {
                    measurements.push(Measurement {
                        source: source.name.clone(),
                        backend: Some(result.backend),
                        scene: result.scene.clone(),
                        pass: result.pass,
                        values,
                    });
                }
            }
        }
    }
    SourceRun {
        measurements,
        missed,
        drivers,
    }
}

/// Measures the checks of every golden pass of `outputs` against the goldens.
fn measure_outputs(
    store: &GoldenStore,
    case: &Case,
    source: &str,
    backend: Option<BackendKind>,
    outputs: &BTreeMap<TargetId, Image>,
) -> Vec<Measurement> {
    measure_outputs_against(store, case, source, backend, outputs, None)
}

/// [`measure_outputs`] against `pinned` where given instead of the golden: the golden a
/// recorded render of one pass was taken against (`outputs` holds that one pass).
fn measure_outputs_against(
    store: &GoldenStore,
    case: &Case,
    source: &str,
    backend: Option<BackendKind>,
    outputs: &BTreeMap<TargetId, Image>,
    pinned: Option<&Image>,
) -> Vec<Measurement> {
    debug_assert!(pinned.is_none() || outputs.len() == 1);
    let mut measurements = Vec::new();
    for (&pass, image) in outputs {
        let Some(rule) = case.rules.get(&pass) else {
            continue;
        };
        let golden = match pinned {
            Some(pinned) => pinned.clone(),
            None => match store.load(case.name(), pass, golden::is_eight_bit(image)) {
                Ok(Some(golden)) => golden,
                _ => continue,
            },
        };
        if let Some(values) = values_of(&golden::check(image, Some(&golden), rule)) {
            measurements.push(Measurement {
                source: source.to_owned(),
                backend,
                scene: case.name().to_owned(),
                pass,
                values,
            });
        }
    }
    measurements
}

/// Measures synthetic rounding of the reference backend's frame of `case`.
pub fn measure_synthetic(
    store: &GoldenStore,
    case: &Case,
    outputs: &BTreeMap<TargetId, Image>,
    source: &str,
) -> Vec<Measurement> {
    measure_outputs(
        store,
        case,
        source,
        None,
        &synthetic_rounding(case, outputs),
    )
}

/// Measures renders recorded on another host: `<dir>/<scene>_<pass>_<backend>.png|exr`, each
/// against the golden of its pass or, when `<scene>_<pass>_<backend>.golden.png|exr` is beside
/// it ([`PINNED_GOLDEN`], added when a bless changed the picture it recorded), against that:
/// the golden as it was when the host rendered it. A pin the render cannot be compared with
/// (another size) is missed, naming it. A recorded render is evidence of another CPU's rounding
/// of one picture, which the limits must hold; it cannot be rendered again of a new picture
/// without that host, and the pinned golden keeps it evidence of the same thing.
pub fn measure_recorded(
    store: &GoldenStore,
    case: &Case,
    source: &str,
    dir: &Path,
) -> (Vec<Measurement>, Vec<Missed>) {
    let mut measurements = Vec::new();
    let mut missed = Vec::new();
    for pass in &case.passes {
        for backend in BackendKind::ALL {
            let stem = format!("{}_{pass}_{}", case.name(), backend.name());
            for (extension, eight_bit) in [("png", true), ("exr", false)] {
                let path = dir.join(format!("{stem}.{extension}"));
                if !path.exists() {
                    continue;
                }
                let read = |path: &Path| {
                    if eight_bit {
                        crate::images::read_png(path)
                    } else {
                        crate::images::read_exr(path)
                    }
                };
                let pin = dir.join(format!("{stem}.{PINNED_GOLDEN}.{extension}"));
                let pinned = pin.exists().then(|| read(&pin)).transpose();
                match read(&path).and_then(|image| Ok((image, pinned?))) {
                    Ok((image, Some(pinned)))
                        if (pinned.width, pinned.height) != (image.width, image.height) =>
                    {
                        missed.push(Missed {
                            source: source.to_owned(),
                            backend,
                            scene: case.name().to_owned(),
                            error: format!(
                                "{}: {}x{}, but the render {} is {}x{}",
                                pin.display(),
                                pinned.width,
                                pinned.height,
                                path.display(),
                                image.width,
                                image.height
                            ),
                            known: false,
                        });
                    }
                    Ok((image, pinned)) => {
                        let outputs = BTreeMap::from([(*pass, image)]);
                        measurements.extend(measure_outputs_against(
                            store,
                            case,
                            source,
                            Some(backend),
                            &outputs,
                            pinned.as_ref(),
                        ));
                    }
                    Err(e) => missed.push(Missed {
                        source: source.to_owned(),
                        backend,
                        scene: case.name().to_owned(),
                        error: e.to_string(),
                        known: false,
                    }),
                }
            }
        }
    }
    (measurements, missed)
}

/// Measures `sources` on `cases`: environment sources through `exe` (the `harness` binary) on
/// `backends`, synthetic rounding from an in-process render on `reference`, recorded hosts from
/// their files. Returns one run per source, in order.
pub fn measure(
    exe: &Path,
    store: &GoldenStore,
    cases: &[Case],
    sources: &[Source],
    backends: &[BackendKind],
    reference: BackendKind,
    mut progress: impl FnMut(&str),
) -> Vec<(Source, SourceRun)> {
    let mut runs = Vec::new();
    for source in sources {
        let run = match &source.kind {
            SourceKind::Environment(_) => {
                measure_environment(exe, source, cases, backends, &mut progress)
            }
            SourceKind::SyntheticRounding => {
                let mut run = SourceRun::default();
                for case in cases {
                    progress(&format!("{} {} on {reference}", source.name, case.name()));
                    match case.render(reference) {
                        Ok(frame) => run.measurements.extend(measure_synthetic(
                            store,
                            case,
                            &frame.outputs,
                            &source.name,
                        )),
                        Err(error) => run.missed.push(Missed {
                            source: source.name.clone(),
                            backend: reference,
                            scene: case.name().to_owned(),
                            error: error.to_string(),
                            known: false,
                        }),
                    }
                }
                run
            }
            SourceKind::Recorded(dir) => {
                let mut run = SourceRun::default();
                for case in cases {
                    let (measurements, missed) = measure_recorded(store, case, &source.name, dir);
                    run.measurements.extend(measurements);
                    run.missed.extend(missed);
                }
                run
            }
        };
        runs.push((source.clone(), run));
    }
    runs
}

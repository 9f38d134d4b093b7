//! Running the self-test: per scene (in parallel) and backend, an unchanged render, synthetic
//! rounding of the reference backend's render, and every mutation, each against the goldens;
//! then the figures golden/noise.toml recorded for the sources this run does not produce.

use std::collections::BTreeMap;

use engine::backend::BackendKind;
use engine::plan::TargetId;
use engine::renderer::{self, PreparedFrame, Readback};
use engine::Image;

use super::{Mutation, MutationChecks, MutationResult, NoiseResult, SelfTest};
use crate::golden::diagnosis;
use crate::golden::noise::{NoiseModel, MAX_NOISE_RATIO};
use crate::golden::portability;
use crate::golden::suite::{self, Case};
use crate::golden::{self, GoldenStore, Outcome};

/// The golden of every pass of a case, by pass (`None` where there is none).
type Goldens = BTreeMap<TargetId, Option<Image>>;

/// Ratios of every golden pass of `outputs` against the goldens.
fn ratios(
    case: &Case,
    goldens: &Goldens,
    outputs: &BTreeMap<TargetId, Image>,
) -> BTreeMap<TargetId, f64> {
    let mut out = BTreeMap::new();
    for pass in &case.passes {
        let (Some(actual), Some(golden)) = (outputs.get(pass), goldens.get(pass)) else {
            continue;
        };
        let ratio = match golden::check(actual, golden.as_ref(), &case.rules[pass]) {
            Outcome::Passed(v) | Outcome::Failed(v) => v.ratio,
            Outcome::MissingGolden | Outcome::Incomparable(_) => f64::INFINITY,
        };
        out.insert(*pass, ratio);
    }
    out
}

/// Runs the self-test on `backends`: every mutation and an unchanged render on each, synthetic
/// rounding of the reference backend's render, and the figures `model` recorded for the sources
/// this run does not produce (CPU code paths, another Mesa, recorded hosts). `checks` says which
/// passes of a mutated render are checked. Scenes run in parallel, one thread each, each with
/// its own backends.
pub fn run(
    cases: &[Case],
    store: &GoldenStore,
    backends: &[BackendKind],
    model: &NoiseModel,
    checks: MutationChecks,
) -> SelfTest {
    let parts: Vec<SelfTest> = std::thread::scope(|scope| {
        let handles: Vec<_> = cases
            .iter()
            .map(|case| scope.spawn(move || run_case(case, store, backends, model, checks)))
            .collect();
        handles
            .into_iter()
            .zip(cases)
            .map(|(handle, case)| {
                handle.join().unwrap_or_else(|_| SelfTest {
                    mutations: vec![],
                    noise: vec![],
                    errors: vec![format!("{}: self-test thread panicked", case.name())],
                })
            })
            .collect()
    });
    let mut result = SelfTest {
        mutations: vec![],
        noise: vec![],
        errors: vec![],
    };
    for part in parts {
        result.mutations.extend(part.mutations);
        result.noise.extend(part.noise);
        result.errors.extend(part.errors);
    }
    result
}

/// The self-test of one scene on every backend.
fn run_case(
    case: &Case,
    store: &GoldenStore,
    backends: &[BackendKind],
    model: &NoiseModel,
    checks: MutationChecks,
) -> SelfTest {
    let mut result = SelfTest {
        mutations: vec![],
        noise: vec![],
        errors: vec![],
    };
    let goldens: Goldens = case
        .passes
        .iter()
        .map(|&pass| {
            let golden = store.load(case.name(), pass, case.is_eight_bit(pass));
            (pass, golden.ok().flatten())
        })
        .collect();
    let reference = suite::reference_among(backends);
    for &kind in backends {
        let reference = Some(kind) == reference;
        run_backend(case, kind, reference, &goldens, checks, &mut result);
    }
    // The sources this run does not produce, from the figures golden/noise.toml recorded.
    recorded_noise(case, model, &mut result.noise);
    result
}

/// One scene on one backend: the unchanged render (and its synthetic rounding, on the
/// `reference` backend), then every mutation. Each render runs only the passes its checked
/// targets depend on (the others are culled; the targets are the same bit for bit).
fn run_backend(
    case: &Case,
    kind: BackendKind,
    reference: bool,
    goldens: &Goldens,
    checks: MutationChecks,
    result: &mut SelfTest,
) {
    let wanted: &[TargetId] = &case.passes;
    let mut backend = match crate::faults::create_backend(kind) {
        Ok(backend) => backend,
        Err(e) => {
            result
                .errors
                .push(format!("{} on {kind}: {e}", case.name()));
            return;
        }
    };
    let mut render = |frame: &PreparedFrame, wanted: &[TargetId]| {
        renderer::render_prepared(backend.as_mut(), frame, Readback::Needed(wanted))
            .map_err(|e| e.to_string())
    };
    match render(&case.frame, wanted) {
        Ok(frame) => unchanged_noise(case, kind, reference, goldens, &frame.outputs, result),
        Err(e) => result
            .errors
            .push(format!("unchanged {} on {kind}: {e}", case.name())),
    }
    for mutation in Mutation::ALL {
        let mut entry = MutationResult {
            scene: case.name().to_owned(),
            mutation,
            backend: kind,
            applies: false,
            ratios: BTreeMap::new(),
            error: None,
            diagnosed_origin: Vec::new(),
            origin_passes: Vec::new(),
        };
        // Environment changes apply to the scene as loaded, prepared anew; the others to the
        // scene as drawn (an extracted sun's light too), re-planned with the same IBL maps.
        let mutated = if mutation.changes_environment() {
            mutation
                .apply(&case.loaded.scene)
                .map(|(scene, variations)| (PreparedFrame::new(&scene), variations))
        } else {
            mutation
                .apply(case.frame.scene())
                .map(|(scene, variations)| (case.frame.varied(scene), variations))
        };
        if let Some((mutated, variations)) = mutated {
            entry.applies = true;
            let checked: Vec<TargetId> = match checks {
                MutationChecks::EveryPass => wanted.to_vec(),
                MutationChecks::Origin => wanted
                    .iter()
                    .copied()
                    .filter(|pass| mutation.is_origin(*pass))
                    .collect(),
            };
            let rendered = mutated
                .map_err(|e| e.to_string())
                .and_then(|frame| render(&frame.with_variations(variations), &checked));
            match rendered {
                Ok(frame) => {
                    entry.ratios = ratios(case, goldens, &frame.outputs);
                    let over = |bound: f64| -> Vec<TargetId> {
                        entry
                            .ratios
                            .iter()
                            .filter(|(_, &r)| r > bound)
                            .map(|(pass, _)| *pass)
                            .collect()
                    };
                    let (failing, moved) = (over(1.0), over(MAX_NOISE_RATIO));
                    entry.diagnosed_origin = diagnosis::origins(&frame.plan, &failing, &moved);
                    let reached: Vec<TargetId> = frame
                        .plan
                        .target_ids()
                        .into_iter()
                        .filter(|t| mutation.starts_in(*t))
                        .collect();
                    entry.origin_passes = diagnosis::writers(&frame.plan, &reached);
                }
                Err(e) => {
                    result.errors.push(format!(
                        "{} on {kind} with `{}`: {e}",
                        case.name(),
                        mutation.describe()
                    ));
                    entry.error = Some(e);
                }
            }
        }
        result.mutations.push(entry);
    }
}

/// The unchanged render's ratios under the drivers as they are, and, on the `reference`
/// backend, under synthetic rounding of it.
fn unchanged_noise(
    case: &Case,
    kind: BackendKind,
    reference: bool,
    goldens: &Goldens,
    outputs: &BTreeMap<TargetId, Image>,
    result: &mut SelfTest,
) {
    for (pass, ratio) in ratios(case, goldens, outputs) {
        result.noise.push(NoiseResult {
            source: "drivers".to_owned(),
            scene: case.name().to_owned(),
            backend: Some(kind),
            pass,
            ratio,
            live: true,
        });
    }
    if reference {
        let synthetic = portability::synthetic_rounding(case, outputs);
        for (pass, ratio) in ratios(case, goldens, &synthetic) {
            result.noise.push(NoiseResult {
                source: "synthetic-rounding".to_owned(),
                scene: case.name().to_owned(),
                backend: None,
                pass,
                ratio,
                live: true,
            });
        }
    }
}

/// The recorded figures of `model` for the sources this run does not produce (CPU code paths,
/// another Mesa, recorded hosts), as ratios against the case's limits.
fn recorded_noise(case: &Case, model: &NoiseModel, noise: &mut Vec<NoiseResult>) {
    let Some(passes) = model.scenes.get(case.name()) else {
        return;
    };
    for (name, checks) in passes {
        // The file's keys are names; one the case has no golden pass for is not its noise.
        let Some((pass, rule)) = name
            .parse::<TargetId>()
            .ok()
            .and_then(|pass| Some((pass, case.rules.get(&pass)?)))
        else {
            continue;
        };
        for (metric, limit) in rule.checks() {
            let Some(figures) = checks.get(&metric.to_string()) else {
                continue;
            };
            for (key, &value) in &figures.noise {
                let (source, backend) = key.split_once('/').unwrap_or((key, "-"));
                if source == "drivers" || source == "synthetic-rounding" {
                    continue;
                }
                noise.push(NoiseResult {
                    source: source.to_owned(),
                    scene: case.name().to_owned(),
                    backend: backend.parse().ok(),
                    pass,
                    ratio: crate::golden::tolerance::ratio(value, limit, false),
                    live: false,
                });
            }
        }
    }
}

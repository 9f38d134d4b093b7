//! Per-pass benchmarks (`cargo bench --bench passes`): for every canonical scene on every
//! available backend, group `<scene>/<backend>` times
//!
//! - `<pass>`: each pass of the scene's plan, GPU time from timestamp queries (a point light's
//!   six face passes count as its shadow pass), one full render per iteration;
//! - `<pass>/floor`: that pass's floor, a trivial full-screen pass writing the same targets
//!   (`harness::measure::bench::Floors`), submitted alone;
//! - `frame`: every pass of the frame together.
//!
//! Backends without timestamps are timed by wall clock around the whole render or submit, and
//! say so. Flat sampling with ten samples of two iterations each (sized from one timed
//! iteration, so criterion does not warn that it cannot complete them) keeps the whole run to a
//! few minutes here; `harness bench` prints the same figures as a table with ratios, quicker.

use std::time::{Duration, Instant};

use criterion::{criterion_group, criterion_main, BenchmarkId, Criterion, SamplingMode};
use engine::backend::{self, Backend, BackendKind};
use engine::plan::PassId;
use engine::renderer::PreparedFrame;
use engine::scene::Scene;
use harness::measure::bench::Floors;

/// GPU time of plan pass `pass` (every pass when `None`) in one render of `frame` (wall time
/// of the render when the backend has no timestamps).
fn timed_render(
    backend: &mut dyn Backend,
    frame: &PreparedFrame,
    pass: Option<PassId>,
) -> Duration {
    harness::measure::bench::timed_render(backend, frame, |timings| match pass {
        Some(pass) => timings.pass_time(pass),
        None => timings.total(),
    })
}

/// Sets the group's warm-up and measurement time for a benchmark from one run of its routine
/// ([`harness::measure::bench::criterion_budget`]).
fn budget(
    group: &mut criterion::BenchmarkGroup<'_, criterion::measurement::WallTime>,
    run_once: impl FnOnce(),
) {
    let (warm_up, measurement) = harness::measure::bench::criterion_budget(run_once, SAMPLES);
    group.warm_up_time(warm_up);
    group.measurement_time(measurement);
}

/// Samples per benchmark (criterion's least).
const SAMPLES: usize = 10;

fn passes(c: &mut Criterion) {
    let names = engine::scene_file::canonical_scenes(&harness::scenes_dir());
    let scenes: Vec<Scene> = names
        .iter()
        .map(|n| harness::load_scene(n).expect("canonical scene").scene)
        .collect();
    for kind in BackendKind::ALL {
        let mut backend = match backend::create(kind) {
            Ok(b) => b,
            Err(e) => {
                eprintln!("skipping {kind}: {e}");
                continue;
            }
        };
        if !backend.info().timestamps {
            eprintln!("{kind}: no GPU timestamps; timing by wall clock");
        }
        for scene in &scenes {
            let prepared = PreparedFrame::new(scene).expect("canonical scene renders");
            let plan = prepared.plan();
            let floors = Floors::new(backend.as_mut(), plan).expect("floor passes");
            let mut group = c.benchmark_group(format!("{}/{kind}", scene.name));
            group.sampling_mode(SamplingMode::Flat);
            group.sample_size(SAMPLES);
            budget(&mut group, || {
                timed_render(backend.as_mut(), &prepared, None);
            });
            group.bench_function("frame", |b| {
                b.iter_custom(|iters| {
                    (0..iters)
                        .map(|_| timed_render(backend.as_mut(), &prepared, None))
                        .sum()
                })
            });
            for spec in &plan.passes {
                let name = spec.id.to_string();
                budget(&mut group, || {
                    timed_render(backend.as_mut(), &prepared, Some(spec.id));
                });
                group.bench_function(BenchmarkId::new(&name, "pass"), |b| {
                    b.iter_custom(|iters| {
                        (0..iters)
                            .map(|_| timed_render(backend.as_mut(), &prepared, Some(spec.id)))
                            .sum()
                    })
                });
                budget(&mut group, || {
                    floors.time(backend.as_mut(), spec.id).expect("floor pass");
                });
                group.bench_function(BenchmarkId::new(&name, "floor"), |b| {
                    b.iter_custom(|iters| {
                        (0..iters)
                            .map(|_| {
                                let start = Instant::now();
                                let ns =
                                    floors.time(backend.as_mut(), spec.id).expect("floor pass");
                                ns.map_or(start.elapsed(), |ns| Duration::from_nanos(ns as u64))
                            })
                            .sum()
                    })
                });
            }
            group.finish();
            floors.destroy(backend.as_mut());
        }
    }
}

criterion_group!(benches, passes);
criterion_main!(benches);

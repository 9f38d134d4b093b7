//! Shadow benchmarks (`cargo bench --bench shadows`): GPU time, from timestamp queries, of
//!
//! - a point light's six shadow faces drawn as six passes against the Quarantamaula engine's single pass through
//!   a geometry shader (gl only), on arrow;
//! - each shadow filter on chess's sun: the map passes (`shadow_0`, and VSM's blur), and the
//!   filter itself, timed on the lighting shader's own lookup run for every pixel (the
//!   `shadow_term_0` debug pass), so the stratified soft filter's outer-ring early-out shows
//!   against the full 16-sample kernel without the BRDF around it.
//!
//! Each iteration renders the whole frame and reports only the GPU time of the passes named, so
//! the figures are comparable within one run. A backend without timestamps is timed by wall
//! clock around the whole render instead (and says so). Unavailable backends are skipped with
//! their reason on stderr.
//!
//! Flat sampling with ten samples keeps the run short on a 2-core machine: every figure is the
//! mean of ten frames, each a full render.

use std::time::Duration;

use criterion::{criterion_group, criterion_main, BenchmarkId, Criterion, SamplingMode};
use engine::backend::{self, Backend, BackendKind};
use engine::plan::PassId;
use engine::renderer::PreparedFrame;
use engine::scene::{Light, PointShadowPass, Scene, ShadowFilter};

/// GPU time of the passes `of` selects in one render of `scene` (wall time of the render where
/// the backend has no timestamps).
fn timed_render(
    backend: &mut dyn Backend,
    scene: &PreparedFrame,
    of: impl Fn(PassId) -> bool,
) -> Duration {
    harness::measure::bench::timed_render(backend, scene, |timings| {
        timings
            .passes
            .iter()
            .zip(&timings.owners)
            .filter(|(_, owner)| of(**owner))
            .map(|(t, _)| t.gpu_ns)
            .sum()
    })
}

/// Light 0's shadow map: its caster pass and, with VSM, its blur passes.
fn shadow_0_map(pass: PassId) -> bool {
    matches!(
        pass,
        PassId::Shadow { light: 0 } | PassId::ShadowBlur { light: 0, .. }
    )
}

fn prepared(scene: &Scene) -> PreparedFrame {
    PreparedFrame::new(scene).unwrap_or_else(|e| panic!("{}: {e}", scene.name))
}

fn with_filter(scene: &Scene, filter: ShadowFilter) -> Scene {
    let mut scene = scene.clone();
    scene.quality.debug_shadow_terms = true;
    for light in &mut scene.lights {
        if let Light::Directional {
            shadow: Some(s), ..
        } = light
        {
            s.filter = filter;
        }
    }
    scene
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

fn shadows(c: &mut Criterion) {
    let arrow = harness::load_scene("arrow").expect("arrow").scene;
    let chess = harness::load_scene("chess").expect("chess").scene;
    for kind in BackendKind::ALL {
        let mut backend = match backend::create(kind) {
            Ok(b) => b,
            Err(e) => {
                eprintln!("skipping {kind}: {e}");
                continue;
            }
        };
        if !backend.info().timestamps {
            eprintln!("{kind}: no GPU timestamps; timing whole renders by wall clock");
        }

        let mut group = c.benchmark_group(format!("arrow/{kind}"));
        group.sampling_mode(SamplingMode::Flat);
        group.sample_size(SAMPLES);
        let mut paths = vec![PointShadowPass::SixPasses];
        if backend.features().geometry_shaders {
            paths.push(PointShadowPass::GeometryShader);
        }
        for path in paths {
            let mut scene = arrow.clone();
            scene.quality.point_shadows = path;
            let scene = prepared(&scene);
            budget(&mut group, || {
                timed_render(backend.as_mut(), &scene, shadow_0_map);
            });
            group.bench_function(BenchmarkId::new("shadow_0", path.name()), |b| {
                b.iter_custom(|iters| {
                    (0..iters)
                        .map(|_| timed_render(backend.as_mut(), &scene, shadow_0_map))
                        .sum()
                })
            });
        }
        group.finish();

        let mut group = c.benchmark_group(format!("chess/{kind}"));
        group.sampling_mode(SamplingMode::Flat);
        group.sample_size(SAMPLES);
        for filter in [
            ShadowFilter::Hard,
            ShadowFilter::Pcf3,
            ShadowFilter::Soft,
            ShadowFilter::SoftFull,
            ShadowFilter::SoftReference,
            ShadowFilter::Vsm,
        ] {
            let scene = prepared(&with_filter(&chess, filter));
            let term = |pass| pass == PassId::ShadowTerm { light: 0 };
            let selections: [(&str, &dyn Fn(PassId) -> bool); 2] =
                [("shadow_0_map", &shadow_0_map), ("shadow_term_0", &term)];
            for (label, of) in selections {
                budget(&mut group, || {
                    timed_render(backend.as_mut(), &scene, of);
                });
                group.bench_function(BenchmarkId::new(label, filter.name()), |b| {
                    b.iter_custom(|iters| {
                        (0..iters)
                            .map(|_| timed_render(backend.as_mut(), &scene, of))
                            .sum()
                    })
                });
            }
        }
        group.finish();
    }
}

criterion_group!(benches, shadows);
criterion_main!(benches);

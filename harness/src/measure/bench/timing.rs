//! Timing the passes: a frame's pass timings from GPU timestamps, their medians over frames,
//! and a scene's every pass against its floor and, for lighting passes, its input floor.

use std::time::Instant;

use engine::backend::{self, Backend, BackendKind};
use engine::plan::{LightingFeature, PassKind};
use engine::plan::{PassSpec, RenderPlan};
use engine::renderer::{self, Faults, Readback};
use engine::scene::Scene;
use engine::stats::{median, percentile};

use super::{BenchError, Floors};

/// Timing of one plan pass.
#[derive(Clone, Debug, serde::Serialize)]
pub struct PassBench {
    /// Plan pass name.
    pub pass: String,
    /// Median GPU time, ms (None without timestamps).
    pub median_ms: Option<f64>,
    /// Median GPU time of its floor, ms.
    pub floor_ms: Option<f64>,
    /// `median_ms / floor_ms`.
    pub ratio: Option<f64>,
    /// Lighting passes: median GPU time of the pass reading its inputs and shading nothing, ms.
    pub input_floor_ms: Option<f64>,
    /// `median_ms / input_floor_ms`.
    pub input_ratio: Option<f64>,
}

/// Timing of one scene on one backend.
#[derive(Clone, Debug, serde::Serialize)]
pub struct SceneBench {
    /// Scene name.
    pub scene: String,
    /// Backend name.
    pub backend: String,
    /// Output size.
    pub width: u32,
    /// Output height.
    pub height: u32,
    /// Frames timed (after one warm-up frame).
    pub frames: usize,
    /// Per plan pass, in plan order.
    pub passes: Vec<PassBench>,
    /// Median over frames of the sum of every pass, ms.
    pub frame_ms: Option<f64>,
    /// Median wall time of a whole render (setup, uploads, readback of nothing), ms.
    pub wall_ms: f64,
    /// The geometry pass's floor: writing the G-buffer and depth once, ms.
    pub gbuffer_floor_ms: Option<f64>,
    /// `frame_ms / gbuffer_floor_ms`.
    pub frame_to_gbuffer_floor: Option<f64>,
}

/// GPU ns of plan pass `spec` in one frame's timings: the render passes named like it (a point
/// light's faces are `<name>+x` .. `<name>-z`). None when the backend has no timestamps.
pub fn pass_time(timings: &[backend::PassTiming], spec: &PassSpec) -> Option<f64> {
    let mut matched = timings.iter().filter(|t| {
        t.name == spec.name
            || (t.name.starts_with(&spec.name)
                && matches!(t.name.as_bytes().get(spec.name.len()), Some(b'+' | b'-')))
    });
    let first = matched.next()?.gpu_ns?;
    matched.try_fold(first, |sum, t| t.gpu_ns.map(|ns| sum + ns))
}

/// Renders `scene` once (nothing read back) for the criterion benchmarks: the GPU ns `pick`
/// takes from the frame's pass timings, or the render's wall time when it gives none (no
/// timestamps). Panics on a failed render, as a benchmark should.
pub fn timed_render(
    backend: &mut dyn Backend,
    scene: &Scene,
    pick: impl FnOnce(&[backend::PassTiming]) -> Option<f64>,
) -> std::time::Duration {
    let start = Instant::now();
    let frame = renderer::render(backend, scene, Readback::Only(&[]))
        .unwrap_or_else(|e| panic!("{}: {e}", scene.name));
    let wall = start.elapsed();
    pick(&frame.timings).map_or(wall, |ns| std::time::Duration::from_nanos(ns as u64))
}

/// Renders `scene` once to warm up, then `frames` times: each frame's pass timings and wall ms.
/// With `without`, the lighting passes run without that part of their work.
pub(super) fn time_frames(
    backend: &mut dyn Backend,
    scene: &Scene,
    frames: usize,
    without: Option<LightingFeature>,
) -> Result<(Vec<Vec<backend::PassTiming>>, Vec<f64>), BenchError> {
    let mut timings = Vec::with_capacity(frames);
    let mut wall = Vec::with_capacity(frames);
    for i in 0..=frames {
        let (frame, ms) = time_frame(backend, scene, without)?;
        if i > 0 {
            wall.push(ms);
            timings.push(frame);
        }
    }
    Ok((timings, wall))
}

/// Renders `scene` once (nothing read back): its pass timings and wall ms.
pub(super) fn time_frame(
    backend: &mut dyn Backend,
    scene: &Scene,
    without: Option<LightingFeature>,
) -> Result<(Vec<backend::PassTiming>, f64), BenchError> {
    let faults = Faults {
        remove_lighting: without,
        ..Faults::default()
    };
    let start = Instant::now();
    let frame = renderer::render_with_faults(backend, scene, Readback::Only(&[]), &faults)
        .map_err(|e| BenchError::Render {
            scene: scene.name.clone(),
            backend: backend.kind().name().to_owned(),
            message: e.to_string(),
        })?;
    Ok((frame.timings, start.elapsed().as_secs_f64() * 1e3))
}

/// Median GPU ms of plan pass `name` over frames (None if the plan has no such pass or the
/// backend no timestamps).
pub(super) fn median_pass_ms(
    plan: &RenderPlan,
    timings: &[Vec<backend::PassTiming>],
    name: &str,
) -> Option<f64> {
    percentile_pass_ms(plan, timings, name, 0.5)
}

/// The `p` percentile (nearest rank) over frames of plan pass `name`'s GPU ms.
pub(super) fn percentile_pass_ms(
    plan: &RenderPlan,
    timings: &[Vec<backend::PassTiming>],
    name: &str,
    p: f64,
) -> Option<f64> {
    let spec = plan.passes.iter().find(|p| p.name == name)?;
    percentile(
        timings
            .iter()
            .filter_map(|t| pass_time(t, spec))
            .map(|ns| ns / 1e6)
            .collect(),
        p,
    )
}

/// Median GPU ms of whole frames.
pub(super) fn median_frame_ms(timings: &[Vec<backend::PassTiming>]) -> Option<f64> {
    median(
        timings
            .iter()
            .filter_map(|t| {
                t.iter()
                    .map(|p| p.gpu_ns)
                    .sum::<Option<f64>>()
                    .map(|ns| ns / 1e6)
            })
            .collect(),
    )
}

/// Times `scene` on `kind`: one warm-up frame, then `frames` frames, each pass and its floor.
pub fn bench_scene(
    scene: &Scene,
    kind: BackendKind,
    frames: usize,
) -> Result<SceneBench, BenchError> {
    let backend_error = |e: backend::BackendError| BenchError::Backend {
        backend: kind.name().to_owned(),
        message: e.to_string(),
    };
    let mut backend = backend::create(kind).map_err(backend_error)?;
    let frames = frames.max(1);
    let plan = RenderPlan::new(scene);
    let (timings, wall) = time_frames(backend.as_mut(), scene, frames, None)?;
    let has_lighting = plan
        .passes
        .iter()
        .any(|p| matches!(p.kind, PassKind::Lighting(_)));
    let input_floor_timings = if has_lighting {
        time_frames(
            backend.as_mut(),
            scene,
            frames,
            Some(LightingFeature::Shading),
        )?
        .0
    } else {
        Vec::new()
    };
    let floors = Floors::new(backend.as_mut(), &plan).map_err(backend_error)?;
    let mut passes = Vec::with_capacity(plan.passes.len());
    let mut floor_result = Ok(());
    for spec in &plan.passes {
        let median_ms = median_pass_ms(&plan, &timings, &spec.name);
        let mut floor_times = Vec::with_capacity(frames);
        for _ in 0..=frames {
            match floors.time(backend.as_mut(), &spec.name) {
                Ok(Some(ns)) => floor_times.push(ns / 1e6),
                Ok(None) => {}
                Err(e) => floor_result = Err(e),
            }
        }
        // The first floor submit is the warm-up.
        if !floor_times.is_empty() {
            floor_times.remove(0);
        }
        let floor_ms = median(floor_times);
        let input_floor_ms = matches!(spec.kind, PassKind::Lighting(_))
            .then(|| median_pass_ms(&plan, &input_floor_timings, &spec.name))
            .flatten();
        passes.push(PassBench {
            pass: spec.name.clone(),
            median_ms,
            floor_ms,
            ratio: median_ms.zip(floor_ms).map(|(p, f)| p / f),
            input_floor_ms,
            input_ratio: median_ms.zip(input_floor_ms).map(|(p, f)| p / f),
        });
    }
    floors.destroy(backend.as_mut());
    floor_result.map_err(backend_error)?;
    let frame_ms = median_frame_ms(&timings);
    let gbuffer_floor_ms = passes
        .iter()
        .find(|p| p.pass == "geometry")
        .and_then(|p| p.floor_ms);
    Ok(SceneBench {
        scene: scene.name.clone(),
        backend: kind.name().to_owned(),
        width: scene.quality.width,
        height: scene.quality.height,
        frames,
        passes,
        frame_ms,
        wall_ms: median(wall).unwrap_or(0.0),
        gbuffer_floor_ms,
        frame_to_gbuffer_floor: frame_ms.zip(gbuffer_floor_ms).map(|(f, g)| f / g),
    })
}

//! Timing the passes: a frame's pass timings from GPU timestamps, their medians over frames,
//! and a scene's every pass against its floor and, for lighting passes, its input floor.

use std::time::Instant;

use engine::backend::{self, Backend, BackendKind};
use engine::plan::{LightingFeature, PassId};
use engine::renderer::{self, PassTimes, PreparedFrame, Readback, Variations};
use engine::scene::Scene;
use engine::stats::{median, percentile};

use super::{BenchError, Floors};

/// Timing of one plan pass.
#[derive(Clone, Debug, serde::Serialize)]
pub struct PassBench {
    /// Plan pass.
    pub pass: PassId,
    /// Median GPU time, ms (None without timestamps).
    pub median_ms: Option<f64>,
    /// Median GPU time of its floor, ms.
    pub floor_ms: Option<f64>,
    /// The pass's time over its floor's, per frame (the floor submitted right after that
    /// frame), at the lower quartile over frames.
    pub ratio: Option<f64>,
    /// Those per-frame ratios, in frame order.
    pub frame_ratios: Vec<f64>,
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
    /// Backend.
    pub backend: BackendKind,
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

/// Renders `scene` once (nothing read back) for the criterion benchmarks: the GPU ns `pick`
/// takes from the frame's pass times, or the render's wall time when it gives none (no
/// timestamps). Panics on a failed render, as a benchmark should.
pub fn timed_render(
    backend: &mut dyn Backend,
    prepared: &PreparedFrame,
    pick: impl FnOnce(&PassTimes) -> Option<f64>,
) -> std::time::Duration {
    let start = Instant::now();
    let frame = renderer::render_prepared(backend, prepared, Readback::Only(&[]))
        .unwrap_or_else(|e| panic!("{}: {e}", prepared.scene().name));
    let wall = start.elapsed();
    pick(&frame.timings).map_or(wall, |ns| std::time::Duration::from_nanos(ns as u64))
}

/// The scene's frame prepared for timing on `kind`, its plan error named as a render error.
pub(super) fn prepare(scene: &Scene, kind: BackendKind) -> Result<PreparedFrame, BenchError> {
    PreparedFrame::new(scene).map_err(|e| BenchError::Render {
        scene: scene.name.clone(),
        backend: kind,
        message: e.to_string(),
    })
}

/// Renders `prepared` once to warm up, then `frames` times: each frame's pass times and wall
/// ms.
pub(super) fn time_frames(
    backend: &mut dyn Backend,
    prepared: &PreparedFrame,
    frames: usize,
) -> Result<(Vec<PassTimes>, Vec<f64>), BenchError> {
    let mut timings = Vec::with_capacity(frames);
    let mut wall = Vec::with_capacity(frames);
    for i in 0..=frames {
        let (frame, ms) = time_frame(backend, prepared)?;
        if i > 0 {
            wall.push(ms);
            timings.push(frame);
        }
    }
    Ok((timings, wall))
}

/// Renders `prepared` once (nothing read back): its pass times and wall ms.
pub fn time_frame(
    backend: &mut dyn Backend,
    prepared: &PreparedFrame,
) -> Result<(PassTimes, f64), BenchError> {
    let start = Instant::now();
    let frame = renderer::render_prepared(backend, prepared, Readback::Only(&[])).map_err(|e| {
        BenchError::Render {
            scene: prepared.scene().name.clone(),
            backend: backend.kind(),
            message: e.to_string(),
        }
    })?;
    Ok((frame.timings, start.elapsed().as_secs_f64() * 1e3))
}

/// Median GPU ms of plan pass `pass` over frames (None if it did not run or the backend has
/// no timestamps).
pub(super) fn median_pass_ms(timings: &[PassTimes], pass: PassId) -> Option<f64> {
    percentile_pass_ms(timings, pass, 0.5)
}

/// The `p` percentile (nearest rank) over frames of plan pass `pass`'s GPU ms.
pub fn percentile_pass_ms(timings: &[PassTimes], pass: PassId, p: f64) -> Option<f64> {
    percentile(
        timings
            .iter()
            .filter_map(|t| t.pass_time(pass))
            .map(|ns| ns / 1e6)
            .collect(),
        p,
    )
}

/// Median GPU ms of whole frames.
pub(super) fn median_frame_ms(timings: &[PassTimes]) -> Option<f64> {
    median(
        timings
            .iter()
            .filter_map(|t| t.total().map(|ns| ns / 1e6))
            .collect(),
    )
}

/// The quantile of a pass's per-frame ratios [`PassBench::ratio`] reports: the lower quartile,
/// as the breakdown's parts (llvmpipe's frame times of a short pass fall in a fast and a slow
/// cluster; a low quantile measures the work, a median jumps between the clusters).
const RATIO_PERCENTILE: f64 = 0.25;

/// Frames timed with each pass's floor right after the frame (see [`time_interleaved`]).
struct Interleaved {
    /// Each frame's pass times.
    timings: Vec<PassTimes>,
    /// Each frame's wall ms.
    wall: Vec<f64>,
    /// Each pass's floor ms, a value per frame.
    floors: std::collections::BTreeMap<PassId, Vec<f64>>,
    /// Each pass's time over its floor's, a value per frame.
    ratios: std::collections::BTreeMap<PassId, Vec<f64>>,
}

/// Renders `prepared` once to warm up (and submits every floor once), then `frames` times,
/// each frame followed by one submit of every pass's floor: each frame's ratios are of times
/// taken moments apart, so a change of the machine's speed between frames (a busy neighbour, a
/// frequency step) falls on the pass and its floor alike.
fn time_interleaved(
    backend: &mut dyn Backend,
    prepared: &PreparedFrame,
    floors: &Floors,
    frames: usize,
) -> Result<Interleaved, BenchError> {
    let kind = backend.kind();
    let floor_error = |e: backend::BackendError| BenchError::Backend {
        backend: kind,
        message: e.to_string(),
    };
    let mut out = Interleaved {
        timings: Vec::with_capacity(frames),
        wall: Vec::with_capacity(frames),
        floors: Default::default(),
        ratios: Default::default(),
    };
    for round in 0..=frames {
        let (times, ms) = time_frame(backend, prepared)?;
        for spec in &prepared.plan().passes {
            let floor = floors.time(backend, spec.id).map_err(floor_error)?;
            if round == 0 {
                continue;
            }
            let Some(floor_ns) = floor else {
                continue;
            };
            out.floors.entry(spec.id).or_default().push(floor_ns / 1e6);
            if let Some(pass_ns) = times.pass_time(spec.id) {
                out.ratios
                    .entry(spec.id)
                    .or_default()
                    .push(pass_ns / floor_ns);
            }
        }
        if round > 0 {
            out.wall.push(ms);
            out.timings.push(times);
        }
    }
    Ok(out)
}

/// Times `scene` on `kind`: one warm-up frame, then `frames` frames, each followed by every
/// pass's floor.
pub fn bench_scene(
    scene: &Scene,
    kind: BackendKind,
    frames: usize,
) -> Result<SceneBench, BenchError> {
    bench_scene_with(scene, kind, frames, Variations::default())
}

/// [`bench_scene`] with `variations` applied to the frames timed (not to the input floor's):
/// `slow_pass` shows how a slower pass shows in the ratios.
pub fn bench_scene_with(
    scene: &Scene,
    kind: BackendKind,
    frames: usize,
    variations: Variations,
) -> Result<SceneBench, BenchError> {
    let backend_error = |e: backend::BackendError| BenchError::Backend {
        backend: kind,
        message: e.to_string(),
    };
    let mut backend = crate::faults::create_backend(kind).map_err(backend_error)?;
    let frames = frames.max(1);
    let prepared = prepare(scene, kind)?;
    let plan = prepared.plan();
    let floors = Floors::new(backend.as_mut(), plan).map_err(backend_error)?;
    let varied = prepared.clone().with_variations(variations);
    let interleaved = time_interleaved(backend.as_mut(), &varied, &floors, frames);
    floors.destroy(backend.as_mut());
    let Interleaved {
        timings,
        wall,
        floors: floor_times,
        ratios,
    } = interleaved?;
    let has_lighting = plan
        .passes
        .iter()
        .any(|p| matches!(p.id, PassId::Lighting(_)));
    let input_floor_timings = if has_lighting {
        let input_floor = prepared.clone().with_variations(Variations {
            remove_lighting: Some(LightingFeature::Shading),
            ..Variations::default()
        });
        time_frames(backend.as_mut(), &input_floor, frames)?.0
    } else {
        Vec::new()
    };
    let mut passes = Vec::with_capacity(plan.passes.len());
    for spec in &plan.passes {
        let median_ms = median_pass_ms(&timings, spec.id);
        let floor_ms = floor_times.get(&spec.id).and_then(|t| median(t.clone()));
        let input_floor_ms = matches!(spec.id, PassId::Lighting(_))
            .then(|| median_pass_ms(&input_floor_timings, spec.id))
            .flatten();
        let frame_ratios = ratios.get(&spec.id).cloned().unwrap_or_default();
        let ratio = percentile(frame_ratios.clone(), RATIO_PERCENTILE);
        passes.push(PassBench {
            pass: spec.id,
            median_ms,
            floor_ms,
            ratio,
            frame_ratios,
            input_floor_ms,
            input_ratio: median_ms.zip(input_floor_ms).map(|(p, f)| p / f),
        });
    }
    let frame_ms = median_frame_ms(&timings);
    let gbuffer_floor_ms = passes
        .iter()
        .find(|p| p.pass == PassId::Geometry)
        .and_then(|p| p.floor_ms);
    Ok(SceneBench {
        scene: scene.name.clone(),
        backend: kind,
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

//! Per-pass timing against floors: where a frame's time goes, and how close each pass is to what
//! the driver can do at all.
//!
//! A pass's time is its GPU time from timestamp queries (the sum over its render passes: a point
//! light's six faces count as its shadow pass), the median over several frames. Its floor is the
//! cheapest pass writing the same targets (same formats and sizes) over every pixel: a
//! full-screen triangle writing constants (`floor.wgsl`), depth included where the pass writes
//! depth, timed the same way in the same run. The ratio pass / floor is what compares across
//! machines; the milliseconds do not.
//!
//! A lighting pass has a second, more honest floor: its *input floor*, the same pass (same
//! routing, same draws) with every draw's shading replaced by reading the inputs its model
//! reads (the G-buffer targets it uses, and depth where positions come from it) and writing
//! their sum. Pass / input floor is
//! the cost of shading alone. `harness bench --breakdown` goes further and times each lighting
//! pass with one part of its work taken away at a time ([`breakdown`]).
//!
//! `harness bench` prints this per scene and backend, and the criterion benchmarks in `benches/`
//! use the same [`Floors`] and [`pass_time`].

use std::collections::BTreeMap;
use std::time::Instant;

use engine::backend::{
    self, Backend, BackendKind, ColorAttachment, ColorTarget, CompareFunction, CullMode,
    DepthAttachment, DepthState, Draw, Handle, LoadOp, Pipeline, PipelineDesc, RenderPass,
    ResourceScope, ShaderDesc, Subresource, Texture, TextureDesc, Topology,
};
use engine::plan::{LightingFeature, PassKind};
use engine::plan::{PassSpec, RenderPlan};
use engine::renderer::{self, Faults, Readback};
use engine::scene::Scene;
use engine::shaders;
use engine::stats::median;

/// Why a benchmark could not run.
#[derive(Debug, thiserror::Error)]
pub enum BenchError {
    /// The backend is missing or failed.
    #[error("{backend}: {message}")]
    Backend {
        /// Backend name.
        backend: String,
        /// What went wrong.
        message: String,
    },
    /// Rendering the scene failed.
    #[error("scene `{scene}` on {backend}: {message}")]
    Render {
        /// Scene name.
        scene: String,
        /// Backend name.
        backend: String,
        /// What went wrong.
        message: String,
    },
}

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

/// Work done once, not per frame, timed apart from frames.
#[derive(Clone, Debug, serde::Serialize)]
pub struct Precompute {
    /// What is computed.
    pub what: String,
    /// Where it runs.
    pub on: String,
    /// Median time of a few runs, ms.
    pub ms: f64,
}

/// The precomputation the renderer does once per process, timed (median of 5 runs): the
/// stratified soft filter's jitter texture (CPU). The IBL maps join this list when they exist.
pub fn precompute() -> Vec<Precompute> {
    let runs: Vec<f64> = (0..5)
        .map(|_| {
            let start = Instant::now();
            std::hint::black_box(engine::renderer::shadows::compute_jitter_texels());
            start.elapsed().as_secs_f64() * 1e3
        })
        .collect();
    let mut out = vec![Precompute {
        what: "shadow jitter texture (32x32x8 RGBA16F)".to_owned(),
        on: "CPU, once per process".to_owned(),
        ms: median(runs).unwrap_or(0.0),
    }];
    out.extend(ibl_precompute());
    out
}

/// The IBL maps of the canonical environments at default settings: built from scratch (the DFG
/// table apart, as it is computed once per process), read back from a disk cache, and found in
/// memory (a second render in the same process). A build (about a second or two) and the DFG
/// table are timed once; the cache reads, median of 3.
fn ibl_precompute() -> Vec<Precompute> {
    use engine::ibl;
    let mut out = Vec::new();
    let start = Instant::now();
    std::hint::black_box(ibl::dfg::table(ibl::dfg::SIZE, ibl::dfg::SAMPLES));
    out.push(Precompute {
        what: format!(
            "IBL DFG table ({}x{}, {} samples)",
            ibl::dfg::SIZE,
            ibl::dfg::SIZE,
            ibl::dfg::SAMPLES
        ),
        on: "CPU, once per process".to_owned(),
        ms: start.elapsed().as_secs_f64() * 1e3,
    });
    ibl::dfg_table();
    let settings = ibl::IblSettings::default();
    let Ok(cache) = tempfile::tempdir() else {
        return out;
    };
    for name in ["sunset.exr", "interior.exr"] {
        let path = crate::scenes_dir().join("assets").join(name);
        let Ok(env) = engine::assets::load_environment(&path) else {
            continue;
        };
        let image = engine::scene::EnvironmentImage {
            label: name.to_owned(),
            width: env.width,
            height: env.height,
            texels: env.texels,
        };
        let timed = |f: &mut dyn FnMut()| {
            median(
                (0..3)
                    .map(|_| {
                        let start = Instant::now();
                        f();
                        start.elapsed().as_secs_f64() * 1e3
                    })
                    .collect(),
            )
            .unwrap_or(0.0)
        };
        let start = Instant::now();
        let maps = ibl::build(&image, &settings);
        out.push(Precompute {
            what: format!("IBL maps of {name}: {}", settings.describe()),
            on: "CPU, built".to_owned(),
            ms: start.elapsed().as_secs_f64() * 1e3,
        });
        let key = ibl::cache::key(&image, &settings);
        if ibl::cache::write(cache.path(), &key, &maps).is_ok() {
            let read = timed(&mut || {
                let key = ibl::cache::key(&image, &settings);
                std::hint::black_box(ibl::cache::read(cache.path(), &key));
            });
            out.push(Precompute {
                what: format!(
                    "IBL maps of {name}, from the disk cache (hash texels, read, verify)"
                ),
                on: "CPU, new process".to_owned(),
                ms: read,
            });
            let shared = std::sync::Arc::new(image);
            let previous = ibl::cache::directory();
            ibl::cache::set_directory(Some(cache.path().to_path_buf()));
            ibl::prepare(&shared, &settings);
            let again = timed(&mut || {
                std::hint::black_box(ibl::prepare(&shared, &settings));
            });
            ibl::cache::set_directory(previous);
            out.push(Precompute {
                what: format!("IBL maps of {name}, next frame of the same scene"),
                on: "CPU, in memory".to_owned(),
                ms: again,
            });
        }
    }
    out
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

/// Floor passes for every pass of a plan, created once on a backend and submitted on demand.
pub struct Floors {
    scope: ResourceScope,
    passes: BTreeMap<String, RenderPass>,
}

impl Floors {
    /// Creates the targets and pipelines of every pass's floor.
    pub fn new(backend: &mut dyn Backend, plan: &RenderPlan) -> backend::Result<Self> {
        let mut scope = ResourceScope::default();
        let result = Self::record(backend, plan, &mut scope);
        match result {
            Ok(passes) => Ok(Self { scope, passes }),
            Err(e) => {
                scope.destroy(backend);
                Err(e)
            }
        }
    }

    fn record(
        backend: &mut dyn Backend,
        plan: &RenderPlan,
        scope: &mut ResourceScope,
    ) -> backend::Result<BTreeMap<String, RenderPass>> {
        let shader = scope.shader(
            backend,
            &ShaderDesc {
                name: shaders::FLOOR.name.to_owned(),
                wgsl: shaders::FLOOR.wgsl.to_owned(),
            },
        )?;
        let mut pipelines: BTreeMap<String, Handle<Pipeline>> = BTreeMap::new();
        let mut passes = BTreeMap::new();
        for spec in &plan.passes {
            let targets: Vec<_> = spec.writes.iter().filter_map(|w| plan.target(w)).collect();
            let colors: Vec<_> = targets.iter().filter(|t| !t.format.is_depth()).collect();
            let depth = targets.iter().find(|t| t.format.is_depth());
            if colors.len() > 5 || (colors.is_empty() && depth.is_none()) {
                continue;
            }
            let key = format!(
                "{:?} {:?}",
                colors.iter().map(|t| t.format).collect::<Vec<_>>(),
                depth.map(|t| t.format)
            );
            let pipeline = match pipelines.get(&key) {
                Some(p) => *p,
                None => {
                    let p = scope.pipeline(
                        backend,
                        &PipelineDesc {
                            label: format!("floor {key}"),
                            shader,
                            vertex_entry: "vs_fullscreen".to_owned(),
                            fragment_entry: (!colors.is_empty())
                                .then(|| format!("fs_floor_{}", colors.len())),
                            vertex_buffers: vec![],
                            bindings: vec![],
                            color_targets: colors
                                .iter()
                                .map(|t| ColorTarget {
                                    format: t.format,
                                    blend: None,
                                })
                                .collect(),
                            depth: depth.map(|t| DepthState {
                                format: t.format,
                                write: true,
                                compare: CompareFunction::Always,
                            }),
                            topology: Topology::TriangleList,
                            cull: CullMode::None,
                            geometry: None,
                            constants: vec![],
                        },
                    )?;
                    pipelines.insert(key, p);
                    p
                }
            };
            let mut texture =
                |spec: &engine::plan::TargetSpec| -> backend::Result<Handle<Texture>> {
                    scope.texture(
                        backend,
                        &TextureDesc::d2(
                            &format!("floor {}", spec.name),
                            spec.width,
                            spec.height,
                            spec.format,
                        ),
                    )
                };
            let mut color_attachments = Vec::new();
            for t in &colors {
                color_attachments.push(ColorAttachment {
                    texture: texture(t)?,
                    subresource: Subresource::default(),
                    load: LoadOp::Clear([0.0; 4]),
                });
            }
            let depth_attachment = match depth {
                Some(t) => Some(DepthAttachment {
                    texture: texture(t)?,
                    subresource: Subresource::default(),
                    load: LoadOp::Clear(1.0),
                }),
                None => None,
            };
            passes.insert(
                spec.name.clone(),
                RenderPass {
                    name: format!("{} floor", spec.name),
                    color_attachments,
                    depth_attachment,
                    viewports: vec![],
                    draws: vec![Draw {
                        pipeline,
                        bindings: vec![],
                        vertex_buffers: vec![],
                        index_buffer: None,
                        count: 3,
                    }],
                },
            );
        }
        Ok(passes)
    }

    /// Submits the floor of plan pass `pass` once; its GPU ns (None without timestamps or when
    /// the pass has no floor).
    pub fn time(&self, backend: &mut dyn Backend, pass: &str) -> backend::Result<Option<f64>> {
        let Some(floor) = self.passes.get(pass) else {
            return Ok(None);
        };
        let timings = backend.submit(std::slice::from_ref(floor))?;
        Ok(timings.first().and_then(|t| t.gpu_ns))
    }

    /// Destroys the floors' resources.
    pub fn destroy(self, backend: &mut dyn Backend) {
        self.scope.destroy(backend);
    }
}

/// Renders `scene` once to warm up, then `frames` times: each frame's pass timings and wall ms.
/// With `without`, the lighting passes run without that part of their work.
fn time_frames(
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
fn time_frame(
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
fn median_pass_ms(
    plan: &RenderPlan,
    timings: &[Vec<backend::PassTiming>],
    name: &str,
) -> Option<f64> {
    let spec = plan.passes.iter().find(|p| p.name == name)?;
    median(
        timings
            .iter()
            .filter_map(|t| pass_time(t, spec))
            .map(|ns| ns / 1e6)
            .collect(),
    )
}

/// Median GPU ms of whole frames.
fn median_frame_ms(timings: &[Vec<backend::PassTiming>]) -> Option<f64> {
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

/// One row of a lighting pass's cost breakdown.
#[derive(Clone, Debug, serde::Serialize)]
pub struct BreakdownRow {
    /// What the row costs (e.g. `light 0 (directional, shadow pcf3)`).
    pub what: String,
    /// Median GPU ms: the input floor's own time, or the pass's time minus its time without
    /// this part.
    pub ms: Option<f64>,
    /// Whether the row is part of the sum (false: a part of another row, shown indented).
    pub summed: bool,
}

/// Where a lighting pass's time goes: its input floor, then each part of its work as the time
/// the pass loses when that part alone is taken away.
#[derive(Clone, Debug, serde::Serialize)]
pub struct PassBreakdown {
    /// Scene name.
    pub scene: String,
    /// Backend name.
    pub backend: String,
    /// Plan pass name.
    pub pass: String,
    /// The pass's median GPU ms as it is.
    pub total_ms: Option<f64>,
    /// The rows, input floor first.
    pub rows: Vec<BreakdownRow>,
    /// Sum of the summed rows, ms.
    pub sum_ms: Option<f64>,
    /// `sum_ms / total_ms`: near 1 when the parts add up (the costs are separable).
    pub sum_to_total: Option<f64>,
}

/// Times every lighting pass of `scene` on `kind` as it is and with one part taken away at a
/// time: the input floor (no shading), the per-pixel setup (the pass with no light and no IBL,
/// less the input floor), IBL, what IBL and the lights share in a draw that shades both (IBL
/// with no light, less IBL beside them), each light (with its shadow lookup), and, as parts of
/// those, shadow lookups and clearcoat. Each variant is `frames` frames after a warm-up.
pub fn breakdown(
    scene: &Scene,
    kind: BackendKind,
    frames: usize,
    progress: impl Fn(&str),
) -> Result<Vec<PassBreakdown>, BenchError> {
    let mut backend = backend::create(kind).map_err(|e| BenchError::Backend {
        backend: kind.name().to_owned(),
        message: e.to_string(),
    })?;
    let frames = frames.max(1);
    let plan = RenderPlan::new(scene);
    let draws = || plan.lighting.iter().flat_map(|pass| &pass.draws);
    let mut removals: Vec<(String, LightingFeature, bool)> = vec![
        (
            "G-buffer reads (input floor)".to_owned(),
            LightingFeature::Shading,
            true,
        ),
        (
            "per-pixel setup (view vector, ambient, output)".to_owned(),
            LightingFeature::Lighting,
            true,
        ),
    ];
    if draws().any(|d| d.variant.ibl) {
        removals.push(("IBL".to_owned(), LightingFeature::Ibl, true));
    }
    // A draw shading IBL and lights together decodes the surface once for both: neither removal
    // alone takes that away. Timed as what IBL costs with no light, less what it costs beside
    // the lights.
    if draws().any(|d| d.variant.ibl && d.variant.lights > 0) {
        removals.push((SHARED_ROW.to_owned(), LightingFeature::Lights, true));
    }
    for (index, light) in scene.lights.iter().enumerate() {
        let shadow = draws()
            .find(|d| d.shadowed == Some(index))
            .and_then(|d| d.variant.shadow)
            .map_or(String::new(), |(_, filter)| {
                format!(", shadow {}", filter.name())
            });
        let kind = match light {
            engine::scene::Light::Directional { .. } => "directional",
            engine::scene::Light::Point { .. } => "point",
        };
        removals.push((
            format!("light {index} ({kind}{shadow})"),
            LightingFeature::Light(index),
            true,
        ));
    }
    if draws().any(|d| d.variant.shadow.is_some()) {
        removals.push((
            "  of which shadow lookups".to_owned(),
            LightingFeature::Shadows,
            false,
        ));
    }
    if draws().any(|d| d.variant.clearcoat) {
        removals.push((
            "  of which clearcoat".to_owned(),
            LightingFeature::Clearcoat,
            false,
        ));
    }
    // Frames are interleaved (one of each variant in turn, after one warm-up frame of each),
    // so that a drift of the machine's speed during the run falls on every variant alike.
    let variants: Vec<Option<LightingFeature>> = std::iter::once(None)
        .chain(removals.iter().map(|(_, feature, _)| Some(*feature)))
        .collect();
    let mut timings: Vec<Vec<Vec<backend::PassTiming>>> = vec![Vec::new(); variants.len()];
    for round in 0..=frames {
        progress(&format!(
            "round {round} of {frames}: {} variants",
            variants.len()
        ));
        for (variant, timed) in variants.iter().zip(&mut timings) {
            let (frame, _) = time_frame(backend.as_mut(), scene, *variant)?;
            if round > 0 {
                timed.push(frame);
            }
        }
    }
    let full = timings.remove(0);
    let without = timings;
    let mut result = Vec::new();
    for spec in plan
        .passes
        .iter()
        .filter(|p| matches!(p.kind, PassKind::Lighting(_)))
    {
        let PassKind::Lighting(model) = spec.kind else {
            continue;
        };
        let pass_draws = plan.lighting_draws(model);
        // Only the parts this pass has (the removals are timed once for every pass).
        let applies = |feature: LightingFeature| match feature {
            LightingFeature::Shading | LightingFeature::Lighting => true,
            LightingFeature::Ibl => pass_draws.iter().any(|d| d.variant.ibl),
            LightingFeature::Lights => pass_draws
                .iter()
                .any(|d| d.variant.ibl && d.variant.lights > 0),
            LightingFeature::Shadows => pass_draws.iter().any(|d| d.variant.shadow.is_some()),
            LightingFeature::Clearcoat => pass_draws.iter().any(|d| d.variant.clearcoat),
            LightingFeature::Light(light) => pass_draws.iter().any(|d| d.lights.contains(&light)),
        };
        let total_ms = median_pass_ms(&plan, &full, &spec.name);
        let ms_without = |feature: LightingFeature| {
            removals
                .iter()
                .position(|(_, f, _)| *f == feature)
                .and_then(|i| median_pass_ms(&plan, &without[i], &spec.name))
        };
        let floor_ms = ms_without(LightingFeature::Shading);
        // IBL's cost beside the lights (the pass minus the pass without IBL), and the pass with
        // IBL and setup alone.
        let ibl_ms = total_ms
            .zip(ms_without(LightingFeature::Ibl))
            .map(|(t, v)| t - v);
        let no_lighting_ms = ms_without(LightingFeature::Lighting);
        let rows: Vec<BreakdownRow> = removals
            .iter()
            .zip(&without)
            .filter(|((_, feature, _), _)| applies(*feature))
            .map(|((what, feature, summed), timings)| {
                let variant_ms = median_pass_ms(&plan, timings, &spec.name);
                let ms = match feature {
                    LightingFeature::Shading => variant_ms,
                    // The variant with no lights and no IBL, less the input floor.
                    LightingFeature::Lighting => variant_ms.zip(floor_ms).map(|(v, f)| v - f),
                    // IBL with no light (less the pass with neither), less IBL beside the lights.
                    LightingFeature::Lights => variant_ms
                        .zip(no_lighting_ms)
                        .zip(ibl_ms)
                        .map(|((v, s), i)| v - s - i),
                    _ => total_ms.zip(variant_ms).map(|(t, v)| t - v),
                };
                BreakdownRow {
                    what: what.clone(),
                    ms,
                    summed: *summed,
                }
            })
            .collect();
        let sum_ms = rows
            .iter()
            .filter(|r| r.summed)
            .map(|r| r.ms)
            .sum::<Option<f64>>();
        result.push(PassBreakdown {
            scene: scene.name.clone(),
            backend: kind.name().to_owned(),
            pass: spec.name.clone(),
            total_ms,
            rows,
            sum_ms,
            sum_to_total: sum_ms.zip(total_ms).map(|(s, t)| s / t),
        });
    }
    Ok(result)
}

/// The breakdown row of what IBL and the lights share in a draw that shades both.
const SHARED_ROW: &str = "shared by IBL and the lights (surface, view)";

/// A pass breakdown as a table.
pub fn breakdown_table(b: &PassBreakdown) -> String {
    let ms = |v: Option<f64>| v.map_or("-".to_owned(), |v| format!("{v:.2}"));
    let share = |v: Option<f64>| {
        v.zip(b.total_ms)
            .map_or(String::new(), |(v, t)| format!("{:.0}%", 100.0 * v / t))
    };
    let mut out = format!(
        "{} {} on {} (GPU ms; each part: the pass minus the pass without it)\n",
        b.scene, b.pass, b.backend
    );
    for row in &b.rows {
        out.push_str(&format!(
            "  {:<44} {:>8} {:>6}\n",
            row.what,
            ms(row.ms),
            share(row.ms)
        ));
    }
    out.push_str(&format!(
        "  {:<44} {:>8} {:>6}\n  {:<44} {:>8}\n",
        "sum of the parts",
        ms(b.sum_ms),
        share(b.sum_ms),
        "pass as it is",
        ms(b.total_ms)
    ));
    out
}

/// One scene's timings as a table.
pub fn table(bench: &SceneBench) -> String {
    let ms = |v: Option<f64>| v.map_or("-".to_owned(), |v| format!("{v:.2}"));
    let ratio = |v: Option<f64>| v.map_or("-".to_owned(), |v| format!("{v:.1}x"));
    let mut out = format!(
        "{} on {} ({}x{}, median of {} frames, GPU ms)\n{:<22} {:>9} {:>9} {:>8} {:>12} {:>8}\n",
        bench.scene,
        bench.backend,
        bench.width,
        bench.height,
        bench.frames,
        "pass",
        "time",
        "floor",
        "ratio",
        "input floor",
        "ratio"
    );
    for p in &bench.passes {
        let (input, input_ratio) = if p.input_floor_ms.is_some() {
            (ms(p.input_floor_ms), ratio(p.input_ratio))
        } else {
            (String::new(), String::new())
        };
        out.push_str(&format!(
            "{:<22} {:>9} {:>9} {:>8} {:>12} {:>8}\n",
            p.pass,
            ms(p.median_ms),
            ms(p.floor_ms),
            ratio(p.ratio),
            input,
            input_ratio
        ));
    }
    out.push_str(&format!(
        "{:<22} {:>9} {:>9} {:>8}   (floor: writing the G-buffer once)\n",
        "frame",
        ms(bench.frame_ms),
        ms(bench.gbuffer_floor_ms),
        ratio(bench.frame_to_gbuffer_floor)
    ));
    out.push_str(&format!(
        "{:<22} {:>9.2}   wall time of a whole render\n",
        "render (wall)", bench.wall_ms
    ));
    out
}

/// The scaling series `harness bench --series` knows.
pub const SERIES: [&str; 4] = ["resolution", "lights", "triangles", "shadow-map"];

/// One point of a scaling series.
#[derive(Clone, Debug, serde::Serialize, serde::Deserialize)]
pub struct SeriesPoint {
    /// Series name (see [`SERIES`]).
    pub series: String,
    /// The value varied: pixels per side, point lights, triangles, or shadow-map texels per side.
    pub value: u64,
    /// The pass the series is about.
    pub pass: String,
    /// Its median GPU time, ms.
    pub pass_ms: Option<f64>,
    /// Median GPU time of the whole frame, ms.
    pub frame_ms: Option<f64>,
}

/// How a frame's cost grows: chess at 256..2048 pixels (frame, lighting), 1..256 point lights on
/// a floor (lighting), chess's meshes subdivided 1x..64x (geometry), chess's sun with 512..4096
/// shadow maps (shadow pass).
pub fn series(
    name: &str,
    kind: BackendKind,
    frames: usize,
    mut progress: impl FnMut(&str),
) -> Result<Vec<SeriesPoint>, BenchError> {
    let chess = || {
        crate::load_scene("chess")
            .map(|l| l.scene)
            .map_err(|e| BenchError::Render {
                scene: "chess".to_owned(),
                backend: kind.name().to_owned(),
                message: e.to_string(),
            })
    };
    let settings: Vec<(u64, Scene, &str)> = match name {
        "resolution" => [256u32, 512, 1024, 2048]
            .into_iter()
            .map(|size| {
                let mut scene = chess()?;
                scene.quality.width = size;
                scene.quality.height = size;
                Ok((u64::from(size), scene, "lighting_pbr"))
            })
            .collect::<Result<_, BenchError>>()?,
        "lights" => [1usize, 8, 64, 256]
            .into_iter()
            .map(|n| {
                (
                    n as u64,
                    crate::test_scenes::many_point_lights(512, n),
                    "lighting_pbr",
                )
            })
            .collect(),
        "triangles" => {
            let mut scene = chess()?;
            let mut points = Vec::new();
            for level in 0..4 {
                if level > 0 {
                    let mut subdivided = std::collections::HashMap::new();
                    for object in &mut scene.objects {
                        let key = std::sync::Arc::as_ptr(&object.mesh);
                        let mesh = subdivided
                            .entry(key)
                            .or_insert_with(|| std::sync::Arc::new(object.mesh.subdivided()))
                            .clone();
                        object.mesh = mesh;
                    }
                }
                let triangles: usize = scene.objects.iter().map(|o| o.mesh.triangle_count()).sum();
                points.push((triangles as u64, scene.clone(), "geometry"));
            }
            points
        }
        "shadow-map" => [512u32, 1024, 2048, 4096]
            .into_iter()
            .map(|size| {
                let mut scene = chess()?;
                for light in &mut scene.lights {
                    if let engine::scene::Light::Directional {
                        shadow: Some(s), ..
                    } = light
                    {
                        s.map_size = size;
                    }
                }
                Ok((u64::from(size), scene, "shadow_0"))
            })
            .collect::<Result<_, BenchError>>()?,
        other => {
            return Err(BenchError::Render {
                scene: "-".to_owned(),
                backend: kind.name().to_owned(),
                message: format!("unknown series `{other}` (known: {})", SERIES.join(", ")),
            })
        }
    };
    let mut backend = backend::create(kind).map_err(|e| BenchError::Backend {
        backend: kind.name().to_owned(),
        message: e.to_string(),
    })?;
    let mut points = Vec::new();
    for (value, scene, pass) in settings {
        progress(&format!("{name} {value}"));
        let plan = RenderPlan::new(&scene);
        let (timings, _) = time_frames(backend.as_mut(), &scene, frames.max(1), None)?;
        points.push(SeriesPoint {
            series: name.to_owned(),
            value,
            pass: pass.to_owned(),
            pass_ms: median_pass_ms(&plan, &timings, pass),
            frame_ms: median_frame_ms(&timings),
        });
    }
    Ok(points)
}

/// A series as a table, with each point's growth against the previous one.
pub fn series_table(points: &[SeriesPoint]) -> String {
    let ms = |v: Option<f64>| v.map_or("-".to_owned(), |v| format!("{v:.2}"));
    let mut out = String::new();
    if let Some(first) = points.first() {
        out.push_str(&format!(
            "{:<12} {:>10} {:>14} {:>10} {:>10} {:>12}\n",
            "series",
            "value",
            format!("{} ms", first.pass),
            "x value",
            "x time",
            "frame ms"
        ));
    }
    for (i, p) in points.iter().enumerate() {
        let (value_growth, time_growth) = match i.checked_sub(1).map(|j| &points[j]) {
            Some(prev) => (
                format!("{:.1}", p.value as f64 / prev.value as f64),
                p.pass_ms
                    .zip(prev.pass_ms)
                    .map_or("-".to_owned(), |(a, b)| format!("{:.2}", a / b)),
            ),
            None => ("-".to_owned(), "-".to_owned()),
        };
        out.push_str(&format!(
            "{:<12} {:>10} {:>14} {:>10} {:>10} {:>12}\n",
            p.series,
            p.value,
            ms(p.pass_ms),
            value_growth,
            time_growth,
            ms(p.frame_ms)
        ));
    }
    out
}

/// File name of `harness bench`'s results in the output folder (read by the check report).
pub const BENCH_JSON: &str = "bench.json";
/// File name of `harness bench --series`'s results in the output folder.
pub const SERIES_JSON: &str = "bench_series.json";

/// A small SVG line chart of a series' pass time against its value (log2 x axis).
pub fn series_svg(points: &[SeriesPoint]) -> String {
    let (w, h, left, bottom, top, right) = (380.0, 200.0, 50.0, 30.0, 20.0, 35.0);
    let data: Vec<(f64, f64)> = points
        .iter()
        .filter_map(|p| p.pass_ms.map(|ms| ((p.value.max(1) as f64).log2(), ms)))
        .collect();
    let Some(first) = points.first() else {
        return String::new();
    };
    let mut svg = format!(
        "<svg xmlns=\"http://www.w3.org/2000/svg\" width=\"{w}\" height=\"{h}\" \
         style=\"background:#fff;border:1px solid #ccc\">\
         <text x=\"{left}\" y=\"14\" font-size=\"12\">{} ms against {}</text>",
        crate::html::escape(&first.pass),
        crate::html::escape(&first.series)
    );
    if data.is_empty() {
        svg.push_str("<text x=\"60\" y=\"100\" font-size=\"12\">no timestamps</text></svg>");
        return svg;
    }
    let (x0, x1) = data.iter().fold((f64::MAX, f64::MIN), |(a, b), (x, _)| {
        (a.min(*x), b.max(*x))
    });
    let y1 = data.iter().map(|(_, y)| *y).fold(0.0, f64::max).max(1e-9);
    let sx = |x: f64| left + (x - x0) / (x1 - x0).max(1e-9) * (w - left - right);
    let sy = |y: f64| h - bottom - y / y1 * (h - bottom - top);
    svg.push_str(&format!(
        "<line x1=\"{left}\" y1=\"{0}\" x2=\"{1}\" y2=\"{0}\" stroke=\"#888\"/>\
         <line x1=\"{left}\" y1=\"{top}\" x2=\"{left}\" y2=\"{0}\" stroke=\"#888\"/>\
         <text x=\"4\" y=\"{2}\" font-size=\"10\">{y1:.1}</text>\
         <text x=\"4\" y=\"{0}\" font-size=\"10\">0</text>",
        h - bottom,
        w - right,
        top + 4.0
    ));
    let line: Vec<String> = data
        .iter()
        .map(|(x, y)| format!("{:.1},{:.1}", sx(*x), sy(*y)))
        .collect();
    svg.push_str(&format!(
        "<polyline fill=\"none\" stroke=\"#2a6\" stroke-width=\"2\" points=\"{}\"/>",
        line.join(" ")
    ));
    for (p, (x, y)) in points.iter().filter(|p| p.pass_ms.is_some()).zip(&data) {
        svg.push_str(&format!(
            "<circle cx=\"{:.1}\" cy=\"{:.1}\" r=\"3\" fill=\"#2a6\"/>\
             <text x=\"{:.1}\" y=\"{}\" font-size=\"10\" text-anchor=\"middle\">{}</text>",
            sx(*x),
            sy(*y),
            sx(*x),
            h - bottom + 14.0,
            p.value
        ));
    }
    svg.push_str("</svg>");
    svg
}

/// HTML sections for the check report from the latest `harness bench` results in `dir`
/// (per-pass times against floors, scaling series plots); empty when there are none.
pub fn report_sections(dir: &std::path::Path) -> String {
    let mut out = String::new();
    if let Some(benches) = std::fs::read(dir.join(BENCH_JSON))
        .ok()
        .and_then(|b| serde_json::from_slice::<serde_json::Value>(&b).ok())
        .and_then(|v| v["scenes"].as_array().cloned())
    {
        out.push_str(
            "<h2>Pass time against floor (latest <code>harness bench</code>)</h2>\
             <table><tr><th>scene</th><th>backend</th><th>pass</th><th>ms</th><th>floor ms</th>\
             <th>ratio</th></tr>",
        );
        let cell = |v: &serde_json::Value, digits: usize| {
            v.as_f64()
                .map_or("-".to_owned(), |x| format!("{x:.digits$}"))
        };
        for b in &benches {
            let scene = crate::html::escape(b["scene"].as_str().unwrap_or("?"));
            let backend = crate::html::escape(b["backend"].as_str().unwrap_or("?"));
            for p in b["passes"].as_array().into_iter().flatten() {
                out.push_str(&format!(
                    "<tr><td>{scene}</td><td>{backend}</td><td>{}</td><td>{}</td><td>{}</td><td>{}</td></tr>",
                    crate::html::escape(p["pass"].as_str().unwrap_or("?")),
                    cell(&p["median_ms"], 2),
                    cell(&p["floor_ms"], 2),
                    cell(&p["ratio"], 1)
                ));
            }
            out.push_str(&format!(
                "<tr><td>{scene}</td><td>{backend}</td><td><b>frame</b> (floor: G-buffer once)</td>\
                 <td>{}</td><td>{}</td><td>{}</td></tr>",
                cell(&b["frame_ms"], 2),
                cell(&b["gbuffer_floor_ms"], 2),
                cell(&b["frame_to_gbuffer_floor"], 1)
            ));
        }
        out.push_str("</table>");
    }
    if let Some(series) = std::fs::read(dir.join(SERIES_JSON))
        .ok()
        .and_then(|b| serde_json::from_slice::<Vec<serde_json::Value>>(&b).ok())
    {
        out.push_str("<h2>How cost grows (latest <code>harness bench --series</code>)</h2>");
        for s in &series {
            let points: Vec<SeriesPoint> =
                serde_json::from_value(s["points"].clone()).unwrap_or_default();
            out.push_str(&format!(
                "<figure>{}<figcaption>{}</figcaption></figure>",
                series_svg(&points),
                crate::html::escape(s["backend"].as_str().unwrap_or("?"))
            ));
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;
    use engine::backend::PassTiming;

    fn timing(name: &str, ns: f64) -> PassTiming {
        PassTiming {
            name: name.to_owned(),
            gpu_ns: Some(ns),
        }
    }

    #[test]
    fn a_pass_time_sums_its_faces_and_nothing_else() {
        let spec = |name: &str| PassSpec {
            name: name.to_owned(),
            kind: engine::plan::PassKind::Geometry,
            reads: vec![],
            writes: vec![],
            detail: String::new(),
        };
        let timings = [
            timing("shadow_0+x", 1.0),
            timing("shadow_0-x", 2.0),
            timing("shadow_0_blur_x", 4.0),
            timing("shadow_1", 8.0),
            timing("geometry", 16.0),
        ];
        assert_eq!(pass_time(&timings, &spec("shadow_0")), Some(3.0));
        assert_eq!(pass_time(&timings, &spec("shadow_0_blur_x")), Some(4.0));
        assert_eq!(pass_time(&timings, &spec("shadow_1")), Some(8.0));
        assert_eq!(pass_time(&timings, &spec("lighting_pbr")), None);
        let untimed = [PassTiming {
            name: "geometry".to_owned(),
            gpu_ns: None,
        }];
        assert_eq!(pass_time(&untimed, &spec("geometry")), None);
    }

    #[test]
    fn series_plots_have_a_point_per_value() {
        let points: Vec<SeriesPoint> = [(1u64, 1.0), (8, 3.0), (64, 20.0)]
            .into_iter()
            .map(|(value, ms)| SeriesPoint {
                series: "lights".to_owned(),
                value,
                pass: "lighting_pbr".to_owned(),
                pass_ms: Some(ms),
                frame_ms: Some(ms + 1.0),
            })
            .collect();
        let svg = series_svg(&points);
        assert_eq!(svg.matches("<circle").count(), 3);
        assert!(svg.contains("lighting_pbr ms against lights"));
        let table = series_table(&points);
        assert!(table.contains("8.0") && table.contains("6.67"), "{table}");
    }
}

//! The breakdown of a lighting pass: where its time goes, timed as the pass with one part of
//! its work taken away at a time (`harness bench --breakdown`).
//!
//! Each variant's time is the lower quartile of its frames, not the median. On llvmpipe a short
//! pass's frame times fall in two clusters (a 0.45 ms pass: 0.31-0.37 ms and 0.50-0.63 ms in
//! 21 frames, as its rasterizer threads are scheduled), and the median of such a pass jumps
//! between them from one variant to the next: the arrow's Blinn-Phong parts added up to 91-130%
//! of the pass with medians, 88-108% with the lower quartile, over the same six runs (three of
//! 5 frames, three of 21). Scheduling only adds time, so the lower frames measure the work.

use engine::backend::{Backend, BackendKind};
use engine::plan::{LightingFeature, PassId, PassSpec, RenderPlan};
use engine::renderer::{PassTimes, PreparedFrame, Variations};
use engine::scene::Scene;

use super::timing::{percentile_pass_ms, prepare, time_frame};
use super::BenchError;

/// The percentile of each variant's frames that stands for its time: the lower quartile (see
/// the module docs).
const BREAKDOWN_PERCENTILE: f64 = 0.25;

/// Frames per variant of `harness bench --breakdown` unless told otherwise: enough for a lower
/// quartile over several frames of each cluster.
pub const BREAKDOWN_FRAMES: usize = 21;

/// One row of a lighting pass's cost breakdown.
#[derive(Clone, Debug, serde::Serialize)]
pub struct BreakdownRow {
    /// What the row costs (e.g. `light 0 (directional, shadow pcf3)`).
    pub what: String,
    /// GPU ms (lower quartile of frames): the input floor's own time, or the pass's time minus
    /// its time without this part.
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
    /// Backend.
    pub backend: BackendKind,
    /// Plan pass.
    pub pass: PassId,
    /// Frames timed per variant (after a warm-up frame).
    pub frames: usize,
    /// The pass's GPU ms as it is (lower quartile of frames).
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
/// those, shadow lookups and clearcoat. Each part is the time the pass loses without it, from a
/// baseline that re-reads the inputs as the variants do ([`LightingFeature::KeptInputs`]); a
/// last row takes that re-read away again, so the rows add up to the pass as it is. Each variant
/// is `frames` frames after a warm-up.
pub fn breakdown(
    scene: &Scene,
    kind: BackendKind,
    frames: usize,
    progress: impl Fn(&str),
) -> Result<Vec<PassBreakdown>, BenchError> {
    let mut backend = crate::faults::create_backend(kind).map_err(|e| BenchError::Backend {
        backend: kind,
        message: e.to_string(),
    })?;
    let frames = frames.max(1);
    let prepared = prepare(scene, kind)?;
    let plan = prepared.plan();
    let removals = removals(prepared.scene(), plan);
    let mut timings = time_variants(backend.as_mut(), &prepared, frames, &removals, progress)?;
    let full = timings.remove(0);
    let kept_inputs = timings.remove(0);
    let frames = VariantFrames {
        full,
        kept_inputs,
        without: timings,
    };
    let mut result = Vec::new();
    for spec in plan
        .passes
        .iter()
        .filter(|p| matches!(p.id, PassId::Lighting(_)))
    {
        result.extend(pass_breakdown(scene, kind, plan, spec, &removals, &frames));
    }
    Ok(result)
}

/// The frames' pass timings of every variant: as it is, the baseline that re-reads its inputs,
/// and without each removal (in the removals' order).
pub struct VariantFrames {
    /// The frames as they are.
    pub full: Vec<PassTimes>,
    /// The frames of the baseline that re-reads the lighting passes' inputs.
    pub kept_inputs: Vec<PassTimes>,
    /// The frames without each removal, in the removals' order.
    pub without: Vec<Vec<PassTimes>>,
}

/// One part of the lighting passes' work to take away: the row's label, the part, and whether
/// the row is part of the sum.
pub type Removal = (String, LightingFeature, bool);

/// The parts of the lighting passes' work to take away one at a time, in row order: the input
/// floor, the per-pixel setup, IBL, what IBL and the lights share, each light, then the parts
/// of those (shadow lookups, clearcoat). Only parts some draw of `plan` has.
pub fn removals(scene: &Scene, plan: &RenderPlan) -> Vec<Removal> {
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
    removals
}

/// Times every variant of the frame (as it is, the baseline with kept inputs, then without each
/// of `removals`): per variant, the pass timings of `frames` frames after a warm-up.
fn time_variants(
    backend: &mut dyn Backend,
    prepared: &PreparedFrame,
    frames: usize,
    removals: &[Removal],
    progress: impl Fn(&str),
) -> Result<Vec<Vec<PassTimes>>, BenchError> {
    // Frames are interleaved (one of each variant in turn, after one warm-up frame of each),
    // so that a drift of the machine's speed during the run falls on every variant alike.
    let variants: Vec<PreparedFrame> = [None, Some(LightingFeature::KeptInputs)]
        .into_iter()
        .chain(removals.iter().map(|(_, feature, _)| Some(*feature)))
        .map(|without| {
            prepared.clone().with_variations(Variations {
                remove_lighting: without,
                ..Variations::default()
            })
        })
        .collect();
    let mut timings: Vec<Vec<PassTimes>> = vec![Vec::new(); variants.len()];
    for round in 0..=frames {
        progress(&format!(
            "round {round} of {frames}: {} variants",
            variants.len()
        ));
        for (variant, timed) in variants.iter().zip(&mut timings) {
            let (frame, _) = time_frame(backend, variant)?;
            if round > 0 {
                timed.push(frame);
            }
        }
    }
    Ok(timings)
}

/// The breakdown of lighting pass `spec` from the frames of every variant; None when `spec` is
/// not a lighting pass.
pub fn pass_breakdown(
    scene: &Scene,
    kind: BackendKind,
    plan: &RenderPlan,
    spec: &PassSpec,
    removals: &[Removal],
    frames: &VariantFrames,
) -> Option<PassBreakdown> {
    let (full, without) = (&frames.full, &frames.without);
    let PassId::Lighting(model) = spec.id else {
        return None;
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
        LightingFeature::KeptInputs => false,
    };
    let pass_ms =
        |timings: &[PassTimes]| percentile_pass_ms(timings, spec.id, BREAKDOWN_PERCENTILE);
    let total_ms = pass_ms(full);
    // The differences are taken from the pass re-reading its inputs, as every variant does.
    let baseline_ms = pass_ms(&frames.kept_inputs);
    let ms_without = |feature: LightingFeature| {
        removals
            .iter()
            .position(|(_, f, _)| *f == feature)
            .and_then(|i| pass_ms(&without[i]))
    };
    let floor_ms = ms_without(LightingFeature::Shading);
    // IBL's cost beside the lights (the pass minus the pass without IBL), and the pass with
    // IBL and setup alone.
    let ibl_ms = baseline_ms
        .zip(ms_without(LightingFeature::Ibl))
        .map(|(t, v)| t - v);
    let no_lighting_ms = ms_without(LightingFeature::Lighting);
    let rows: Vec<BreakdownRow> = removals
        .iter()
        .zip(without)
        .filter(|((_, feature, _), _)| applies(*feature))
        .map(|((what, feature, summed), timings)| {
            let variant_ms = pass_ms(timings);
            let ms = match feature {
                LightingFeature::Shading => variant_ms,
                // The variant with no lights and no IBL, less the input floor.
                LightingFeature::Lighting => variant_ms.zip(floor_ms).map(|(v, f)| v - f),
                // IBL with no light (less the pass with neither), less IBL beside the lights.
                LightingFeature::Lights => variant_ms
                    .zip(no_lighting_ms)
                    .zip(ibl_ms)
                    .map(|((v, s), i)| v - s - i),
                _ => baseline_ms.zip(variant_ms).map(|(b, v)| b - v),
            };
            BreakdownRow {
                what: what.clone(),
                ms,
                summed: *summed,
            }
        })
        .chain(std::iter::once(BreakdownRow {
            what: REREAD_ROW.to_owned(),
            ms: total_ms.zip(baseline_ms).map(|(t, b)| t - b),
            summed: true,
        }))
        .collect();
    let sum_ms = rows
        .iter()
        .filter(|r| r.summed)
        .map(|r| r.ms)
        .sum::<Option<f64>>();
    Some(PassBreakdown {
        scene: scene.name.clone(),
        backend: kind,
        pass: spec.id,
        frames: full.len(),
        total_ms,
        rows,
        sum_ms,
        sum_to_total: sum_ms.zip(total_ms).map(|(s, t)| s / t),
    })
}

/// The breakdown row that takes away the variants' re-read of the inputs (`KEEP_INPUTS`): the
/// pass as it is less the baseline. Small where the compiler merges most re-reads with the
/// shading's reads (gl: 0.1-0.2 ms of chess's 9), not where it does not (wgpu-gl: 1.0-1.8 ms).
const REREAD_ROW: &str = "less the variants' re-read of the inputs";

/// The breakdown row of what IBL and the lights share in a draw that shades both.
const SHARED_ROW: &str = "shared by IBL and the lights (surface, view)";

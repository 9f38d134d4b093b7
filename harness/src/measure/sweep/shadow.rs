//! The shadow sweep: every shadow filter at several map sizes, timed, and its shadow term
//! measured against exact visibility by ray casting and against the converged soft filter.

use engine::backend::BackendKind;
use engine::plan::TargetId;
use engine::renderer::PreparedFrame;
use engine::renderer::{self, Frame, Readback};
use engine::scene::{Light, Scene, ShadowFilter};

use super::{lighting, pareto_front, pass_ms, shadow_map, stats, timing_rounds, SweepError};
use crate::reference::shadows;

/// One setting of the sweep.
#[derive(Clone, Debug, serde::Serialize)]
pub struct SweepRow {
    /// Filter.
    pub filter: String,
    /// Shadow map size (per face).
    pub map_size: u32,
    /// Shadow-map fetches per shaded pixel (the soft filter's early-out usually needs 4 of
    /// its 16).
    pub fetches: u32,
    /// Median GPU time of the shadow-map pass(es), ms.
    pub shadow_ms: Option<f64>,
    /// Median GPU time of the lighting passes, ms.
    pub lighting_ms: Option<f64>,
    /// Fraction of lit-surface pixels misclassified against ray casting (term > 0.5 = lit).
    pub misclassified: f64,
    /// Mean |term - soft reference| over lit-surface pixels (soft filters only).
    pub error_vs_soft_reference: Option<f64>,
    /// 99th percentile and maximum of |term - soft reference| (soft filters only).
    pub soft_reference_p99_max: Option<(f64, f64)>,
    /// Whether this is the scene's own setting.
    pub is_default: bool,
    /// Whether no other setting is both faster (shadow + lighting GPU time) and more accurate
    /// (misclassified fraction): on the Pareto front.
    pub pareto: bool,
}

fn with_shadow(scene: &Scene, filter: ShadowFilter, map_size: u32) -> Scene {
    with_shadow_samples(scene, filter, map_size, None)
}

fn with_shadow_samples(
    scene: &Scene,
    filter: ShadowFilter,
    map_size: u32,
    samples: Option<u32>,
) -> Scene {
    let mut scene = scene.clone();
    scene.quality.debug_shadow_terms = true;
    for light in &mut scene.lights {
        if let Light::Directional {
            shadow: Some(s), ..
        }
        | Light::Point {
            shadow: Some(s), ..
        } = light
        {
            s.filter = filter;
            s.map_size = map_size;
            if let Some(samples) = samples {
                s.soft_samples = samples;
            }
        }
    }
    scene
}

/// What the shadow sweep's renders cost.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum ShadowSweepCost {
    /// Every pass of the frame runs and the shadow and lighting passes are timed: the cost
    /// columns and the Pareto front (the `harness sweep` command).
    Timed,
    /// Only the passes the shadow terms depend on run (no lighting, no tone mapping: the terms
    /// are the same bit for bit), untimed: the times are `None` and no row is on a front. For
    /// checking errors (the sweep test).
    Untimed,
}

/// Runs the shadow sweep on one backend. `repeats` rounds of timed renders, each rendering every
/// setting once, for the timing medians.
pub fn shadow_sweep(
    scene: &Scene,
    kind: BackendKind,
    repeats: usize,
    progress: impl FnMut(&str),
) -> Result<Vec<SweepRow>, SweepError> {
    shadow_sweep_with(scene, kind, repeats, ShadowSweepCost::Timed, progress)
}

/// [`shadow_sweep`] at the given `cost`.
pub fn shadow_sweep_with(
    scene: &Scene,
    kind: BackendKind,
    repeats: usize,
    cost: ShadowSweepCost,
    mut progress: impl FnMut(&str),
) -> Result<Vec<SweepRow>, SweepError> {
    let light = scene
        .lights
        .iter()
        .position(Light::casts_shadows)
        .ok_or_else(|| SweepError::NoShadows(scene.name.clone()))?;
    let any_point_shadows = scene.lights.iter().any(|l| {
        matches!(
            l,
            Light::Point {
                shadow: Some(_),
                ..
            }
        )
    });
    let own = match &scene.lights[light] {
        Light::Directional {
            shadow: Some(s), ..
        }
        | Light::Point {
            shadow: Some(s), ..
        } => Some((s.filter, s.map_size)),
        _ => None,
    };
    let mut backend =
        crate::faults::create_backend(kind).map_err(|e| SweepError::Render(e.to_string()))?;
    let term_name = TargetId::ShadowTerm { light };
    // What the ray-cast comparison reads (shadow settings change no target but the maps').
    let hard = PreparedFrame::new(&with_shadow(scene, ShadowFilter::Hard, 512))?;
    let wanted = shadows::visibility_targets(hard.plan(), light);
    let timed = cost == ShadowSweepCost::Timed;
    let readback = if timed {
        Readback::Only(&wanted)
    } else {
        Readback::Needed(&wanted)
    };
    let mut rows = Vec::new();
    // With timing: each setting's frame, for the timing rounds after the loop.
    let mut prepared = Vec::new();
    let mut ray_cast: Option<shadows::RayCastVisibility> = None;
    for map_size in [512u32, 1024, 2048] {
        progress(&format!("soft reference at {map_size}"));
        let reference_scene = with_shadow(scene, ShadowFilter::SoftReference, map_size);
        let reference = renderer::render(backend.as_mut(), &reference_scene, readback)?;
        for (filter, samples) in [
            (ShadowFilter::Hard, None),
            (ShadowFilter::Pcf3, None),
            (ShadowFilter::Bilinear, None),
            (ShadowFilter::Pcf3Bilinear, None),
            (ShadowFilter::Soft, None),
            (ShadowFilter::SoftFull, None),
            (ShadowFilter::Vogel, Some(16)),
            (ShadowFilter::Vogel, Some(64)),
            (ShadowFilter::Vogel, Some(256)),
            (ShadowFilter::Vsm, None),
        ] {
            if filter == ShadowFilter::Vsm && any_point_shadows {
                continue; // VSM is for directional lights
            }
            let label = match samples {
                Some(n) => format!("{}-{n}", filter.name()),
                None => filter.name().to_owned(),
            };
            progress(&format!("{label} at {map_size}"));
            let mutated = with_shadow_samples(scene, filter, map_size, samples);
            let prepared_frame = PreparedFrame::new(&mutated)?;
            let frame = &renderer::render_prepared(backend.as_mut(), &prepared_frame, readback)?;
            if timed {
                prepared.push(prepared_frame);
            }
            // Shadow settings change no geometry: one ray cast serves every setting whose
            // G-buffer is the same (checked, bit for bit).
            let cast = match ray_cast.take() {
                Some(cast) if cast.holds_for(frame) => cast,
                _ => shadows::RayCastVisibility::cast(&mutated, frame, light, 1e-4)?,
            };
            let visibility = cast.error(frame)?;
            ray_cast = Some(cast);
            let soft = matches!(
                filter,
                ShadowFilter::Soft
                    | ShadowFilter::SoftFull
                    | ShadowFilter::Vogel
                    | ShadowFilter::Vsm
            )
            .then(|| {
                abs_difference_stats(
                    frame.outputs[&term_name].as_f32().unwrap_or_default(),
                    reference.outputs[&term_name].as_f32().unwrap_or_default(),
                    frame,
                )
            });
            rows.push(SweepRow {
                filter: label,
                map_size,
                fetches: filter.fetches(samples.unwrap_or(64)),
                shadow_ms: None,
                lighting_ms: None,
                misclassified: visibility.fraction,
                error_vs_soft_reference: soft.map(|s| s.0),
                soft_reference_p99_max: soft.map(|s| (s.1, s.2)),
                is_default: own == Some((filter, map_size)),
                pareto: false,
            });
        }
    }
    if !timed {
        return Ok(rows);
    }
    // The times: `repeats` rounds over every setting in turn.
    let rounds = timing_rounds(backend.as_mut(), &prepared, repeats, &mut progress)?;
    for (row, frames) in rows.iter_mut().zip(&rounds) {
        row.shadow_ms = pass_ms(frames, shadow_map);
        row.lighting_ms = pass_ms(frames, lighting);
    }
    let points: Vec<(f64, f64)> = rows
        .iter()
        .map(|r| {
            (
                r.shadow_ms.unwrap_or(0.0) + r.lighting_ms.unwrap_or(0.0),
                r.misclassified,
            )
        })
        .collect();
    for (row, on_front) in rows.iter_mut().zip(pareto_front(&points)) {
        row.pareto = on_front;
    }
    Ok(rows)
}

/// Mean, 99th percentile and maximum absolute difference of two shadow terms over the covered
/// pixels.
fn abs_difference_stats(a: &[f32], b: &[f32], frame: &Frame) -> (f64, f64, f64) {
    let mask = frame
        .outputs
        .get(&TargetId::Mask(0))
        .and_then(|m| m.as_u8())
        .unwrap_or_default();
    let mut differences = Vec::new();
    for i in 0..a.len().min(b.len()) / 4 {
        if mask
            .get(i * 4..i * 4 + 4)
            .is_some_and(|m| m.iter().any(|&v| v > 127))
        {
            differences.push(f64::from((a[i * 4] - b[i * 4]).abs()));
        }
    }
    stats(differences)
}

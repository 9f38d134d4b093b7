//! Speed against error for one quality knob.
//!
//! `harness sweep --scene ibl --knob ibl` varies the IBL precompute (sample count, specular
//! size, SH9 irradiance) and measures each setting's precompute time, lighting-pass time and
//! error against the Monte Carlo reference ([`crate::ibl_reference`]) per roughness.
//!
//! `harness sweep --scene chess --knob shadow` renders
//! the scene once per setting (shadow filter x map size), times the passes from GPU timestamps
//! (median of several renders), and measures the error of the shadow term against
//!
//! - exact hard visibility by ray casting ([`crate::shadow_reference`]): the fraction of
//!   lit-surface pixels whose term is on the wrong side of 0.5, and the mean absolute difference;
//! - the converged soft filter (`soft-reference`, 1024 samples) for the soft filters and VSM
//!   (directional lights only): mean absolute difference.

use engine::backend::{self, BackendKind};
use engine::plan;
use engine::renderer::{self, Frame, Readback};
use engine::scene::{Light, Scene, ShadowFilter};

use crate::bench::median;
use crate::shadow_reference;

/// One setting of the sweep.
#[derive(Clone, Debug, serde::Serialize)]
pub struct SweepRow {
    /// Filter.
    pub filter: String,
    /// Shadow map size (per face).
    pub map_size: u32,
    /// Median GPU time of the shadow-map pass(es), ms.
    pub shadow_ms: Option<f64>,
    /// Median GPU time of the lighting passes, ms.
    pub lighting_ms: Option<f64>,
    /// Fraction of lit-surface pixels misclassified against ray casting (term > 0.5 = lit).
    pub misclassified: f64,
    /// Mean |term - soft reference| over lit-surface pixels (soft filters only).
    pub error_vs_soft_reference: Option<f64>,
}

/// Why a sweep failed.
#[derive(Debug, thiserror::Error)]
pub enum SweepError {
    /// The knob is not one the sweep knows.
    #[error("unknown knob `{0}` (known: shadow, ibl)")]
    UnknownKnob(String),
    /// The scene has no environment (for the `ibl` knob).
    #[error("scene `{0}` has no environment")]
    NoEnvironment(String),
    /// The scene has no shadowed light.
    #[error("scene `{0}` has no light with shadows")]
    NoShadows(String),
    /// Rendering failed.
    #[error("{0}")]
    Render(String),
}

fn with_shadow(scene: &Scene, filter: ShadowFilter, map_size: u32) -> Scene {
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
        }
    }
    scene
}

fn pass_ms(frames: &[Frame], prefix: &str) -> Option<f64> {
    median(
        frames
            .iter()
            .filter_map(|f| {
                let ns: Vec<f64> = f
                    .timings
                    .iter()
                    .filter(|t| t.name.starts_with(prefix) && !t.name.starts_with("shadow_term"))
                    .filter_map(|t| t.gpu_ns)
                    .collect();
                (!ns.is_empty()).then(|| ns.iter().sum::<f64>() / 1e6)
            })
            .collect(),
    )
}

/// Runs the shadow sweep on one backend. `repeats` renders per setting for the timing median.
pub fn shadow_sweep(
    scene: &Scene,
    kind: BackendKind,
    repeats: usize,
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
    let mut backend = backend::create(kind).map_err(|e| SweepError::Render(e.to_string()))?;
    let term_name = plan::shadow_term_target_name(light);
    let wanted = [
        term_name.as_str(),
        plan::GBUFFER_TARGETS[0],
        plan::GBUFFER_TARGETS[1],
        "mask",
    ];
    let mut render = |scene: &Scene| {
        renderer::render(backend.as_mut(), scene, Readback::Only(&wanted))
            .map_err(|e| SweepError::Render(e.to_string()))
    };
    let mut rows = Vec::new();
    for map_size in [512u32, 1024, 2048] {
        progress(&format!("soft reference at {map_size}"));
        let reference_scene = with_shadow(scene, ShadowFilter::SoftReference, map_size);
        let reference = render(&reference_scene)?;
        for filter in [
            ShadowFilter::Hard,
            ShadowFilter::Pcf3,
            ShadowFilter::Soft,
            ShadowFilter::SoftFull,
            ShadowFilter::Vsm,
        ] {
            if filter == ShadowFilter::Vsm && any_point_shadows {
                continue; // VSM is for directional lights
            }
            progress(&format!("{} at {map_size}", filter.name()));
            let mutated = with_shadow(scene, filter, map_size);
            let frames = (0..repeats.max(1))
                .map(|_| render(&mutated))
                .collect::<Result<Vec<_>, _>>()?;
            let frame = &frames[0];
            let visibility = shadow_reference::visibility_error(&mutated, frame, light, 1e-4)
                .map_err(SweepError::Render)?;
            let soft = matches!(
                filter,
                ShadowFilter::Soft | ShadowFilter::SoftFull | ShadowFilter::Vsm
            )
            .then(|| {
                mean_abs_difference(
                    frame.outputs[&term_name].as_f32().unwrap_or_default(),
                    reference.outputs[&term_name].as_f32().unwrap_or_default(),
                    frame,
                )
            });
            rows.push(SweepRow {
                filter: filter.name().to_owned(),
                map_size,
                shadow_ms: pass_ms(&frames, "shadow_"),
                lighting_ms: pass_ms(&frames, "lighting_"),
                misclassified: visibility.fraction,
                error_vs_soft_reference: soft,
            });
        }
    }
    Ok(rows)
}

/// Mean absolute difference of two shadow terms over the covered pixels.
fn mean_abs_difference(a: &[f32], b: &[f32], frame: &Frame) -> f64 {
    let mask = frame
        .outputs
        .get("mask")
        .and_then(|m| m.as_u8())
        .unwrap_or_default();
    let (mut sum, mut n) = (0.0, 0usize);
    for i in 0..a.len().min(b.len()) / 4 {
        if mask
            .get(i * 4..i * 4 + 4)
            .is_some_and(|m| m.iter().any(|&v| v > 127))
        {
            sum += f64::from((a[i * 4] - b[i * 4]).abs());
            n += 1;
        }
    }
    sum / n.max(1) as f64
}

/// The sweep as a table.
pub fn table(rows: &[SweepRow]) -> String {
    let mut out = format!(
        "{:<10} {:>6} {:>11} {:>13} {:>14} {:>16}\n",
        "filter", "map", "shadow ms", "lighting ms", "misclassified", "vs soft ref"
    );
    let ms = |v: Option<f64>| v.map_or("-".to_owned(), |v| format!("{v:.2}"));
    for r in rows {
        out.push_str(&format!(
            "{:<10} {:>6} {:>11} {:>13} {:>13.3}% {:>16}\n",
            r.filter,
            r.map_size,
            ms(r.shadow_ms),
            ms(r.lighting_ms),
            r.misclassified * 100.0,
            r.error_vs_soft_reference
                .map_or("-".to_owned(), |e| format!("{e:.4}"))
        ));
    }
    out
}

/// One setting of the IBL sweep.
#[derive(Clone, Debug, serde::Serialize)]
pub struct IblSweepRow {
    /// What differs from the default settings.
    pub setting: String,
    /// The settings.
    pub settings: engine::ibl::IblSettings,
    /// CPU precompute of the maps without caches, seconds (the DFG table, shared by every
    /// setting, is computed once per process and not included).
    pub precompute_s: f64,
    /// Median GPU time of the lighting pass, ms.
    pub lighting_ms: Option<f64>,
    /// Error of the light buffer against the Monte Carlo reference, per roughness.
    pub by_roughness: Vec<crate::ibl_reference::RoughnessError>,
    /// Mean relative error over every reference pixel.
    pub mean_relative: f64,
    /// Mean relative error per material family (rows) and roughness (columns: roughness, error,
    /// pixels).
    pub by_family: Vec<crate::ibl_reference::FamilyRow>,
}

/// The settings the IBL sweep visits: the default, then one knob changed at a time.
pub fn ibl_settings() -> Vec<(String, engine::ibl::IblSettings)> {
    use engine::ibl::{IblSettings, IrradianceMethod};
    let d = IblSettings::default();
    vec![
        ("default".to_owned(), d.clone()),
        (
            "64 samples".to_owned(),
            IblSettings {
                specular_samples: 64,
                ..d.clone()
            },
        ),
        (
            "1024 samples".to_owned(),
            IblSettings {
                specular_samples: 1024,
                ..d.clone()
            },
        ),
        (
            "specular 64".to_owned(),
            IblSettings {
                specular_size: 64,
                ..d.clone()
            },
        ),
        (
            "specular 256".to_owned(),
            IblSettings {
                specular_size: 256,
                ..d.clone()
            },
        ),
        (
            "sh9 irradiance".to_owned(),
            IblSettings {
                irradiance: IrradianceMethod::Sh9,
                ..d
            },
        ),
    ]
}

/// Reference pixels and directions per strategy of the IBL sweep's Monte Carlo reference.
pub const IBL_REFERENCE_PIXELS: usize = 144;
/// Directions per strategy and pixel (three or four strategies).
pub const IBL_REFERENCE_SAMPLES: usize = 8192;

/// Runs the IBL sweep on one backend: per setting, the precompute time, the lighting pass's GPU
/// time (median of `repeats` renders) and the error against the Monte Carlo reference per
/// roughness. The reference is computed once, from the default render's G-buffer (the
/// G-buffer does not depend on IBL settings).
pub fn ibl_sweep(
    scene: &Scene,
    kind: BackendKind,
    repeats: usize,
    mut progress: impl FnMut(&str),
) -> Result<Vec<IblSweepRow>, SweepError> {
    let environment = scene
        .environment
        .as_ref()
        .ok_or_else(|| SweepError::NoEnvironment(scene.name.clone()))?;
    let mut backend = backend::create(kind).map_err(|e| SweepError::Render(e.to_string()))?;
    let mut rows = Vec::new();
    let mut references = None;
    for (name, settings) in ibl_settings() {
        progress(&format!("precompute {name}"));
        engine::ibl::dfg_table();
        let start = std::time::Instant::now();
        std::hint::black_box(engine::ibl::build(&environment.image, &settings));
        let precompute_s = start.elapsed().as_secs_f64();
        let mut variant = scene.clone();
        variant.quality.ibl = settings.clone();
        let mut frames = Vec::new();
        for _ in 0..repeats.max(1) {
            frames.push(
                renderer::render(backend.as_mut(), &variant, Readback::All)
                    .map_err(|e| SweepError::Render(e.to_string()))?,
            );
        }
        if references.is_none() {
            progress("Monte Carlo reference");
            references = Some(
                crate::ibl_reference::reference_pixels(
                    scene,
                    &frames[0],
                    IBL_REFERENCE_PIXELS,
                    IBL_REFERENCE_SAMPLES,
                )
                .map_err(SweepError::Render)?,
            );
        }
        let references = references.as_deref().unwrap_or_default();
        let by_roughness = crate::ibl_reference::error_by_roughness(&frames[0], references);
        let by_family = crate::ibl_reference::error_by_family(&frames[0], references);
        let total: usize = by_roughness.iter().map(|r| r.pixels).sum();
        let mean_relative = by_roughness
            .iter()
            .map(|r| r.mean_relative * r.pixels as f64)
            .sum::<f64>()
            / total.max(1) as f64;
        rows.push(IblSweepRow {
            setting: name,
            settings,
            precompute_s,
            lighting_ms: pass_ms(&frames, "lighting"),
            by_roughness,
            mean_relative,
            by_family,
        });
    }
    Ok(rows)
}

/// The IBL sweep as a table: one line per setting, the mean relative error per roughness in
/// columns, then the reference's own noise.
pub fn ibl_table(rows: &[IblSweepRow]) -> String {
    let Some(first) = rows.first() else {
        return String::new();
    };
    let mut out = format!(
        "{:<15} {:>13} {:>12}",
        "setting", "precompute s", "lighting ms"
    );
    for g in &first.by_roughness {
        out.push_str(&format!(" {:>7}", format!("r {:.1}", g.roughness)));
    }
    out.push_str(&format!(" {:>7}\n", "mean"));
    for r in rows {
        out.push_str(&format!(
            "{:<15} {:>13.3} {:>12}",
            r.setting,
            r.precompute_s,
            r.lighting_ms.map_or("-".to_owned(), |v| format!("{v:.1}"))
        ));
        for g in &r.by_roughness {
            out.push_str(&format!(" {:>6.2}%", g.mean_relative * 100.0));
        }
        out.push_str(&format!(" {:>6.2}%\n", r.mean_relative * 100.0));
        out.push_str(&format!("{:<15} {:>13} {:>12}", "  (median)", "", ""));
        for g in &r.by_roughness {
            out.push_str(&format!(" {:>6.2}%", g.median_relative * 100.0));
        }
        out.push('\n');
    }
    out.push_str(&format!("{:<15} {:>13} {:>12}", "(ref. noise)", "", ""));
    for g in &first.by_roughness {
        out.push_str(&format!(" {:>6.2}%", g.reference_noise * 100.0));
    }
    out.push('\n');
    out.push_str(&format!(
        "\n{} settings, mean relative error per material row:\n",
        first.setting
    ));
    for (family, cells) in &first.by_family {
        out.push_str(&format!("{family:<15} {:>13} {:>12}", "", ""));
        for (_, error, _) in cells {
            out.push_str(&format!(" {:>6.2}%", error * 100.0));
        }
        out.push('\n');
    }
    out
}

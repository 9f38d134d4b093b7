//! Speed against error for one quality knob.
//!
//! `harness sweep --scene ibl --knob ibl` varies the IBL precompute (sample count, specular
//! size, SH9 irradiance) and measures each setting's precompute time, lighting-pass time and
//! error against the Monte Carlo reference ([`crate::reference::ibl`]) per roughness.
//!
//! `harness sweep --scene chess --knob shadow` renders
//! the scene once per setting (shadow filter x map size), times the passes from GPU timestamps
//! (median of several renders), and measures the error of the shadow term against
//!
//! - exact hard visibility by ray casting ([`crate::reference::shadows`]): the fraction of
//!   lit-surface pixels whose term is on the wrong side of 0.5, and the mean absolute difference;
//! - the converged soft filter (`soft-reference`, 1024 samples) for the soft filters and VSM
//!   (directional lights only): mean absolute difference.

use engine::backend::{self, BackendKind};
use engine::plan;
use engine::renderer::{self, Frame, Readback};
use engine::scene::{Light, Scene, ShadowFilter};

use crate::reference::shadows;
use engine::stats::median;

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

/// Why a sweep failed.
#[derive(Debug, thiserror::Error)]
pub enum SweepError {
    /// The knob is not one the sweep knows.
    #[error("unknown knob `{0}` (known: shadow, ibl, gbuffer)")]
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
    let own = match &scene.lights[light] {
        Light::Directional {
            shadow: Some(s), ..
        }
        | Light::Point {
            shadow: Some(s), ..
        } => Some((s.filter, s.map_size)),
        _ => None,
    };
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
            let frames = (0..repeats.max(1))
                .map(|_| render(&mutated))
                .collect::<Result<Vec<_>, _>>()?;
            let frame = &frames[0];
            let visibility = shadows::visibility_error(&mutated, frame, light, 1e-4)
                .map_err(SweepError::Render)?;
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
                shadow_ms: pass_ms(&frames, "shadow_"),
                lighting_ms: pass_ms(&frames, "lighting_"),
                misclassified: visibility.fraction,
                error_vs_soft_reference: soft.map(|s| s.0),
                soft_reference_p99_max: soft.map(|s| (s.1, s.2)),
                is_default: own == Some((filter, map_size)),
                pareto: false,
            });
        }
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
        .get("mask")
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

/// Mean, 99th percentile and maximum of some errors (zeros when there are none).
pub fn stats(mut errors: Vec<f64>) -> (f64, f64, f64) {
    if errors.is_empty() {
        return (0.0, 0.0, 0.0);
    }
    errors.sort_by(f64::total_cmp);
    let mean = errors.iter().sum::<f64>() / errors.len() as f64;
    let p99 = engine::stats::percentile_of_sorted(&errors, 0.99);
    (mean, p99, errors[errors.len() - 1])
}

/// The sweep as a table.
pub fn table(rows: &[SweepRow]) -> String {
    let mut out = format!(
        "{:<13} {:>6} {:>7} {:>11} {:>13} {:>14} {:>24}  {}\n",
        "filter",
        "map",
        "fetches",
        "shadow ms",
        "lighting ms",
        "misclassified",
        "vs soft ref mean/p99/max",
        "front"
    );
    let ms = |v: Option<f64>| v.map_or("-".to_owned(), |v| format!("{v:.2}"));
    for r in rows {
        out.push_str(&format!(
            "{:<13} {:>6} {:>7} {:>11} {:>13} {:>13.3}% {:>24}  {}{}\n",
            r.filter,
            r.map_size,
            r.fetches,
            ms(r.shadow_ms),
            ms(r.lighting_ms),
            r.misclassified * 100.0,
            r.error_vs_soft_reference
                .zip(r.soft_reference_p99_max)
                .map_or("-".to_owned(), |(mean, (p99, max))| format!(
                    "{mean:.4}/{p99:.3}/{max:.2}"
                )),
            if r.pareto { "*" } else { "" },
            if r.is_default { " (default)" } else { "" }
        ));
    }
    out.push_str("front: * = on the Pareto front of GPU time (shadow + lighting) against misclassification\n");
    out
}

/// The shadow sweep's errors without times (which vary run to run), rounded so that the text
/// is stable: the insta snapshot of the canonical scenes' sweep.
pub fn stable_table(rows: &[SweepRow]) -> String {
    let mut out = format!(
        "{:<13} {:>6} {:>7} {:>14} {:>12}\n",
        "filter", "map", "fetches", "misclassified", "vs soft ref"
    );
    for r in rows {
        out.push_str(&format!(
            "{:<13} {:>6} {:>7} {:>13.1}% {:>12}{}\n",
            r.filter,
            r.map_size,
            r.fetches,
            r.misclassified * 100.0,
            r.error_vs_soft_reference
                .map_or("-".to_owned(), |e| format!("{e:.3}")),
            if r.is_default { "  (default)" } else { "" }
        ));
    }
    out
}

/// Which points (cost, error) are on the Pareto front: no other point is at most as costly
/// and at most as wrong, and strictly better in one of the two.
pub fn pareto_front(points: &[(f64, f64)]) -> Vec<bool> {
    let points: Vec<Vec<f64>> = points.iter().map(|&(c, e)| vec![c, e]).collect();
    pareto_front_n(&points)
}

/// [`pareto_front`] over any number of criteria, each to be minimised: a point is on the front
/// when no other point is at most as large in every criterion and smaller in one.
pub fn pareto_front_n(points: &[Vec<f64>]) -> Vec<bool> {
    let dominates = |a: &[f64], b: &[f64]| {
        a.iter().zip(b).all(|(x, y)| x <= y) && a.iter().zip(b).any(|(x, y)| x < y)
    };
    points
        .iter()
        .map(|p| !points.iter().any(|q| dominates(q, p)))
        .collect()
}

/// An SVG scatter plot (plotters) of error against cost: every setting labelled, the Pareto
/// front joined and in green, the default ringed in orange.
pub fn pareto_svg(
    title: &str,
    x_label: &str,
    y_label: &str,
    points: &[(String, f64, f64, bool, bool)],
) -> String {
    use plotters::prelude::*;
    let mut svg = String::new();
    let drawn = (|| -> Result<(), Box<dyn std::error::Error>> {
        let root = SVGBackend::with_string(&mut svg, (480, 300)).into_drawing_area();
        root.fill(&WHITE)?;
        let finite = |v: f64| if v.is_finite() { v } else { 0.0 };
        let (x0, x1) = points.iter().fold((f64::MAX, f64::MIN), |(a, b), p| {
            (a.min(finite(p.1)), b.max(finite(p.1)))
        });
        let y1 = points.iter().map(|p| finite(p.2)).fold(0.0, f64::max);
        let pad = ((x1 - x0) * 0.08).max(1e-6);
        let mut chart = ChartBuilder::on(&root)
            .caption(title, ("sans-serif", 14))
            .margin(10)
            .x_label_area_size(32)
            .y_label_area_size(56)
            .build_cartesian_2d((x0 - pad)..(x1 + pad), 0.0..(y1 * 1.1).max(1e-9))?;
        chart
            .configure_mesh()
            .x_desc(x_label)
            .y_desc(y_label)
            .label_style(("sans-serif", 10))
            .draw()?;
        let mut front: Vec<(f64, f64)> = points
            .iter()
            .filter(|p| p.3)
            .map(|p| (finite(p.1), finite(p.2)))
            .collect();
        front.sort_by(|a, b| a.0.total_cmp(&b.0));
        let green = RGBColor(34, 160, 102);
        chart.draw_series(LineSeries::new(front, green.stroke_width(2)))?;
        for (label, x, y, on_front, is_default) in points {
            let at = (finite(*x), finite(*y));
            let color = if *on_front {
                green
            } else {
                RGBColor(150, 150, 150)
            };
            chart.draw_series(std::iter::once(Circle::new(at, 4, color.filled())))?;
            if *is_default {
                chart.draw_series(std::iter::once(Circle::new(
                    at,
                    8,
                    RGBColor(204, 102, 0).stroke_width(2),
                )))?;
            }
            chart.draw_series(std::iter::once(Text::new(
                label.clone(),
                at,
                ("sans-serif", 9).into_font(),
            )))?;
        }
        root.present()?;
        Ok(())
    })();
    match drawn {
        Ok(()) => svg,
        Err(e) => format!("<p>plot failed: {e}</p>"),
    }
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
    pub by_roughness: Vec<crate::reference::ibl::RoughnessError>,
    /// Mean relative error over every reference pixel.
    pub mean_relative: f64,
    /// 99th percentile and maximum relative error over every reference pixel.
    pub p99_max_relative: (f64, f64),
    /// Mean and 95th-percentile relative error per material family (rows) and roughness
    /// (cells).
    pub by_family: Vec<crate::reference::ibl::FamilyRow>,
    /// Whether these are the default settings.
    pub is_default: bool,
    /// Whether no other setting has both a shorter precompute and a smaller mean error.
    pub pareto: bool,
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
                ..d.clone()
            },
        ),
        (
            "fis 16".to_owned(),
            IblSettings {
                runtime_samples: 16,
                ..d.clone()
            },
        ),
        (
            "fis 64".to_owned(),
            IblSettings {
                runtime_samples: 64,
                ..d.clone()
            },
        ),
        (
            "fis 256".to_owned(),
            IblSettings {
                runtime_samples: 256,
                ..d.clone()
            },
        ),
        // The extracted sun without its shadow: the Monte Carlo reference, like the split sum,
        // sees the environment unoccluded, so a shadow one sphere casts on the next would count
        // as an error of the lighting (the shadow itself is tested in tests/ibl.rs).
        (
            "sun".to_owned(),
            IblSettings {
                extract_sun: true,
                sun_shadow: false,
                ..d.clone()
            },
        ),
        (
            "sun + fis 64".to_owned(),
            IblSettings {
                extract_sun: true,
                sun_shadow: false,
                runtime_samples: 64,
                ..d
            },
        ),
    ]
}

/// Reference pixels and directions per strategy of the IBL sweep's Monte Carlo reference.
pub const IBL_REFERENCE_PIXELS: usize = 576;
/// Directions per strategy and pixel (three or four strategies).
pub const IBL_REFERENCE_SAMPLES: usize = 4096;

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
    let mut built: Vec<(engine::ibl::cache::Key, f64)> = Vec::new();
    for (name, settings) in ibl_settings() {
        progress(&format!("precompute {name}"));
        engine::ibl::dfg_table();
        // Timed, and kept in memory for the render below. Settings that change only the
        // render (the runtime samples) share an earlier setting's maps and its time.
        let key = engine::ibl::cache::key_of_shared(&environment.image, &settings);
        let precompute_s = match built.iter().find(|(k, _)| *k == key) {
            Some(&(_, seconds)) => seconds,
            None => {
                let (_, seconds) = engine::ibl::build_timed(&environment.image, &settings);
                built.push((key, seconds));
                seconds
            }
        };
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
                crate::reference::ibl::reference_pixels(
                    scene,
                    &frames[0],
                    IBL_REFERENCE_PIXELS,
                    IBL_REFERENCE_SAMPLES,
                )
                .map_err(SweepError::Render)?,
            );
        }
        let references = references.as_deref().unwrap_or_default();
        let by_roughness = crate::reference::ibl::error_by_roughness(&frames[0], references);
        let by_family = crate::reference::ibl::error_by_family(&frames[0], references);
        let (_, p99, max) = stats(crate::reference::ibl::pixel_errors(&frames[0], references));
        let total: usize = by_roughness.iter().map(|r| r.pixels).sum();
        let mean_relative = by_roughness
            .iter()
            .map(|r| r.mean_relative * r.pixels as f64)
            .sum::<f64>()
            / total.max(1) as f64;
        let is_default = settings == engine::ibl::IblSettings::default();
        rows.push(IblSweepRow {
            setting: name,
            settings,
            precompute_s,
            lighting_ms: pass_ms(&frames, "lighting"),
            by_roughness,
            mean_relative,
            p99_max_relative: (p99, max),
            by_family,
            is_default,
            pareto: false,
        });
    }
    // Two costs: the precompute (once per environment and settings) and the lighting pass (every
    // frame; the filtered importance sampling settings spend it there).
    let points: Vec<Vec<f64>> = rows
        .iter()
        .map(|r| {
            vec![
                r.precompute_s,
                r.lighting_ms.unwrap_or(f64::INFINITY),
                r.mean_relative,
            ]
        })
        .collect();
    for (row, on_front) in rows.iter_mut().zip(pareto_front_n(&points)) {
        row.pareto = on_front;
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
    out.push_str(&format!(" {:>7} {:>7} {:>7}\n", "mean", "p99", "max"));
    for r in rows {
        out.push_str(&format!(
            "{:<15} {:>13.3} {:>12}",
            format!("{}{}", r.setting, if r.pareto { " *" } else { "" }),
            r.precompute_s,
            r.lighting_ms.map_or("-".to_owned(), |v| format!("{v:.1}"))
        ));
        for g in &r.by_roughness {
            out.push_str(&format!(" {:>6.2}%", g.mean_relative * 100.0));
        }
        out.push_str(&format!(
            " {:>6.2}% {:>6.1}% {:>6.1}%\n",
            r.mean_relative * 100.0,
            r.p99_max_relative.0 * 100.0,
            r.p99_max_relative.1 * 100.0
        ));
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
    out.push_str("* = on the Pareto front of precompute time, lighting time and mean error\n");
    for row in family_rows(rows) {
        out.push_str(&format!(
            "\n{}, relative error per material row (mean, then p95):\n",
            row.setting
        ));
        for (family, cells) in &row.by_family {
            out.push_str(&format!("{family:<15} {:>13} {:>12}", "", "mean"));
            for cell in cells {
                out.push_str(&format!(" {:>6.2}%", cell.mean * 100.0));
            }
            out.push_str(&format!("\n{:<15} {:>13} {:>12}", "", "", "p95"));
            for cell in cells {
                out.push_str(&format!(" {:>6.2}%", cell.p95 * 100.0));
            }
            out.push('\n');
        }
    }
    out.push_str(&format!("\n{}\n", ibl_goal_line(rows)));
    out
}

/// The accuracy goal for IBL against the Monte Carlo reference: in every cell (material row x
/// roughness), at most this mean relative error...
pub const IBL_GOAL_MEAN: f64 = 0.05;
/// ...and at most this 95th-percentile relative error.
pub const IBL_GOAL_P95: f64 = 0.15;

/// A row's worst cell mean and worst cell p95 relative error over every material row and
/// roughness.
pub fn worst_cells(row: &IblSweepRow) -> (f64, f64) {
    row.by_family
        .iter()
        .flat_map(|(_, cells)| cells)
        .fold((0.0f64, 0.0f64), |(mean, p95), c| {
            (mean.max(c.mean), p95.max(c.p95))
        })
}

/// One line: the settings that meet the goal ([`IBL_GOAL_MEAN`], [`IBL_GOAL_P95`] in every
/// cell), or that none does and which comes closest.
pub fn ibl_goal_line(rows: &[IblSweepRow]) -> String {
    let meeting: Vec<&str> = rows
        .iter()
        .filter(|r| {
            let (mean, p95) = worst_cells(r);
            mean <= IBL_GOAL_MEAN && p95 <= IBL_GOAL_P95
        })
        .map(|r| r.setting.as_str())
        .collect();
    let goal = format!(
        "goal: every material row and roughness within {:.0}% mean and {:.0}% p95",
        IBL_GOAL_MEAN * 100.0,
        IBL_GOAL_P95 * 100.0
    );
    if !meeting.is_empty() {
        return format!("{goal}: met by {}", meeting.join(", "));
    }
    let closest = rows.iter().min_by(|a, b| {
        let score = |r: &IblSweepRow| {
            let (mean, p95) = worst_cells(r);
            (mean / IBL_GOAL_MEAN).max(p95 / IBL_GOAL_P95)
        };
        score(a).total_cmp(&score(b))
    });
    match closest {
        Some(r) => {
            let (mean, p95) = worst_cells(r);
            format!(
                "{goal}: met by none; closest {} (worst cell {:.1}% mean, {:.1}% p95)",
                r.setting,
                mean * 100.0,
                p95 * 100.0
            )
        }
        None => format!("{goal}: nothing swept"),
    }
}

/// The rows whose error per material row the tables show: the first (the defaults) and every
/// filtered-importance-sampling setting.
fn family_rows(rows: &[IblSweepRow]) -> impl Iterator<Item = &IblSweepRow> {
    rows.iter()
        .enumerate()
        .filter(|(i, r)| *i == 0 || r.settings.runtime_samples > 0 || r.settings.extract_sun)
        .map(|(_, r)| r)
}

/// The IBL sweep's errors without times, rounded so that the text is stable: the insta
/// snapshot of the canonical scenes' sweep.
pub fn stable_ibl_table(rows: &[IblSweepRow]) -> String {
    let Some(first) = rows.first() else {
        return String::new();
    };
    let mut out = format!("{:<15}", "setting");
    for g in &first.by_roughness {
        out.push_str(&format!(" {:>6}", format!("r {:.1}", g.roughness)));
    }
    out.push_str(&format!(" {:>6}\n", "mean"));
    for r in rows {
        out.push_str(&format!("{:<15}", r.setting));
        for g in &r.by_roughness {
            out.push_str(&format!(" {:>5.1}%", g.mean_relative * 100.0));
        }
        out.push_str(&format!(" {:>5.1}%\n", r.mean_relative * 100.0));
    }
    for row in family_rows(rows) {
        out.push_str(&format!(
            "\n{}, per material row (mean, p95):\n",
            row.setting
        ));
        for (family, cells) in &row.by_family {
            out.push_str(&format!("{family:<15}"));
            for cell in cells {
                out.push_str(&format!(" {:>5.1}%", cell.mean * 100.0));
            }
            out.push_str(&format!("\n{:<15}", ""));
            for cell in cells {
                out.push_str(&format!(" {:>5.1}%", cell.p95 * 100.0));
            }
            out.push('\n');
        }
    }
    out
}

/// File name of a sweep's results in the output folder (read by the check report).
pub fn result_file(scene: &str, knob: &str) -> String {
    format!("sweep_{scene}_{knob}.json")
}

/// HTML sections for the check report from the sweeps kept in `dir` (`harness sweep` writes
/// them): per sweep, its table and a Pareto plot of error against cost. Empty without any.
pub fn report_sections(dir: &std::path::Path) -> String {
    let mut files: Vec<std::path::PathBuf> = std::fs::read_dir(dir)
        .into_iter()
        .flatten()
        .flatten()
        .map(|e| e.path())
        .filter(|p| {
            p.file_name()
                .and_then(|n| n.to_str())
                .is_some_and(|n| n.starts_with("sweep_") && n.ends_with(".json"))
        })
        .collect();
    files.sort();
    let mut out = String::new();
    for path in files {
        let Some(bytes) = std::fs::read(&path).ok() else {
            continue;
        };
        let name = path
            .file_stem()
            .and_then(|n| n.to_str())
            .unwrap_or("sweep")
            .to_owned();
        if let Ok(rows) = serde_json::from_slice::<Vec<serde_json::Value>>(&bytes) {
            let is_ibl = rows
                .first()
                .is_some_and(|r| r.get("precompute_s").is_some());
            let is_gbuffer = rows
                .first()
                .is_some_and(|r| r.get("p99_relative").is_some());
            let points: Vec<(String, f64, f64, bool, bool)> = rows
                .iter()
                .map(|r| {
                    let label = if is_gbuffer {
                        format!(
                            "{} at {}",
                            r["setting"].as_str().unwrap_or("?"),
                            r["distance"].as_f64().unwrap_or(0.0)
                        )
                    } else if is_ibl {
                        r["setting"].as_str().unwrap_or("?").to_owned()
                    } else {
                        format!(
                            "{} {}",
                            r["filter"].as_str().unwrap_or("?"),
                            r["map_size"].as_u64().unwrap_or(0)
                        )
                    };
                    let (cost, error) = if is_gbuffer {
                        (
                            r["gpu_ms"].as_f64().unwrap_or(0.0),
                            r["p99_relative"].as_f64().unwrap_or(0.0),
                        )
                    } else if is_ibl {
                        (
                            r["precompute_s"].as_f64().unwrap_or(0.0),
                            r["mean_relative"].as_f64().unwrap_or(0.0),
                        )
                    } else {
                        (
                            r["shadow_ms"].as_f64().unwrap_or(0.0)
                                + r["lighting_ms"].as_f64().unwrap_or(0.0),
                            r["misclassified"].as_f64().unwrap_or(0.0),
                        )
                    };
                    (
                        label,
                        cost,
                        error,
                        r["pareto"].as_bool().unwrap_or(false),
                        r["is_default"].as_bool().unwrap_or(false),
                    )
                })
                .collect();
            // The G-buffer sweep's front is per distance: plot the farthest distance only.
            let farthest = rows
                .iter()
                .filter_map(|r| r["distance"].as_f64())
                .fold(0.0, f64::max);
            let plotted: Vec<(String, f64, f64, bool, bool)> = points
                .iter()
                .zip(&rows)
                .filter(|(_, r)| !is_gbuffer || r["distance"].as_f64() == Some(farthest))
                .map(|(p, _)| p.clone())
                .collect();
            let (x_label, y_label) = if is_gbuffer {
                (
                    "geometry + lighting GPU ms",
                    "p99 relative error of the light buffer",
                )
            } else if is_ibl {
                ("precompute s", "mean relative error")
            } else {
                ("shadow + lighting GPU ms", "misclassified fraction")
            };
            out.push_str(&format!(
                "<h2>Speed against error: <code>{name}</code> (latest <code>harness sweep</code>)</h2>\
                 <p>{y_label} against {x_label}; green: Pareto front, ringed: the default.</p>{}<table>\
                 <tr><th>setting</th><th>{x_label}</th><th>{y_label}</th><th>front</th></tr>",
                pareto_svg(
                    &if is_gbuffer {
                        format!("{name} at distance {farthest}")
                    } else {
                        name.clone()
                    },
                    x_label,
                    y_label,
                    &plotted
                )
            ));
            for (label, cost, error, front, default) in &points {
                out.push_str(&format!(
                    "<tr><td>{label}{}</td><td>{cost:.3}</td><td>{error:.4}</td><td>{}</td></tr>",
                    if *default { " (default)" } else { "" },
                    if *front { "*" } else { "" }
                ));
            }
            out.push_str("</table>");
        }
    }
    out
}

/// One setting and distance of the G-buffer sweep.
#[derive(Clone, Debug, serde::Serialize)]
pub struct GbufferSweepRow {
    /// Position storage / normal encoding.
    pub setting: String,
    /// Distance the scene (camera too) is moved from the origin, in scene units.
    pub distance: f64,
    /// Median GPU time of the geometry and lighting passes, ms.
    pub gpu_ms: Option<f64>,
    /// Mean relative error of the light buffer against the reference (the scene at the origin
    /// with the default storage), over covered pixels.
    pub mean_relative: f64,
    /// Its 99th percentile.
    pub p99_relative: f64,
    /// Largest relative error.
    pub max_relative: f64,
    /// Whether this is the default storage.
    pub is_default: bool,
    /// On the Pareto front of time against p99 error among the settings at this distance.
    pub pareto: bool,
}

/// The G-buffer settings the sweep visits.
pub fn gbuffer_settings() -> Vec<engine::scene::GbufferSettings> {
    use engine::scene::{GbufferSettings, NormalEncoding, PositionStorage};
    let mut out = Vec::new();
    for position in [
        PositionStorage::CameraRelative,
        PositionStorage::World,
        PositionStorage::Depth,
    ] {
        for normal in [NormalEncoding::Fp16, NormalEncoding::Octahedral] {
            out.push(GbufferSettings { position, normal });
        }
    }
    out
}

/// Distances the G-buffer sweep moves the scene by (the offset is along (1, 0.5, -1), so that
/// no coordinate stays small).
pub const GBUFFER_DISTANCES: [f64; 3] = [0.0, 1e3, 1e4];

fn relative_errors(reference: &Frame, frame: &Frame) -> (f64, f64, f64) {
    let (Some(a), Some(b)) = (
        reference.output(plan::LIGHT).and_then(|i| i.as_f32()),
        frame.output(plan::LIGHT).and_then(|i| i.as_f32()),
    ) else {
        return (f64::NAN, f64::NAN, f64::NAN);
    };
    let mask = reference
        .outputs
        .get("mask")
        .and_then(|m| m.as_u8())
        .unwrap_or_default();
    let peak = a.iter().copied().fold(0.0f32, f32::max).max(1e-6);
    let floor = 1e-3 * peak;
    let mut errors: Vec<f64> = Vec::new();
    for i in 0..a.len().min(b.len()) / 4 {
        let covered = mask
            .get(i * 4..i * 4 + 4)
            .is_some_and(|m| m.iter().any(|&v| v > 127));
        if !covered {
            continue;
        }
        for c in 0..3 {
            let (x, y) = (a[i * 4 + c], b[i * 4 + c]);
            errors.push(f64::from((x - y).abs() / x.abs().max(floor)));
        }
    }
    stats(errors)
}

/// Runs the G-buffer sweep on one backend: every position storage and normal encoding, with
/// the scene at the origin and moved 1 km and 10 km away, against the scene at the origin with
/// the default storage.
pub fn gbuffer_sweep(
    scene: &Scene,
    kind: BackendKind,
    repeats: usize,
    mut progress: impl FnMut(&str),
) -> Result<Vec<GbufferSweepRow>, SweepError> {
    let mut backend = backend::create(kind).map_err(|e| SweepError::Render(e.to_string()))?;
    let wanted = [plan::LIGHT, "mask"];
    let mut render = |scene: &Scene| {
        renderer::render(backend.as_mut(), scene, Readback::Only(&wanted))
            .map_err(|e| SweepError::Render(e.to_string()))
    };
    let mut base = scene.clone();
    base.quality.gbuffer = engine::scene::GbufferSettings::default();
    progress("reference (default storage at the origin)");
    let reference = render(&base)?;
    let mut rows = Vec::new();
    for distance in GBUFFER_DISTANCES {
        let first = rows.len();
        for settings in gbuffer_settings() {
            progress(&format!("{} at {distance}", settings.name()));
            let mut variant = base.translated(glam::DVec3::new(1.0, 0.5, -1.0) * (distance / 1.5));
            variant.quality.gbuffer = settings;
            let frames = (0..repeats.max(1))
                .map(|_| render(&variant))
                .collect::<Result<Vec<_>, _>>()?;
            let (mean, p99, max) = relative_errors(&reference, &frames[0]);
            let gpu_ms = pass_ms(&frames, "geometry")
                .zip(pass_ms(&frames, "lighting_"))
                .map(|(g, l)| g + l);
            rows.push(GbufferSweepRow {
                setting: settings.name(),
                distance,
                gpu_ms,
                mean_relative: mean,
                p99_relative: p99,
                max_relative: max,
                is_default: settings == engine::scene::GbufferSettings::default(),
                pareto: false,
            });
        }
        let points: Vec<(f64, f64)> = rows[first..]
            .iter()
            .map(|r| (r.gpu_ms.unwrap_or(0.0), r.p99_relative))
            .collect();
        for (row, on_front) in rows[first..].iter_mut().zip(pareto_front(&points)) {
            row.pareto = on_front;
        }
    }
    Ok(rows)
}

/// The G-buffer sweep as a table.
pub fn gbuffer_table(rows: &[GbufferSweepRow]) -> String {
    let mut out = format!(
        "{:<28} {:>9} {:>14} {:>10} {:>10} {:>10}  {}\n",
        "storage (position/normal)",
        "distance",
        "geom+light ms",
        "mean rel",
        "p99 rel",
        "max rel",
        "front"
    );
    for r in rows {
        out.push_str(&format!(
            "{:<28} {:>9} {:>14} {:>10.2e} {:>10.2e} {:>10.2e}  {}{}\n",
            r.setting,
            r.distance,
            r.gpu_ms.map_or("-".to_owned(), |v| format!("{v:.2}")),
            r.mean_relative,
            r.p99_relative,
            r.max_relative,
            if r.pareto { "*" } else { "" },
            if r.is_default { " (default)" } else { "" }
        ));
    }
    out.push_str("front: * = on the Pareto front of GPU time against p99 error at that distance\n");
    out
}

/// The G-buffer sweep's p99 errors without times, as power-of-ten bands so that the text is
/// stable: the insta snapshot of the canonical scene's sweep.
pub fn stable_gbuffer_table(rows: &[GbufferSweepRow]) -> String {
    let band = |e: f64| {
        if e <= 0.0 {
            "0".to_owned()
        } else {
            format!("1e{}", e.log10().ceil() as i32)
        }
    };
    let mut out = format!(
        "{:<28} {:>9} {:>10}\n",
        "storage (position/normal)", "distance", "p99 <="
    );
    for r in rows {
        out.push_str(&format!(
            "{:<28} {:>9} {:>10}{}\n",
            r.setting,
            r.distance,
            band(r.p99_relative),
            if r.is_default { "  (default)" } else { "" }
        ));
    }
    out
}

//! The hard numerical cases: the scene files in `scenes/hard/` and the chess scene moved and
//! scaled, each rendered and checked against its invariant. `harness hard` prints the table and
//! keeps it for the check report; `tests/integration/hard_cases.rs` asserts every row on every backend.
//!
//! Every case must have no NaN/Inf in any pass and a light buffer within 0..65000 (the lighting
//! pass's fp16 clamp); then each has its own check (the `check` column).

use engine::backend::{self, BackendKind};
use engine::renderer::{self, Frame, Readback};
use engine::scene::{Light, Scene};
use glam::DVec3;

use crate::reference::{self, shadows};

/// Largest value the lighting pass writes (its fp16 clamp).
pub const FP16_SAFE_MAX: f32 = 65000.0;

/// The scene files in `scenes/hard/`, by name.
pub const SCENE_CASES: [&str; 8] = [
    "degenerate",
    "furnace",
    "grazing",
    "grazing_shadow",
    "light_on_surface",
    "material_extremes",
    "roughness_zero",
    "sun_1e5",
];

/// Cases lit only by analytic lights without shadows, where the f64 reference of the lighting
/// pass is defined; each must match it within p99.9 <= 2e-3 relative.
pub const REFERENCE_CASES: [&str; 5] = [
    "degenerate",
    "grazing",
    "light_on_surface",
    "material_extremes",
    "roughness_zero",
];

/// One hard case on one backend.
#[derive(Clone, Debug, serde::Serialize)]
pub struct HardCaseRow {
    /// Case name.
    pub case: String,
    /// Backend.
    pub backend: BackendKind,
    /// Non-finite values over every float pass.
    pub non_finite: usize,
    /// Light buffer range.
    pub light_min: f32,
    /// Light buffer range.
    pub light_max: f32,
    /// What the case's own check measures.
    pub check: String,
    /// Its value.
    pub value: f64,
    /// Its bound (value must be <= bound).
    pub bound: f64,
    /// Whether everything held.
    pub passed: bool,
}

/// Why a hard case could not run.
#[derive(Debug, thiserror::Error)]
pub enum HardCaseError {
    /// Its scene file did not load.
    #[error(transparent)]
    Scene(#[from] engine::scene_file::SceneFileError),
    /// The backend is missing or failed.
    #[error(transparent)]
    Backend(#[from] backend::BackendError),
    /// The render failed.
    #[error(transparent)]
    Render(#[from] engine::renderer::RenderError),
    /// The comparison with its reference could not run.
    #[error(transparent)]
    Reference(#[from] reference::ReferenceError),
    /// Two renders could not be compared.
    #[error(transparent)]
    Compare(#[from] crate::golden::metrics::compare::CompareError),
}

/// Loads `scenes/hard/<name>.toml`.
pub fn scene(name: &str) -> Result<Scene, HardCaseError> {
    let path = crate::workspace_root().join(format!("scenes/hard/{name}.toml"));
    Ok(engine::scene_file::load(&path)?.scene)
}

fn render(backend: &mut dyn backend::Backend, scene: &Scene) -> Result<Frame, HardCaseError> {
    Ok(renderer::render(backend, scene, Readback::All)?)
}

/// A frame's final image.
fn final_image(frame: &Frame) -> Result<&engine::Image, reference::ReferenceError> {
    frame
        .output(engine::plan::TargetId::Final)
        .ok_or(reference::ReferenceError::MissingOutput {
            target: engine::plan::TargetId::Final,
            storage: "8-bit",
        })
}

/// Non-finite values in every float output, and the light buffer's range.
pub fn finiteness(frame: &Frame) -> (usize, f32, f32) {
    let mut bad = 0;
    let (mut min, mut max) = (0.0f32, 0.0f32);
    for (name, image) in &frame.outputs {
        let Some(data) = image.as_f32() else {
            continue;
        };
        bad += data.iter().filter(|v| !v.is_finite()).count();
        if *name == engine::plan::TargetId::Light {
            (min, max) = data
                .iter()
                .filter(|v| v.is_finite())
                .fold((f32::MAX, f32::MIN), |(a, b), &v| (a.min(v), b.max(v)));
        }
    }
    (bad, min, max)
}

/// The chess scene `factor` times larger or smaller about the origin: camera, objects, point
/// lights and shadow biases (meters) too.
pub fn scaled(scene: &Scene, factor: f64) -> Scene {
    let mut s = scene.clone();
    s.camera.position *= factor;
    s.camera.target *= factor;
    s.camera.near *= factor;
    s.camera.far *= factor;
    for object in &mut s.objects {
        object.transform.translation *= factor;
        object.transform.scale *= factor;
    }
    for light in &mut s.lights {
        match light {
            Light::Directional { shadow, .. } => {
                if let Some(shadow) = shadow {
                    shadow.bias *= factor as f32;
                }
            }
            Light::Point {
                position,
                radius,
                shadow,
                ..
            } => {
                *position *= factor;
                *radius *= factor as f32;
                if let Some(shadow) = shadow {
                    shadow.bias *= factor as f32;
                }
            }
        }
    }
    s
}

fn light(frame: &Frame) -> &[f32] {
    frame
        .output(engine::plan::TargetId::Light)
        .and_then(|i| i.as_f32())
        .unwrap_or(&[])
}

/// p99 of the relative difference of two light buffers (floor 1e-2).
fn seed_difference(a: &Frame, b: &Frame) -> f64 {
    let errors: Vec<f64> = light(a)
        .iter()
        .zip(light(b))
        .map(|(x, y)| f64::from((x - y).abs() / x.abs().max(1e-2)))
        .collect();
    engine::stats::percentile(errors, 0.99).unwrap_or(f64::NAN)
}

/// Largest |L - 1| over the pixels of every lighting model (the furnace).
fn furnace_error(frame: &Frame) -> f64 {
    let light = light(frame);
    let mut worst = 0.0f64;
    let mut pixels = 0;
    for channel in &frame.plan.mask_channels {
        let Some(mask) = frame
            .output(engine::plan::TargetId::Mask(channel.target))
            .and_then(|m| m.as_u8())
        else {
            return f64::NAN;
        };
        for i in 0..light.len() / 4 {
            if mask[i * 4 + channel.channel] > 127 {
                pixels += 1;
                for c in 0..3 {
                    worst = worst.max(f64::from((light[i * 4 + c] - 1.0).abs()));
                }
            }
        }
    }
    if pixels < 3000 {
        f64::NAN
    } else {
        worst
    }
}

fn row(
    case: &str,
    kind: BackendKind,
    frame: &Frame,
    check: &str,
    value: f64,
    bound: f64,
) -> HardCaseRow {
    let (non_finite, light_min, light_max) = finiteness(frame);
    HardCaseRow {
        case: case.to_owned(),
        backend: kind,
        non_finite,
        light_min,
        light_max,
        check: check.to_owned(),
        value,
        bound,
        passed: non_finite == 0
            && light_min >= 0.0
            && light_max <= FP16_SAFE_MAX
            && value.is_finite()
            && value <= bound,
    }
}

/// Runs every hard case on one backend.
pub fn run(
    kind: BackendKind,
    mut progress: impl FnMut(&str),
) -> Result<Vec<HardCaseRow>, HardCaseError> {
    let mut backend = crate::faults::create_backend(kind)?;
    let mut rows = Vec::new();
    for case in SCENE_CASES {
        progress(case);
        let scene = scene(case)?;
        let frame = render(backend.as_mut(), &scene)?;
        let row = if REFERENCE_CASES.contains(&case) {
            let error = reference::lighting_error(&scene, &frame)?;
            let value = if error.pixels > 1000 && error.non_finite == 0 {
                error.p999_relative
            } else {
                f64::NAN
            };
            row(
                case,
                kind,
                &frame,
                "lighting vs f64 reference, p99.9 relative",
                value,
                2e-3,
            )
        } else if case == "grazing_shadow" {
            let error = shadows::visibility_error(&scene, &frame, 0, 1e-4)?;
            let value = if error.shadowed_by_reference > 2000 {
                error.fraction
            } else {
                f64::NAN
            };
            row(
                case,
                kind,
                &frame,
                "shadow term vs ray casting, misclassified",
                value,
                0.01,
            )
        } else if case == "sun_1e5" {
            let mut other = scene.clone();
            other.quality.ibl.seed = 11;
            let second = render(backend.as_mut(), &other)?;
            let value = seed_difference(&frame, &second);
            row(
                case,
                kind,
                &frame,
                "prefilter seeds 0 vs 11, p99 relative",
                value,
                0.02,
            )
        } else {
            row(
                case,
                kind,
                &frame,
                "max |L - 1| over every model",
                furnace_error(&frame),
                0.01,
            )
        };
        rows.push(row);
    }
    progress("chess moved and scaled");
    let chess = crate::load_scene("chess")?.scene;
    let reference = render(backend.as_mut(), &chess)?;
    for (what, moved) in [
        (
            "chess 1e4 away",
            chess.translated(DVec3::new(1e4, 0.0, -1e4)),
        ),
        (
            "chess 1e5 away",
            chess.translated(DVec3::new(-1e5, 1e5, 1e5)),
        ),
        ("chess x0.001", scaled(&chess, 1e-3)),
        ("chess x1000", scaled(&chess, 1e3)),
    ] {
        let frame = render(backend.as_mut(), &moved)?;
        let diff = crate::golden::metrics::compare::u8_difference(
            final_image(&reference)?,
            final_image(&frame)?,
            1,
        )?;
        rows.push(row(
            what,
            kind,
            &frame,
            "final vs chess, fraction of pixels over 1/255",
            1.0 - diff.fraction_within,
            1e-3,
        ));
    }
    Ok(rows)
}

/// The rows as a table.
pub fn table(rows: &[HardCaseRow]) -> String {
    let mut out = format!(
        "{:<18} {:<12} {:>5} {:>10}  {:<46} {:>10} {:>8}  {}\n",
        "case", "backend", "NaN", "light max", "check", "value", "bound", "ok"
    );
    for r in rows {
        out.push_str(&format!(
            "{:<18} {:<12} {:>5} {:>10.1}  {:<46} {:>10.2e} {:>8.0e}  {}\n",
            r.case,
            r.backend,
            r.non_finite,
            r.light_max,
            r.check,
            r.value,
            r.bound,
            if r.passed { "ok" } else { "FAILED" }
        ));
    }
    out
}

/// File name of `harness hard`'s results in the output folder (read by the check report).
pub const RESULTS_JSON: &str = "hard_cases.json";

/// The hard-case table as an HTML section for the check report, from the results kept in
/// `dir`; empty when there are none.
pub fn report_section(dir: &std::path::Path) -> String {
    let Some(rows) = std::fs::read(dir.join(RESULTS_JSON))
        .ok()
        .and_then(|b| serde_json::from_slice::<Vec<serde_json::Value>>(&b).ok())
    else {
        return String::new();
    };
    let mut out = String::from(
        "<h2>Hard cases (latest <code>harness hard</code>)</h2>\
         <table><tr><th>case</th><th>backend</th><th>NaN/Inf</th><th>light max</th>\
         <th>check</th><th>value</th><th>bound</th><th></th></tr>",
    );
    let escape = crate::html::escape;
    for r in rows {
        let passed = r["passed"].as_bool().unwrap_or(false);
        out.push_str(&format!(
            "<tr class=\"{}\"><td>{}</td><td>{}</td><td>{}</td><td>{:.1}</td><td>{}</td><td>{:.2e}</td><td>{:.0e}</td><td>{}</td></tr>",
            if passed { "passed" } else { "failed" },
            escape(r["case"].as_str().unwrap_or("?")),
            escape(r["backend"].as_str().unwrap_or("?")),
            r["non_finite"].as_u64().unwrap_or(0),
            r["light_max"].as_f64().unwrap_or(f64::NAN),
            escape(r["check"].as_str().unwrap_or("?")),
            r["value"].as_f64().unwrap_or(f64::NAN),
            r["bound"].as_f64().unwrap_or(f64::NAN),
            if passed { "ok" } else { "FAILED" }
        ));
    }
    out.push_str("</table>");
    out
}

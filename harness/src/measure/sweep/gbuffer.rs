//! The G-buffer sweep: every position storage and normal encoding, with the scene at the origin
//! and moved far from it, timed and measured against the default storage at the origin.

use engine::backend::BackendKind;
use engine::plan::{PassId, TargetId};
use engine::renderer::{self, Frame, Readback};
use engine::scene::Scene;

use super::{lighting, pareto_front, pass_ms, stats, SweepError};

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
        reference.output(TargetId::Light).and_then(|i| i.as_f32()),
        frame.output(TargetId::Light).and_then(|i| i.as_f32()),
    ) else {
        return (f64::NAN, f64::NAN, f64::NAN);
    };
    let mask = reference
        .outputs
        .get(&TargetId::Mask(0))
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
    let mut backend =
        crate::faults::create_backend(kind).map_err(|e| SweepError::Render(e.to_string()))?;
    let wanted = [TargetId::Light, TargetId::Mask(0)];
    let mut render = |scene: &Scene| {
        renderer::render(backend.as_mut(), scene, Readback::Only(&wanted)).map_err(SweepError::from)
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
            let gpu_ms = pass_ms(&frames, |p| p == PassId::Geometry)
                .zip(pass_ms(&frames, lighting))
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

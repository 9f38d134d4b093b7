//! Speed against error for one quality knob.
//!
//! `harness sweep --scene ibl --knob ibl` varies the IBL precompute (sample count, specular
//! size, SH9 irradiance) and measures each setting's precompute time, lighting-pass time and
//! error against the Monte Carlo reference ([`crate::reference::ibl`]) per roughness.
//!
//! `harness sweep --scene chess --knob shadow` renders
//! the scene once per setting (shadow filter x map size), times the passes from GPU timestamps
//! (median of several rounds, each rendering every setting once), and measures the error of the
//! shadow term against
//!
//! - exact hard visibility by ray casting ([`crate::reference::shadows`]): the fraction of
//!   lit-surface pixels whose term is on the wrong side of 0.5, and the mean absolute difference;
//! - the converged soft filter (`soft-reference`, 1024 samples) for the soft filters and VSM
//!   (directional lights only): mean absolute difference.

mod gbuffer;
pub mod ibl;
mod pareto;
mod report;
mod shadow;
mod tables;

pub use gbuffer::{gbuffer_settings, gbuffer_sweep, GbufferSweepRow, GBUFFER_DISTANCES};
pub use ibl::{
    ibl_settings, ibl_sweep, ibl_sweep_with, parse_tried_setting, IblSweepChoice, IblSweepRow,
    MapSource, BEST_SETTING, IBL_REFERENCE_PIXELS, IBL_REFERENCE_SAMPLES,
};
pub use pareto::{pareto_front, pareto_front_n, pareto_svg};
pub use report::{report_sections, result_file};
pub use shadow::{shadow_sweep, shadow_sweep_with, ShadowSweepCost, SweepRow};
pub use tables::{
    gbuffer_table, ibl_default_goal_line, ibl_goal_line, ibl_table, stable_gbuffer_table,
    stable_ibl_table, stable_table, table, worst_cells, IBL_DEFAULT_COST, IBL_DEFAULT_MEAN,
    IBL_GOAL_MEAN, IBL_GOAL_P95,
};

use engine::plan::PassId;
use engine::renderer::{self, Frame, PreparedFrame, Readback};
use engine::stats::median;

/// Why a sweep failed.
#[derive(Debug, thiserror::Error)]
pub enum SweepError {
    /// The scene has no environment (for the `ibl` knob).
    #[error("scene `{0}` has no environment")]
    NoEnvironment(String),
    /// The scene has no shadowed light.
    #[error("scene `{0}` has no light with shadows")]
    NoShadows(String),
    /// Rendering failed.
    #[error("{0}")]
    Render(String),
    /// The comparison with the reference could not run.
    #[error(transparent)]
    Reference(#[from] crate::reference::ReferenceError),
}

impl From<engine::renderer::RenderError> for SweepError {
    fn from(e: engine::renderer::RenderError) -> Self {
        SweepError::Render(e.to_string())
    }
}

/// Median over frames of the GPU ms of every pass `of` selects (summed in each frame).
pub fn pass_ms(frames: &[Frame], of: impl Fn(PassId) -> bool) -> Option<f64> {
    median(
        frames
            .iter()
            .filter_map(|f| {
                let ns: Vec<f64> = f
                    .timings
                    .passes
                    .iter()
                    .zip(&f.timings.owners)
                    .filter(|(_, owner)| of(**owner))
                    .filter_map(|(t, _)| t.gpu_ns)
                    .collect();
                (!ns.is_empty()).then(|| ns.iter().sum::<f64>() / 1e6)
            })
            .collect(),
    )
}

/// `repeats` timed renders of each of `frames`, in rounds: each round renders every frame once,
/// in order, reading nothing back (the timestamps are all a timing needs). A sweep takes
/// minutes, and a host drifts over minutes: renders of one setting back to back put the drift on
/// some settings only (one IBL sweep read a setting at 16.4 ms that took 10.3 ms rendered in
/// turn with the default), rounds spread it over all of them.
fn timing_rounds(
    backend: &mut dyn engine::backend::Backend,
    frames: &[PreparedFrame],
    repeats: usize,
    progress: &mut impl FnMut(&str),
) -> Result<Vec<Vec<Frame>>, SweepError> {
    let rounds = repeats.max(1);
    let mut rendered: Vec<Vec<Frame>> = frames.iter().map(|_| Vec::new()).collect();
    for round in 0..rounds {
        progress(&format!("timing round {} of {rounds}", round + 1));
        for (frame, times) in frames.iter().zip(&mut rendered) {
            let timed = renderer::render_prepared(backend, frame, Readback::Only(&[]))?;
            times.push(timed);
        }
    }
    Ok(rendered)
}

/// The shadow maps' passes (casters and VSM blurs, not the shadow-term outputs).
fn shadow_map(pass: PassId) -> bool {
    matches!(pass, PassId::Shadow { .. } | PassId::ShadowBlur { .. })
}

/// The lighting passes, which the sweeps time.
fn lighting(pass: PassId) -> bool {
    matches!(pass, PassId::Lighting(_))
}

/// A quality knob `harness sweep` times against error.
#[derive(Clone, Copy, Debug, PartialEq, Eq, clap::ValueEnum)]
pub enum Knob {
    /// Shadow filter x map size, against ray-cast visibility.
    Shadow,
    /// IBL settings, against a Monte Carlo reference.
    Ibl,
    /// G-buffer position storage x normal encoding, at 0, 1 km and 10 km from the origin.
    Gbuffer,
}

impl Knob {
    /// Its name on the command line and in file names.
    pub fn name(self) -> &'static str {
        match self {
            Knob::Shadow => "shadow",
            Knob::Ibl => "ibl",
            Knob::Gbuffer => "gbuffer",
        }
    }
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

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

mod floors;
pub mod lighting_breakdown;
mod precompute;
mod report;
mod series;
mod tables;
pub mod timing;

use engine::backend::BackendKind;

pub use floors::Floors;
pub use lighting_breakdown::{breakdown, BreakdownRow, PassBreakdown, BREAKDOWN_FRAMES};
pub use precompute::{precompute, Precompute};
pub use report::{report_sections, series_svg, BENCH_JSON, SERIES_JSON};
pub use series::{series, Series, SeriesPoint};
pub use tables::{breakdown_table, series_table, table};
pub use timing::{bench_scene, bench_scene_with, timed_render, PassBench, SceneBench};

/// Criterion's warm-up and measurement time for a benchmark, from one run of its routine timed
/// by wall clock (criterion sizes samples from its warm-up's wall time, not from the GPU time a
/// routine reports): `samples` samples of two iterations each. Flat sampling warns "Unable to
/// complete N samples" whenever a sample gets one iteration; two each keep it quiet at twice
/// the cost of one.
pub fn criterion_budget(
    run_once: impl FnOnce(),
    samples: usize,
) -> (std::time::Duration, std::time::Duration) {
    let start = std::time::Instant::now();
    run_once();
    let one = start.elapsed().max(std::time::Duration::from_micros(10));
    (one, one.mul_f64(samples as f64 * 1.5))
}

/// Frames timed per scene and backend by `harness bench` and its series unless told otherwise.
pub const BENCH_FRAMES: usize = 5;

/// Why a benchmark could not run.
#[derive(Debug, thiserror::Error)]
pub enum BenchError {
    /// The backend is missing or failed.
    #[error("{backend}: {message}")]
    Backend {
        /// Backend.
        backend: BackendKind,
        /// What went wrong.
        message: String,
    },
    /// Rendering the scene failed.
    #[error("scene `{scene}` on {backend}: {message}")]
    Render {
        /// Scene name.
        scene: String,
        /// Backend.
        backend: BackendKind,
        /// What went wrong.
        message: String,
    },
}

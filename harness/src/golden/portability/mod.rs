//! Measuring the noise model's figures: the sources of variation a user's machine can bring
//! (the three backends, llvmpipe's other CPU code paths, a second Mesa release, synthetic host
//! rounding, renders recorded on other hosts), the metrics of unchanged renders under each, and
//! the model ([`crate::golden::noise`]) built from them: the portability check behind
//! `harness noise` and `scripts/portability.sh`.
//!
//! Sources that change the driver's environment run `harness check --json` as a child process
//! per scene and backend, so a driver that aborts takes down one measurement, not the run.
//!
//! The parts: `sources.rs` names the sources of variation, `measuring.rs` measures unchanged
//! renders under them, `rounding.rs` is the synthetic host rounding, and `model.rs` turns the
//! measurements into the noise model and the table of ratios.

pub mod measuring;
pub mod model;
pub mod rounding;
pub mod sources;

pub use measuring::{
    known_driver_crash, measure, measure_environment, measure_recorded, measure_synthetic,
    Measurement, Missed, SourceRun, PINNED_GOLDEN,
};
pub use model::{build_model, ratios, table, Ratio};
pub use rounding::{requantize_final, step_ulps, synthetic_rounding, tone_map, ulp_noise};
pub use sources::{mesa_backports, mesa_backports_prefix, select, sources, Source, SourceKind};

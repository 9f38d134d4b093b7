//! Goldens: the store of blessed images and their records ([`store`], re-exported here), the
//! tolerances and the metrics they are measured in, the canonical suite that renders and
//! compares, the `check` run, the noise model the limits are derived from, and the mutation
//! self-test that proves the limits catch real changes.

pub mod accept;
pub mod bless;
pub mod check;
pub mod command_line;
pub mod diagnosis;
pub mod merge;
pub mod metrics;
pub mod noise;
pub mod orphans;
pub mod pass_kind;
pub mod portability;
pub mod scene_inputs;
pub mod selftest;
pub mod speed;
pub mod store;
pub mod suite;
pub mod tolerance;
pub mod verify;
pub mod verify_cache;

pub use store::*;

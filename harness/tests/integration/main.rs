//! The harness's integration tests, as one test binary: one link instead of twenty, and one
//! libtest run whose threads keep both cores busy across what were separate binaries (cargo
//! runs test binaries one after another, so a binary whose last test runs alone left a core
//! idle). Each module is the former `tests/<module>.rs`.
//!
//! The golden suite keeps a binary of its own, `tests/golden.rs` (its own runner, one trial per
//! scene, pass and backend). The leak tests measure their process's memory, which other tests'
//! allocations would disturb, so each runs in a child process (see `leaks`). What the modules
//! share is in `tests/common/`.

#[path = "../common/mod.rs"]
mod common;

mod ambient_occlusion;
mod backends;
mod cli_accept;
mod cli_bless;
mod cli_check;
mod cli_check_shards;
mod cli_inspect;
mod cli_measure;
mod cli_render;
mod cli_workspace;
mod faults;
mod hard_cases;
mod ibl;
mod layout;
mod leaks;
mod limits;
mod models;
mod noise;
mod plans;
mod renderer;
mod report;
mod review;
mod selftest;
mod shadows;
mod speed;
mod speed_hooks;
mod sweeps;
mod units;
mod verify_cache;

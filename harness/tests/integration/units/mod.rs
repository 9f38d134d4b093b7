//! The library's unit tests: one module per module of `harness/src` (`golden_store` tests
//! `harness::golden::store`), through its public items. They live here, not in `#[cfg(test)]`
//! modules, because `cargo test` compiles a library with unit tests a second time in test mode:
//! for this crate 35 of the test build's 94 CPU-s (2026-11-26, 2-vCPU AMD EPYC), on every
//! `cargo test` after an edit and in every clean build. `harness/Cargo.toml` turns the library's
//! test target off (`[lib] test = false`), and `layout::the_harness_library_holds_no_unit_tests` keeps a
//! test from being written where it would never run.

mod faults;
mod golden_accept;
mod golden_bless;
mod golden_check;
mod golden_diagnosis;
mod golden_metrics;
mod golden_metrics_compare;
mod golden_metrics_flip_memo;
mod golden_noise;
mod golden_portability_model;
mod golden_portability_rounding;
mod golden_portability_sources;
mod golden_scene_inputs;
mod golden_speed_bless;
mod golden_speed_goldens;
mod golden_speed_history;
mod golden_speed_measure;
mod golden_speed_model;
mod golden_speed_recorded;
mod golden_speed_verdict;
mod golden_store;
mod golden_suite;
mod golden_tolerance;
mod golden_verify;
mod html;
mod images;
mod measure_bench;
mod measure_bench_lighting_breakdown;
mod measure_speed;
mod measure_sweep_ibl;
mod reference_ibl;
mod reference_lighting;
mod reference_shadows;
mod root;
mod url;

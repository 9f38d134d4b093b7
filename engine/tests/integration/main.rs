//! The engine's integration tests, as one test binary: one link instead of seven, and one libtest
//! run whose threads keep both cores busy across them (cargo runs test binaries one after
//! another). Each module is the former `tests/<module>.rs`; what they share is in
//! `tests/common/`, their inputs in `tests/fixtures/`.

#[path = "../common/mod.rs"]
mod common;

mod environment;
mod ibl;
mod materials;
mod obj_errors;
mod scene_files;
mod scene_values;
mod tangents;
mod textures;

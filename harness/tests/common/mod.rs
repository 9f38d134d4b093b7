//! Shared helpers for GPU tests: which backends to run, and when a missing one is a failure.

use engine::backend::{self, BackendKind};

/// Backends available here. A backend named in `REQUIRE_BACKENDS` (comma-separated; CI sets
/// `gl,wgpu-vulkan,wgpu-gl`) must be available, or the test fails; any other missing backend
/// is reported on stderr and left out.
pub fn available_backends() -> Vec<BackendKind> {
    let required = std::env::var("REQUIRE_BACKENDS").unwrap_or_default();
    let mut kinds = Vec::new();
    for kind in BackendKind::ALL {
        let status = backend::probe(kind);
        if status.available {
            kinds.push(kind);
        } else if required.split(',').any(|r| r.trim() == kind.name()) {
            panic!(
                "{kind} is required by REQUIRE_BACKENDS but unavailable: {} (fix: {})",
                status.reason.unwrap_or_default(),
                status.fix.unwrap_or_default()
            );
        } else {
            eprintln!(
                "note: {kind} skipped, unavailable: {} (fix: {})",
                status.reason.unwrap_or_default(),
                status.fix.unwrap_or_default()
            );
        }
    }
    kinds
}

//! Cross-backend check of the first scene (the lit cube): every available backend renders it and
//! is compared with the first available backend under the foundation's tolerances.

use engine::backend::{self, BackendKind, BackendStatus};
use engine::lit_cube::{self, LitCubeImages};

use crate::golden::metrics::compare::{
    relative_difference, u8_difference, RelativeDifference, U8Difference,
};

/// Image size of the first scene.
pub const SIZE: u32 = 128;
/// RGBA8: per-channel difference allowed, in 1/255 steps.
pub const LDR_TOLERANCE: u8 = 1;
/// RGBA8: fraction of pixels that must be within [`LDR_TOLERANCE`].
pub const LDR_MIN_FRACTION: f64 = 0.999;
/// RGBA16F: relative difference allowed per channel.
pub const HDR_MAX_RELATIVE: f64 = 1e-3;
/// RGBA16F: fraction of pixels that must be within [`HDR_MAX_RELATIVE`]. Not all: on llvmpipe and
/// lavapipe, a ~1e-7 difference in interpolated UVs between the GLSL and SPIR-V paths can move
/// an 8-bit linear-filter weight by one step at a checker edge (a few pixels, ~1% relative).
pub const HDR_MIN_FRACTION: f64 = 0.999;
/// RGBA16F: absolute difference no pixel may exceed. One 1/256 filter-weight step across the
/// checker's full contrast under the scene's light is 6.5e-3.
pub const HDR_MAX_ABS: f64 = 1e-2;
/// RGBA16F: magnitude below which differences count as absolute (fp16 resolves ~6e-8 near 0).
pub const HDR_FLOOR: f64 = 1e-3;

/// One backend's render compared with the reference backend's.
#[derive(Debug, serde::Serialize)]
pub struct Agreement {
    /// Backend compared.
    pub backend: BackendKind,
    /// Backend compared with.
    pub reference: BackendKind,
    /// RGBA8 statistics.
    pub ldr: U8Difference,
    /// RGBA16F statistics.
    pub hdr: RelativeDifference,
    /// Depth statistics (relative).
    pub depth: RelativeDifference,
}

impl Agreement {
    /// Whether the foundation's tolerances hold.
    pub fn passes(&self) -> bool {
        self.ldr.fraction_within >= LDR_MIN_FRACTION
            && !self.hdr.non_finite
            && self.hdr.fraction_within >= HDR_MIN_FRACTION
            && self.hdr.max_abs <= HDR_MAX_ABS
    }
}

/// Renders the first scene on `kind`.
pub fn render(kind: BackendKind) -> Result<LitCubeImages, backend::BackendError> {
    let mut backend = crate::faults::create_backend(kind)?;
    lit_cube::render(backend.as_mut(), SIZE)
}

/// Compares two renders under the foundation's tolerances.
pub fn agreement(
    backend: BackendKind,
    images: &LitCubeImages,
    reference: BackendKind,
    reference_images: &LitCubeImages,
) -> Result<Agreement, crate::golden::metrics::compare::CompareError> {
    Ok(Agreement {
        backend,
        reference,
        ldr: u8_difference(&images.ldr, &reference_images.ldr, LDR_TOLERANCE)?,
        hdr: relative_difference(
            &images.hdr,
            &reference_images.hdr,
            HDR_FLOOR,
            HDR_MAX_RELATIVE,
        )?,
        depth: relative_difference(&images.depth, &reference_images.depth, 1e-6, 1e-6)?,
    })
}

/// Probes every backend.
pub fn probe_all() -> Vec<BackendStatus> {
    BackendKind::ALL.into_iter().map(backend::probe).collect()
}

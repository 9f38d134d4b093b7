//! The names of the plan's render targets: the fixed ones and those numbered per light or per
//! mask target. Readback, goldens and the CLI's `--pass` use them.

/// Names of the G-buffer targets, in attachment order.
pub const GBUFFER_TARGETS: [&str; 5] = [
    "gbuffer_position",
    "gbuffer_normal",
    "gbuffer_tangent",
    "gbuffer_albedo",
    "gbuffer_material",
];

/// Name of the depth target.
pub const DEPTH: &str = "depth";
/// Name of the HDR light buffer.
pub const LIGHT: &str = "light";
/// Name of the lighting passes' routing depth: each lighting pass clears it, marks its model's
/// pixels (from the mask) at depth 0, and draws its lights with an equal-depth test, so that the
/// depth test skips other pixels before any shading.
pub const ROUTE: &str = "route";
/// Name of the tone-mapped output.
pub const FINAL: &str = "final";

/// Name of the shadow map of light `index`.
pub fn shadow_target_name(index: usize) -> String {
    format!("shadow_{index}")
}

/// Name of the VSM moments target of light `index` (filter `vsm` only).
pub fn shadow_moments_target_name(index: usize) -> String {
    format!("shadow_{index}_moments")
}

/// Name of the VSM blur's intermediate target of light `index`.
pub fn shadow_blur_target_name(index: usize) -> String {
    format!("shadow_{index}_blur")
}

/// Name of the shadow-term debug output of light `index`.
pub fn shadow_term_target_name(index: usize) -> String {
    format!("shadow_term_{index}")
}

/// Name of mask target `index`.
pub fn mask_target_name(index: usize) -> String {
    if index == 0 {
        "mask".to_owned()
    } else {
        format!("mask_{index}")
    }
}

//! The render plan: the passes and targets a scene needs, and nothing more. Built from a
//! [`Scene`](crate::scene::Scene) before anything touches a backend, printable (its `Display`
//! is what the insta snapshots hold), and executed by [`crate::renderer`].
//!
//! What is left out, and when: no shader-mask channel for a lighting model no object uses (and a
//! second mask target only past four models), no lighting pass for an unused model, no skybox
//! or IBL precompute without an environment, no gizmos unless the quality settings ask for them.
//!
//! Built stage by stage in `build`; the lighting draws and their shader variants are in
//! `lighting`, the targets' names in `target_names`, the plan's text in `display`.

use crate::backend::TextureFormat;
use crate::scene::LightingModel;

mod build;
mod display;
mod lighting;
mod target_names;

pub use lighting::{
    shadow_filter_code, LightingDraw, LightingFeature, LightingPass, LightingVariant, PixelRect,
    ShadowKind, MAX_LIGHTS_PER_DRAW,
};
pub use target_names::{
    mask_target_name, shadow_blur_target_name, shadow_moments_target_name, shadow_target_name,
    shadow_term_target_name, DEPTH, FINAL, GBUFFER_TARGETS, LIGHT, ROUTE,
};

/// A render target the plan allocates; every one can be read back by its name.
#[derive(Clone, Debug, PartialEq)]
pub struct TargetSpec {
    /// Name used for readback, goldens and the CLI's `--pass`.
    pub name: String,
    /// Texel format.
    pub format: TextureFormat,
    /// Width in texels.
    pub width: u32,
    /// Height in texels.
    pub height: u32,
    /// What the channels hold.
    pub contents: String,
}

/// What a pass does.
#[derive(Clone, Debug, PartialEq)]
pub enum PassKind {
    /// Draws the shadow casters into the depth map of light `light` (a point light's six atlas
    /// faces are six passes, one viewport each), and for VSM into its moments too.
    Shadow {
        /// Index into the scene's lights.
        light: usize,
    },
    /// VSM: one direction of the separable Gaussian blur of light `light`'s moments.
    ShadowBlur {
        /// Index into the scene's lights.
        light: usize,
    },
    /// Draws every object into the G-buffer and depth.
    Geometry,
    /// Draws every object's one-hot lighting-model channel into the mask targets.
    ShaderMask,
    /// On the CPU, before any GPU pass: the environment's IBL maps (prefiltered specular,
    /// irradiance, DFG), read by the lighting passes; cached in memory and on disk.
    IblPrecompute,
    /// Fills uncovered pixels of the light buffer from the environment.
    Skybox,
    /// Shades one lighting model's pixels into the light buffer.
    Lighting(LightingModel),
    /// Debug: writes light `light`'s shadow term per pixel.
    ShadowTerm {
        /// Index into the scene's lights.
        light: usize,
    },
    /// Exposed HDR light buffer to the sRGB final image.
    ToneMap,
    /// Lines over the final image.
    Gizmos,
}

/// One pass of the plan.
#[derive(Clone, Debug, PartialEq)]
pub struct PassSpec {
    /// Pass name (also the name of its GPU timing).
    pub name: String,
    /// What it does.
    pub kind: PassKind,
    /// Targets it reads.
    pub reads: Vec<String>,
    /// Targets it writes.
    pub writes: Vec<String>,
    /// Draw count and other facts worth reviewing.
    pub detail: String,
}

/// Where a lighting model's pixels are flagged.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct MaskChannel {
    /// The model.
    pub model: LightingModel,
    /// Mask target index (0 for `mask`, 1 for `mask_1`).
    pub target: usize,
    /// Channel within the target (0 = R .. 3 = A).
    pub channel: usize,
}

/// The passes and targets of one scene.
#[derive(Clone, Debug, PartialEq)]
pub struct RenderPlan {
    /// Scene name.
    pub scene: String,
    /// Output width.
    pub width: u32,
    /// Output height.
    pub height: u32,
    /// Targets, in allocation order.
    pub targets: Vec<TargetSpec>,
    /// Passes, in execution order.
    pub passes: Vec<PassSpec>,
    /// Lighting model to mask channel assignment.
    pub mask_channels: Vec<MaskChannel>,
    /// Each lighting pass's draws and their shader variants, in pass order.
    pub lighting: Vec<LightingPass>,
}

impl RenderPlan {
    /// The target with this name.
    pub fn target(&self, name: &str) -> Option<&TargetSpec> {
        self.targets.iter().find(|t| t.name == name)
    }

    /// Names of every target, in allocation order.
    pub fn target_names(&self) -> Vec<&str> {
        self.targets.iter().map(|t| t.name.as_str()).collect()
    }
}

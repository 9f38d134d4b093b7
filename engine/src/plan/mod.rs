//! The render plan: the passes and targets a scene needs, and nothing more. Built from a
//! [`Scene`](crate::scene::Scene) before anything touches a backend, printable (its `Display`
//! is what the insta snapshots hold), and executed by [`crate::renderer`].
//!
//! What is left out, and when: no shader-mask channel for a lighting model no object uses (and a
//! second mask target only past four models), no lighting pass for an unused model, no skybox
//! or IBL precompute without an environment, no ambient occlusion without `[quality.ssao]` (or
//! without a lit model to read it), no gizmos unless the quality settings ask for them.
//!
//! Built stage by stage in `build`; the lighting draws and their shader variants are in
//! `lighting`, the typed identities of targets and passes (and their names) in `ids`, the plan's
//! text in `display`.

use crate::backend::TextureFormat;
use crate::scene::LightingModel;

mod build;
mod display;
mod ids;
mod lighting;

pub use ids::{BlurAxis, GBufferTarget, PassId, TargetContent, TargetId, UnknownName};
pub use lighting::{
    shadow_filter_code, LightingDraw, LightingFeature, LightingPass, LightingVariant, PixelRect,
    ShadowKind, MAX_LIGHTS_PER_DRAW,
};

/// A render target the plan allocates; every one can be read back.
#[derive(Clone, Debug, PartialEq)]
pub struct TargetSpec {
    /// Which target (its name, for readback, goldens and the CLI's `--pass`, is its `Display`).
    pub id: TargetId,
    /// Texel format.
    pub format: TextureFormat,
    /// Width in texels.
    pub width: u32,
    /// Height in texels.
    pub height: u32,
    /// What the channels hold.
    pub contents: String,
}

/// One pass of the plan.
#[derive(Clone, Debug, PartialEq)]
pub struct PassSpec {
    /// Which pass, and what it does (its name, also that of its GPU timing, is its `Display`).
    pub id: PassId,
    /// Targets it reads.
    pub reads: Vec<TargetId>,
    /// Targets it writes.
    pub writes: Vec<TargetId>,
    /// Draw count and other facts worth reviewing.
    pub detail: String,
}

/// A target name that a scene's plan does not have.
#[derive(Clone, Debug, PartialEq, Eq, thiserror::Error)]
#[error("scene `{scene}` has no pass output `{name}` (its outputs: {available})")]
pub struct UnknownTarget {
    /// Scene name.
    pub scene: String,
    /// The name asked for.
    pub name: String,
    /// The scene's targets, comma-separated.
    pub available: String,
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
    /// The target `id`, if the plan has it.
    pub fn target(&self, id: TargetId) -> Option<&TargetSpec> {
        self.targets.iter().find(|t| t.id == id)
    }

    /// Every target, in allocation order.
    pub fn target_ids(&self) -> Vec<TargetId> {
        self.targets.iter().map(|t| t.id).collect()
    }

    /// The pass `id`, if the plan has it.
    pub fn pass(&self, id: PassId) -> Option<&PassSpec> {
        self.passes.iter().find(|p| p.id == id)
    }

    /// The target a name at an edge (the CLI, a file, a TOML key) stands for, if this plan has
    /// it; the error lists the targets it has.
    pub fn target_named(&self, name: &str) -> Result<TargetId, UnknownTarget> {
        name.parse::<TargetId>()
            .ok()
            .filter(|id| self.target(*id).is_some())
            .ok_or_else(|| UnknownTarget {
                scene: self.scene.clone(),
                name: name.to_owned(),
                available: self.target_list(),
            })
    }

    /// Which of the plan's passes (in order) the `wanted` targets depend on, from the passes'
    /// declared reads and writes: walking back from the wanted targets, a pass is needed when it
    /// writes a target still needed, and then what it reads is needed too. Every earlier writer
    /// of a needed target is kept (also where a later one clears it), so the kept passes leave
    /// the wanted targets exactly as the whole frame would.
    pub fn passes_needed_for(&self, wanted: &[TargetId]) -> Vec<bool> {
        let mut needed: Vec<TargetId> = wanted.to_vec();
        let mut keep = vec![false; self.passes.len()];
        for (index, pass) in self.passes.iter().enumerate().rev() {
            if !pass.writes.iter().any(|t| needed.contains(t)) {
                continue;
            }
            keep[index] = true;
            for target in &pass.reads {
                if !needed.contains(target) {
                    needed.push(*target);
                }
            }
        }
        keep
    }

    /// The targets' names, comma-separated, for messages.
    pub fn target_list(&self) -> String {
        let names: Vec<String> = self.targets.iter().map(|t| t.id.to_string()).collect();
        names.join(", ")
    }
}

//! The passes of a frame, one file each, in the order [`super::render`] records them: shadow
//! maps, geometry and shader mask, skybox, lighting, tone mapping and gizmos. Each records its
//! [`RenderPass`](crate::backend::RenderPass)es from the plan over the frame's shared
//! resources ([`super::resources::FrameResources`]).

pub(super) mod geometry;
pub(super) mod gizmos;
pub(super) mod lighting;
pub(super) mod shadow;
pub(super) mod skybox;
pub(super) mod tonemap;

use crate::backend::RenderPass;
use crate::plan::PassId;

/// The render passes recorded for a frame, each with the plan pass it belongs to: a point
/// light's six faces all belong to its shadow pass, and the clear of an otherwise unwritten
/// light buffer to none. Culling and timing go by these owners, never by the passes' names
/// (which are only debug labels for the backend).
#[derive(Default)]
pub(in crate::renderer) struct Recorded {
    /// The render passes, in submission order.
    pub passes: Vec<RenderPass>,
    /// Each one's plan pass.
    pub owners: Vec<Option<PassId>>,
}

impl Recorded {
    /// Records `pass` as (part of) the plan's pass `owner`.
    pub fn push(&mut self, owner: PassId, pass: RenderPass) {
        self.passes.push(pass);
        self.owners.push(Some(owner));
    }

    /// Records a pass the plan does not list (the light buffer's clear where nothing else
    /// writes it).
    pub fn push_unplanned(&mut self, pass: RenderPass) {
        self.passes.push(pass);
        self.owners.push(None);
    }
}

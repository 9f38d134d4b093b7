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

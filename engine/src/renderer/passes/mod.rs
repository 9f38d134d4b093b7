//! The passes of a frame, one file each. [`record`] is the one list of what each kind of plan
//! pass records: the renderer walks the plan's passes in order and dispatches each here, with
//! one [`FrameContext`] that every pass records into and reads what earlier passes left.
//!
//! Adding a pass: a [`PassId`] variant and its place in the plan's builder, a file here with
//! its `record`, and an arm below. The harness takes what it needs from the plan's types.

pub(super) mod ambient_occlusion;
pub(super) mod geometry;
pub(super) mod gizmos;
pub(super) mod lighting;
pub(super) mod shadow;
pub(super) mod skybox;
pub(super) mod tonemap;

use super::resources::FrameResources;
use super::shadows::ShadowView;
use super::{PreparedFrame, RenderError, Variations};
use crate::backend::{Backend, Buffer, Handle, RenderPass, ResourceScope};
use crate::ibl::IblMaps;
use crate::plan::{PassId, RenderPlan};
use crate::scene::Scene;

/// Records the plan's pass `pass` into `ctx`.
pub(super) fn record(ctx: &mut FrameContext<'_>, pass: PassId) -> Result<(), RenderError> {
    match pass {
        PassId::Shadow { light } => shadow::record_map(ctx, light),
        PassId::ShadowBlur { light, axis } => shadow::record_blur(ctx, light, axis),
        PassId::Geometry => geometry::record_geometry(ctx),
        PassId::ShaderMask => geometry::record_mask(ctx),
        PassId::AmbientOcclusion => ambient_occlusion::record(ctx),
        // On the CPU, when the frame was prepared (`PreparedFrame::new`): nothing to record.
        PassId::IblPrecompute => Ok(()),
        PassId::Skybox => skybox::record(ctx),
        PassId::Lighting(model) => lighting::record_model(ctx, model),
        PassId::ClearLight => lighting::record_clear(ctx),
        PassId::ShadowTerm { light } => lighting::record_shadow_term(ctx, light),
        PassId::ToneMap => tonemap::record(ctx),
        PassId::Gizmos => gizmos::record(ctx),
    }
}

/// What every pass of one frame records with: the backend and the scope that owns what the
/// passes create (destroyed after submission), the scene as drawn and its plan, the frame's
/// shared resources, the variations asked for, and what earlier passes leave for later ones.
pub(super) struct FrameContext<'a> {
    /// The backend recorded for.
    pub backend: &'a mut dyn Backend,
    /// Owner of every resource the passes create.
    pub scope: &'a mut ResourceScope,
    /// The scene as drawn.
    pub scene: &'a Scene,
    /// Its plan.
    pub plan: &'a RenderPlan,
    /// The plan's targets, the meshes, material textures and camera.
    pub frame: &'a FrameResources,
    /// Test and benchmark hooks (none in a plain render).
    pub variations: &'a Variations,
    /// The environment's IBL maps, prepared with the frame.
    pub ibl_maps: Option<&'a IblMaps>,
    /// Each shadowed light's view(s).
    pub views: Vec<ShadowView>,
    /// The render passes recorded so far.
    pub recorded: Recorded,
    /// Whether a pass recorded so far wrote the light buffer: later ones add to it.
    pub light_written: bool,
    /// Each object's uniform buffer, made by the geometry pass and read by the mask pass.
    pub object_uniforms: Vec<Handle<Buffer>>,
    /// The shadow passes' pipelines, made by the first shadow pass.
    pub shadow: Option<shadow::ShadowPipelines>,
    /// What the lighting passes and shadow terms bind, made by the first of them.
    pub lighting: Option<lighting::LightingResources<'a>>,
}

impl<'a> FrameContext<'a> {
    /// A context with nothing recorded yet.
    pub fn new(
        backend: &'a mut dyn Backend,
        scope: &'a mut ResourceScope,
        frame: &'a FrameResources,
        prepared: &'a PreparedFrame,
    ) -> Self {
        Self {
            backend,
            scope,
            scene: &prepared.scene,
            plan: &prepared.plan,
            frame,
            variations: &prepared.variations,
            ibl_maps: prepared.ibl_maps.as_deref(),
            views: super::shadows::shadow_views(&prepared.scene),
            recorded: Recorded::default(),
            light_written: false,
            object_uniforms: Vec::new(),
            shadow: None,
            lighting: None,
        }
    }

    /// The shadow view of light `light` (the plan has a shadow pass only for a light with one).
    pub fn view(&self, light: usize) -> Result<ShadowView, RenderError> {
        self.views
            .iter()
            .find(|v| v.light == light)
            .cloned()
            .ok_or_else(|| RenderError::InvalidScene {
                scene: self.scene.name.clone(),
                problem: format!("the plan shadows light {light}, which has no shadow view"),
            })
    }
}

/// The render passes recorded for a frame, each with the plan pass it belongs to: a point
/// light's six faces all belong to its shadow pass. Culling and timing go by these owners, never
/// by the passes' names (which are only debug labels for the backend).
#[derive(Default)]
pub(in crate::renderer) struct Recorded {
    /// The render passes, in submission order.
    pub passes: Vec<RenderPass>,
    /// Each one's plan pass.
    pub owners: Vec<PassId>,
}

impl Recorded {
    /// Records `pass` as (part of) the plan's pass `owner`.
    pub fn push(&mut self, owner: PassId, pass: RenderPass) {
        self.passes.push(pass);
        self.owners.push(owner);
    }
}

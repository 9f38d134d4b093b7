//! The deferred renderer: executes the [`RenderPlan`] of a [`PreparedFrame`] on any [`Backend`]
//! and reads back the pass outputs by [`TargetId`].
//!
//! One call to [`render_prepared`] (or [`render`], which prepares the frame first) uploads the
//! scene, records the plan's passes in order, submits them at once, reads back what was asked
//! for and destroys everything it created. There is no state
//! between calls: the same scene on the same driver gives the same images, bit for bit.
//!
//! Precision: positions never reach the GPU in absolute world coordinates. Object, light and
//! camera positions are subtracted in f64 ([`Transform::relative_to`]); the G-buffer stores
//! camera-relative positions, so a scene 10 km from the origin renders like one at the origin.

pub mod ambient_occlusion;
mod builders;
mod cull;
mod ibl;
mod passes;
mod recorded;
mod resources;
pub mod shadows;
mod uniforms;
pub mod variations;

use std::collections::BTreeMap;
use std::sync::Arc;

use glam::{DMat4, DVec3, Mat3, Mat4};

use crate::backend::*;
use crate::ibl::IblMaps;
use crate::image::Image;
use crate::plan::{PassId, RenderPlan, TargetId};
use crate::scene::{Scene, Transform};
use resources::FrameResources;

pub use crate::scene::InvalidScene;
pub use uniforms::{ambient_radiance, light_uniforms};

/// Checks a scene before anything reaches the GPU ([`Scene::validate`]), as a render error.
pub fn validate(scene: &Scene) -> Result<(), RenderError> {
    scene.validate().map_err(RenderError::from)
}

impl From<InvalidScene> for RenderError {
    fn from(e: InvalidScene) -> Self {
        RenderError::InvalidScene {
            scene: e.scene,
            problem: e.problem,
        }
    }
}
pub use recorded::RecordedFrame;
pub use variations::{SlowPass, Variations};

/// Why a frame could not be rendered.
#[derive(Debug, thiserror::Error)]
pub enum RenderError {
    /// The backend refused or failed (its message names the backend, and the pass or resource
    /// where it applies).
    #[error("scene `{scene}`: {source}")]
    Backend {
        /// Scene name.
        scene: String,
        /// What the backend said.
        #[source]
        source: BackendError,
    },
    /// Reading a pass output back failed.
    #[error("scene `{scene}`: reading back pass output `{output}` failed: {source}")]
    Readback {
        /// Scene name.
        scene: String,
        /// Target name.
        output: String,
        /// What the backend said.
        #[source]
        source: BackendError,
    },
    /// The scene cannot be rendered as given (NaN, zero scale, empty mesh ...).
    #[error("scene `{scene}`: {problem}")]
    InvalidScene {
        /// Scene name.
        scene: String,
        /// What is wrong.
        problem: String,
    },
    /// A shader's reflection (its bindings) could not be read: a shader that does not parse,
    /// or a binding looked up under a name the shader does not declare.
    #[error("scene `{scene}`: {source}")]
    Shader {
        /// Scene name.
        scene: String,
        /// What naga said.
        #[source]
        source: crate::shaders::ShaderError,
    },
    /// A readback asked for a target the plan does not have.
    #[error("scene `{scene}` has no pass output `{name}` (its outputs: {available})")]
    UnknownOutput {
        /// Scene name.
        scene: String,
        /// Requested name.
        name: String,
        /// Names that exist.
        available: String,
    },
}

impl From<crate::shaders::ShaderError> for RenderError {
    /// A shader's reflection failed inside a render; [`render_prepared`] fills in the scene's
    /// name.
    fn from(source: crate::shaders::ShaderError) -> Self {
        RenderError::Shader {
            scene: String::new(),
            source,
        }
    }
}

impl From<BackendError> for RenderError {
    /// A backend error inside a render; [`render_prepared`] fills in the scene's name.
    fn from(source: BackendError) -> Self {
        RenderError::Backend {
            scene: String::new(),
            source,
        }
    }
}

/// Which outputs to read back after the frame.
#[derive(Clone, Copy, Debug)]
pub enum Readback<'a> {
    /// Every target of the plan.
    All,
    /// Only these targets; every pass of the plan still runs (what the bench times).
    Only(&'a [TargetId]),
    /// Only these targets, and only the passes they depend on run: the others are culled before
    /// submission, so they take no GPU time and report no timing. The targets read back are the
    /// same, bit for bit, as with [`Readback::Only`].
    Needed(&'a [TargetId]),
}

/// A rendered frame: the plan it followed, the outputs read back, and GPU time per pass.
pub struct Frame {
    /// The plan that was executed.
    pub plan: RenderPlan,
    /// Read-back outputs by target.
    pub outputs: BTreeMap<TargetId, Image>,
    /// GPU time of every submitted render pass, with the plan pass it belongs to.
    pub timings: PassTimes,
}

impl Frame {
    /// The output of target `id`, if it was read back.
    pub fn output(&self, id: TargetId) -> Option<&Image> {
        self.outputs.get(&id)
    }
}

/// A frame's GPU times: one per submitted render pass (a point light's faces are one render
/// pass each), each with the plan pass it belongs to.
#[derive(Clone, Debug, Default)]
pub struct PassTimes {
    /// Each submitted render pass's time, in submission order (names are debug labels).
    pub passes: Vec<PassTiming>,
    /// The plan pass each entry of `passes` belongs to.
    pub owners: Vec<PassId>,
}

impl PassTimes {
    /// Whether the plan's pass `id` ran in this frame (it was not culled).
    pub fn ran(&self, id: PassId) -> bool {
        self.owners.contains(&id)
    }

    /// GPU ns of the plan's pass `id`: the sum over its render passes (a point light's six
    /// faces). None when the pass did not run (culled, or not in the plan) or the backend has
    /// no timestamps.
    pub fn pass_time(&self, id: PassId) -> Option<f64> {
        let mut times = self
            .passes
            .iter()
            .zip(&self.owners)
            .filter(|(_, owner)| **owner == id)
            .map(|(timing, _)| timing.gpu_ns);
        let first = times.next()??;
        times.try_fold(first, |sum, ns| ns.map(|ns| sum + ns))
    }

    /// GPU ns of the whole frame: every render pass submitted (None without timestamps).
    pub fn total(&self) -> Option<f64> {
        self.passes.iter().map(|p| p.gpu_ns).sum()
    }
}

/// A scene made ready to draw, once: the scene as drawn (with `[quality.ibl] extract_sun`, the
/// environment's sun added as a directional light), its IBL maps, and the plan of it. The plan
/// is only ever built here, so whatever names a render's passes and targets (the renderer,
/// the golden suite, `harness plan`, `render --pass`, the benches) sees the frame that runs.
#[derive(Clone)]
pub struct PreparedFrame {
    scene: Scene,
    plan: RenderPlan,
    ibl_maps: Option<Arc<IblMaps>>,
    variations: Variations,
}

impl PreparedFrame {
    /// Validates `scene`, prepares its IBL maps (built, or read from their caches) and plans
    /// the scene as drawn.
    pub fn new(scene: &Scene) -> Result<Self, RenderError> {
        validate(scene)?;
        let ibl_maps = scene
            .environment
            .as_ref()
            .map(|environment| crate::ibl::prepare(&environment.image, &scene.quality.ibl).0);
        if let (Some(maps), Some(environment)) = (&ibl_maps, &scene.environment) {
            if !maps.is_finite() {
                let brightest = environment
                    .image
                    .texels
                    .iter()
                    .flat_map(|t| &t[..3])
                    .fold(0f32, |m, v| m.max(*v));
                return Err(RenderError::InvalidScene {
                    scene: scene.name.clone(),
                    problem: format!(
                        "environment {}: its IBL maps overflow 32-bit floats (its brightest \
                         texel is {brightest:.3e}); scale the image down",
                        environment.image.label
                    ),
                });
            }
        }
        // With `extract_sun`, the maps lack the environment's sun: it is lit as a light instead.
        let scene = crate::ibl::sun::scene_with_sun(scene, ibl_maps.as_deref())
            .unwrap_or_else(|| scene.clone());
        let plan = RenderPlan::new(&scene);
        Ok(Self {
            scene,
            plan,
            ibl_maps,
            variations: Variations::default(),
        })
    }

    /// This frame with `variations` (test and benchmark hooks; see [`variations`]). Lighting
    /// work taken away shows in the plan's lighting draws.
    pub fn with_variations(mut self, variations: Variations) -> Self {
        if let Some(feature) = variations.remove_lighting {
            self.plan.remove_lighting_feature(feature, &self.scene);
        }
        if variations.unspecialised_lighting {
            self.plan.unspecialise_lighting();
        }
        self.variations = variations;
        self
    }

    /// The scene as drawn: an extracted sun is its last light.
    pub fn scene(&self) -> &Scene {
        &self.scene
    }

    /// This frame with `scene`, a variation of its scene as drawn, and no variations of its own
    /// (set them again with [`PreparedFrame::with_variations`]) (a light, a material, the
    /// camera, a shadow setting changed: what the mutation self-test and the benches vary),
    /// validated and planned again. The IBL maps are kept, so the variation must keep the
    /// environment and the IBL settings as they are (an extracted sun's light follows both);
    /// one that does not is refused: prepare the changed scene with [`PreparedFrame::new`].
    pub fn varied(&self, scene: Scene) -> Result<Self, RenderError> {
        let same_environment = match (&self.scene.environment, &scene.environment) {
            (None, None) => true,
            (Some(a), Some(b)) => {
                Arc::ptr_eq(&a.image, &b.image)
                    && a.rotation_degrees == b.rotation_degrees
                    && a.intensity == b.intensity
            }
            _ => false,
        };
        if !same_environment || self.scene.quality.ibl != scene.quality.ibl {
            return Err(RenderError::InvalidScene {
                scene: scene.name,
                problem: "a variation of a prepared frame changed its environment or IBL \
                          settings, which its IBL maps (and an extracted sun) depend on; \
                          prepare the changed scene anew"
                    .to_owned(),
            });
        }
        validate(&scene)?;
        let plan = RenderPlan::new(&scene);
        Ok(Self {
            scene,
            plan,
            ibl_maps: self.ibl_maps.clone(),
            variations: Variations::default(),
        })
    }

    /// The plan of the scene as drawn.
    pub fn plan(&self) -> &RenderPlan {
        &self.plan
    }
}

/// Renders `scene` and reads back the requested outputs. Everything created is destroyed before
/// returning, also on error.
pub fn render(
    backend: &mut dyn Backend,
    scene: &Scene,
    readback: Readback<'_>,
) -> Result<Frame, RenderError> {
    render_prepared(backend, &PreparedFrame::new(scene)?, readback)
}

/// Renders a prepared frame and reads back the requested outputs. Everything created is
/// destroyed before returning, also on error.
pub fn render_prepared(
    backend: &mut dyn Backend,
    prepared: &PreparedFrame,
    readback: Readback<'_>,
) -> Result<Frame, RenderError> {
    let (scene, plan) = (&prepared.scene, &prepared.plan);
    let wanted: Vec<TargetId> = match readback {
        Readback::All => plan.target_ids(),
        Readback::Only(ids) | Readback::Needed(ids) => {
            if let Some(missing) = ids.iter().find(|id| plan.target(**id).is_none()) {
                return Err(RenderError::UnknownOutput {
                    scene: scene.name.clone(),
                    name: missing.to_string(),
                    available: plan.target_list(),
                });
            }
            ids.to_vec()
        }
    };
    let wanted = Wanted {
        targets: &wanted,
        cull: matches!(readback, Readback::Needed(_)),
    };
    let mut scope = ResourceScope::default();
    let result = record_and_submit(backend, prepared, wanted, &mut scope);
    scope.destroy(backend);
    let (outputs, timings) = result.map_err(|e| recorded::named(&scene.name, e))?;
    Ok(Frame {
        plan: plan.clone(),
        outputs,
        timings,
    })
}

/// Camera-relative view and projection of the scene's camera.
pub struct CameraMatrices {
    /// Rotation-only view matrix (camera at the origin).
    pub view: DMat4,
    /// Projection (depth 0..1).
    pub projection: DMat4,
}

impl CameraMatrices {
    /// The matrices for a scene.
    pub fn new(scene: &Scene) -> Self {
        let aspect = f64::from(scene.quality.width) / f64::from(scene.quality.height);
        Self {
            view: scene.camera.view_rotation(),
            projection: scene.camera.projection(aspect),
        }
    }

    /// Camera-relative world space to clip space.
    pub fn view_projection(&self) -> DMat4 {
        self.projection * self.view
    }
}

type Outputs = (BTreeMap<TargetId, Image>, PassTimes);

/// The targets a frame reads back, and whether the passes they do not depend on are culled.
#[derive(Clone, Copy)]
struct Wanted<'a> {
    targets: &'a [TargetId],
    cull: bool,
}

/// The render passes of a frame as recorded, each with the plan pass it belongs to, and the
/// frame's targets.
pub(crate) struct Recorded {
    frame: FrameResources,
    passes: Vec<RenderPass>,
    owners: Vec<PassId>,
    /// A [`SlowPass`]'s pass and its render passes without the injected copies.
    unslowed: Option<(PassId, Vec<RenderPass>)>,
}

/// Creates the frame's resources in `scope` and records the passes of its plan in its order
/// (each dispatched by its [`PassId`] in [`passes::record`], one file each, over one shared
/// [`passes::FrameContext`]), then applies a [`SlowPass`] variation.
fn record(
    backend: &mut dyn Backend,
    prepared: &PreparedFrame,
    scope: &mut ResourceScope,
) -> Result<Recorded, RenderError> {
    let (scene, plan) = (&prepared.scene, &prepared.plan);
    let frame = FrameResources::create(backend, scope, scene, plan)?;
    let mut ctx = passes::FrameContext::new(backend, scope, &frame, prepared);
    for spec in &plan.passes {
        passes::record(&mut ctx, spec.id)?;
    }
    let passes::Recorded { passes, owners } = std::mem::take(&mut ctx.recorded);
    drop(ctx);
    let (passes, owners, unslowed) = match prepared.variations.slow_pass {
        Some(slow) => {
            let (passes, owners, originals) = recorded::slowed(plan, passes, owners, slow);
            (passes, owners, Some((slow.pass, originals)))
        }
        None => (passes, owners, None),
    };
    Ok(Recorded {
        frame,
        passes,
        owners,
        unslowed,
    })
}

/// Records the frame ([`record`]), submits its passes at once (when `wanted` culls, only those
/// its targets depend on) and reads back the `wanted` targets.
fn record_and_submit(
    backend: &mut dyn Backend,
    prepared: &PreparedFrame,
    wanted: Wanted<'_>,
    scope: &mut ResourceScope,
) -> Result<Outputs, RenderError> {
    let (scene, plan) = (&prepared.scene, &prepared.plan);
    let Recorded {
        frame,
        mut passes,
        mut owners,
        ..
    } = record(backend, prepared, scope)?;
    if wanted.cull {
        // The plan says which passes the wanted targets need. The recorded passes' attachments
        // and bindings give an upper bound (they count a loaded depth attachment as written, as
        // the mask pass's is not): wherever debug assertions are on, so in every test render
        // that culls, the plan must keep no pass outside it. That the plan keeps enough is the
        // test that renders every target of every canonical scene culled and compares it with
        // the whole frame's, bit for bit (harness/tests/integration/renderer.rs).
        let needed = plan.passes_needed_for(wanted.targets);
        let keep: Vec<bool> = owners
            .iter()
            .map(|owner| {
                let index = plan.passes.iter().position(|p| p.id == *owner);
                index.is_some_and(|i| needed[i])
            })
            .collect();
        if cfg!(debug_assertions) {
            let targets: Vec<Handle<Texture>> =
                wanted.targets.iter().map(|id| frame.target(*id)).collect();
            let recorded = cull::needed(&passes, &targets);
            let extra: Vec<PassId> = owners
                .iter()
                .zip(keep.iter().zip(&recorded))
                .filter_map(|(owner, (&plan, &recorded))| (plan && !recorded).then_some(*owner))
                .collect();
            debug_assert!(
                extra.is_empty(),
                "scene `{}`: for {:?}, the plan keeps {extra:?}, which the recorded passes do \
                 not need",
                scene.name,
                wanted.targets
            );
        }
        let mut kept = keep.iter().copied();
        passes.retain(|_| kept.next().unwrap_or(false));
        let mut kept = keep.iter().copied();
        owners.retain(|_| kept.next().unwrap_or(false));
    }
    let timings = backend.submit(&passes)?;
    let mut outputs = BTreeMap::new();
    for &id in wanted.targets {
        outputs.insert(
            id,
            backend
                .read_texture(frame.target(id), Subresource::default())
                .map_err(|source| RenderError::Readback {
                    scene: scene.name.clone(),
                    output: id.to_string(),
                    source,
                })?,
        );
    }
    Ok((
        outputs,
        PassTimes {
            passes: timings,
            owners,
        },
    ))
}

/// Object-to-camera-relative matrix and its normal matrix, in f32.
pub fn object_matrices(transform: &Transform, camera_position: DVec3) -> (Mat4, Mat3) {
    let model = transform.relative_to(camera_position).as_mat4();
    let normal = Mat3::from_mat4(model).inverse().transpose();
    (model, normal)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::plan::BlurAxis;

    fn times(entries: &[(PassId, Option<f64>)]) -> PassTimes {
        PassTimes {
            passes: entries
                .iter()
                .map(|(owner, ns)| PassTiming {
                    name: owner.to_string(),
                    gpu_ns: *ns,
                })
                .collect(),
            owners: entries.iter().map(|(owner, _)| *owner).collect(),
        }
    }

    #[test]
    fn a_pass_time_sums_its_render_passes_and_nothing_else() {
        let shadow_0 = PassId::Shadow { light: 0 };
        let blur = PassId::ShadowBlur {
            light: 0,
            axis: BlurAxis::X,
        };
        let shadow_1 = PassId::Shadow { light: 1 };
        let frame = times(&[
            (shadow_0, Some(1.0)),
            (shadow_0, Some(2.0)),
            (blur, Some(4.0)),
            (shadow_1, Some(8.0)),
            (PassId::ClearLight, Some(32.0)),
            (PassId::Geometry, Some(16.0)),
        ]);
        assert_eq!(frame.pass_time(shadow_0), Some(3.0));
        assert_eq!(frame.pass_time(blur), Some(4.0));
        assert_eq!(frame.pass_time(shadow_1), Some(8.0));
        assert_eq!(frame.pass_time(PassId::Skybox), None);
        assert!(!frame.ran(PassId::Skybox) && frame.ran(PassId::Geometry));
        assert_eq!(frame.total(), Some(63.0));
        let untimed = times(&[(PassId::Geometry, None)]);
        assert_eq!(untimed.pass_time(PassId::Geometry), None);
        assert_eq!(untimed.total(), None);
    }
}

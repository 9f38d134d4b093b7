//! The deferred renderer: executes a [`RenderPlan`] for a [`Scene`] on any [`Backend`] and reads
//! back the pass outputs by name.
//!
//! One call to [`render`] uploads the scene, records every pass of the plan, submits them at
//! once, reads back what was asked for and destroys everything it created. There is no state
//! between calls: the same scene on the same driver gives the same images, bit for bit.
//!
//! Precision: positions never reach the GPU in absolute world coordinates. Object, light and
//! camera positions are subtracted in f64 ([`Transform::relative_to`]); the G-buffer stores
//! camera-relative positions, so a scene 10 km from the origin renders like one at the origin.

mod builders;
mod cull;
mod ibl;
mod passes;
mod resources;
pub mod shadows;
mod uniforms;
mod validate;

use std::collections::BTreeMap;

use glam::{DMat4, DVec3, Mat3, Mat4};

use crate::backend::*;
use crate::image::Image;
use crate::plan::{LightingFeature, RenderPlan};
use crate::scene::{Scene, Transform};
use resources::FrameResources;

pub use uniforms::{ambient_radiance, light_uniforms};
pub use validate::validate;

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
    /// A readback asked for a target the plan does not have.
    #[error("scene `{scene}` has no pass output `{name}` (it has: {available})")]
    UnknownOutput {
        /// Scene name.
        scene: String,
        /// Requested name.
        name: String,
        /// Names that exist.
        available: String,
    },
}

impl From<BackendError> for RenderError {
    /// A backend error inside a render; [`render_with_faults`] fills in the scene's name.
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
    Only(&'a [&'a str]),
    /// Only these targets, and only the passes they depend on run: the others are culled before
    /// submission, so they take no GPU time and report no timing. The targets read back are the
    /// same, bit for bit, as with [`Readback::Only`].
    Needed(&'a [&'a str]),
}

/// A rendered frame: the plan it followed, the outputs read back, and GPU time per pass.
pub struct Frame {
    /// The plan that was executed.
    pub plan: RenderPlan,
    /// Read-back outputs by target name.
    pub outputs: BTreeMap<String, Image>,
    /// GPU time per pass, in plan order.
    pub timings: Vec<PassTiming>,
}

impl Frame {
    /// The output with this name, if it was read back.
    pub fn output(&self, name: &str) -> Option<&Image> {
        self.outputs.get(name)
    }
}

/// Deliberate departures from the scene: faults for the harness's mutation self-test (proof that
/// the golden tolerances catch a broken pass), and lighting work taken away for the bench's cost
/// breakdown. All off by default; [`render`] never sets them.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Faults {
    /// The geometry pass writes albedo with red and blue swapped.
    pub swap_albedo_red_blue: bool,
    /// The tone-mapping pass scales the light buffer by this before its curve (a fault in the
    /// last pass only: the light buffer stays as it was).
    pub tonemap_input_scale: Option<f32>,
    /// The lighting passes run without this part of their work (see
    /// [`RenderPlan::remove_lighting_feature`]).
    pub remove_lighting: Option<LightingFeature>,
    /// The light uniforms carry each light's radiance times this: a fault in the uniform
    /// packing, which only a reference that derives the lights from the scene itself catches.
    pub light_radiance_scale: Option<f32>,
}

/// Renders `scene` and reads back the requested outputs. Everything created is destroyed before
/// returning, also on error.
pub fn render(
    backend: &mut dyn Backend,
    scene: &Scene,
    readback: Readback<'_>,
) -> Result<Frame, RenderError> {
    render_with_faults(backend, scene, readback, &Faults::default())
}

/// The scene as [`render`] draws it: with `[quality.ibl] extract_sun`, the environment's sun
/// added as a directional light (finding it needs the IBL maps: built, or read from their
/// caches); otherwise the scene itself. Whatever names a render's passes and targets
/// (`harness plan`, `harness render --pass`) plans from this, so it lists what the render has.
pub fn scene_as_drawn(scene: &Scene) -> std::borrow::Cow<'_, Scene> {
    let maps = scene
        .environment
        .as_ref()
        .filter(|_| scene.quality.ibl.extract_sun)
        .map(|environment| crate::ibl::prepare(&environment.image, &scene.quality.ibl).0);
    match crate::ibl::sun::scene_with_sun(scene, maps.as_deref()) {
        Some(with_sun) => std::borrow::Cow::Owned(with_sun),
        None => std::borrow::Cow::Borrowed(scene),
    }
}

/// [`render`] with deliberate faults injected (see [`Faults`]).
pub fn render_with_faults(
    backend: &mut dyn Backend,
    scene: &Scene,
    readback: Readback<'_>,
    faults: &Faults,
) -> Result<Frame, RenderError> {
    validate(scene)?;
    let ibl_maps = scene
        .environment
        .as_ref()
        .map(|environment| crate::ibl::prepare(&environment.image, &scene.quality.ibl).0);
    // With `extract_sun`, the maps lack the environment's sun: it is lit as a light instead.
    let with_sun = crate::ibl::sun::scene_with_sun(scene, ibl_maps.as_deref());
    let scene = with_sun.as_ref().unwrap_or(scene);
    let mut plan = RenderPlan::new(scene);
    if let Some(feature) = faults.remove_lighting {
        plan.remove_lighting_feature(feature, scene);
    }
    let wanted: Vec<String> = match readback {
        Readback::All => plan
            .target_names()
            .iter()
            .map(|s| (*s).to_owned())
            .collect(),
        Readback::Only(names) | Readback::Needed(names) => {
            for name in names {
                if plan.target(name).is_none() {
                    return Err(RenderError::UnknownOutput {
                        scene: scene.name.clone(),
                        name: (*name).to_owned(),
                        available: plan.target_names().join(", "),
                    });
                }
            }
            names.iter().map(|s| (*s).to_owned()).collect()
        }
    };
    let wanted = Wanted {
        names: &wanted,
        cull: matches!(readback, Readback::Needed(_)),
    };
    let mut scope = ResourceScope::default();
    let result = record_and_submit(
        backend,
        scene,
        &plan,
        wanted,
        faults,
        ibl_maps.as_deref(),
        &mut scope,
    );
    scope.destroy(backend);
    let (outputs, timings) = result.map_err(|e| match e {
        RenderError::Backend { source, .. } => RenderError::Backend {
            scene: scene.name.clone(),
            source,
        },
        other => other,
    })?;
    Ok(Frame {
        plan,
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

type Outputs = (BTreeMap<String, Image>, Vec<PassTiming>);

/// The targets a frame reads back, and whether the passes they do not depend on are culled.
#[derive(Clone, Copy)]
struct Wanted<'a> {
    names: &'a [String],
    cull: bool,
}

/// Records every pass of `plan` (in [`passes`], one file each), submits them at once (when
/// `wanted` culls, only those its targets depend on) and reads back the `wanted` targets.
fn record_and_submit(
    backend: &mut dyn Backend,
    scene: &Scene,
    plan: &RenderPlan,
    wanted: Wanted<'_>,
    faults: &Faults,
    ibl_maps: Option<&crate::ibl::IblMaps>,
    scope: &mut ResourceScope,
) -> Result<Outputs, RenderError> {
    let frame = FrameResources::create(backend, scope, scene, plan)?;
    let mut passes = Vec::new();
    let views = shadows::shadow_views(scene);
    passes::shadow::record(backend, scope, scene, &views, &frame, &mut passes)?;
    passes::geometry::record(backend, scope, scene, plan, &frame, faults, &mut passes)?;
    let light_cleared = passes::skybox::record(backend, scope, scene, &frame, &mut passes)?;
    passes::lighting::record(
        backend,
        scope,
        scene,
        plan,
        &frame,
        &views,
        faults,
        ibl_maps,
        light_cleared,
        &mut passes,
    )?;
    passes::tonemap::record(backend, scope, scene, &frame, faults, &mut passes)?;
    if scene.quality.gizmos {
        passes.push(passes::gizmos::pass(
            backend,
            scope,
            scene,
            frame.view_projection,
            frame.target(crate::plan::FINAL),
        )?);
    }

    if wanted.cull {
        let targets: Vec<Handle<Texture>> =
            wanted.names.iter().map(|name| frame.target(name)).collect();
        passes = cull::needed(passes, &targets);
    }
    let timings = backend.submit(&passes)?;
    let mut outputs = BTreeMap::new();
    for name in wanted.names {
        outputs.insert(
            name.clone(),
            backend
                .read_texture(frame.target(name), Subresource::default())
                .map_err(|source| RenderError::Readback {
                    scene: scene.name.clone(),
                    output: name.clone(),
                    source,
                })?,
        );
    }
    Ok((outputs, timings))
}

/// Object-to-camera-relative matrix and its normal matrix, in f32.
pub fn object_matrices(transform: &Transform, camera_position: DVec3) -> (Mat4, Mat3) {
    let model = transform.relative_to(camera_position).as_mat4();
    let normal = Mat3::from_mat4(model).inverse().transpose();
    (model, normal)
}

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

mod gizmos;
mod ibl;
pub mod shadows;
mod uniforms;

use std::collections::{BTreeMap, HashMap};
use std::sync::Arc;

use glam::{DMat4, DVec3, Mat3, Mat4};

use crate::backend::*;
use crate::image::Image;
use crate::mesh::{MeshData, Vertex};
use crate::plan::{self, LightingFeature, MaskChannel, PassKind, RenderPlan};
use crate::scene::{Light, Scene, ToneMap, Transform};
use crate::shaders;

pub use uniforms::{ambient_radiance, light_uniforms};

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
    /// Only these targets.
    Only(&'a [&'a str]),
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
        Readback::Only(names) => {
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
    let mut scope = ResourceScope::default();
    let result = record_and_submit(
        backend,
        scene,
        &plan,
        &wanted,
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

/// Checks what would otherwise turn into NaN pixels or a driver error.
pub fn validate(scene: &Scene) -> Result<(), RenderError> {
    let invalid = |problem: String| RenderError::InvalidScene {
        scene: scene.name.clone(),
        problem,
    };
    let q = &scene.quality;
    if q.width == 0 || q.height == 0 || q.width > 8192 || q.height > 8192 {
        return Err(invalid(format!(
            "output size {}x{} is outside 1..8192",
            q.width, q.height
        )));
    }
    if !(q.exposure.is_finite() && q.exposure > 0.0) {
        return Err(invalid(format!(
            "exposure {} must be finite and positive",
            q.exposure
        )));
    }
    let c = &scene.camera;
    let finite3 = |v: DVec3| v.is_finite();
    if !finite3(c.position) || !finite3(c.target) || !finite3(c.up) {
        return Err(invalid(
            "camera position, target and up must be finite".into(),
        ));
    }
    let forward = c.target - c.position;
    if forward.length() < 1e-9 || forward.normalize().cross(c.up).length() < 1e-6 {
        return Err(invalid(
            "camera target must differ from its position and not lie along `up`".into(),
        ));
    }
    if !(c.fov_y_degrees > 0.0 && c.fov_y_degrees < 180.0) {
        return Err(invalid(format!(
            "camera fov {} must be between 0 and 180 degrees",
            c.fov_y_degrees
        )));
    }
    if !(c.near > 0.0 && c.far > c.near && c.far.is_finite()) {
        return Err(invalid(format!(
            "camera near {} and far {} must satisfy 0 < near < far",
            c.near, c.far
        )));
    }
    if !scene.ambient.iter().all(|a| a.is_finite() && *a >= 0.0) {
        return Err(invalid("ambient must be finite and non-negative".into()));
    }
    for object in &scene.objects {
        let t = &object.transform;
        if !finite3(t.translation) || !t.rotation.is_finite() || !finite3(t.scale) {
            return Err(invalid(format!(
                "object `{}`: transform is not finite",
                object.name
            )));
        }
        if t.scale.abs().min_element() < 1e-12 {
            return Err(invalid(format!(
                "object `{}`: scale {:?} has a zero component",
                object.name, t.scale
            )));
        }
        let m = &object.material;
        let scalars = [
            m.roughness,
            m.metallic,
            m.specular,
            m.anisotropy,
            m.clearcoat,
            m.clearcoat_roughness,
            m.specular_exponent,
        ];
        if !m.base_color.iter().chain(&scalars).all(|v| v.is_finite()) {
            return Err(invalid(format!(
                "object `{}`: material has a NaN or infinite parameter",
                object.name
            )));
        }
        for index in [
            m.base_color_map,
            m.normal_map,
            m.roughness_map,
            m.metallic_map,
            m.clearcoat_map,
            m.specular_map,
        ]
        .into_iter()
        .flatten()
        {
            if index >= scene.textures.len() {
                return Err(invalid(format!(
                    "object `{}`: texture index {index} out of range ({} textures)",
                    object.name,
                    scene.textures.len()
                )));
            }
        }
        if object.mesh.indices.is_empty() {
            return Err(invalid(format!(
                "object `{}`: mesh has no triangles",
                object.name
            )));
        }
        let vertex_count = object.mesh.vertices.len();
        if object
            .mesh
            .indices
            .iter()
            .any(|&i| i as usize >= vertex_count)
        {
            return Err(invalid(format!(
                "object `{}`: mesh index out of range ({vertex_count} vertices)",
                object.name
            )));
        }
    }
    for (i, light) in scene.lights.iter().enumerate() {
        let ok = match light {
            Light::Directional {
                direction,
                color,
                intensity,
                ..
            } => {
                direction.is_finite()
                    && direction.length() > 1e-12
                    && color.iter().all(|c| c.is_finite())
                    && intensity.is_finite()
            }
            Light::Point {
                position,
                color,
                intensity,
                radius,
                falloff,
                ..
            } => {
                position.is_finite()
                    && color.iter().all(|c| c.is_finite())
                    && intensity.is_finite()
                    && *radius > 0.0
                    && radius.is_finite()
                    && *falloff > 0.0
                    && falloff.is_finite()
            }
        };
        if !ok {
            return Err(invalid(format!(
                "light {i}: parameters must be finite, with a non-zero direction, and radius and \
                 falloff positive"
            )));
        }
        if let Some(problem) = shadows::settings_problem(light) {
            return Err(invalid(format!("light {i}: {problem}")));
        }
    }
    if scene.environment.is_some() {
        if let Some(problem) = scene.quality.ibl.problem() {
            return Err(invalid(problem));
        }
    }
    if let Some(env) = &scene.environment {
        if !(env.intensity.is_finite() && env.intensity >= 0.0 && env.rotation_degrees.is_finite())
        {
            return Err(invalid(
                "environment intensity and rotation must be finite".into(),
            ));
        }
        let image = &env.image;
        if image.width == 0
            || image.height == 0
            || image.texels.len() != (image.width * image.height) as usize
        {
            return Err(invalid(format!("environment `{}`: bad size", image.label)));
        }
    }
    Ok(())
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

/// GPU copies of one mesh.
struct GpuMesh {
    vertices: Handle<Buffer>,
    indices: Handle<Buffer>,
    count: u32,
}

type Outputs = (BTreeMap<String, Image>, Vec<PassTiming>);

/// The resources of one lighting draw ([`plan::LightingDraw`]): its lights' uniforms, and the
/// maps of its shadowed light (placeholders when it has none).
struct LightDraw {
    lights: Vec<uniforms::LightData>,
    shadow_map: Handle<Texture>,
    /// The VSM moments (a placeholder unless the light's filter is `vsm`).
    moments: Handle<Texture>,
    shadow_uniform: Handle<Buffer>,
    /// Nearest or linear-filtering comparison, by the light's filter.
    shadow_sampler: Handle<Sampler>,
}

fn binding(binding: u32, resource: BindingResource) -> Binding {
    Binding { binding, resource }
}

fn texture_layout(binding: u32) -> BindingLayout {
    BindingLayout {
        binding,
        kind: BindingKind::Texture {
            sample_type: TextureSampleType::UnfilterableFloat,
            view: TextureViewKind::D2,
        },
    }
}

fn filterable_texture_layout(binding: u32) -> BindingLayout {
    BindingLayout {
        binding,
        kind: BindingKind::Texture {
            sample_type: TextureSampleType::Float,
            view: TextureViewKind::D2,
        },
    }
}

fn cube_layout(binding: u32) -> BindingLayout {
    BindingLayout {
        binding,
        kind: BindingKind::Texture {
            sample_type: TextureSampleType::Float,
            view: TextureViewKind::Cube,
        },
    }
}

fn uniform_layout() -> BindingLayout {
    BindingLayout {
        binding: 0,
        kind: BindingKind::UniformBuffer,
    }
}

fn fullscreen_pipeline(
    label: &str,
    shader: Handle<Shader>,
    fragment_entry: &str,
    bindings: Vec<BindingLayout>,
    format: TextureFormat,
    blend: Option<BlendState>,
) -> PipelineDesc {
    PipelineDesc {
        label: label.to_owned(),
        shader,
        vertex_entry: "vs_fullscreen".to_owned(),
        fragment_entry: Some(fragment_entry.to_owned()),
        vertex_buffers: vec![],
        bindings,
        color_targets: vec![ColorTarget { format, blend }],
        depth: None,
        topology: Topology::TriangleList,
        cull: CullMode::None,
        geometry: None,
        constants: vec![],
    }
}

fn fullscreen_draw(pipeline: Handle<Pipeline>, bindings: Vec<Binding>) -> Draw {
    Draw {
        pipeline,
        bindings,
        vertex_buffers: vec![],
        index_buffer: None,
        count: 3,
    }
}

fn attachment(texture: Handle<Texture>, load: LoadOp<[f32; 4]>) -> ColorAttachment {
    ColorAttachment {
        texture,
        subresource: Subresource::default(),
        load,
    }
}

fn record_and_submit(
    backend: &mut dyn Backend,
    scene: &Scene,
    plan: &RenderPlan,
    wanted: &[String],
    faults: &Faults,
    ibl_maps: Option<&crate::ibl::IblMaps>,
    scope: &mut ResourceScope,
) -> Result<Outputs, RenderError> {
    let mut targets: HashMap<String, Handle<Texture>> = HashMap::new();
    for spec in &plan.targets {
        let handle = scope.texture(
            backend,
            &TextureDesc::d2(&spec.name, spec.width, spec.height, spec.format),
        )?;
        targets.insert(spec.name.clone(), handle);
    }
    let target = |name: &str| targets[name];

    // Meshes, uploaded once per distinct mesh.
    let mut meshes: HashMap<*const MeshData, GpuMesh> = HashMap::new();
    for object in &scene.objects {
        let key = Arc::as_ptr(&object.mesh);
        if meshes.contains_key(&key) {
            continue;
        }
        let mesh = &object.mesh;
        let vertices = scope.buffer(
            backend,
            &format!("{} vertices", mesh.name),
            BufferUsage::Vertex,
            bytemuck::cast_slice(&mesh.vertices),
        )?;
        let indices = scope.buffer(
            backend,
            &format!("{} indices", mesh.name),
            BufferUsage::Index,
            bytemuck::cast_slice(&mesh.indices),
        )?;
        meshes.insert(
            key,
            GpuMesh {
                vertices,
                indices,
                count: mesh.indices.len() as u32,
            },
        );
    }

    // Material textures, plus a white texel bound wherever a material has no map.
    let mut textures = Vec::with_capacity(scene.textures.len());
    for image in &scene.textures {
        let format = match (image.format, image.srgb) {
            (crate::assets::TexelFormat::Rgba16Float, _) => TextureFormat::Rgba16Float,
            (crate::assets::TexelFormat::Rgba8, true) => TextureFormat::Rgba8UnormSrgb,
            (crate::assets::TexelFormat::Rgba8, false) => TextureFormat::Rgba8Unorm,
        };
        let handle = scope.texture(
            backend,
            &TextureDesc {
                mip_levels: image.mips.len().max(1) as u32,
                ..TextureDesc::d2(&image.label, image.width, image.height, format)
            },
        )?;
        for (mip, texels) in image.mips.iter().enumerate() {
            backend.write_texture(
                handle,
                Subresource {
                    mip: mip as u32,
                    layer: 0,
                },
                texels,
            )?;
        }
        textures.push(handle);
    }
    let white = scope.texture(
        backend,
        &TextureDesc::d2("white", 1, 1, TextureFormat::Rgba8Unorm),
    )?;
    backend.write_texture(white, Subresource::default(), &[255; 4])?;
    let black = scope.texture(
        backend,
        &TextureDesc::d2("black", 1, 1, TextureFormat::Rgba8Unorm),
    )?;
    backend.write_texture(black, Subresource::default(), &[0, 0, 0, 0])?;
    let material_sampler = scope.sampler(
        backend,
        &SamplerDesc::linear("material", AddressMode::Repeat),
    )?;

    let shader =
        |scope: &mut ResourceScope, backend: &mut dyn Backend, source: shaders::ShaderSource| {
            scope.shader(
                backend,
                &ShaderDesc {
                    name: source.name.to_owned(),
                    wgsl: source.wgsl.to_owned(),
                },
            )
        };
    let camera = CameraMatrices::new(scene);
    let view_projection = camera.view_projection().as_mat4();
    let mask_targets: Vec<Handle<Texture>> = plan
        .targets
        .iter()
        .filter(|t| t.name.starts_with("mask"))
        .map(|t| target(&t.name))
        .collect();

    let mut passes = Vec::new();

    // Shadow maps.
    let views = shadows::shadow_views(scene);
    shadows::record(
        backend,
        scope,
        scene,
        &views,
        &|name| targets[name],
        &|object| (&meshes[&Arc::as_ptr(&object.mesh)]).into(),
        &mut passes,
    )?;

    // Geometry and shader-mask passes.
    let gbuffer_shader = shader(scope, backend, shaders::GBUFFER)?;
    let vertex_layout = VertexBufferLayout {
        stride: std::mem::size_of::<Vertex>() as u32,
        attributes: vec![
            VertexAttribute {
                location: 0,
                format: VertexFormat::Float32x3,
                offset: 0,
            },
            VertexAttribute {
                location: 1,
                format: VertexFormat::Float32x3,
                offset: 12,
            },
            VertexAttribute {
                location: 2,
                format: VertexFormat::Float32x2,
                offset: 24,
            },
            VertexAttribute {
                location: 3,
                format: VertexFormat::Float32x4,
                offset: 32,
            },
        ],
    };
    let mut gbuffer_bindings = vec![uniform_layout()];
    gbuffer_bindings.extend((1..=6).map(filterable_texture_layout));
    gbuffer_bindings.push(BindingLayout {
        binding: 7,
        kind: BindingKind::Sampler(SamplerBindingKind::Filtering),
    });
    let geometry_pipeline = scope.pipeline(
        backend,
        &PipelineDesc {
            label: "geometry".to_owned(),
            shader: gbuffer_shader,
            vertex_entry: "vs_main".to_owned(),
            fragment_entry: Some("fs_gbuffer".to_owned()),
            vertex_buffers: vec![vertex_layout.clone()],
            bindings: gbuffer_bindings,
            color_targets: plan::GBUFFER_TARGETS
                .iter()
                .map(|_| ColorTarget {
                    format: TextureFormat::Rgba16Float,
                    blend: None,
                })
                .collect(),
            depth: Some(DepthState {
                format: TextureFormat::Depth32Float,
                write: true,
                compare: CompareFunction::Less,
            }),
            topology: Topology::TriangleList,
            cull: CullMode::Back,
            geometry: None,
            constants: vec![],
        },
    )?;
    let mask_pipeline = scope.pipeline(
        backend,
        &PipelineDesc {
            label: "mask".to_owned(),
            shader: gbuffer_shader,
            vertex_entry: "vs_main".to_owned(),
            fragment_entry: Some(
                if mask_targets.len() > 1 {
                    "fs_mask_2"
                } else {
                    "fs_mask_1"
                }
                .to_owned(),
            ),
            vertex_buffers: vec![vertex_layout],
            bindings: vec![uniform_layout()],
            color_targets: mask_targets
                .iter()
                .map(|_| ColorTarget {
                    format: TextureFormat::Rgba8Unorm,
                    blend: None,
                })
                .collect(),
            depth: Some(DepthState {
                format: TextureFormat::Depth32Float,
                write: false,
                compare: CompareFunction::LessEqual,
            }),
            topology: Topology::TriangleList,
            cull: CullMode::Back,
            geometry: None,
            constants: vec![],
        },
    )?;
    let mut geometry_draws = Vec::new();
    let mut mask_draws = Vec::new();
    for object in &scene.objects {
        let channel = plan
            .mask_channels
            .iter()
            .find(|c| c.model == object.lighting)
            .copied()
            .unwrap_or(MaskChannel {
                model: object.lighting,
                target: 0,
                channel: 0,
            });
        let data = uniforms::object_uniforms(
            object,
            &object.transform,
            scene.camera.position,
            view_projection,
            channel,
            faults,
            &scene.quality.gbuffer,
        );
        let uniform = scope.buffer(
            backend,
            &format!("{} uniforms", object.name),
            BufferUsage::Uniform,
            bytemuck::cast_slice(&data),
        )?;
        let m = &object.material;
        let map = |index: Option<usize>| index.map_or(white, |i| textures[i]);
        let mesh = &meshes[&Arc::as_ptr(&object.mesh)];
        geometry_draws.push(Draw {
            pipeline: geometry_pipeline,
            bindings: vec![
                binding(0, BindingResource::Buffer(uniform)),
                binding(1, BindingResource::Texture(map(m.base_color_map))),
                binding(2, BindingResource::Texture(map(m.normal_map))),
                binding(3, BindingResource::Texture(map(m.roughness_map))),
                binding(4, BindingResource::Texture(map(m.metallic_map))),
                binding(5, BindingResource::Texture(map(m.clearcoat_map))),
                binding(6, BindingResource::Texture(map(m.specular_map))),
                binding(7, BindingResource::Sampler(material_sampler)),
            ],
            vertex_buffers: vec![mesh.vertices],
            index_buffer: Some((mesh.indices, IndexFormat::U32)),
            count: mesh.count,
        });
        mask_draws.push(Draw {
            pipeline: mask_pipeline,
            bindings: vec![binding(0, BindingResource::Buffer(uniform))],
            vertex_buffers: vec![mesh.vertices],
            index_buffer: Some((mesh.indices, IndexFormat::U32)),
            count: mesh.count,
        });
    }
    passes.push(RenderPass {
        name: "geometry".to_owned(),
        color_attachments: plan::GBUFFER_TARGETS
            .iter()
            .map(|name| attachment(target(name), LoadOp::Clear([0.0; 4])))
            .collect(),
        depth_attachment: Some(DepthAttachment {
            texture: target(plan::DEPTH),
            subresource: Subresource::default(),
            load: LoadOp::Clear(1.0),
        }),
        viewports: vec![],
        draws: geometry_draws,
    });
    passes.push(RenderPass {
        name: "mask".to_owned(),
        color_attachments: mask_targets
            .iter()
            .map(|&t| attachment(t, LoadOp::Clear([0.0; 4])))
            .collect(),
        depth_attachment: Some(DepthAttachment {
            texture: target(plan::DEPTH),
            subresource: Subresource::default(),
            load: LoadOp::Load,
        }),
        viewports: vec![],
        draws: mask_draws,
    });

    // Light buffer: skybox (if any) then one pass per lighting model.
    let light_buffer = target(plan::LIGHT);
    let mut light_cleared = false;
    if let Some(environment) = &scene.environment {
        let image = &environment.image;
        let texture = scope.texture(
            backend,
            &TextureDesc::d2(
                &image.label,
                image.width,
                image.height,
                TextureFormat::Rgba16Float,
            ),
        )?;
        let texels: Vec<u16> = image
            .texels
            .iter()
            .flat_map(|t| {
                t.iter()
                    .map(|&c| half::f16::from_f32(c.clamp(0.0, 65000.0)).to_bits())
            })
            .collect();
        backend.write_texture(
            texture,
            Subresource::default(),
            bytemuck::cast_slice(&texels),
        )?;
        let sampler = scope.sampler(
            backend,
            &SamplerDesc {
                mipmap_filter: FilterMode::Nearest,
                ..SamplerDesc::linear("environment", AddressMode::Repeat)
            },
        )?;
        let skybox_shader = shader(scope, backend, shaders::SKYBOX)?;
        let pipeline = scope.pipeline(
            backend,
            &fullscreen_pipeline(
                "skybox",
                skybox_shader,
                "fs_skybox",
                vec![
                    uniform_layout(),
                    texture_layout(1),
                    texture_layout(2),
                    filterable_texture_layout(3),
                    BindingLayout {
                        binding: 4,
                        kind: BindingKind::Sampler(SamplerBindingKind::Filtering),
                    },
                ],
                TextureFormat::Rgba16Float,
                None,
            ),
        )?;
        let data = uniforms::skybox_uniforms(scene, &camera);
        let uniform = scope.buffer(
            backend,
            "skybox uniforms",
            BufferUsage::Uniform,
            bytemuck::cast_slice(&data),
        )?;
        passes.push(RenderPass {
            name: "skybox".to_owned(),
            color_attachments: vec![attachment(light_buffer, LoadOp::Clear([0.0; 4]))],
            depth_attachment: None,
            viewports: vec![],
            draws: vec![fullscreen_draw(
                pipeline,
                vec![
                    binding(0, BindingResource::Buffer(uniform)),
                    // No objects, no mask target: the black texel says nothing is covered.
                    binding(
                        1,
                        BindingResource::Texture(mask_targets.first().copied().unwrap_or(black)),
                    ),
                    binding(
                        2,
                        BindingResource::Texture(mask_targets.get(1).copied().unwrap_or(black)),
                    ),
                    binding(3, BindingResource::Texture(texture)),
                    binding(4, BindingResource::Sampler(sampler)),
                ],
            )],
        });
        light_cleared = true;
    }

    let lighting_shader = shader(scope, backend, shaders::LIGHTING)?;
    // Parameters in uniform buffers; nothing in them steers a branch or loop (see the top of
    // lighting.wgsl), so lavapipe has nothing to specialise per draw.
    let mut lighting_bindings = vec![BindingLayout {
        binding: 0,
        kind: BindingKind::UniformBuffer,
    }];
    lighting_bindings.extend((1..=6).map(texture_layout));
    lighting_bindings.extend([
        BindingLayout {
            binding: 7,
            kind: BindingKind::Texture {
                sample_type: TextureSampleType::Depth,
                view: TextureViewKind::D2,
            },
        },
        BindingLayout {
            binding: 8,
            kind: BindingKind::Sampler(SamplerBindingKind::Comparison),
        },
        BindingLayout {
            binding: 9,
            kind: BindingKind::UniformBuffer,
        },
        BindingLayout {
            binding: 10,
            kind: BindingKind::Texture {
                sample_type: TextureSampleType::UnfilterableFloat,
                view: TextureViewKind::D2Array,
            },
        },
        filterable_texture_layout(11),
        BindingLayout {
            binding: 12,
            kind: BindingKind::Sampler(SamplerBindingKind::Filtering),
        },
        cube_layout(13),
        cube_layout(14),
        filterable_texture_layout(15),
        BindingLayout {
            binding: 16,
            kind: BindingKind::Sampler(SamplerBindingKind::Filtering),
        },
        texture_layout(17),
    ]);
    let ibl_textures = ibl::upload(backend, scope, ibl_maps)?;
    let jitter_layers = (shadows::SOFT_RINGS * shadows::SOFT_SECTORS / 2) as u32;
    let jitter = scope.texture(
        backend,
        &TextureDesc {
            kind: TextureKind::D2Array {
                layers: jitter_layers,
            },
            ..TextureDesc::d2(
                "shadow jitter",
                shadows::JITTER_TILE,
                shadows::JITTER_TILE,
                TextureFormat::Rgba16Float,
            )
        },
    )?;
    let jitter_texels = shadows::jitter_texels();
    let layer_len = (shadows::JITTER_TILE * shadows::JITTER_TILE * 4) as usize;
    for (layer, texels) in jitter_texels.chunks(layer_len).enumerate() {
        backend.write_texture(
            jitter,
            Subresource {
                mip: 0,
                layer: layer as u32,
            },
            bytemuck::cast_slice(texels),
        )?;
    }
    let mut lights = light_uniforms(scene);
    if let Some(scale) = faults.light_radiance_scale {
        for light in &mut lights {
            for channel in &mut light.color[..3] {
                *channel *= scale;
            }
        }
    }
    let shadow_sampler = scope.sampler(
        backend,
        &SamplerDesc {
            compare: Some(CompareFunction::LessEqual),
            ..SamplerDesc::nearest("shadow compare")
        },
    )?;
    let linear_shadow_sampler = scope.sampler(
        backend,
        &SamplerDesc {
            compare: Some(CompareFunction::LessEqual),
            mipmap_filter: FilterMode::Nearest,
            ..SamplerDesc::linear("shadow compare linear", AddressMode::ClampToEdge)
        },
    )?;
    let moments_sampler = scope.sampler(
        backend,
        &SamplerDesc {
            mipmap_filter: FilterMode::Nearest,
            ..SamplerDesc::linear("shadow moments", AddressMode::ClampToEdge)
        },
    )?;
    // Bind group of a lighting-shader draw (`lighting.wgsl` bindings 0..17).
    let lighting_bind_group = |uniform, mask, draw: &LightDraw| {
        let mut bindings = vec![binding(0, BindingResource::Buffer(uniform))];
        bindings.extend(
            plan::GBUFFER_TARGETS
                .iter()
                .enumerate()
                .map(|(i, name)| binding(i as u32 + 1, BindingResource::Texture(targets[*name]))),
        );
        bindings.extend([
            binding(6, BindingResource::Texture(mask)),
            binding(7, BindingResource::Texture(draw.shadow_map)),
            binding(8, BindingResource::Sampler(draw.shadow_sampler)),
            binding(9, BindingResource::Buffer(draw.shadow_uniform)),
            binding(10, BindingResource::Texture(jitter)),
            binding(11, BindingResource::Texture(draw.moments)),
            binding(12, BindingResource::Sampler(moments_sampler)),
            binding(13, BindingResource::Texture(ibl_textures.irradiance)),
            binding(14, BindingResource::Texture(ibl_textures.specular)),
            binding(15, BindingResource::Texture(ibl_textures.dfg)),
            binding(16, BindingResource::Sampler(ibl_textures.sampler)),
            binding(17, BindingResource::Texture(targets[plan::DEPTH])),
        ]);
        bindings
    };
    let no_shadow_map = scope.texture(
        backend,
        &TextureDesc::d2("no shadow", 1, 1, TextureFormat::Depth32Float),
    )?;
    let no_moments = scope.texture(
        backend,
        &TextureDesc::d2("no moments", 1, 1, TextureFormat::Rgba16Float),
    )?;
    let no_shadow_uniform = scope.buffer(
        backend,
        "no shadow uniforms",
        BufferUsage::Uniform,
        bytemuck::cast_slice(&shadows::shadow_uniforms(None)),
    )?;
    // Each shadowed light's maps and shadow uniforms, by scene light index.
    let mut shadow_bindings = HashMap::new();
    for view in &views {
        let uniform = scope.buffer(
            backend,
            &format!("shadow uniforms light {}", view.light),
            BufferUsage::Uniform,
            bytemuck::cast_slice(&shadows::shadow_uniforms(Some(view))),
        )?;
        let moments = plan::shadow_moments_target_name(view.light);
        let sampler = if view.settings.filter.linear_comparison() {
            linear_shadow_sampler
        } else {
            shadow_sampler
        };
        shadow_bindings.insert(
            view.light,
            (
                targets[&plan::shadow_target_name(view.light)],
                targets.get(&moments).copied().unwrap_or(no_moments),
                uniform,
                sampler,
            ),
        );
    }
    // The resources of one of the plan's lighting draws.
    let light_draw = |draw: &plan::LightingDraw| {
        let (shadow_map, moments, shadow_uniform, shadow_sampler) = draw
            .shadowed
            .and_then(|light| shadow_bindings.get(&light).copied())
            .unwrap_or((no_shadow_map, no_moments, no_shadow_uniform, shadow_sampler));
        LightDraw {
            lights: draw.lights.iter().map(|&i| lights[i]).collect(),
            shadow_map,
            moments,
            shadow_uniform,
            shadow_sampler,
        }
    };
    // One pipeline per (entry point, variant, routed or not), created on first use.
    let mut lighting_pipelines: HashMap<String, Handle<Pipeline>> = HashMap::new();
    let mut lighting_pipeline = |scope: &mut ResourceScope,
                                 backend: &mut dyn Backend,
                                 entry: &str,
                                 variant: &plan::LightingVariant,
                                 routed: bool|
     -> Result<Handle<Pipeline>, RenderError> {
        let key = format!("{entry} {variant:?} {routed}");
        if let Some(&pipeline) = lighting_pipelines.get(&key) {
            return Ok(pipeline);
        }
        let blend = routed.then_some(BlendState::ADDITIVE);
        let desc = PipelineDesc {
            depth: routed.then_some(DepthState {
                format: TextureFormat::Depth32Float,
                write: false,
                compare: CompareFunction::Equal,
            }),
            constants: variant.constants(),
            ..fullscreen_pipeline(
                &format!("lighting {entry} ({variant})"),
                lighting_shader,
                entry,
                lighting_bindings.clone(),
                TextureFormat::Rgba16Float,
                blend,
            )
        };
        let pipeline = scope.pipeline(backend, &desc)?;
        lighting_pipelines.insert(key, pipeline);
        Ok(pipeline)
    };
    // Routing: marks the pass's model's pixels at depth 0 in the cleared routing target; it
    // adds zero to the light buffer (a pass's pipelines must all match its attachments).
    let route_pipeline = if plan.lighting.is_empty() {
        None
    } else {
        Some(scope.pipeline(
            backend,
            &PipelineDesc {
                depth: Some(DepthState {
                    format: TextureFormat::Depth32Float,
                    write: true,
                    compare: CompareFunction::Always,
                }),
                ..fullscreen_pipeline(
                    "lighting route",
                    lighting_shader,
                    "fs_route",
                    vec![
                        BindingLayout {
                            binding: 0,
                            kind: BindingKind::UniformBuffer,
                        },
                        texture_layout(6),
                    ],
                    TextureFormat::Rgba16Float,
                    Some(BlendState::ADDITIVE),
                )
            },
        )?)
    };
    for (channel, pass) in plan.mask_channels.iter().zip(&plan.lighting) {
        let model = channel.model;
        let mask = mask_targets[channel.target];
        let mut draws = Vec::new();
        for (index, draw) in pass.draws.iter().enumerate() {
            let resources = light_draw(draw);
            let data = uniforms::lighting_uniforms(
                scene,
                &camera,
                *channel,
                &resources.lights,
                draw.first,
                ibl_textures.max_lod,
            );
            let uniform = scope.buffer(
                backend,
                &format!("lighting {model} batch {index}"),
                BufferUsage::Uniform,
                bytemuck::cast_slice(&data),
            )?;
            if index == 0 {
                if let Some(route) = route_pipeline {
                    draws.push(fullscreen_draw(
                        route,
                        vec![
                            binding(0, BindingResource::Buffer(uniform)),
                            binding(6, BindingResource::Texture(mask)),
                        ],
                    ));
                }
            }
            let pipeline =
                lighting_pipeline(scope, backend, model.entry_point(), &draw.variant, true)?;
            let bindings = lighting_bind_group(uniform, mask, &resources);
            draws.push(fullscreen_draw(pipeline, bindings));
        }
        let load = if light_cleared {
            LoadOp::Load
        } else {
            LoadOp::Clear([0.0; 4])
        };
        light_cleared = true;
        passes.push(RenderPass {
            name: plan
                .passes
                .iter()
                .find(|p| p.kind == PassKind::Lighting(model))
                .map_or_else(|| format!("lighting_{model}"), |p| p.name.clone()),
            color_attachments: vec![attachment(light_buffer, load)],
            depth_attachment: Some(DepthAttachment {
                texture: target(plan::ROUTE),
                subresource: Subresource::default(),
                load: LoadOp::Clear(1.0),
            }),
            // Only the pixels around the model's objects are rasterized (frag.xy stays in
            // image coordinates, so the shaders read the right texels).
            viewports: pass
                .rect
                .map(|r| Viewport {
                    x: r.x as f32,
                    y: r.y as f32,
                    width: r.width as f32,
                    height: r.height as f32,
                    min_depth: 0.0,
                    max_depth: 1.0,
                })
                .into_iter()
                .collect(),
            draws,
        });
    }
    if !light_cleared {
        // No objects and no environment: the light buffer is black.
        passes.push(RenderPass {
            name: "clear_light".to_owned(),
            color_attachments: vec![attachment(light_buffer, LoadOp::Clear([0.0; 4]))],
            depth_attachment: None,
            viewports: vec![],
            draws: vec![],
        });
    }

    // Debug: each shadowed light's shadow term, through the lighting shader's own lookup.
    if scene.quality.debug_shadow_terms {
        for view in &views {
            let name = plan::shadow_term_target_name(view.light);
            let mut draws = plan.lighting.iter().flat_map(|pass| &pass.draws);
            let Some(draw) = draws.find(|d| d.shadowed == Some(view.light)) else {
                continue;
            };
            let pipeline =
                lighting_pipeline(scope, backend, "fs_shadow_term", &draw.variant, false)?;
            let resources = light_draw(draw);
            let channel = plan.mask_channels[0];
            let data =
                uniforms::lighting_uniforms(scene, &camera, channel, &resources.lights, false, 0.0);
            let uniform = scope.buffer(
                backend,
                &format!("{name} uniforms"),
                BufferUsage::Uniform,
                bytemuck::cast_slice(&data),
            )?;
            let bindings = lighting_bind_group(uniform, mask_targets[0], &resources);
            passes.push(RenderPass {
                name: name.clone(),
                color_attachments: vec![attachment(target(&name), LoadOp::Clear([0.0; 4]))],
                depth_attachment: None,
                viewports: vec![],
                draws: vec![fullscreen_draw(pipeline, bindings)],
            });
        }
    }

    // Tone mapping.
    let tonemap_shader = shader(scope, backend, shaders::TONEMAP)?;
    let tonemap_pipeline = scope.pipeline(
        backend,
        &fullscreen_pipeline(
            "tonemap",
            tonemap_shader,
            "fs_tonemap",
            vec![uniform_layout(), texture_layout(1)],
            TextureFormat::Rgba8UnormSrgb,
            None,
        ),
    )?;
    let operator: u32 = match scene.quality.tone_map {
        ToneMap::Aces => 0,
        ToneMap::Reinhard => 1,
        ToneMap::Clamp => 2,
    };
    let input_scale = faults.tonemap_input_scale.unwrap_or(1.0);
    let tonemap_uniform = scope.buffer(
        backend,
        "tonemap uniforms",
        BufferUsage::Uniform,
        bytemuck::cast_slice(&[operator, 0, 0, 0, input_scale.to_bits(), 0, 0, 0]),
    )?;
    passes.push(RenderPass {
        name: "tonemap".to_owned(),
        color_attachments: vec![attachment(target(plan::FINAL), LoadOp::Clear([0.0; 4]))],
        depth_attachment: None,
        viewports: vec![],
        draws: vec![fullscreen_draw(
            tonemap_pipeline,
            vec![
                binding(0, BindingResource::Buffer(tonemap_uniform)),
                binding(1, BindingResource::Texture(light_buffer)),
            ],
        )],
    });

    if scene.quality.gizmos {
        passes.push(gizmos::pass(
            backend,
            scope,
            scene,
            view_projection,
            target(plan::FINAL),
        )?);
    }

    let timings = backend.submit(&passes)?;
    let mut outputs = BTreeMap::new();
    for name in wanted {
        outputs.insert(
            name.clone(),
            backend
                .read_texture(target(name), Subresource::default())
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

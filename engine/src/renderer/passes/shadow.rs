//! The shadow passes: each shadowed light's casters drawn depth-only into its map (a point
//! light's six faces one pass each, or all six in one pass through a geometry stage), VSM
//! moments into their colour target, and the separable blur of the moments.

use super::super::builders::{
    attachment, binding, fullscreen_draw, fullscreen_pipeline, texture_layout,
};
use super::super::shadows::{blur_weights, ShadowView};
use super::super::RenderError;
use super::FrameContext;
use crate::backend::*;
use crate::plan::{BlurAxis, PassId, TargetId};
use crate::scene::{PointShadowPass, Scene, ShadowFilter};
use crate::shaders;

/// Names of a point light's faces, as suffixes of their passes' names.
const FACE_NAMES: [&str; 6] = ["+x", "-x", "+y", "-y", "+z", "-z"];

/// The pipelines the shadow passes draw with; the optional ones exist only when a view needs
/// them. Made once per frame, by its first shadow pass.
pub(in crate::renderer) struct ShadowPipelines {
    /// Depth only.
    depth: Handle<Pipeline>,
    /// Depth through the geometry stage that draws a point light's six faces at once.
    layered: Option<Handle<Pipeline>>,
    /// Depth and VSM moments.
    moments: Option<Handle<Pipeline>>,
    /// The moments' separable blur.
    blur: Option<Handle<Pipeline>>,
}

fn uses_vsm(view: &ShadowView) -> bool {
    view.settings.filter == ShadowFilter::Vsm
}

/// The pipeline drawing shadow casters: depth only, or depth and VSM moments.
fn caster_pipeline(shader: Handle<Shader>, moments: bool) -> PipelineDesc {
    PipelineDesc {
        label: if moments { "shadow moments" } else { "shadow" }.to_owned(),
        shader,
        vertex_entry: "vs_shadow".to_owned(),
        fragment_entry: moments.then(|| "fs_shadow_moments".to_owned()),
        vertex_buffers: vec![VertexBufferLayout {
            stride: std::mem::size_of::<crate::mesh::Vertex>() as u32,
            attributes: vec![VertexAttribute {
                location: 0,
                format: VertexFormat::Float32x3,
                offset: 0,
            }],
        }],
        bindings: vec![BindingLayout {
            binding: 0,
            kind: BindingKind::UniformBuffer,
        }],
        color_targets: if moments {
            vec![ColorTarget {
                format: TextureFormat::Rgba16Float,
                blend: None,
            }]
        } else {
            vec![]
        },
        depth: Some(DepthState {
            format: TextureFormat::Depth32Float,
            write: true,
            compare: CompareFunction::Less,
        }),
        topology: Topology::TriangleList,
        cull: CullMode::None,
        geometry: None,
        constants: vec![],
    }
}

fn pipelines(
    backend: &mut dyn Backend,
    scope: &mut ResourceScope,
    scene: &Scene,
    views: &[ShadowView],
) -> Result<ShadowPipelines, RenderError> {
    let shader = scope.shader(
        backend,
        &ShaderDesc {
            name: shaders::SHADOW.name.to_owned(),
            wgsl: shaders::SHADOW.wgsl.to_owned(),
        },
    )?;
    let depth = scope.pipeline(backend, &caster_pipeline(shader, false))?;
    let layered = if scene.quality.point_shadows == PointShadowPass::GeometryShader
        && views.iter().any(|v| v.point)
    {
        let desc = PipelineDesc {
            label: "shadow six faces".to_owned(),
            vertex_entry: "vs_shadow_object".to_owned(),
            geometry: Some(GeometryStage {
                name: "gl/point_shadow_faces.geom".to_owned(),
                glsl: shaders::POINT_SHADOW_FACES_GEOMETRY.to_owned(),
            }),
            ..caster_pipeline(shader, false)
        };
        Some(scope.pipeline(backend, &desc)?)
    } else {
        None
    };
    let (moments, blur) = if views.iter().any(uses_vsm) {
        let blur = fullscreen_pipeline(
            "shadow moments blur",
            shader,
            "fs_moments_blur",
            vec![
                BindingLayout {
                    binding: 1,
                    kind: BindingKind::UniformBuffer,
                },
                texture_layout(2),
            ],
            TextureFormat::Rgba16Float,
            None,
        );
        (
            Some(scope.pipeline(backend, &caster_pipeline(shader, true))?),
            Some(scope.pipeline(backend, &blur)?),
        )
    } else {
        (None, None)
    };
    Ok(ShadowPipelines {
        depth,
        layered,
        moments,
        blur,
    })
}

/// The frame's shadow pipelines, made on first use.
fn frame_pipelines<'c>(ctx: &'c mut FrameContext<'_>) -> Result<&'c ShadowPipelines, RenderError> {
    if ctx.shadow.is_none() {
        let made = pipelines(ctx.backend, ctx.scope, ctx.scene, &ctx.views)?;
        ctx.shadow = Some(made);
    }
    Ok(ctx.shadow.as_ref().expect("made above"))
}

/// Light `light`'s shadow map: one pass per face (or one for all six through the geometry
/// stage), and its VSM moments with it.
pub(in crate::renderer) fn record_map(
    ctx: &mut FrameContext<'_>,
    light: usize,
) -> Result<(), RenderError> {
    let view = ctx.view(light)?;
    let pipelines = frame_pipelines(ctx)?;
    let (moments, depth, layered) = (pipelines.moments, pipelines.depth, pipelines.layered);
    let frame = ctx.frame;
    let pass = PassId::Shadow { light };
    let name = pass.to_string();
    let texture = frame.target(TargetId::Shadow { light });
    let (pipeline, color_attachments) = match moments.filter(|_| uses_vsm(&view)) {
        Some(pipeline) => (
            pipeline,
            vec![ColorAttachment {
                texture: frame.target(TargetId::ShadowMoments { light }),
                subresource: Subresource::default(),
                // Where no caster is drawn: depth 1 (the far plane), no variance.
                load: LoadOp::Clear([1.0, 0.0, 1.0, 0.0]),
            }],
        ),
        None => (depth, vec![]),
    };
    // Which faces each pass draws: one each, or all six through the geometry stage.
    let single_pass =
        view.point && ctx.scene.quality.point_shadows == PointShadowPass::GeometryShader;
    let groups: Vec<Vec<usize>> = if single_pass {
        vec![(0..view.faces.len()).collect()]
    } else {
        (0..view.faces.len()).map(|face| vec![face]).collect()
    };
    let pipeline = match layered.filter(|_| single_pass) {
        Some(layered) => layered,
        None => pipeline,
    };
    for (group_index, faces) in groups.iter().enumerate() {
        let draws = caster_draws(ctx, &view, faces, pipeline)?;
        ctx.recorded.push(
            pass,
            RenderPass {
                name: if view.point && !single_pass {
                    format!("{name}{}", FACE_NAMES[faces[0]])
                } else {
                    name.clone()
                },
                color_attachments: color_attachments.clone(),
                depth_attachment: Some(DepthAttachment {
                    texture,
                    subresource: Subresource::default(),
                    load: if group_index == 0 {
                        LoadOp::Clear(1.0)
                    } else {
                        LoadOp::Load
                    },
                }),
                viewports: face_viewports(&view, faces),
                draws,
            },
        );
    }
    Ok(())
}

/// One draw per shadow caster, with its matrices for `faces`.
fn caster_draws(
    ctx: &mut FrameContext<'_>,
    view: &ShadowView,
    faces: &[usize],
    pipeline: Handle<Pipeline>,
) -> Result<Vec<Draw>, RenderError> {
    let scene = ctx.scene;
    let name = PassId::Shadow { light: view.light };
    let mut draws = Vec::new();
    for object in scene.objects.iter().filter(|o| o.casts_shadows) {
        let model = object.transform.relative_to(scene.camera.position);
        let matrices: Vec<f32> = faces
            .iter()
            .flat_map(|&face| (view.faces[face] * model).as_mat4().to_cols_array())
            .collect();
        let uniform = ctx.scope.buffer(
            ctx.backend,
            &format!("{name} {} faces {faces:?}", object.name),
            BufferUsage::Uniform,
            bytemuck::cast_slice(&matrices),
        )?;
        let mesh = ctx.frame.mesh(object);
        draws.push(Draw {
            pipeline,
            bindings: vec![binding(0, BindingResource::Buffer(uniform))],
            vertex_buffers: vec![mesh.vertices],
            index_buffer: Some((mesh.indices, IndexFormat::U32)),
            count: mesh.count,
        });
    }
    Ok(draws)
}

/// The viewports of `faces`: a point light's faces in a 3x2 atlas, a directional map whole.
fn face_viewports(view: &ShadowView, faces: &[usize]) -> Vec<Viewport> {
    faces
        .iter()
        .map(|&face| {
            let (x, y) = if view.point {
                ((face % 3) as u32 * view.size, (face / 3) as u32 * view.size)
            } else {
                (0, 0)
            };
            Viewport {
                x: x as f32,
                y: y as f32,
                width: view.size as f32,
                height: view.size as f32,
                min_depth: 0.0,
                max_depth: 1.0,
            }
        })
        .collect()
}

/// One direction of the separable Gaussian blur of light `light`'s VSM moments: along x into
/// the intermediate target, then along y back into the moments.
pub(in crate::renderer) fn record_blur(
    ctx: &mut FrameContext<'_>,
    light: usize,
    axis: BlurAxis,
) -> Result<(), RenderError> {
    let view = ctx.view(light)?;
    let Some(pipeline) = frame_pipelines(ctx)?.blur else {
        return Err(RenderError::InvalidScene {
            scene: ctx.scene.name.clone(),
            problem: format!("the plan blurs light {light}'s moments, which has no VSM"),
        });
    };
    let radius = view.settings.vsm_blur_radius;
    let moments = ctx.frame.target(TargetId::ShadowMoments { light });
    let blurred_x = ctx.frame.target(TargetId::ShadowBlur { light });
    let (step, source, destination) = match axis {
        BlurAxis::X => ([1.0f32, 0.0], moments, blurred_x),
        BlurAxis::Y => ([0.0, 1.0], blurred_x, moments),
    };
    let pass = PassId::ShadowBlur { light, axis };
    let mut data = vec![step[0], step[1], radius as f32, 0.0];
    data.extend(blur_weights(radius));
    let uniform = ctx.scope.buffer(
        ctx.backend,
        &format!("{pass} uniforms"),
        BufferUsage::Uniform,
        bytemuck::cast_slice(&data),
    )?;
    ctx.recorded.push(
        pass,
        RenderPass {
            name: pass.to_string(),
            color_attachments: vec![attachment(destination, LoadOp::Clear([0.0; 4]))],
            depth_attachment: None,
            viewports: vec![],
            draws: vec![fullscreen_draw(
                pipeline,
                vec![
                    binding(1, BindingResource::Buffer(uniform)),
                    binding(2, BindingResource::Texture(source)),
                ],
            )],
        },
    );
    Ok(())
}

//! The geometry pass (every object into the G-buffer targets and depth) and the shader-mask pass
//! (every object's lighting model into its mask channel, at the geometry's depth). One draw per
//! object in each; the mask pass reuses the uniform buffers the geometry pass made (left in the
//! frame context) and the G-buffer shader.

use super::super::builders::{
    attachment, binding, filterable_texture_layout, shader, uniform_layout,
};
use super::super::{uniforms, RenderError};
use super::FrameContext;
use crate::backend::*;
use crate::mesh::Vertex;
use crate::plan::{MaskChannel, PassId, TargetId};
use crate::scene::Object;
use crate::shaders;

/// The vertex layout of [`Vertex`]: position, normal, uv, tangent.
fn vertex_layout() -> VertexBufferLayout {
    VertexBufferLayout {
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
    }
}

/// The G-buffer shader, which the geometry and mask passes share.
fn gbuffer_shader(ctx: &mut FrameContext<'_>) -> Result<Handle<Shader>, RenderError> {
    shader(ctx.scope, ctx.backend, shaders::GBUFFER)
}

/// A pass's pipeline, and where an object of the scene mirrors ([`Transform::mirrors`]), its
/// twin that culls front faces instead: a mirrored object's triangles are wound the other way
/// round on screen, so culling its back faces would show its inside.
///
/// [`Transform::mirrors`]: crate::scene::Transform::mirrors
struct CullingPipelines {
    unmirrored: Handle<Pipeline>,
    mirrored: Option<Handle<Pipeline>>,
}

impl CullingPipelines {
    /// The pipeline that draws `object`.
    fn of(&self, object: &Object) -> Handle<Pipeline> {
        match self.mirrored {
            Some(mirrored) if object.transform.mirrors() => mirrored,
            _ => self.unmirrored,
        }
    }
}

/// The pipelines of `desc` (which culls back faces) for the scene's objects: the mirrored twin
/// only where an object needs it.
fn culling_pipelines(
    ctx: &mut FrameContext<'_>,
    desc: PipelineDesc,
) -> Result<CullingPipelines, RenderError> {
    let unmirrored = ctx.scope.pipeline(ctx.backend, &desc)?;
    let mirrored = if ctx.scene.objects.iter().any(|o| o.transform.mirrors()) {
        let desc = PipelineDesc {
            label: format!("{} (mirrored objects)", desc.label),
            cull: CullMode::Front,
            ..desc
        };
        Some(ctx.scope.pipeline(ctx.backend, &desc)?)
    } else {
        None
    };
    Ok(CullingPipelines {
        unmirrored,
        mirrored,
    })
}

/// Every object into the G-buffer targets and depth; leaves each object's uniform buffer in
/// `ctx` for the mask pass.
pub(in crate::renderer) fn record_geometry(ctx: &mut FrameContext<'_>) -> Result<(), RenderError> {
    let gbuffer_shader = gbuffer_shader(ctx)?;
    let mut bindings = vec![uniform_layout()];
    bindings.extend((1..=6).map(filterable_texture_layout));
    bindings.push(BindingLayout {
        binding: 7,
        kind: BindingKind::Sampler(SamplerBindingKind::Filtering),
    });
    let pipelines = culling_pipelines(
        ctx,
        PipelineDesc {
            label: "geometry".to_owned(),
            shader: gbuffer_shader,
            vertex_entry: "vs_main".to_owned(),
            fragment_entry: Some("fs_gbuffer".to_owned()),
            vertex_buffers: vec![vertex_layout()],
            bindings,
            color_targets: TargetId::GBUFFER
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
    let (scene, frame, plan) = (ctx.scene, ctx.frame, ctx.plan);
    let mut draws = Vec::new();
    let mut object_uniforms = Vec::new();
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
            frame.view_projection,
            channel,
            ctx.variations,
            &scene.quality.gbuffer,
        );
        let uniform = ctx.scope.buffer(
            ctx.backend,
            &format!("{} uniforms", object.name),
            BufferUsage::Uniform,
            bytemuck::cast_slice(&data),
        )?;
        object_uniforms.push(uniform);
        let m = &object.material;
        let map = |index: Option<usize>| index.map_or(frame.white, |i| frame.textures[i]);
        let mesh = frame.mesh(object);
        draws.push(Draw {
            pipeline: pipelines.of(object),
            bindings: vec![
                binding(0, BindingResource::Buffer(uniform)),
                binding(1, BindingResource::Texture(map(m.base_color_map))),
                binding(2, BindingResource::Texture(map(m.normal_map))),
                binding(3, BindingResource::Texture(map(m.roughness_map))),
                binding(4, BindingResource::Texture(map(m.metallic_map))),
                binding(5, BindingResource::Texture(map(m.clearcoat_map))),
                binding(6, BindingResource::Texture(map(m.specular_map))),
                binding(7, BindingResource::Sampler(frame.material_sampler)),
            ],
            vertex_buffers: vec![mesh.vertices],
            index_buffer: Some((mesh.indices, IndexFormat::U32)),
            count: mesh.count,
        });
    }
    ctx.object_uniforms = object_uniforms;
    ctx.recorded.push(
        PassId::Geometry,
        RenderPass {
            name: PassId::Geometry.to_string(),
            color_attachments: TargetId::GBUFFER
                .into_iter()
                .map(|id| attachment(frame.target(id), LoadOp::Clear([0.0; 4])))
                .collect(),
            depth_attachment: Some(DepthAttachment {
                texture: frame.target(TargetId::Depth),
                subresource: Subresource::default(),
                load: LoadOp::Clear(1.0),
            }),
            viewports: vec![],
            draws,
        },
    );
    Ok(())
}

/// Every object's one-hot lighting-model channel into the mask targets, at the geometry pass's
/// depth, with the uniform buffers that pass made.
pub(in crate::renderer) fn record_mask(ctx: &mut FrameContext<'_>) -> Result<(), RenderError> {
    let gbuffer_shader = gbuffer_shader(ctx)?;
    let frame = ctx.frame;
    let pipelines = culling_pipelines(
        ctx,
        PipelineDesc {
            label: "mask".to_owned(),
            shader: gbuffer_shader,
            vertex_entry: "vs_main".to_owned(),
            fragment_entry: Some(
                if frame.mask_targets.len() > 1 {
                    "fs_mask_2"
                } else {
                    "fs_mask_1"
                }
                .to_owned(),
            ),
            vertex_buffers: vec![vertex_layout()],
            bindings: vec![uniform_layout()],
            color_targets: frame
                .mask_targets
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
    if ctx.object_uniforms.len() != ctx.scene.objects.len() {
        return Err(RenderError::InvalidScene {
            scene: ctx.scene.name.clone(),
            problem: "the plan has a mask pass before its geometry pass".to_owned(),
        });
    }
    let draws = ctx
        .scene
        .objects
        .iter()
        .zip(&ctx.object_uniforms)
        .map(|(object, &uniform)| {
            let mesh = frame.mesh(object);
            Draw {
                pipeline: pipelines.of(object),
                bindings: vec![binding(0, BindingResource::Buffer(uniform))],
                vertex_buffers: vec![mesh.vertices],
                index_buffer: Some((mesh.indices, IndexFormat::U32)),
                count: mesh.count,
            }
        })
        .collect();
    ctx.recorded.push(
        PassId::ShaderMask,
        RenderPass {
            name: PassId::ShaderMask.to_string(),
            color_attachments: frame
                .mask_targets
                .iter()
                .map(|&t| attachment(t, LoadOp::Clear([0.0; 4])))
                .collect(),
            depth_attachment: Some(DepthAttachment {
                texture: frame.target(TargetId::Depth),
                subresource: Subresource::default(),
                load: LoadOp::Load,
            }),
            viewports: vec![],
            draws,
        },
    );
    Ok(())
}

//! The geometry pass (every object into the G-buffer targets and depth) and the shader-mask pass
//! (every object's lighting model into its mask channel, at the geometry's depth). One draw per
//! object in each; the two share the object's uniform buffer and the G-buffer shader.

use super::super::builders::{
    attachment, binding, filterable_texture_layout, shader, uniform_layout,
};
use super::super::resources::FrameResources;
use super::super::{uniforms, Faults, RenderError};
use crate::backend::*;
use crate::mesh::Vertex;
use crate::plan::{MaskChannel, PassId, RenderPlan, TargetId};
use crate::scene::Scene;
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

/// The geometry and mask pipelines.
fn pipelines(
    backend: &mut dyn Backend,
    scope: &mut ResourceScope,
    mask_targets: usize,
) -> Result<(Handle<Pipeline>, Handle<Pipeline>), RenderError> {
    let gbuffer_shader = shader(scope, backend, shaders::GBUFFER)?;
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
            vertex_buffers: vec![vertex_layout()],
            bindings: gbuffer_bindings,
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
    let mask_pipeline = scope.pipeline(
        backend,
        &PipelineDesc {
            label: "mask".to_owned(),
            shader: gbuffer_shader,
            vertex_entry: "vs_main".to_owned(),
            fragment_entry: Some(
                if mask_targets > 1 {
                    "fs_mask_2"
                } else {
                    "fs_mask_1"
                }
                .to_owned(),
            ),
            vertex_buffers: vec![vertex_layout()],
            bindings: vec![uniform_layout()],
            color_targets: (0..mask_targets)
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
    Ok((geometry_pipeline, mask_pipeline))
}

/// Records the geometry pass, then the mask pass, into `passes`.
pub(in crate::renderer) fn record(
    backend: &mut dyn Backend,
    scope: &mut ResourceScope,
    scene: &Scene,
    plan: &RenderPlan,
    frame: &FrameResources,
    faults: &Faults,
    passes: &mut super::Recorded,
) -> Result<(), RenderError> {
    let (geometry_pipeline, mask_pipeline) = pipelines(backend, scope, frame.mask_targets.len())?;
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
            frame.view_projection,
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
        let map = |index: Option<usize>| index.map_or(frame.white, |i| frame.textures[i]);
        let mesh = frame.mesh(object);
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
                binding(7, BindingResource::Sampler(frame.material_sampler)),
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
    passes.push(
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
            draws: geometry_draws,
        },
    );
    passes.push(
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
            draws: mask_draws,
        },
    );
    Ok(())
}

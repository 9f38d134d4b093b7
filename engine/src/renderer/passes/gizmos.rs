//! The gizmos pass: world axes at the origin, a line towards each directional light and a small
//! three-axis marker at each point light, drawn as lines over the final image without depth
//! testing. Off unless the scene's quality settings ask for it (goldens stay free of overlays).

use glam::{DVec3, Mat4};

use crate::backend::*;
use crate::scene::{Light, Scene};
use crate::shaders;

/// Line vertices (camera-relative position, color) for a scene's gizmos.
pub fn lines(scene: &Scene) -> Vec<[f32; 6]> {
    let origin = scene.camera.position;
    // Scale markers with the distance to what the camera looks at, so they stay visible.
    let size = (scene.camera.target - scene.camera.position).length() * 0.15;
    let mut vertices = Vec::new();
    let mut line = |a: DVec3, b: DVec3, color: [f32; 3]| {
        for p in [a, b] {
            let r = (p - origin).as_vec3();
            vertices.push([r.x, r.y, r.z, color[0], color[1], color[2]]);
        }
    };
    let axes = [
        (DVec3::X, [1.0, 0.1, 0.1]),
        (DVec3::Y, [0.1, 1.0, 0.1]),
        (DVec3::Z, [0.2, 0.4, 1.0]),
    ];
    for (axis, color) in axes {
        line(DVec3::ZERO, axis * size, color);
    }
    for light in &scene.lights {
        match light {
            Light::Directional { direction, .. } => {
                line(
                    DVec3::ZERO,
                    direction.normalize() * size * 2.0,
                    [1.0, 0.9, 0.2],
                );
            }
            Light::Point { position, .. } => {
                for (axis, _) in axes {
                    let half = axis * size * 0.15;
                    line(*position - half, *position + half, [1.0, 0.9, 0.2]);
                }
            }
        }
    }
    vertices
}

/// Records the gizmos pass over the final image (loaded, not cleared).
pub(in crate::renderer) fn record(
    ctx: &mut super::FrameContext<'_>,
) -> Result<(), super::super::RenderError> {
    let pass = gizmos_pass(
        ctx.backend,
        ctx.scope,
        ctx.scene,
        ctx.frame.view_projection,
        ctx.frame.target(crate::plan::TargetId::Final),
    )?;
    ctx.recorded.push(crate::plan::PassId::Gizmos, pass);
    Ok(())
}

/// The gizmos pass onto `target`.
fn gizmos_pass(
    backend: &mut dyn Backend,
    scope: &mut ResourceScope,
    scene: &Scene,
    view_projection: Mat4,
    target: Handle<Texture>,
) -> Result<RenderPass> {
    let vertices = lines(scene);
    let shader = scope.shader(
        backend,
        &ShaderDesc {
            name: shaders::GIZMO.name.to_owned(),
            wgsl: shaders::GIZMO.wgsl.to_owned(),
        },
    )?;
    let pipeline = scope.pipeline(
        backend,
        &PipelineDesc {
            label: "gizmos".to_owned(),
            shader,
            vertex_entry: "vs_gizmo".to_owned(),
            fragment_entry: Some("fs_gizmo".to_owned()),
            vertex_buffers: vec![VertexBufferLayout {
                stride: 24,
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
                ],
            }],
            bindings: vec![BindingLayout {
                binding: 0,
                kind: BindingKind::UniformBuffer,
            }],
            color_targets: vec![ColorTarget {
                format: TextureFormat::Rgba8UnormSrgb,
                blend: None,
            }],
            depth: None,
            topology: Topology::LineList,
            cull: CullMode::None,
            geometry: None,
            constants: vec![],
        },
    )?;
    let uniform = scope.buffer(
        backend,
        "gizmo uniforms",
        BufferUsage::Uniform,
        bytemuck::cast_slice(&view_projection.to_cols_array()),
    )?;
    let buffer = scope.buffer(
        backend,
        "gizmo lines",
        BufferUsage::Vertex,
        bytemuck::cast_slice(&vertices),
    )?;
    Ok(RenderPass {
        name: crate::plan::PassId::Gizmos.to_string(),
        color_attachments: vec![ColorAttachment {
            texture: target,
            subresource: Subresource::default(),
            load: LoadOp::Load,
        }],
        depth_attachment: None,
        viewports: vec![],
        draws: vec![Draw {
            pipeline,
            bindings: vec![Binding {
                binding: 0,
                resource: BindingResource::Buffer(uniform),
            }],
            vertex_buffers: vec![buffer],
            index_buffer: None,
            count: vertices.len() as u32,
        }],
    })
}

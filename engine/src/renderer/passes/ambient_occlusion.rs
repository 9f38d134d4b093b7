//! The screen-space ambient occlusion pass (`shaders/ssao.wgsl`): one full-screen draw from the
//! camera's depth and the G-buffer's normals into the occlusion target, with the kernel of
//! [`crate::renderer::ambient_occlusion`] in its uniforms.

use super::super::ambient_occlusion::kernel;
use super::super::builders::{attachment, binding, fullscreen_draw, fullscreen_pipeline, shader};
use super::super::RenderError;
use super::FrameContext;
use crate::backend::*;
use crate::plan::{GBufferTarget, PassId, TargetId};
use crate::scene::{NormalEncoding, SsaoSettings};
use crate::shader_bindings::ModuleBindings;
use crate::shaders;

/// Kernel points the uniform array holds.
const KERNEL_CAPACITY: usize = SsaoSettings::MAX_SAMPLES as usize;

/// Records the occlusion pass (the plan has one only where the scene asks for it).
pub(in crate::renderer) fn record(ctx: &mut FrameContext<'_>) -> Result<(), RenderError> {
    let (scene, frame) = (ctx.scene, ctx.frame);
    let Some(settings) = scene.quality.ssao else {
        return Err(RenderError::InvalidScene {
            scene: scene.name.clone(),
            problem: "the plan has an occlusion pass but the scene no [quality.ssao]".to_owned(),
        });
    };
    let (backend, scope) = (&mut *ctx.backend, &mut *ctx.scope);
    let bindings = ModuleBindings::of(shaders::SSAO)?;
    let module = shader(scope, backend, shaders::SSAO)?;
    let normal_mode = match scene.quality.gbuffer.normal {
        NormalEncoding::Fp16 => 0.0,
        NormalEncoding::Octahedral => 1.0,
    };
    let pipeline = scope.pipeline(
        backend,
        &PipelineDesc {
            constants: vec![
                ("SAMPLES".to_owned(), f64::from(settings.samples)),
                ("NORMAL_MODE".to_owned(), normal_mode),
            ],
            ..fullscreen_pipeline(
                "ambient occlusion",
                module,
                "fs_ambient_occlusion",
                bindings.layouts(),
                TextureFormat::Rgba16Float,
                None,
            )
        },
    )?;
    let view_projection = frame.camera.view_projection();
    let forward = (scene.camera.target - scene.camera.position).normalize();
    let mut data: Vec<f32> = Vec::with_capacity(36 + 4 * KERNEL_CAPACITY);
    data.extend(view_projection.as_mat4().to_cols_array());
    data.extend(view_projection.inverse().as_mat4().to_cols_array());
    data.extend(forward.as_vec3().to_array());
    data.push(settings.radius);
    let mut points = kernel(settings.samples);
    points.resize(KERNEL_CAPACITY, glam::DVec3::ZERO);
    for point in points {
        data.extend(point.as_vec3().to_array());
        data.push(0.0);
    }
    let uniform = scope.buffer(
        backend,
        "ambient occlusion uniforms",
        BufferUsage::Uniform,
        bytemuck::cast_slice(&data),
    )?;
    let texture = |target| BindingResource::Texture(frame.target(target));
    let draw_bindings = vec![
        binding(bindings.slot("u")?, BindingResource::Buffer(uniform)),
        binding(bindings.slot("scene_depth")?, texture(TargetId::Depth)),
        binding(
            bindings.slot("gbuffer_normal")?,
            texture(TargetId::GBuffer(GBufferTarget::Normal)),
        ),
    ];
    ctx.recorded.push(
        PassId::AmbientOcclusion,
        RenderPass {
            name: PassId::AmbientOcclusion.to_string(),
            color_attachments: vec![attachment(
                frame.target(TargetId::AmbientOcclusion),
                LoadOp::Clear([1.0; 4]),
            )],
            depth_attachment: None,
            viewports: vec![],
            draws: vec![fullscreen_draw(pipeline, draw_bindings)],
        },
    );
    Ok(())
}

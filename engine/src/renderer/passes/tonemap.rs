//! The tone-mapping pass: the light buffer through the scene's operator into the 8-bit sRGB
//! final image.

use super::super::builders::{
    attachment, binding, fullscreen_draw, fullscreen_pipeline, shader, texture_layout,
    uniform_layout,
};
use super::super::RenderError;
use super::FrameContext;
use crate::backend::*;
use crate::plan::{PassId, TargetId};
use crate::scene::ToneMap;
use crate::shaders;

/// Records the tone-mapping pass: the exposed light buffer into the sRGB final image.
pub(in crate::renderer) fn record(ctx: &mut FrameContext<'_>) -> Result<(), RenderError> {
    let (scene, frame, variations) = (ctx.scene, ctx.frame, ctx.variations);
    let (backend, scope) = (&mut *ctx.backend, &mut *ctx.scope);
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
    let input_scale = variations.tonemap_input_scale.unwrap_or(1.0);
    let tonemap_uniform = scope.buffer(
        backend,
        "tonemap uniforms",
        BufferUsage::Uniform,
        bytemuck::cast_slice(&[operator, 0, 0, 0, input_scale.to_bits(), 0, 0, 0]),
    )?;
    ctx.recorded.push(
        PassId::ToneMap,
        RenderPass {
            name: PassId::ToneMap.to_string(),
            color_attachments: vec![attachment(
                frame.target(TargetId::Final),
                LoadOp::Clear([0.0; 4]),
            )],
            depth_attachment: None,
            viewports: vec![],
            draws: vec![fullscreen_draw(
                tonemap_pipeline,
                vec![
                    binding(0, BindingResource::Buffer(tonemap_uniform)),
                    binding(1, BindingResource::Texture(frame.target(TargetId::Light))),
                ],
            )],
        },
    );
    Ok(())
}

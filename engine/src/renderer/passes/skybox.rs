//! The skybox pass: the environment image behind the objects, written into the light buffer
//! where the shader masks say no object covers the pixel.

use super::super::builders::{
    attachment, binding, filterable_texture_layout, fullscreen_draw, fullscreen_pipeline, shader,
    texture_layout, uniform_layout,
};
use super::super::{uniforms, RenderError};
use super::FrameContext;
use crate::backend::*;
use crate::plan::{PassId, TargetId};
use crate::shaders;

/// Records the skybox pass (the plan has one only with an environment); it clears the light
/// buffer, which the lighting passes then add to.
pub(in crate::renderer) fn record(ctx: &mut FrameContext<'_>) -> Result<(), RenderError> {
    let (scene, frame) = (ctx.scene, ctx.frame);
    let (backend, scope) = (&mut *ctx.backend, &mut *ctx.scope);
    let Some(environment) = &scene.environment else {
        return Err(RenderError::InvalidScene {
            scene: scene.name.clone(),
            problem: "the plan has a skybox but the scene no environment".to_owned(),
        });
    };
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
    let texels = crate::image::fp16_bits(image.texels.iter().flatten().copied());
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
    let data = uniforms::skybox_uniforms(scene, &frame.camera);
    let uniform = scope.buffer(
        backend,
        "skybox uniforms",
        BufferUsage::Uniform,
        bytemuck::cast_slice(&data),
    )?;
    let mask = |index: usize| {
        frame
            .mask_targets
            .get(index)
            .copied()
            .unwrap_or(frame.black)
    };
    ctx.light_written = true;
    ctx.recorded.push(
        PassId::Skybox,
        RenderPass {
            name: PassId::Skybox.to_string(),
            color_attachments: vec![attachment(
                frame.target(TargetId::Light),
                LoadOp::Clear([0.0; 4]),
            )],
            depth_attachment: None,
            viewports: vec![],
            draws: vec![fullscreen_draw(
                pipeline,
                vec![
                    binding(0, BindingResource::Buffer(uniform)),
                    // No objects, no mask target: the black texel says nothing is covered.
                    binding(1, BindingResource::Texture(mask(0))),
                    binding(2, BindingResource::Texture(mask(1))),
                    binding(3, BindingResource::Texture(texture)),
                    binding(4, BindingResource::Sampler(sampler)),
                ],
            )],
        },
    );
    Ok(())
}

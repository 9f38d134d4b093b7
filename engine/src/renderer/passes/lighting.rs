//! The lighting passes: per lighting model, its draws of `lighting.wgsl` (one per batch of
//! lights, each a pipeline specialised to the draw's variant) add into the light buffer, only
//! over the model's pixels: a routing draw marks them in a depth target that the shading draws
//! test for equality. Also the debug shadow-term outputs, through the same shader's lookup.

use std::collections::HashMap;
use std::sync::Arc;

use super::super::builders::{attachment, binding, fullscreen_draw, fullscreen_pipeline, shader};
use super::super::ibl::{self, IblTextures};
use super::super::resources::FrameResources;
use super::super::shadows::{self, ShadowView};
use super::super::{light_uniforms, uniforms, RenderError, Variations};
use super::FrameContext;
use crate::backend::*;
use crate::plan::{LightingDraw, LightingPass, LightingVariant, MaskChannel, PassId, TargetId};
use crate::scene::{LightingModel, Scene};
use crate::shader_bindings::ModuleBindings;
use crate::shaders;

/// The soft shadow filters' jitter: rotation offsets per pixel of a tile, one layer per pair
/// of samples.
fn upload_jitter(
    backend: &mut dyn Backend,
    scope: &mut ResourceScope,
) -> Result<Handle<Texture>, RenderError> {
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
    Ok(jitter)
}

/// A shadowed light's bindings: its map, its VSM moments (or the placeholder), its shadow
/// uniforms and the comparison sampler its filter needs.
#[derive(Clone, Copy)]
struct ShadowBindings {
    map: Handle<Texture>,
    moments: Handle<Texture>,
    uniform: Handle<Buffer>,
    sampler: Handle<Sampler>,
}

/// The resources of one lighting draw ([`crate::plan::LightingDraw`]): its lights' uniforms, and the
/// maps of its shadowed light (placeholders when it has none).
struct LightDraw {
    lights: Vec<uniforms::LightData>,
    shadow: ShadowBindings,
}

/// What every lighting draw of the frame binds, and the pipelines made so far.
pub(in crate::renderer) struct LightingResources<'a> {
    frame: &'a FrameResources,
    shader: Handle<Shader>,
    /// `lighting.wgsl`'s bindings, from naga's reflection of it (the layout of every lighting
    /// pipeline, and the slots the bind groups fill by name). Parameters are in uniform
    /// buffers; nothing in them steers a branch or loop (see the top of
    /// shaders/lighting/inputs.wgsl), so lavapipe has nothing to specialise per draw.
    bindings: Arc<ModuleBindings>,
    ibl: IblTextures,
    jitter: Handle<Texture>,
    lights: Vec<uniforms::LightData>,
    moments_sampler: Handle<Sampler>,
    /// What a draw without a shadowed light binds.
    no_shadow: ShadowBindings,
    /// Each shadowed light's bindings, by scene light index.
    shadowed: HashMap<usize, ShadowBindings>,
    /// One pipeline per (entry point, variant, routed or not), created on first use.
    pipelines: HashMap<String, Handle<Pipeline>>,
    /// The routing pipeline, made by the first lighting pass.
    route: Option<Handle<Pipeline>>,
}

impl<'a> LightingResources<'a> {
    fn create(
        backend: &mut dyn Backend,
        scope: &mut ResourceScope,
        scene: &Scene,
        frame: &'a FrameResources,
        views: &[ShadowView],
        variations: &Variations,
        ibl: IblTextures,
    ) -> Result<Self, RenderError> {
        let lighting_shader = shader(scope, backend, shaders::LIGHTING)?;
        let jitter = upload_jitter(backend, scope)?;
        let mut lights = light_uniforms(scene);
        if let Some(scale) = variations.light_radiance_scale {
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
        let mut shadowed = HashMap::new();
        for view in views {
            let uniform = scope.buffer(
                backend,
                &format!("shadow uniforms light {}", view.light),
                BufferUsage::Uniform,
                bytemuck::cast_slice(&shadows::shadow_uniforms(Some(view))),
            )?;
            let sampler = if view.settings.filter.linear_comparison() {
                linear_shadow_sampler
            } else {
                shadow_sampler
            };
            shadowed.insert(
                view.light,
                ShadowBindings {
                    map: frame.target(TargetId::Shadow { light: view.light }),
                    moments: frame
                        .optional_target(TargetId::ShadowMoments { light: view.light })
                        .unwrap_or(no_moments),
                    uniform,
                    sampler,
                },
            );
        }
        Ok(Self {
            frame,
            shader: lighting_shader,
            bindings: ModuleBindings::of(shaders::LIGHTING)?,
            ibl,
            jitter,
            lights,
            moments_sampler,
            no_shadow: ShadowBindings {
                map: no_shadow_map,
                moments: no_moments,
                uniform: no_shadow_uniform,
                sampler: shadow_sampler,
            },
            shadowed,
            pipelines: HashMap::new(),
            route: None,
        })
    }

    /// The resources of one of the plan's lighting draws.
    fn light_draw(&self, draw: &LightingDraw) -> LightDraw {
        let shadow = draw
            .shadowed
            .and_then(|light| self.shadowed.get(&light).copied())
            .unwrap_or(self.no_shadow);
        LightDraw {
            lights: draw.lights.iter().map(|&i| self.lights[i]).collect(),
            shadow,
        }
    }

    /// Bind group of a lighting-shader draw: each resource at the slot of the `lighting.wgsl`
    /// variable named beside it.
    fn bind_group(
        &self,
        uniform: Handle<Buffer>,
        mask: Handle<Texture>,
        draw: &LightDraw,
    ) -> Result<Vec<Binding>, RenderError> {
        let texture = |target| BindingResource::Texture(self.frame.target(target));
        let [position, normal, tangent, albedo, material] = TargetId::GBUFFER;
        let resources = [
            ("u", BindingResource::Buffer(uniform)),
            ("gbuffer_position", texture(position)),
            ("gbuffer_normal", texture(normal)),
            ("gbuffer_tangent", texture(tangent)),
            ("gbuffer_albedo", texture(albedo)),
            ("gbuffer_material", texture(material)),
            ("shader_mask", BindingResource::Texture(mask)),
            ("shadow_map", BindingResource::Texture(draw.shadow.map)),
            (
                "shadow_sampler",
                BindingResource::Sampler(draw.shadow.sampler),
            ),
            ("shadow", BindingResource::Buffer(draw.shadow.uniform)),
            ("shadow_jitter", BindingResource::Texture(self.jitter)),
            (
                "shadow_moments",
                BindingResource::Texture(draw.shadow.moments),
            ),
            (
                "moments_sampler",
                BindingResource::Sampler(self.moments_sampler),
            ),
            (
                "ibl_irradiance",
                BindingResource::Texture(self.ibl.irradiance),
            ),
            ("ibl_specular", BindingResource::Texture(self.ibl.specular)),
            ("ibl_dfg", BindingResource::Texture(self.ibl.dfg)),
            ("ibl_radiance", BindingResource::Texture(self.ibl.radiance)),
            ("ibl_sampler", BindingResource::Sampler(self.ibl.sampler)),
            ("scene_depth", texture(TargetId::Depth)),
            // Read only by draws with AMBIENT_OCCLUSION, in scenes that have the target.
            (
                "ambient_occlusion",
                BindingResource::Texture(
                    self.frame
                        .optional_target(TargetId::AmbientOcclusion)
                        .unwrap_or(self.frame.white),
                ),
            ),
        ];
        resources
            .into_iter()
            .map(|(name, resource)| Ok(binding(self.bindings.slot(name)?, resource)))
            .collect()
    }

    /// The pipeline of `entry` specialised to `variant`; `routed` ones add into the light
    /// buffer where the routing target's depth is equal (the model's pixels).
    fn pipeline(
        &mut self,
        scope: &mut ResourceScope,
        backend: &mut dyn Backend,
        entry: &str,
        variant: &LightingVariant,
        routed: bool,
    ) -> Result<Handle<Pipeline>, RenderError> {
        let key = format!("{entry} {variant:?} {routed}");
        if let Some(&pipeline) = self.pipelines.get(&key) {
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
                self.shader,
                entry,
                self.bindings.layouts(),
                TextureFormat::Rgba16Float,
                blend,
            )
        };
        let pipeline = scope.pipeline(backend, &desc)?;
        self.pipelines.insert(key, pipeline);
        Ok(pipeline)
    }

    /// Routing: marks the pass's model's pixels at depth 0 in the cleared routing target; it
    /// adds zero to the light buffer (a pass's pipelines must all match its attachments).
    fn route_pipeline(
        &self,
        scope: &mut ResourceScope,
        backend: &mut dyn Backend,
    ) -> Result<Handle<Pipeline>, RenderError> {
        Ok(scope.pipeline(
            backend,
            &PipelineDesc {
                depth: Some(DepthState {
                    format: TextureFormat::Depth32Float,
                    write: true,
                    compare: CompareFunction::Always,
                }),
                ..fullscreen_pipeline(
                    "lighting route",
                    self.shader,
                    "fs_route",
                    self.bindings.layouts_of(&["u", "shader_mask"])?,
                    TextureFormat::Rgba16Float,
                    Some(BlendState::ADDITIVE),
                )
            },
        )?)
    }
}

/// The frame's lighting resources, made by its first lighting pass or shadow term.
fn resources<'c, 'a>(
    ctx: &'c mut FrameContext<'a>,
) -> Result<&'c mut LightingResources<'a>, RenderError> {
    if ctx.lighting.is_none() {
        // The radiance chain only where a draw of the plan samples it.
        let sampled = ctx
            .plan
            .lighting
            .iter()
            .flat_map(|pass| &pass.draws)
            .any(|draw| draw.variant.samples_ibl());
        let ibl = ibl::upload(ctx.backend, ctx.scope, ctx.ibl_maps, sampled)?;
        let made = LightingResources::create(
            ctx.backend,
            ctx.scope,
            ctx.scene,
            ctx.frame,
            &ctx.views,
            ctx.variations,
            ibl,
        )?;
        ctx.lighting = Some(made);
    }
    Ok(ctx.lighting.as_mut().expect("made above"))
}

/// Records lighting model `model`'s pass: its routing draw, then one draw per batch of lights,
/// added into the light buffer (cleared first when no pass before it wrote it).
pub(in crate::renderer) fn record_model(
    ctx: &mut FrameContext<'_>,
    model: LightingModel,
) -> Result<(), RenderError> {
    let (scene, plan, frame) = (ctx.scene, ctx.plan, ctx.frame);
    let Some((channel, pass)) = plan
        .mask_channels
        .iter()
        .zip(&plan.lighting)
        .find(|(channel, _)| channel.model == model)
    else {
        return Err(RenderError::InvalidScene {
            scene: scene.name.clone(),
            problem: format!("the plan has a {model} lighting pass but no mask channel for it"),
        });
    };
    resources(ctx)?;
    let FrameContext {
        backend,
        scope,
        lighting,
        ..
    } = ctx;
    let resources = lighting.as_mut().expect("made above");
    let route = match resources.route {
        Some(route) => route,
        None => {
            let route = resources.route_pipeline(scope, *backend)?;
            resources.route = Some(route);
            route
        }
    };
    let draws = model_draws(*backend, scope, scene, resources, *channel, pass, route)?;
    let load = if ctx.light_written {
        LoadOp::Load
    } else {
        LoadOp::Clear([0.0; 4])
    };
    ctx.light_written = true;
    let render_pass = model_pass(frame, *channel, pass, load, draws);
    ctx.recorded.push(PassId::Lighting(model), render_pass);
    Ok(())
}

/// Clears the light buffer where no pass writes it (no objects and no environment).
pub(in crate::renderer) fn record_clear(ctx: &mut FrameContext<'_>) -> Result<(), RenderError> {
    ctx.light_written = true;
    ctx.recorded.push(
        PassId::ClearLight,
        RenderPass {
            name: PassId::ClearLight.to_string(),
            color_attachments: vec![attachment(
                ctx.frame.target(TargetId::Light),
                LoadOp::Clear([0.0; 4]),
            )],
            depth_attachment: None,
            viewports: vec![],
            draws: vec![],
        },
    );
    Ok(())
}

/// The draws of one model's lighting pass: the routing draw, then one per batch of lights.
fn model_draws(
    backend: &mut dyn Backend,
    scope: &mut ResourceScope,
    scene: &Scene,
    resources: &mut LightingResources<'_>,
    channel: MaskChannel,
    pass: &LightingPass,
    route_pipeline: Handle<Pipeline>,
) -> Result<Vec<Draw>, RenderError> {
    let model = channel.model;
    let mask = resources.frame.mask_targets[channel.target];
    let mut draws = Vec::new();
    for (index, draw) in pass.draws.iter().enumerate() {
        let light_draw = resources.light_draw(draw);
        let data = uniforms::lighting_uniforms(
            scene,
            &resources.frame.camera,
            channel,
            &light_draw.lights,
            draw.first,
            resources.ibl.max_lod,
        );
        let uniform = scope.buffer(
            backend,
            &format!("lighting {model} batch {index}"),
            BufferUsage::Uniform,
            bytemuck::cast_slice(&data),
        )?;
        if index == 0 {
            draws.push(fullscreen_draw(
                route_pipeline,
                vec![
                    binding(
                        resources.bindings.slot("u")?,
                        BindingResource::Buffer(uniform),
                    ),
                    binding(
                        resources.bindings.slot("shader_mask")?,
                        BindingResource::Texture(mask),
                    ),
                ],
            ));
        }
        let pipeline =
            resources.pipeline(scope, backend, model.entry_point(), &draw.variant, true)?;
        let bindings = resources.bind_group(uniform, mask, &light_draw)?;
        draws.push(fullscreen_draw(pipeline, bindings));
    }
    Ok(draws)
}

/// One model's lighting pass over its `draws`: into the light buffer, routed through the
/// cleared routing depth target, rasterising only the model's rectangle.
fn model_pass(
    frame: &FrameResources,
    channel: MaskChannel,
    pass: &LightingPass,
    load: LoadOp<[f32; 4]>,
    draws: Vec<Draw>,
) -> RenderPass {
    let model = channel.model;
    RenderPass {
        name: PassId::Lighting(model).to_string(),
        color_attachments: vec![attachment(frame.target(TargetId::Light), load)],
        depth_attachment: Some(DepthAttachment {
            texture: frame.target(TargetId::Route),
            subresource: Subresource::default(),
            load: LoadOp::Clear(1.0),
        }),
        // Only the pixels around the model's objects are rasterized (frag.xy stays in image
        // coordinates, so the shaders read the right texels).
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
    }
}

/// Debug: light `light`'s shadow term, through the lighting shader's own lookup.
pub(in crate::renderer) fn record_shadow_term(
    ctx: &mut FrameContext<'_>,
    light: usize,
) -> Result<(), RenderError> {
    let (scene, plan) = (ctx.scene, ctx.plan);
    let term = TargetId::ShadowTerm { light };
    let pass = PassId::ShadowTerm { light };
    let mut draws = plan.lighting.iter().flat_map(|pass| &pass.draws);
    let Some(draw) = draws.find(|d| d.shadowed == Some(light)) else {
        // No lighting draw looks this light's shadow up: nothing to show.
        return Ok(());
    };
    resources(ctx)?;
    let FrameContext {
        backend,
        scope,
        lighting,
        recorded,
        ..
    } = ctx;
    let resources = lighting.as_mut().expect("made above");
    let pipeline = resources.pipeline(scope, *backend, "fs_shadow_term", &draw.variant, false)?;
    let light_draw = resources.light_draw(draw);
    let channel = plan.mask_channels[0];
    let data = uniforms::lighting_uniforms(
        scene,
        &resources.frame.camera,
        channel,
        &light_draw.lights,
        false,
        0.0,
    );
    let uniform = scope.buffer(
        *backend,
        &format!("{pass} uniforms"),
        BufferUsage::Uniform,
        bytemuck::cast_slice(&data),
    )?;
    let bindings = resources.bind_group(uniform, resources.frame.mask_targets[0], &light_draw)?;
    recorded.push(
        pass,
        RenderPass {
            name: pass.to_string(),
            color_attachments: vec![attachment(
                resources.frame.target(term),
                LoadOp::Clear([0.0; 4]),
            )],
            depth_attachment: None,
            viewports: vec![],
            draws: vec![fullscreen_draw(pipeline, bindings)],
        },
    );
    Ok(())
}

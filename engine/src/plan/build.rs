//! [`RenderPlan::new`], stage by stage: the screen-sized targets, each shadowed light's maps and
//! passes, geometry and shader mask, the ambient occlusion (with `[quality.ssao]`), the
//! environment's passes, one lighting pass per model (or the light buffer's clear when there is
//! neither a model nor an environment), the shadow-term debug outputs, then tone mapping and
//! gizmos.

use crate::backend::TextureFormat;
use crate::scene::{Light, LightingModel, Scene, ShadowFilter, ShadowSettings, SsaoSettings};

use super::lighting::{lighting_passes, LightingPass};
use super::{
    BlurAxis, GBufferTarget, MaskChannel, PassId, PassSpec, RenderPlan, TargetId, TargetSpec,
};

impl RenderPlan {
    /// Builds the plan for a scene as drawn. Only [`crate::renderer::PreparedFrame`] calls
    /// this, so that no caller can plan a scene other than the one that renders.
    pub(crate) fn new(scene: &Scene) -> Self {
        let models = scene.lighting_models();
        let mask_channels = mask_channels(&models);
        let mask_targets = models.len().div_ceil(4);
        let mut targets = screen_targets(scene, &models, &mask_channels, mask_targets);
        let casters = scene.objects.iter().filter(|o| o.casts_shadows).count();
        let ShadowStage {
            targets: shadow_targets,
            passes: shadow_passes,
            lights: shadowed,
            maps: shadow_maps,
        } = ShadowStage::new(scene, casters);
        targets.extend(shadow_targets);

        let masks: Vec<TargetId> = (0..mask_targets).map(TargetId::Mask).collect();
        let gbuffer = TargetId::GBUFFER;
        let mut passes = shadow_passes;
        passes.push(geometry_pass(scene, &gbuffer));
        passes.push(mask_pass(&models, &masks));
        // Only a lit model's pass reads the occlusion.
        let lit = models.iter().any(|&m| m != LightingModel::Unlit);
        let occlusion = scene.quality.ssao.filter(|_| lit);
        if let Some(settings) = occlusion {
            let (target, pass) = ambient_occlusion(scene, settings);
            targets.push(target);
            passes.push(pass);
        }
        passes.extend(environment_passes(scene, &masks));
        let lighting = lighting_passes(scene, &models, casters > 0);
        passes.extend(lighting_pass_specs(
            scene,
            &mask_channels,
            &lighting,
            &gbuffer,
            &shadow_maps,
        ));
        if scene.environment.is_none() && models.is_empty() {
            passes.push(PassSpec {
                id: PassId::ClearLight,
                reads: vec![],
                writes: vec![TargetId::Light],
                detail: "nothing else writes the light buffer: black".to_owned(),
            });
        }
        if scene.quality.debug_shadow_terms {
            for &light in &shadowed {
                let (target, pass) = shadow_term_output(scene, light, &gbuffer, &shadow_maps);
                targets.push(target);
                passes.push(pass);
            }
        }
        passes.extend(output_passes(scene));
        Self {
            scene: scene.name.clone(),
            width: scene.quality.width,
            height: scene.quality.height,
            targets,
            passes,
            mask_channels,
            lighting,
        }
    }
}

/// Each used lighting model's mask channel: four to a mask target, in the models' order.
fn mask_channels(models: &[LightingModel]) -> Vec<MaskChannel> {
    models
        .iter()
        .enumerate()
        .map(|(i, &model)| MaskChannel {
            model,
            target: i / 4,
            channel: i % 4,
        })
        .collect()
}

/// The targets of the output's size: G-buffer, depth, masks, the lighting passes' routing depth
/// (when any model is used), the light buffer and the final image.
fn screen_targets(
    scene: &Scene,
    models: &[LightingModel],
    mask_channels: &[MaskChannel],
    mask_targets: usize,
) -> Vec<TargetSpec> {
    let gbuffer_contents = [
        "xyz camera-relative position, w roughness",
        "xyz normal (normal-mapped), w specular",
        "xyz tangent, w handedness",
        "rgb base color, a anisotropy",
        "r metallic, g clearcoat, b clearcoat roughness, a specular exponent",
    ];
    let mut targets: Vec<TargetSpec> = TargetId::GBUFFER
        .into_iter()
        .zip(gbuffer_contents)
        .map(|(id, contents)| TargetSpec {
            id,
            format: TextureFormat::Rgba16Float,
            width: scene.quality.width,
            height: scene.quality.height,
            contents: contents.to_owned(),
        })
        .collect();
    targets.push(TargetSpec {
        id: TargetId::Depth,
        format: TextureFormat::Depth32Float,
        width: scene.quality.width,
        height: scene.quality.height,
        contents: "depth, 0 near .. 1 far".to_owned(),
    });
    for index in 0..mask_targets {
        let channels: Vec<String> = mask_channels
            .iter()
            .filter(|c| c.target == index)
            .map(|c| format!("{} {}", ["r", "g", "b", "a"][c.channel], c.model))
            .collect();
        targets.push(TargetSpec {
            id: TargetId::Mask(index),
            format: TextureFormat::Rgba8Unorm,
            width: scene.quality.width,
            height: scene.quality.height,
            contents: channels.join(", "),
        });
    }
    if !models.is_empty() {
        targets.push(TargetSpec {
            id: TargetId::Route,
            format: TextureFormat::Depth32Float,
            width: scene.quality.width,
            height: scene.quality.height,
            contents: "lighting routing: 0 where the last lighting pass's model shades, else 1"
                .to_owned(),
        });
    }
    targets.push(TargetSpec {
        id: TargetId::Light,
        format: TextureFormat::Rgba16Float,
        width: scene.quality.width,
        height: scene.quality.height,
        contents: format!("exposed radiance (exposure {})", scene.quality.exposure),
    });
    targets.push(TargetSpec {
        id: TargetId::Final,
        format: TextureFormat::Rgba8UnormSrgb,
        width: scene.quality.width,
        height: scene.quality.height,
        contents: format!("{} tone-mapped, sRGB", scene.quality.tone_map.name()),
    });
    targets
}

/// The shadow maps' part of a plan.
struct ShadowStage {
    /// Each shadowed light's map, VSM moments and VSM blur intermediate.
    targets: Vec<TargetSpec>,
    /// Their caster and blur passes, light by light.
    passes: Vec<PassSpec>,
    /// The shadowed lights.
    lights: Vec<usize>,
    /// The maps the lighting passes read.
    maps: Vec<TargetId>,
}

impl ShadowStage {
    /// The maps and passes of every light with shadow settings (none when nothing casts).
    fn new(scene: &Scene, casters: usize) -> Self {
        let mut stage = Self {
            targets: Vec::new(),
            passes: Vec::new(),
            lights: Vec::new(),
            maps: Vec::new(),
        };
        for (index, light) in scene.lights.iter().enumerate() {
            let (settings, point) = match light {
                Light::Directional { shadow, .. } => (shadow, false),
                Light::Point { shadow, .. } => (shadow, true),
            };
            let Some(settings) = settings.filter(|_| casters > 0) else {
                continue;
            };
            stage.add_light(scene, index, settings, point, casters);
        }
        stage
    }

    /// Light `index`'s map (a point light's six-face atlas), its VSM moments, and the caster
    /// pass that writes them, then the VSM blur.
    fn add_light(
        &mut self,
        scene: &Scene,
        index: usize,
        settings: ShadowSettings,
        point: bool,
        casters: usize,
    ) {
        let n = settings.map_size;
        let map = TargetId::Shadow { light: index };
        self.targets.push(TargetSpec {
            id: map,
            format: TextureFormat::Depth32Float,
            width: if point { 3 * n } else { n },
            height: if point { 2 * n } else { n },
            contents: if point {
                format!("point light {index}: six {n}x{n} faces (+X -X +Y / -Y +Z -Z), perspective depth")
            } else {
                format!("directional light {index}: orthographic depth fitted to the casters")
            },
        });
        self.lights.push(index);
        self.maps.push(map);
        let mut writes = vec![map];
        let vsm = settings.filter == ShadowFilter::Vsm;
        if vsm {
            let moments = TargetId::ShadowMoments { light: index };
            self.targets.push(TargetSpec {
                id: moments,
                format: TextureFormat::Rgba16Float,
                width: n,
                height: n,
                contents: format!(
                    "light {index} VSM moments: depth (r + g), depth^2 (b + a), blurred"
                ),
            });
            writes.push(moments);
            self.maps.push(moments);
        }
        self.passes.push(PassSpec {
            id: PassId::Shadow { light: index },
            reads: vec![],
            writes,
            detail: format!(
                "{casters} casters{}, filter {}, bias {} m, slope {} texels, normal offset {} texels",
                if point {
                    format!(" x 6 faces ({})", scene.quality.point_shadows.name())
                } else {
                    String::new()
                },
                settings.filter.name(),
                settings.bias,
                settings.slope_bias,
                settings.normal_offset
            ),
        });
        if vsm && settings.vsm_blur_radius > 0 {
            self.add_vsm_blur(index, settings);
        }
    }

    /// The separable Gaussian blur of light `index`'s VSM moments: along x into the blur
    /// target, then along y back into the moments.
    fn add_vsm_blur(&mut self, index: usize, settings: ShadowSettings) {
        let n = settings.map_size;
        let moments = TargetId::ShadowMoments { light: index };
        let blur = TargetId::ShadowBlur { light: index };
        self.targets.push(TargetSpec {
            id: blur,
            format: TextureFormat::Rgba16Float,
            width: n,
            height: n,
            contents: format!("light {index} VSM moments blurred along x"),
        });
        let radius = settings.vsm_blur_radius;
        for (axis, name, reads, writes) in [
            (BlurAxis::X, "x", moments, blur),
            (BlurAxis::Y, "y", blur, moments),
        ] {
            self.passes.push(PassSpec {
                id: PassId::ShadowBlur { light: index, axis },
                reads: vec![reads],
                writes: vec![writes],
                detail: format!("Gaussian along {name}, radius {radius} texels"),
            });
        }
    }
}

/// The screen-space ambient occlusion's target and pass: from the camera's depth and the
/// G-buffer's normals, before any lighting.
fn ambient_occlusion(scene: &Scene, settings: SsaoSettings) -> (TargetSpec, PassSpec) {
    let target = TargetSpec {
        id: TargetId::AmbientOcclusion,
        format: TextureFormat::Rgba16Float,
        width: scene.quality.width,
        height: scene.quality.height,
        contents: "rgb ambient occlusion, 1 unoccluded .. 0 occluded".to_owned(),
    };
    let pass = PassSpec {
        id: PassId::AmbientOcclusion,
        reads: vec![TargetId::Depth, TargetId::GBuffer(GBufferTarget::Normal)],
        writes: vec![TargetId::AmbientOcclusion],
        detail: format!(
            "{} kernel points in a {} m hemisphere, halo removal at the radius",
            settings.samples, settings.radius
        ),
    };
    (target, pass)
}

/// Every object into the G-buffer and depth.
fn geometry_pass(scene: &Scene, gbuffer: &[TargetId]) -> PassSpec {
    let objects = scene.objects.len();
    let triangles: usize = scene.objects.iter().map(|o| o.mesh.triangle_count()).sum();
    PassSpec {
        id: PassId::Geometry,
        reads: vec![],
        writes: gbuffer.iter().copied().chain([TargetId::Depth]).collect(),
        detail: format!("{objects} objects, {triangles} triangles"),
    }
}

/// Every object's lighting-model channel into the mask targets.
fn mask_pass(models: &[LightingModel], masks: &[TargetId]) -> PassSpec {
    PassSpec {
        id: PassId::ShaderMask,
        reads: vec![TargetId::Depth],
        writes: masks.to_vec(),
        detail: format!(
            "{} models: {}",
            models.len(),
            models
                .iter()
                .map(|m| m.name())
                .collect::<Vec<_>>()
                .join(", ")
        ),
    }
}

/// With an environment: the IBL precompute on the CPU and the skybox; none without.
fn environment_passes(scene: &Scene, masks: &[TargetId]) -> Vec<PassSpec> {
    let Some(environment) = &scene.environment else {
        return Vec::new();
    };
    vec![
        PassSpec {
            id: PassId::IblPrecompute,
            reads: vec![],
            writes: vec![],
            detail: format!("CPU, cached: {}", scene.quality.ibl.describe()),
        },
        PassSpec {
            id: PassId::Skybox,
            reads: masks.to_vec(),
            writes: vec![TargetId::Light],
            detail: format!(
                "{}x{} equirectangular, rotation {} deg, intensity {}",
                environment.image.width,
                environment.image.height,
                environment.rotation_degrees,
                environment.intensity
            ),
        },
    ]
}

/// One lighting pass per used model, in mask-channel order; every model but unlit reads the
/// shadow maps.
fn lighting_pass_specs(
    scene: &Scene,
    mask_channels: &[MaskChannel],
    lighting: &[LightingPass],
    gbuffer: &[TargetId],
    shadow_maps: &[TargetId],
) -> Vec<PassSpec> {
    mask_channels
        .iter()
        .zip(lighting)
        .enumerate()
        .map(|(index, (channel, pass))| {
            let mut reads = gbuffer.to_vec();
            // The camera's depth is bound for positions reconstructed from it.
            reads.extend([TargetId::Depth, TargetId::Mask(channel.target)]);
            if channel.model != LightingModel::Unlit {
                reads.extend(shadow_maps.iter().copied());
                if scene.quality.ssao.is_some() {
                    reads.push(TargetId::AmbientOcclusion);
                }
            }
            // Each adds into the light buffer the skybox or the pass before cleared.
            if index > 0 || scene.environment.is_some() {
                reads.push(TargetId::Light);
            }
            PassSpec {
                id: PassId::Lighting(channel.model),
                reads,
                writes: vec![TargetId::Route, TargetId::Light],
                detail: if channel.model == LightingModel::Unlit {
                    "1 draw, no lights, routed by depth test".to_owned()
                } else {
                    format!(
                        "{} light(s) in {} draw(s), additive, routed by depth test",
                        scene.lights.len(),
                        pass.draws.len()
                    )
                },
            }
        })
        .collect()
}

/// Debug: the target and pass that write shadowed light `light`'s shadow term per pixel.
fn shadow_term_output(
    scene: &Scene,
    light: usize,
    gbuffer: &[TargetId],
    shadow_maps: &[TargetId],
) -> (TargetSpec, PassSpec) {
    let term = TargetId::ShadowTerm { light };
    let target = TargetSpec {
        id: term,
        format: TextureFormat::Rgba16Float,
        width: scene.quality.width,
        height: scene.quality.height,
        contents: format!("debug: light {light}'s shadow term (1 = lit)"),
    };
    // The lighting shader's bind group: the G-buffer, depth and first mask target, the light's
    // maps, the occlusion where there is one.
    let mut reads = gbuffer.to_vec();
    reads.extend([
        TargetId::Depth,
        TargetId::Mask(0),
        TargetId::Shadow { light },
    ]);
    let moments = TargetId::ShadowMoments { light };
    if shadow_maps.contains(&moments) {
        reads.push(moments);
    }
    if scene.quality.ssao.is_some() {
        reads.push(TargetId::AmbientOcclusion);
    }
    let pass = PassSpec {
        id: PassId::ShadowTerm { light },
        reads,
        writes: vec![term],
        detail: "debug output of the lighting pass's shadow lookup".to_owned(),
    };
    (target, pass)
}

/// Tone mapping into the final image, then the gizmos over it when the quality settings ask.
fn output_passes(scene: &Scene) -> Vec<PassSpec> {
    let mut passes = vec![PassSpec {
        id: PassId::ToneMap,
        reads: vec![TargetId::Light],
        writes: vec![TargetId::Final],
        detail: scene.quality.tone_map.name().to_owned(),
    }];
    if scene.quality.gizmos {
        passes.push(PassSpec {
            id: PassId::Gizmos,
            // Drawn over the tone-mapped image.
            reads: vec![TargetId::Final],
            writes: vec![TargetId::Final],
            detail: "axes, light directions, point-light markers; no depth test".to_owned(),
        });
    }
    passes
}

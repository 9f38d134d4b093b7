//! The render plan: the passes and targets a scene needs, and nothing more. Built from a
//! [`Scene`] before anything touches a backend, printable (its `Display` is what the insta
//! snapshots hold), and executed by [`crate::renderer`].
//!
//! What is left out, and when: no shader-mask channel for a lighting model no object uses (and a
//! second mask target only past four models), no lighting pass for an unused model, no skybox
//! or IBL precompute without an environment, no gizmos unless the quality settings ask for them.

use std::fmt;

use crate::backend::TextureFormat;
use crate::scene::{
    GbufferSettings, Light, LightingModel, NormalEncoding, PositionStorage, Scene, ShadowFilter,
};

/// Lights handled by one lighting draw (the size of the uniform array in `lighting.wgsl`).
pub const MAX_LIGHTS_PER_DRAW: usize = 16;

/// A render target the plan allocates; every one can be read back by its name.
#[derive(Clone, Debug, PartialEq)]
pub struct TargetSpec {
    /// Name used for readback, goldens and the CLI's `--pass`.
    pub name: String,
    /// Texel format.
    pub format: TextureFormat,
    /// Width in texels.
    pub width: u32,
    /// Height in texels.
    pub height: u32,
    /// What the channels hold.
    pub contents: String,
}

/// What a pass does.
#[derive(Clone, Debug, PartialEq)]
pub enum PassKind {
    /// Draws the shadow casters into the depth map of light `light` (a point light's six atlas
    /// faces are six passes, one viewport each), and for VSM into its moments too.
    Shadow {
        /// Index into the scene's lights.
        light: usize,
    },
    /// VSM: one direction of the separable Gaussian blur of light `light`'s moments.
    ShadowBlur {
        /// Index into the scene's lights.
        light: usize,
    },
    /// Draws every object into the G-buffer and depth.
    Geometry,
    /// Draws every object's one-hot lighting-model channel into the mask targets.
    ShaderMask,
    /// On the CPU, before any GPU pass: the environment's IBL maps (prefiltered specular,
    /// irradiance, DFG), read by the lighting passes; cached in memory and on disk.
    IblPrecompute,
    /// Fills uncovered pixels of the light buffer from the environment.
    Skybox,
    /// Shades one lighting model's pixels into the light buffer.
    Lighting(LightingModel),
    /// Debug: writes light `light`'s shadow term per pixel.
    ShadowTerm {
        /// Index into the scene's lights.
        light: usize,
    },
    /// Exposed HDR light buffer to the sRGB final image.
    ToneMap,
    /// Lines over the final image.
    Gizmos,
}

/// One pass of the plan.
#[derive(Clone, Debug, PartialEq)]
pub struct PassSpec {
    /// Pass name (also the name of its GPU timing).
    pub name: String,
    /// What it does.
    pub kind: PassKind,
    /// Targets it reads.
    pub reads: Vec<String>,
    /// Targets it writes.
    pub writes: Vec<String>,
    /// Draw count and other facts worth reviewing.
    pub detail: String,
}

/// Where a lighting model's pixels are flagged.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct MaskChannel {
    /// The model.
    pub model: LightingModel,
    /// Mask target index (0 for `mask`, 1 for `mask_1`).
    pub target: usize,
    /// Channel within the target (0 = R .. 3 = A).
    pub channel: usize,
}

/// The passes and targets of one scene.
#[derive(Clone, Debug, PartialEq)]
pub struct RenderPlan {
    /// Scene name.
    pub scene: String,
    /// Output width.
    pub width: u32,
    /// Output height.
    pub height: u32,
    /// Targets, in allocation order.
    pub targets: Vec<TargetSpec>,
    /// Passes, in execution order.
    pub passes: Vec<PassSpec>,
    /// Lighting model to mask channel assignment.
    pub mask_channels: Vec<MaskChannel>,
    /// Each lighting pass's draws and their shader variants, in pass order.
    pub lighting: Vec<LightingPass>,
}

/// Names of the G-buffer targets, in attachment order.
pub const GBUFFER_TARGETS: [&str; 5] = [
    "gbuffer_position",
    "gbuffer_normal",
    "gbuffer_tangent",
    "gbuffer_albedo",
    "gbuffer_material",
];

/// Name of the depth target.
pub const DEPTH: &str = "depth";
/// Name of the HDR light buffer.
pub const LIGHT: &str = "light";
/// Name of the lighting passes' routing depth: each lighting pass clears it, marks its model's
/// pixels (from the mask) at depth 0, and draws its lights with an equal-depth test, so that the
/// depth test skips other pixels before any shading.
pub const ROUTE: &str = "route";
/// Name of the tone-mapped output.
pub const FINAL: &str = "final";

/// Name of the shadow map of light `index`.
pub fn shadow_target_name(index: usize) -> String {
    format!("shadow_{index}")
}

/// Name of the VSM moments target of light `index` (filter `vsm` only).
pub fn shadow_moments_target_name(index: usize) -> String {
    format!("shadow_{index}_moments")
}

/// Name of the VSM blur's intermediate target of light `index`.
pub fn shadow_blur_target_name(index: usize) -> String {
    format!("shadow_{index}_blur")
}

/// Name of the shadow-term debug output of light `index`.
pub fn shadow_term_target_name(index: usize) -> String {
    format!("shadow_term_{index}")
}

/// Name of mask target `index`.
pub fn mask_target_name(index: usize) -> String {
    if index == 0 {
        "mask".to_owned()
    } else {
        format!("mask_{index}")
    }
}

impl RenderPlan {
    /// Builds the plan for a scene.
    pub fn new(scene: &Scene) -> Self {
        let models = scene.lighting_models();
        let mask_channels: Vec<MaskChannel> = models
            .iter()
            .enumerate()
            .map(|(i, &model)| MaskChannel {
                model,
                target: i / 4,
                channel: i % 4,
            })
            .collect();
        let mask_targets = models.len().div_ceil(4);
        let gbuffer_contents = [
            "xyz camera-relative position, w roughness",
            "xyz normal (normal-mapped), w specular",
            "xyz tangent, w handedness",
            "rgb base color, a anisotropy",
            "r metallic, g clearcoat, b clearcoat roughness, a specular exponent",
        ];
        let mut targets: Vec<TargetSpec> = GBUFFER_TARGETS
            .iter()
            .zip(gbuffer_contents)
            .map(|(name, contents)| TargetSpec {
                name: (*name).to_owned(),
                format: TextureFormat::Rgba16Float,
                width: scene.quality.width,
                height: scene.quality.height,
                contents: contents.to_owned(),
            })
            .collect();
        targets.push(TargetSpec {
            name: DEPTH.to_owned(),
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
                name: mask_target_name(index),
                format: TextureFormat::Rgba8Unorm,
                width: scene.quality.width,
                height: scene.quality.height,
                contents: channels.join(", "),
            });
        }
        if !models.is_empty() {
            targets.push(TargetSpec {
                name: ROUTE.to_owned(),
                format: TextureFormat::Depth32Float,
                width: scene.quality.width,
                height: scene.quality.height,
                contents: "lighting routing: 0 where the last lighting pass's model shades, else 1"
                    .to_owned(),
            });
        }
        targets.push(TargetSpec {
            name: LIGHT.to_owned(),
            format: TextureFormat::Rgba16Float,
            width: scene.quality.width,
            height: scene.quality.height,
            contents: format!("exposed radiance (exposure {})", scene.quality.exposure),
        });
        targets.push(TargetSpec {
            name: FINAL.to_owned(),
            format: TextureFormat::Rgba8UnormSrgb,
            width: scene.quality.width,
            height: scene.quality.height,
            contents: format!("{} tone-mapped, sRGB", scene.quality.tone_map.name()),
        });
        let casters = scene.objects.iter().filter(|o| o.casts_shadows).count();
        let mut shadow_passes = Vec::new();
        // The shadowed lights, and the maps the lighting passes read.
        let mut shadowed = Vec::new();
        let mut shadow_maps = Vec::new();
        for (index, light) in scene.lights.iter().enumerate() {
            let (settings, point) = match light {
                Light::Directional { shadow, .. } => (shadow, false),
                Light::Point { shadow, .. } => (shadow, true),
            };
            let Some(settings) = settings.filter(|_| casters > 0) else {
                continue;
            };
            let n = settings.map_size;
            let name = shadow_target_name(index);
            targets.push(TargetSpec {
                name: name.clone(),
                format: TextureFormat::Depth32Float,
                width: if point { 3 * n } else { n },
                height: if point { 2 * n } else { n },
                contents: if point {
                    format!("point light {index}: six {n}x{n} faces (+X -X +Y / -Y +Z -Z), perspective depth")
                } else {
                    format!("directional light {index}: orthographic depth fitted to the casters")
                },
            });
            shadowed.push(index);
            shadow_maps.push(name.clone());
            let mut writes = vec![name.clone()];
            let vsm = settings.filter == ShadowFilter::Vsm;
            if vsm {
                let moments = shadow_moments_target_name(index);
                targets.push(TargetSpec {
                    name: moments.clone(),
                    format: TextureFormat::Rgba16Float,
                    width: n,
                    height: n,
                    contents: format!(
                        "light {index} VSM moments: depth (r + g), depth^2 (b + a), blurred"
                    ),
                });
                writes.push(moments.clone());
                shadow_maps.push(moments);
            }
            shadow_passes.push(PassSpec {
                name: name.clone(),
                kind: PassKind::Shadow { light: index },
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
                let moments = shadow_moments_target_name(index);
                let blur = shadow_blur_target_name(index);
                targets.push(TargetSpec {
                    name: blur.clone(),
                    format: TextureFormat::Rgba16Float,
                    width: n,
                    height: n,
                    contents: format!("light {index} VSM moments blurred along x"),
                });
                let radius = settings.vsm_blur_radius;
                for (axis, reads, writes) in [("x", &moments, &blur), ("y", &blur, &moments)] {
                    shadow_passes.push(PassSpec {
                        name: format!("{name}_blur_{axis}"),
                        kind: PassKind::ShadowBlur { light: index },
                        reads: vec![reads.clone()],
                        writes: vec![writes.clone()],
                        detail: format!("Gaussian along {axis}, radius {radius} texels"),
                    });
                }
            }
        }

        let masks: Vec<String> = (0..mask_targets).map(mask_target_name).collect();
        let gbuffer: Vec<String> = GBUFFER_TARGETS.iter().map(|s| (*s).to_owned()).collect();
        let mut passes = shadow_passes;
        let objects = scene.objects.len();
        let triangles: usize = scene.objects.iter().map(|o| o.mesh.triangle_count()).sum();
        passes.push(PassSpec {
            name: "geometry".to_owned(),
            kind: PassKind::Geometry,
            reads: vec![],
            writes: gbuffer.iter().cloned().chain([DEPTH.to_owned()]).collect(),
            detail: format!("{objects} objects, {triangles} triangles"),
        });
        passes.push(PassSpec {
            name: "mask".to_owned(),
            kind: PassKind::ShaderMask,
            reads: vec![DEPTH.to_owned()],
            writes: masks.clone(),
            detail: format!(
                "{} models: {}",
                models.len(),
                models
                    .iter()
                    .map(|m| m.name())
                    .collect::<Vec<_>>()
                    .join(", ")
            ),
        });
        if let Some(environment) = &scene.environment {
            passes.push(PassSpec {
                name: "ibl_precompute".to_owned(),
                kind: PassKind::IblPrecompute,
                reads: vec![],
                writes: vec![],
                detail: format!("CPU, cached: {}", scene.quality.ibl.describe()),
            });
            passes.push(PassSpec {
                name: "skybox".to_owned(),
                kind: PassKind::Skybox,
                reads: masks.clone(),
                writes: vec![LIGHT.to_owned()],
                detail: format!(
                    "{}x{} equirectangular, rotation {} deg, intensity {}",
                    environment.image.width,
                    environment.image.height,
                    environment.rotation_degrees,
                    environment.intensity
                ),
            });
        }
        let lighting = lighting_passes(scene, &models, casters > 0);
        for (channel, pass) in mask_channels.iter().zip(&lighting) {
            let mut reads = gbuffer.clone();
            reads.push(mask_target_name(channel.target));
            if channel.model != LightingModel::Unlit {
                reads.extend(shadow_maps.iter().cloned());
            }
            passes.push(PassSpec {
                name: format!("lighting_{}", channel.model.name().replace('-', "_")),
                kind: PassKind::Lighting(channel.model),
                reads,
                writes: vec![ROUTE.to_owned(), LIGHT.to_owned()],
                detail: if channel.model == LightingModel::Unlit {
                    "1 draw, no lights, routed by depth test".to_owned()
                } else {
                    format!(
                        "{} light(s) in {} draw(s), additive, routed by depth test",
                        scene.lights.len(),
                        pass.draws.len()
                    )
                },
            });
        }
        if scene.quality.debug_shadow_terms {
            for &light in &shadowed {
                let name = shadow_term_target_name(light);
                targets.push(TargetSpec {
                    name: name.clone(),
                    format: TextureFormat::Rgba16Float,
                    width: scene.quality.width,
                    height: scene.quality.height,
                    contents: format!("debug: light {light}'s shadow term (1 = lit)"),
                });
                let mut reads = gbuffer.clone();
                reads.push(shadow_target_name(light));
                let moments = shadow_moments_target_name(light);
                if shadow_maps.contains(&moments) {
                    reads.push(moments);
                }
                passes.push(PassSpec {
                    name: name.clone(),
                    kind: PassKind::ShadowTerm { light },
                    reads,
                    writes: vec![name],
                    detail: "debug output of the lighting pass's shadow lookup".to_owned(),
                });
            }
        }
        passes.push(PassSpec {
            name: "tonemap".to_owned(),
            kind: PassKind::ToneMap,
            reads: vec![LIGHT.to_owned()],
            writes: vec![FINAL.to_owned()],
            detail: scene.quality.tone_map.name().to_owned(),
        });
        if scene.quality.gizmos {
            passes.push(PassSpec {
                name: "gizmos".to_owned(),
                kind: PassKind::Gizmos,
                reads: vec![],
                writes: vec![FINAL.to_owned()],
                detail: "axes, light directions, point-light markers; no depth test".to_owned(),
            });
        }
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

    /// The target with this name.
    pub fn target(&self, name: &str) -> Option<&TargetSpec> {
        self.targets.iter().find(|t| t.name == name)
    }

    /// Names of every target, in allocation order.
    pub fn target_names(&self) -> Vec<&str> {
        self.targets.iter().map(|t| t.name.as_str()).collect()
    }
}

fn format_name(format: TextureFormat) -> &'static str {
    match format {
        TextureFormat::Rgba8Unorm => "rgba8",
        TextureFormat::Rgba8UnormSrgb => "rgba8-srgb",
        TextureFormat::Rgba16Float => "rgba16f",
        TextureFormat::Rgba32Float => "rgba32f",
        TextureFormat::R32Float => "r32f",
        TextureFormat::Depth32Float => "depth32f",
    }
}

impl fmt::Display for RenderPlan {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        writeln!(f, "scene {} at {}x{}", self.scene, self.width, self.height)?;
        writeln!(f, "targets:")?;
        for t in &self.targets {
            writeln!(
                f,
                "  {:<17} {:<10} {:<9} {}",
                t.name,
                format_name(t.format),
                format!("{}x{}", t.width, t.height),
                t.contents
            )?;
        }
        writeln!(f, "passes:")?;
        for (i, p) in self.passes.iter().enumerate() {
            writeln!(f, "  {}. {:<21} {}", i + 1, p.name, p.detail)?;
            if let PassKind::Lighting(model) = p.kind {
                if let Some(r) = self
                    .lighting
                    .iter()
                    .find(|l| l.model == model)
                    .and_then(|l| l.rect)
                {
                    writeln!(
                        f,
                        "       pixels {}..{} x {}..{} (its objects' screen bounds)",
                        r.x,
                        r.x + r.width,
                        r.y,
                        r.y + r.height
                    )?;
                }
                for (d, draw) in self.lighting_draws(model).iter().enumerate() {
                    writeln!(f, "       draw {}: {}", d + 1, draw.variant)?;
                }
            }
            if !p.reads.is_empty() {
                writeln!(f, "       reads  {}", p.reads.join(", "))?;
            }
            if !p.writes.is_empty() {
                writeln!(f, "       writes {}", p.writes.join(", "))?;
            }
        }
        Ok(())
    }
}

/// A shadowed light's kind, as a lighting draw's specialisation sees it.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum ShadowKind {
    /// A directional light's orthographic map.
    Directional,
    /// A point light's six-face atlas.
    Point,
}

/// The shader variant of one lighting draw: the values of `lighting.wgsl`'s `override`
/// constants, chosen from the scene so that a draw compiles only the code it uses. Two draws
/// with equal variants share a pipeline; backends cache pipelines by these constants.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub struct LightingVariant {
    /// Lights shaded by the draw (`LIGHT_COUNT`, at most [`MAX_LIGHTS_PER_DRAW`]).
    pub lights: u32,
    /// Whether any of them is directional (`DIRECTIONAL_LIGHTS`).
    pub directional: bool,
    /// Whether any of them is a point light (`POINT_LIGHTS`).
    pub point: bool,
    /// Whether any of them is a directional light with a disc (an extracted sun), whose
    /// specular the PBR model widens to the disc (`SUN_DISC`).
    pub sun_disc: bool,
    /// The shadowed light in slot 0, its kind and filter (`SHADOW_KIND`, `SHADOW_FILTER`).
    pub shadow: Option<(ShadowKind, ShadowFilter)>,
    /// Samples of the Vogel-disk filters (`VOGEL_SAMPLES`; 0 for the other filters).
    pub vogel_samples: u32,
    /// Image-based lighting in this draw (`IBL`).
    pub ibl: bool,
    /// Filtered importance samples of the specular IBL per pixel; 0 for the split sum
    /// (`IBL_SAMPLES`, from `[quality.ibl] runtime_samples`).
    pub ibl_samples: u32,
    /// Some surface of the model has clearcoat (`CLEARCOAT`; the shader still branches per
    /// pixel when true).
    pub clearcoat: bool,
    /// Some surface of the model is anisotropic (`ANISOTROPY`; per pixel when true).
    pub anisotropy: bool,
    /// G-buffer position storage and normal encoding (`POSITION_MODE`, `NORMAL_MODE`).
    pub gbuffer: GbufferSettings,
    /// The cost breakdown's input floor: reads the inputs, no shading (`INPUT_FLOOR`).
    pub input_floor: bool,
    /// The cost breakdown's other variants: read every input even where the work left needs
    /// fewer (`KEEP_INPUTS`), so that each part's time excludes the reads the input floor counts.
    pub keep_inputs: bool,
}

impl LightingVariant {
    /// The pipeline-overridable constants of `lighting.wgsl`, by name, for this variant.
    pub fn constants(&self) -> Vec<(String, f64)> {
        let flag = |b: bool| if b { 1.0 } else { 0.0 };
        let (kind, filter) = match self.shadow {
            None => (0.0, 0.0),
            Some((kind, filter)) => (
                match kind {
                    ShadowKind::Directional => 1.0,
                    ShadowKind::Point => 2.0,
                },
                f64::from(shadow_filter_code(filter)),
            ),
        };
        let position = match self.gbuffer.position {
            PositionStorage::CameraRelative => 0.0,
            PositionStorage::World => 1.0,
            PositionStorage::Depth => 2.0,
        };
        let normal = match self.gbuffer.normal {
            NormalEncoding::Fp16 => 0.0,
            NormalEncoding::Octahedral => 1.0,
        };
        [
            ("SHADOW_KIND", kind),
            ("SHADOW_FILTER", filter),
            ("VOGEL_SAMPLES", f64::from(self.vogel_samples)),
            ("LIGHT_COUNT", f64::from(self.lights)),
            ("DIRECTIONAL_LIGHTS", flag(self.directional)),
            ("POINT_LIGHTS", flag(self.point)),
            ("SUN_DISC", flag(self.sun_disc)),
            ("IBL", flag(self.ibl)),
            ("IBL_SAMPLES", f64::from(self.ibl_samples)),
            ("CLEARCOAT", flag(self.clearcoat)),
            ("ANISOTROPY", flag(self.anisotropy)),
            ("POSITION_MODE", position),
            ("NORMAL_MODE", normal),
            ("INPUT_FLOOR", flag(self.input_floor)),
            ("KEEP_INPUTS", flag(self.keep_inputs)),
        ]
        .into_iter()
        .map(|(name, value)| (name.to_owned(), value))
        .collect()
    }
}

impl fmt::Display for LightingVariant {
    /// e.g. `1 directional, shadow directional pcf3, clearcoat, gbuffer camera-relative/fp16`.
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let types = match (self.directional, self.point) {
            (true, true) => " directional+point",
            (true, false) => " directional",
            (false, true) => " point",
            (false, false) => "",
        };
        write!(f, "{}{types} light(s)", self.lights)?;
        if let Some((kind, filter)) = self.shadow {
            let kind = match kind {
                ShadowKind::Directional => "directional",
                ShadowKind::Point => "point",
            };
            write!(f, ", shadow {kind} {}", filter.name())?;
            if self.vogel_samples > 0 && filter == ShadowFilter::Vogel {
                write!(f, " ({} samples)", self.vogel_samples)?;
            }
        }
        if self.ibl && self.ibl_samples > 0 {
            write!(f, ", ibl ({} samples)", self.ibl_samples)?;
        }
        for (on, name) in [
            (self.sun_disc, "sun disc"),
            (self.ibl && self.ibl_samples == 0, "ibl"),
            (self.clearcoat, "clearcoat"),
            (self.anisotropy, "anisotropy"),
            (self.input_floor, "input floor"),
            (self.keep_inputs, "keep inputs"),
        ] {
            if on {
                write!(f, ", {name}")?;
            }
        }
        write!(f, ", gbuffer {}", self.gbuffer.name())
    }
}

/// `SHADOW_FILTER`'s code for a filter (also `ShadowUniforms.map.x`).
pub fn shadow_filter_code(filter: ShadowFilter) -> u32 {
    match filter {
        ShadowFilter::Hard => 0,
        ShadowFilter::Pcf3 => 1,
        ShadowFilter::Soft => 2,
        ShadowFilter::SoftFull => 3,
        ShadowFilter::SoftReference => 4,
        ShadowFilter::Vsm => 5,
        ShadowFilter::Vogel => 6,
        ShadowFilter::Bilinear => 7,
        ShadowFilter::Pcf3Bilinear => 8,
    }
}

/// One full-screen draw of a lighting pass: the scene lights it shades and its variant.
#[derive(Clone, Debug, PartialEq)]
pub struct LightingDraw {
    /// Indices into the scene's lights, in uniform-slot order.
    pub lights: Vec<usize>,
    /// The shadowed light (then the only one, in slot 0), if any.
    pub shadowed: Option<usize>,
    /// Whether this is the pass's first draw (ambient, IBL and unlit albedo are added once).
    pub first: bool,
    /// Its shader variant.
    pub variant: LightingVariant,
}

/// One lighting pass: a model and its draws.
#[derive(Clone, Debug, PartialEq)]
pub struct LightingPass {
    /// The lighting model.
    pub model: LightingModel,
    /// Its draws, in order.
    pub draws: Vec<LightingDraw>,
    /// The pixels its draws cover: the screen rectangle around its objects' bounding boxes
    /// (None: the whole image, when a box reaches behind the camera).
    pub rect: Option<PixelRect>,
}

/// A rectangle of pixels: columns `x..x + width`, rows `y..y + height` (row 0 at the top).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct PixelRect {
    /// First column.
    pub x: u32,
    /// First row.
    pub y: u32,
    /// Columns.
    pub width: u32,
    /// Rows.
    pub height: u32,
}

/// The screen rectangle around the bounding boxes of `model`'s objects, widened by two pixels
/// (rasterization rounding), clamped to the image; None when a box corner is not in front of
/// the camera (its projection would not bound it).
fn model_rect(scene: &Scene, model: LightingModel) -> Option<PixelRect> {
    let (width, height) = (scene.quality.width, scene.quality.height);
    let aspect = f64::from(width) / f64::from(height);
    let view_projection = scene.camera.projection(aspect) * scene.camera.view_rotation();
    let (mut lo, mut hi) = (glam::DVec2::splat(f64::MAX), glam::DVec2::splat(f64::MIN));
    for object in scene.objects.iter().filter(|o| o.lighting == model) {
        let m = view_projection * object.transform.relative_to(scene.camera.position);
        let (min, max) = (object.mesh.bounds.min, object.mesh.bounds.max);
        for corner in 0..8 {
            let pick = |axis: usize| {
                f64::from(if corner & (1 << axis) == 0 {
                    min[axis]
                } else {
                    max[axis]
                })
            };
            let clip = m * glam::DVec4::new(pick(0), pick(1), pick(2), 1.0);
            // NaN compares false: treated like a corner behind the camera.
            if clip.w.is_nan() || clip.w <= 1e-9 {
                return None;
            }
            let pixel = glam::DVec2::new(
                (clip.x / clip.w * 0.5 + 0.5) * f64::from(width),
                (0.5 - clip.y / clip.w * 0.5) * f64::from(height),
            );
            lo = lo.min(pixel);
            hi = hi.max(pixel);
        }
    }
    if lo.x > hi.x || lo.y > hi.y {
        return None; // no objects of this model
    }
    let clamp = |v: f64, size: u32| v.clamp(0.0, f64::from(size)) as u32;
    let (x0, y0) = (
        clamp(lo.x.floor() - 2.0, width),
        clamp(lo.y.floor() - 2.0, height),
    );
    let (x1, y1) = (
        clamp(hi.x.ceil() + 2.0, width),
        clamp(hi.y.ceil() + 2.0, height),
    );
    // An object entirely off screen keeps one pixel (a viewport cannot be empty).
    Some(PixelRect {
        x: x0.min(width - 1),
        y: y0.min(height - 1),
        width: (x1.max(x0 + 1) - x0).min(width - x0.min(width - 1)),
        height: (y1.max(y0 + 1) - y0).min(height - y0.min(height - 1)),
    })
}

/// A part of the lighting passes' work that the bench's cost breakdown takes away, to time the
/// pass without it (`harness bench --breakdown`). Images rendered with one are not the scene's.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum LightingFeature {
    /// Every draw's shading: the draws only read their inputs (the input floor).
    Shading,
    /// Image-based lighting.
    Ibl,
    /// Shadow lookups (the lights stay, unshadowed).
    Shadows,
    /// Clearcoat lobes.
    Clearcoat,
    /// One light (by scene index), with its shadow lookup.
    Light(usize),
    /// Every light and IBL: what is left is reading the inputs and the per-pixel setup (view
    /// vector, ambient, output).
    Lighting,
    /// Every light, IBL kept.
    Lights,
}

/// The draws of each lighting model: unshadowed lights 16 to a draw, then one draw per shadowed
/// light (with its maps bound); at least one draw (ambient). Unlit gets one draw and no lights.
fn lighting_passes(
    scene: &Scene,
    models: &[LightingModel],
    any_casters: bool,
) -> Vec<LightingPass> {
    let shadowed: Vec<usize> = (0..scene.lights.len())
        .filter(|&i| any_casters && scene.lights[i].casts_shadows())
        .collect();
    let plain: Vec<usize> = (0..scene.lights.len())
        .filter(|i| !shadowed.contains(i))
        .collect();
    let mut batches: Vec<(Vec<usize>, Option<usize>)> = plain
        .chunks(MAX_LIGHTS_PER_DRAW)
        .map(|c| (c.to_vec(), None))
        .collect();
    batches.extend(shadowed.iter().map(|&i| (vec![i], Some(i))));
    if batches.is_empty() {
        batches.push((vec![], None));
    }
    let ibl = scene
        .environment
        .as_ref()
        .is_some_and(|e| e.intensity * scene.quality.exposure > 0.0);
    models
        .iter()
        .map(|&model| {
            let materials = || {
                scene
                    .objects
                    .iter()
                    .filter(move |o| o.lighting == model)
                    .map(|o| &o.material)
            };
            let pbr = model == LightingModel::Pbr;
            let base = LightingVariant {
                lights: 0,
                directional: false,
                point: false,
                sun_disc: false,
                shadow: None,
                vogel_samples: 0,
                ibl: false,
                ibl_samples: 0,
                clearcoat: pbr
                    && materials().any(|m| m.clearcoat != 0.0 || m.clearcoat_map.is_some()),
                anisotropy: pbr && materials().any(|m| m.anisotropy != 0.0),
                gbuffer: scene.quality.gbuffer,
                input_floor: false,
                keep_inputs: false,
            };
            let draws = if model == LightingModel::Unlit {
                vec![LightingDraw {
                    lights: vec![],
                    shadowed: None,
                    first: true,
                    variant: base,
                }]
            } else {
                batches
                    .iter()
                    .enumerate()
                    .map(|(index, (lights, shadowed))| {
                        let mut draw = LightingDraw {
                            lights: lights.clone(),
                            shadowed: *shadowed,
                            first: index == 0,
                            variant: LightingVariant {
                                ibl: ibl && index == 0,
                                ibl_samples: if ibl && index == 0 && pbr {
                                    scene.quality.ibl.runtime_samples
                                } else {
                                    0
                                },
                                ..base
                            },
                        };
                        draw.specialise(scene);
                        // Only the PBR model widens its highlight to a disc.
                        draw.variant.sun_disc &= pbr;
                        draw
                    })
                    .collect()
            };
            LightingPass {
                model,
                draws,
                rect: model_rect(scene, model),
            }
        })
        .collect()
}

impl LightingDraw {
    /// Sets the light-dependent part of the variant from `lights` and `shadowed`.
    fn specialise(&mut self, scene: &Scene) {
        let light = |i: usize| &scene.lights[i];
        self.variant.lights = self.lights.len() as u32;
        self.variant.directional = self
            .lights
            .iter()
            .any(|&i| matches!(light(i), Light::Directional { .. }));
        self.variant.point = self
            .lights
            .iter()
            .any(|&i| matches!(light(i), Light::Point { .. }));
        self.variant.sun_disc = self.lights.iter().any(|&i| {
            matches!(light(i), Light::Directional { angular_radius, .. } if *angular_radius > 0.0)
        });
        let settings = self.shadowed.and_then(|i| match light(i) {
            Light::Directional { shadow, .. } => shadow.map(|s| (ShadowKind::Directional, s)),
            Light::Point { shadow, .. } => shadow.map(|s| (ShadowKind::Point, s)),
        });
        self.variant.shadow = settings.map(|(kind, s)| (kind, s.filter));
        self.variant.vogel_samples = match settings.map(|(_, s)| (s.filter, s.soft_samples)) {
            Some((ShadowFilter::Vogel, samples)) => samples,
            Some((ShadowFilter::SoftReference, _)) => 1024,
            _ => 0,
        };
    }
}

impl RenderPlan {
    /// The draws of `model`'s lighting pass (empty if the plan has none).
    pub fn lighting_draws(&self, model: LightingModel) -> &[LightingDraw] {
        self.lighting
            .iter()
            .find(|p| p.model == model)
            .map_or(&[], |p| &p.draws[..])
    }

    /// Takes `feature` out of every lighting pass (for the bench's cost breakdown): the frame
    /// then times the passes without it. A light taken out leaves its draw, with no light.
    pub fn remove_lighting_feature(&mut self, feature: LightingFeature, scene: &Scene) {
        for pass in &mut self.lighting {
            for draw in &mut pass.draws {
                match feature {
                    LightingFeature::Shading => draw.variant.input_floor = true,
                    LightingFeature::Ibl => {
                        draw.variant.ibl = false;
                        draw.variant.ibl_samples = 0;
                    }
                    LightingFeature::Shadows => draw.shadowed = None,
                    LightingFeature::Clearcoat => draw.variant.clearcoat = false,
                    LightingFeature::Light(light) => {
                        draw.lights.retain(|&i| i != light);
                        if draw.shadowed == Some(light) {
                            draw.shadowed = None;
                        }
                    }
                    LightingFeature::Lighting => {
                        draw.lights.clear();
                        draw.shadowed = None;
                        draw.variant.ibl = false;
                        draw.variant.ibl_samples = 0;
                    }
                    LightingFeature::Lights => {
                        draw.lights.clear();
                        draw.shadowed = None;
                    }
                }
                draw.variant.keep_inputs = feature != LightingFeature::Shading;
                if pass.model != LightingModel::Unlit {
                    draw.specialise(scene);
                }
            }
        }
    }
}

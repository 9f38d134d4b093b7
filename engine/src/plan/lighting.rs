//! The lighting passes' draws: which lights each full-screen draw of a lighting model shades,
//! the shader variant it compiles ([`LightingVariant`], the `override` constants of
//! `lighting.wgsl`), the screen rectangle a model's pass covers, and the features the bench's
//! cost breakdown can take out of them.

use crate::scene::{
    GbufferSettings, Light, LightingModel, NormalEncoding, PositionStorage, Scene, ShadowFilter,
};

use super::RenderPlan;

/// Lights handled by one lighting draw (the size of the uniform array in `lighting.wgsl`).
pub const MAX_LIGHTS_PER_DRAW: usize = 16;

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
    /// How many times its own solid angle each of those samples reads (`IBL_FOOTPRINT`, from
    /// `[quality.ibl] runtime_footprint`; one without samples).
    pub ibl_footprint: crate::scene::Footprint,
    /// Filtered importance samples of the anisotropic pixels when `ibl_samples` is 0
    /// (`IBL_ANISOTROPIC_SAMPLES`, from `[quality.ibl] anisotropic_samples`).
    pub ibl_anisotropic_samples: u32,
    /// The split sum's dominant direction (`IBL_FROSTBITE_DOMINANT`, from `[quality.ibl]
    /// dominant_direction`).
    pub ibl_dominant: crate::scene::DominantDirection,
    /// The split sum reads anisotropic pixels by taps (`IBL_ANISOTROPIC_TAPS`, from
    /// `[quality.ibl] anisotropic_lookup`).
    pub ibl_anisotropic_taps: bool,
    /// Some surface of the model has clearcoat (`CLEARCOAT`; the shader still branches per
    /// pixel when true).
    pub clearcoat: bool,
    /// Some surface of the model is anisotropic (`ANISOTROPY`; per pixel when true).
    pub anisotropy: bool,
    /// G-buffer position storage and normal encoding (`POSITION_MODE`, `NORMAL_MODE`).
    pub gbuffer: GbufferSettings,
    /// The ambient and IBL diffuse light of this draw are scaled by the screen-space ambient
    /// occlusion (`AMBIENT_OCCLUSION`; first draws of a lit model in a scene with SSAO).
    pub ambient_occlusion: bool,
    /// Draws of the model's pass (`DRAWS`). They add into the same pixels, so each clamps its
    /// output to the fp16-safe maximum divided by this, and their sum stays finite.
    pub draws: u32,
    /// The cost breakdown's input floor: reads the inputs, no shading (`INPUT_FLOOR`).
    pub input_floor: bool,
    /// The cost breakdown's other variants: read every input even where the work left needs
    /// fewer (`KEEP_INPUTS`), so that each part's time excludes the reads the input floor counts.
    pub keep_inputs: bool,
}

impl LightingVariant {
    /// Whether the draw takes filtered importance samples of the environment (of every pixel or
    /// of the anisotropic ones), which read the IBL's radiance chain.
    pub fn samples_ibl(&self) -> bool {
        self.ibl_samples > 0 || self.ibl_anisotropic_samples > 0
    }

    /// No IBL in the draw, and its knobs back to what a draw without IBL has (so that variants
    /// that differ only there share a pipeline).
    pub fn remove_ibl(&mut self) {
        self.ibl = false;
        self.ibl_samples = 0;
        self.ibl_anisotropic_samples = 0;
        self.ibl_footprint = crate::scene::Footprint::ONE;
        self.ibl_dominant = crate::scene::DominantDirection::Filament;
        self.ibl_anisotropic_taps = false;
    }

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
            ("IBL_FOOTPRINT", self.ibl_footprint.factor()),
            (
                "IBL_ANISOTROPIC_SAMPLES",
                f64::from(self.ibl_anisotropic_samples),
            ),
            (
                "IBL_FROSTBITE_DOMINANT",
                flag(self.ibl_dominant == crate::scene::DominantDirection::Frostbite),
            ),
            ("IBL_ANISOTROPIC_TAPS", flag(self.ibl_anisotropic_taps)),
            ("CLEARCOAT", flag(self.clearcoat)),
            ("ANISOTROPY", flag(self.anisotropy)),
            ("POSITION_MODE", position),
            ("NORMAL_MODE", normal),
            ("DRAWS", f64::from(self.draws)),
            ("INPUT_FLOOR", flag(self.input_floor)),
            ("KEEP_INPUTS", flag(self.keep_inputs)),
            ("AMBIENT_OCCLUSION", flag(self.ambient_occlusion)),
        ]
        .into_iter()
        .map(|(name, value)| (name.to_owned(), value))
        .collect()
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
    /// Nothing: the pass as it is, except that every draw also re-reads its inputs
    /// (`KEEP_INPUTS`) as the variants with a part taken away do. The baseline of their
    /// differences, so that a re-read the compiler does not merge away is not counted as a part.
    KeptInputs,
}

/// The draws of each lighting model: unshadowed lights 16 to a draw, then one draw per shadowed
/// light (with its maps bound); at least one draw (ambient). Unlit gets one draw and no lights.
pub(super) fn lighting_passes(
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
                ibl_footprint: crate::scene::Footprint::ONE,
                ibl_anisotropic_samples: 0,
                ibl_dominant: crate::scene::DominantDirection::Filament,
                ibl_anisotropic_taps: false,
                clearcoat: pbr
                    && materials().any(|m| m.clearcoat != 0.0 || m.clearcoat_map.is_some()),
                anisotropy: pbr && materials().any(|m| m.anisotropy != 0.0),
                gbuffer: scene.quality.gbuffer,
                ambient_occlusion: false,
                draws: if model == LightingModel::Unlit {
                    1
                } else {
                    u32::try_from(batches.len()).unwrap_or(u32::MAX)
                },
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
                        // The first draw of the PBR model carries its IBL and the IBL's knobs.
                        let knobs = &scene.quality.ibl;
                        let pbr_ibl = ibl && index == 0 && pbr;
                        let ibl_samples = if pbr_ibl { knobs.runtime_samples } else { 0 };
                        let anisotropic_samples = if pbr_ibl && base.anisotropy && ibl_samples == 0
                        {
                            knobs.anisotropic_samples
                        } else {
                            0
                        };
                        let mut draw = LightingDraw {
                            lights: lights.clone(),
                            shadowed: *shadowed,
                            first: index == 0,
                            variant: LightingVariant {
                                ibl: ibl && index == 0,
                                ambient_occlusion: scene.quality.ssao.is_some() && index == 0,
                                ibl_samples,
                                ibl_anisotropic_samples: anisotropic_samples,
                                ibl_footprint: if ibl_samples > 0 || anisotropic_samples > 0 {
                                    knobs.runtime_footprint
                                } else {
                                    crate::scene::Footprint::ONE
                                },
                                ibl_dominant: if pbr_ibl {
                                    knobs.dominant_direction
                                } else {
                                    crate::scene::DominantDirection::Filament
                                },
                                ibl_anisotropic_taps: pbr_ibl
                                    && base.anisotropy
                                    && knobs.anisotropic_lookup
                                        == crate::scene::AnisotropicLookup::Taps,
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

    /// Gives every lighting draw the one generic variant a shader without specialisation would
    /// run (for `harness check --debug-unspecialised-lighting`, a slowdown the speed checks
    /// must catch): as many lights as a draw holds ([`MAX_LIGHTS_PER_DRAW`], the slots past the
    /// draw's own lights zero, so they add exact zeros), both light types picked per light,
    /// the split-sum IBL in every draw (weighted by the uniforms' intensity, zero in the draws
    /// and scenes without it), and for PBR the sun disc, clearcoat and anisotropy branched on
    /// per pixel. Only what needs resources of its own stays the draw's: its shadowed light's
    /// filter, the IBL's samples, the ambient occlusion. The shader gives the same picture; it
    /// only does more work for it.
    pub fn unspecialise_lighting(&mut self) {
        for pass in &mut self.lighting {
            if pass.model == LightingModel::Unlit {
                continue;
            }
            let pbr = pass.model == LightingModel::Pbr;
            for draw in &mut pass.draws {
                draw.variant.lights = MAX_LIGHTS_PER_DRAW as u32;
                draw.variant.ibl = true;
                draw.variant.directional = true;
                draw.variant.point = true;
                draw.variant.sun_disc = pbr;
                draw.variant.clearcoat = pbr;
                draw.variant.anisotropy = pbr;
            }
        }
    }

    /// Takes `feature` out of every lighting pass (for the bench's cost breakdown): the frame
    /// then times the passes without it. A light taken out leaves its draw, with no light.
    pub fn remove_lighting_feature(&mut self, feature: LightingFeature, scene: &Scene) {
        for pass in &mut self.lighting {
            for draw in &mut pass.draws {
                match feature {
                    LightingFeature::Shading => draw.variant.input_floor = true,
                    LightingFeature::Ibl => {
                        draw.variant.remove_ibl();
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
                        draw.variant.remove_ibl();
                    }
                    LightingFeature::Lights => {
                        draw.lights.clear();
                        draw.shadowed = None;
                    }
                    LightingFeature::KeptInputs => {}
                }
                draw.variant.keep_inputs = feature != LightingFeature::Shading;
                if pass.model != LightingModel::Unlit {
                    draw.specialise(scene);
                }
            }
        }
    }
}

//! The scene model: an immutable snapshot of everything a frame depends on (camera, objects,
//! lights, environment, quality settings). Rendering a [`Scene`] is a pure function of it.
//!
//! World positions are `f64` ([`DVec3`]): the renderer subtracts the camera position in double
//! precision before anything reaches the GPU, so a scene 10 km from the origin renders like the
//! same scene at the origin.

use std::fmt;
use std::str::FromStr;
use std::sync::Arc;

use glam::{DMat4, DQuat, DVec3};
use serde::{Deserialize, Serialize};

use crate::mesh::MeshData;

/// A decoded RGBA8 texture with its full mip chain (top row first).
#[derive(Clone, Debug)]
pub struct TextureImage {
    /// Where it came from (file path or generator name), for messages.
    pub label: String,
    /// Whether the texels are sRGB-encoded color or linear data.
    pub srgb: bool,
    /// Width of mip 0.
    pub width: u32,
    /// Height of mip 0.
    pub height: u32,
    /// How the texels are stored: RGBA8 (sRGB-encoded where `srgb`), or linear RGBA16F from a
    /// 16-bit file.
    pub format: crate::assets::TexelFormat,
    /// Texels per mip level in `format`, level 0 first.
    pub mips: Vec<Vec<u8>>,
}

/// An equirectangular HDR environment: linear RGBA f32 texels, top row first.
#[derive(Clone, Debug)]
pub struct EnvironmentImage {
    /// Where it came from, for messages.
    pub label: String,
    /// Width in texels (longitude).
    pub width: u32,
    /// Height in texels (latitude, north at the top).
    pub height: u32,
    /// Texels.
    pub texels: Vec<[f32; 4]>,
}

/// A perspective camera.
#[derive(Clone, Debug, PartialEq)]
pub struct Camera {
    /// Eye position in world space.
    pub position: DVec3,
    /// Point looked at.
    pub target: DVec3,
    /// Up direction.
    pub up: DVec3,
    /// Vertical field of view in degrees.
    pub fov_y_degrees: f64,
    /// Near plane distance.
    pub near: f64,
    /// Far plane distance.
    pub far: f64,
}

impl Camera {
    /// World-to-view rotation with the camera at the origin (camera-relative view matrix).
    pub fn view_rotation(&self) -> DMat4 {
        DMat4::look_at_rh(DVec3::ZERO, self.target - self.position, self.up)
    }

    /// Projection with depth 0 at the near plane and 1 at the far plane.
    pub fn projection(&self, aspect: f64) -> DMat4 {
        DMat4::perspective_rh(self.fov_y_degrees.to_radians(), aspect, self.near, self.far)
    }
}

/// Translation, rotation and scale of an object.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Transform {
    /// World position.
    pub translation: DVec3,
    /// Orientation.
    pub rotation: DQuat,
    /// Scale per axis.
    pub scale: DVec3,
}

impl Default for Transform {
    fn default() -> Self {
        Self {
            translation: DVec3::ZERO,
            rotation: DQuat::IDENTITY,
            scale: DVec3::ONE,
        }
    }
}

impl Transform {
    /// Object-to-camera-relative matrix: the translation is taken relative to `origin` in f64.
    pub fn relative_to(&self, origin: DVec3) -> DMat4 {
        DMat4::from_scale_rotation_translation(self.scale, self.rotation, self.translation - origin)
    }
}

/// How the pixels of an object are lit. Each model used in a scene gets one shader-mask channel
/// and one full-screen lighting pass.
#[derive(Clone, Copy, Debug, PartialEq, Eq, PartialOrd, Ord, Hash, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum LightingModel {
    /// Filament's PBR: Lambert diffuse, GGX/Smith/Schlick specular, clearcoat, anisotropy.
    Pbr,
    /// Lambert diffuse plus Blinn-Phong specular with an exponent (the r2 seed's model).
    BlinnPhong,
    /// Lambert diffuse only.
    Lambert,
    /// Cel shading: N.L quantised into three bands.
    Toon,
    /// Albedo as emitted radiance, no lights.
    Unlit,
}

impl LightingModel {
    /// Every model, in mask-channel order.
    pub const ALL: [LightingModel; 5] = [
        LightingModel::Pbr,
        LightingModel::BlinnPhong,
        LightingModel::Lambert,
        LightingModel::Toon,
        LightingModel::Unlit,
    ];

    /// Name used in scene files, pass names and messages.
    pub fn name(self) -> &'static str {
        match self {
            LightingModel::Pbr => "pbr",
            LightingModel::BlinnPhong => "blinn-phong",
            LightingModel::Lambert => "lambert",
            LightingModel::Toon => "toon",
            LightingModel::Unlit => "unlit",
        }
    }

    /// The fragment entry point of its lighting pass in `lighting.wgsl`.
    pub fn entry_point(self) -> &'static str {
        match self {
            LightingModel::Pbr => "fs_pbr",
            LightingModel::BlinnPhong => "fs_blinn_phong",
            LightingModel::Lambert => "fs_lambert",
            LightingModel::Toon => "fs_toon",
            LightingModel::Unlit => "fs_unlit",
        }
    }
}

impl fmt::Display for LightingModel {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.name())
    }
}

impl FromStr for LightingModel {
    type Err = String;
    fn from_str(s: &str) -> Result<Self, String> {
        Self::ALL
            .into_iter()
            .find(|m| m.name() == s)
            .ok_or_else(|| {
                let names: Vec<_> = Self::ALL.iter().map(|m| m.name()).collect();
                format!(
                    "unknown lighting model `{s}` (expected one of: {})",
                    names.join(", ")
                )
            })
    }
}

/// Index of a texture in [`Scene::textures`].
pub type TextureIndex = usize;

/// Surface parameters. Where a map is present it replaces the scalar (the seed's rule: per-object
/// parameters are the fallback where a material has no map).
#[derive(Clone, Debug, PartialEq)]
pub struct Material {
    /// Base color (albedo), linear RGB.
    pub base_color: [f32; 3],
    /// Perceptual roughness, 0..1.
    pub roughness: f32,
    /// Metallic, 0..1.
    pub metallic: f32,
    /// Specular (F0 = 0.16 specular^2 for dielectrics), 0..1; also Blinn-Phong's specular scale.
    pub specular: f32,
    /// Anisotropy, -1..1 (positive stretches highlights along the tangent).
    pub anisotropy: f32,
    /// Clearcoat strength, 0..1.
    pub clearcoat: f32,
    /// Clearcoat perceptual roughness, 0..1.
    pub clearcoat_roughness: f32,
    /// Blinn-Phong specular exponent.
    pub specular_exponent: f32,
    /// Base color map (sRGB; multiplies nothing, replaces `base_color`).
    pub base_color_map: Option<TextureIndex>,
    /// Tangent-space normal map (linear, OpenGL convention: +Y along +v).
    pub normal_map: Option<TextureIndex>,
    /// Roughness map (linear, red channel).
    pub roughness_map: Option<TextureIndex>,
    /// Metallic map (linear, red channel).
    pub metallic_map: Option<TextureIndex>,
    /// Clearcoat strength map (linear, red channel).
    pub clearcoat_map: Option<TextureIndex>,
    /// Specular map (linear, red channel).
    pub specular_map: Option<TextureIndex>,
}

impl Default for Material {
    fn default() -> Self {
        Self {
            base_color: [0.8, 0.8, 0.8],
            roughness: 0.5,
            metallic: 0.0,
            specular: 0.5,
            anisotropy: 0.0,
            clearcoat: 0.0,
            clearcoat_roughness: 0.1,
            specular_exponent: 32.0,
            base_color_map: None,
            normal_map: None,
            roughness_map: None,
            metallic_map: None,
            clearcoat_map: None,
            specular_map: None,
        }
    }
}

/// One drawable: a mesh with a transform, a material and a lighting model.
#[derive(Clone, Debug)]
pub struct Object {
    /// Name for messages and plans.
    pub name: String,
    /// Geometry (shared between objects that use the same mesh).
    pub mesh: Arc<MeshData>,
    /// Placement.
    pub transform: Transform,
    /// Surface.
    pub material: Material,
    /// Which lighting pass shades it.
    pub lighting: LightingModel,
    /// Whether it is drawn into shadow maps.
    pub casts_shadows: bool,
}

/// How a shadow map is filtered.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum ShadowFilter {
    /// One depth comparison (hard shadows).
    Hard,
    /// 3x3 percentage-closer filtering (nine comparisons, one texel apart).
    Pcf3,
    /// The seed's stratified soft shadows (GPU Gems 2, ch. 17): 16 samples in 4 concentric rings
    /// of 4 sectors within `soft_radius` texels, jittered per pixel from a precomputed texture;
    /// the outer ring is tested first and, when its 4 samples agree, that answer is returned.
    Soft,
    /// [`ShadowFilter::Soft`] without the early-out (all 16 samples always), for tests and
    /// benchmarks.
    SoftFull,
    /// The converged soft filter: 1024 samples on a Vogel (golden-angle) disk of `soft_radius`
    /// texels, no jitter. The reference the soft filters' error is measured against in sweeps.
    SoftReference,
    /// `soft_samples` samples on a Vogel (golden-angle) disk of `soft_radius` texels, no jitter:
    /// the soft filter with its sample count as a knob (`soft-reference` is this at 1024).
    Vogel,
    /// Variance shadow maps (the r2 seed; directional lights only): the map stores depth and
    /// depth squared, blurred by a separable Gaussian, sampled bilinearly, and turned into a
    /// visibility by Chebyshev's bound with a minimum variance and light-bleeding reduction.
    Vsm,
    /// One comparison through a linear-filtering comparison sampler: the hardware's 2x2
    /// percentage-closer filter, bilinearly weighted (one fetch).
    Bilinear,
    /// Four linear-filtered comparisons half a texel off the centre diagonally: a 3x3 tent
    /// (weights 1 2 1 by 1 2 1) that slides smoothly with the receiver (four fetches instead of
    /// `pcf3`'s nine).
    Pcf3Bilinear,
}

impl ShadowFilter {
    /// Name in scene files and plans.
    pub fn name(self) -> &'static str {
        match self {
            ShadowFilter::Hard => "hard",
            ShadowFilter::Pcf3 => "pcf3",
            ShadowFilter::Soft => "soft",
            ShadowFilter::SoftFull => "soft-full",
            ShadowFilter::SoftReference => "soft-reference",
            ShadowFilter::Vogel => "vogel",
            ShadowFilter::Vsm => "vsm",
            ShadowFilter::Bilinear => "bilinear",
            ShadowFilter::Pcf3Bilinear => "pcf3-bilinear",
        }
    }

    /// Shadow-map fetches per shaded pixel (the stratified soft filter's early-out makes 4 of
    /// its 16 the common case; `vogel_samples` is the `vogel` filter's count).
    pub fn fetches(self, vogel_samples: u32) -> u32 {
        match self {
            ShadowFilter::Hard | ShadowFilter::Bilinear | ShadowFilter::Vsm => 1,
            ShadowFilter::Pcf3 => 9,
            ShadowFilter::Pcf3Bilinear => 4,
            ShadowFilter::Soft | ShadowFilter::SoftFull => 16,
            ShadowFilter::SoftReference => 1024,
            ShadowFilter::Vogel => vogel_samples,
        }
    }

    /// Whether the filter reads the map through a linear-filtering comparison sampler.
    pub fn linear_comparison(self) -> bool {
        matches!(self, ShadowFilter::Bilinear | ShadowFilter::Pcf3Bilinear)
    }
}

/// Shadow-map settings of a light. Biases are in world units (meters), so they mean the same
/// for every map size and light type.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ShadowSettings {
    /// Shadow map size in texels (square; per cube face for point lights).
    pub map_size: u32,
    /// Constant bias: the receiver is moved this far towards the light before comparing.
    pub bias: f32,
    /// Slope-scaled bias in shadow-map texels: adds `slope_bias * texel * tan(angle between
    /// normal and light)` meters (tan clamped to 10), doubled for 3x3 PCF, whose outer taps
    /// reach one texel further; grazing surfaces get more.
    pub slope_bias: f32,
    /// Normal offset in shadow-map texels: the receiver is moved along its normal by this many
    /// texel widths (at its distance) before projecting.
    pub normal_offset: f32,
    /// Filter.
    pub filter: ShadowFilter,
    /// Radius of the soft filters' sample disk, in texels.
    pub soft_radius: f32,
    /// Samples of the `vogel` filter (1..=4096).
    pub soft_samples: u32,
    /// VSM: radius of the Gaussian blur of the moments, in texels (0: no blur passes).
    pub vsm_blur_radius: u32,
    /// VSM: the smallest variance Chebyshev's bound uses, in squared map depth (0..1) units;
    /// hides the moments' rounding on lit surfaces.
    pub vsm_min_variance: f32,
    /// VSM: light-bleeding reduction; visibilities below this are cut to 0 and the rest
    /// rescaled to 0..1 (0 = off).
    pub vsm_bleeding_reduction: f32,
}

impl ShadowSettings {
    /// How many texels beyond the centre the filter reads (scales the slope and normal biases).
    pub fn reach(&self) -> f32 {
        match self.filter {
            ShadowFilter::Hard => 1.0,
            ShadowFilter::Pcf3 | ShadowFilter::Pcf3Bilinear => 2.0,
            ShadowFilter::Bilinear => 1.5,
            ShadowFilter::Soft
            | ShadowFilter::SoftFull
            | ShadowFilter::SoftReference
            | ShadowFilter::Vogel => 1.0 + self.soft_radius.max(0.0),
            // Chebyshev's bound is soft near the mean, so VSM needs only the hard filter's bias
            // (measured: a larger reach adds peter-panning and no acne goes away).
            ShadowFilter::Vsm => 1.0,
        }
    }
}

impl Default for ShadowSettings {
    fn default() -> Self {
        Self {
            map_size: 1024,
            bias: 0.0002,
            slope_bias: 0.5,
            normal_offset: 0.5,
            filter: ShadowFilter::Pcf3,
            soft_radius: 2.5,
            soft_samples: 64,
            vsm_blur_radius: 2,
            vsm_min_variance: 1e-6,
            vsm_bleeding_reduction: 0.2,
        }
    }
}

/// A light. Incoming radiance is `color * intensity * attenuation * shadow`.
#[derive(Clone, Debug, PartialEq)]
pub enum Light {
    /// Parallel light from a direction.
    Directional {
        /// Direction from the surface towards the light (normalised when used).
        direction: DVec3,
        /// Linear RGB color.
        color: [f32; 3],
        /// Intensity multiplier.
        intensity: f32,
        /// Angular radius of the light's disc in radians (0: a point at infinity). A disc widens
        /// and dims the specular highlight it makes on smooth surfaces; `intensity` stays the
        /// irradiance it gives a surface facing it.
        angular_radius: f32,
        /// Shadow map, if it casts shadows.
        shadow: Option<ShadowSettings>,
    },
    /// Light from a point with the r2 renderer's attenuation
    /// `max(0, 1 - (distance / radius)^(1 / falloff))`.
    Point {
        /// World position.
        position: DVec3,
        /// Linear RGB color.
        color: [f32; 3],
        /// Intensity multiplier.
        intensity: f32,
        /// Distance at which the light reaches zero.
        radius: f32,
        /// Shape of the falloff: 1 is linear, below 1 stays bright longer, above 1 fades sooner.
        falloff: f32,
        /// Shadow cube map, if it casts shadows.
        shadow: Option<ShadowSettings>,
    },
}

impl Light {
    /// Whether the light has shadow settings.
    pub fn casts_shadows(&self) -> bool {
        match self {
            Light::Directional { shadow, .. } | Light::Point { shadow, .. } => shadow.is_some(),
        }
    }
}

/// An environment map around the scene.
#[derive(Clone, Debug)]
pub struct Environment {
    /// The equirectangular image.
    pub image: Arc<EnvironmentImage>,
    /// Rotation about +Y in degrees.
    pub rotation_degrees: f32,
    /// Radiance multiplier.
    pub intensity: f32,
}

/// Tone-mapping operator from the exposed HDR light buffer to display values.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum ToneMap {
    /// Narkowicz's fit of the ACES filmic curve: `x(2.51x+0.03) / (x(2.43x+0.59)+0.14)`.
    Aces,
    /// Reinhard: `x / (1 + x)` per channel.
    Reinhard,
    /// Clamp to 0..1 (for tests that read display values directly).
    Clamp,
}

impl ToneMap {
    /// Name in scene files and plans.
    pub fn name(self) -> &'static str {
        match self {
            ToneMap::Aces => "aces",
            ToneMap::Reinhard => "reinhard",
            ToneMap::Clamp => "clamp",
        }
    }
}

/// How a point light's six shadow-map faces are drawn.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum PointShadowPass {
    /// Six depth-only passes, one viewport (atlas tile) each: every backend.
    SixPasses,
    /// The seed's single pass: a geometry shader emits each caster triangle once per face and
    /// routes it to that face's viewport (`gl_ViewportIndex`). Backends with geometry shaders
    /// only (`gl`); the same depth values as six passes.
    GeometryShader,
}

impl PointShadowPass {
    /// Name in scene files and plans.
    pub fn name(self) -> &'static str {
        match self {
            PointShadowPass::SixPasses => "six-passes",
            PointShadowPass::GeometryShader => "geometry-shader",
        }
    }
}

/// How the G-buffer stores positions (a precision knob).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum PositionStorage {
    /// World position minus the camera position, in fp16 (the default): precise at any distance
    /// from the origin.
    CameraRelative,
    /// World position in fp16: the naive layout, which breaks far from the origin (spacing 8 m
    /// at 10 km). Kept to show why.
    World,
    /// Nothing stored: the lighting pass reconstructs the position from the depth buffer (D32F)
    /// and the inverse view-projection.
    Depth,
}

/// How the G-buffer stores normals (a precision knob).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum NormalEncoding {
    /// xyz in fp16 (the default).
    Fp16,
    /// Octahedral: two fp16 components (the third channel left zero).
    Octahedral,
}

/// G-buffer precision settings (`[quality.gbuffer]`).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct GbufferSettings {
    /// Position storage.
    pub position: PositionStorage,
    /// Normal encoding.
    pub normal: NormalEncoding,
}

impl Default for GbufferSettings {
    fn default() -> Self {
        Self {
            position: PositionStorage::CameraRelative,
            normal: NormalEncoding::Fp16,
        }
    }
}

impl GbufferSettings {
    /// Short name, e.g. `camera-relative/fp16`.
    pub fn name(&self) -> String {
        let position = match self.position {
            PositionStorage::CameraRelative => "camera-relative",
            PositionStorage::World => "world",
            PositionStorage::Depth => "depth",
        };
        let normal = match self.normal {
            NormalEncoding::Fp16 => "fp16",
            NormalEncoding::Octahedral => "octahedral",
        };
        format!("{position}/{normal}")
    }
}

/// Output size and the knobs that trade time for error.
#[derive(Clone, Debug, PartialEq)]
pub struct Quality {
    /// Output width in pixels.
    pub width: u32,
    /// Output height in pixels.
    pub height: u32,
    /// Linear exposure applied before the light buffer (keeps fp16 in range).
    pub exposure: f32,
    /// Tone-mapping operator.
    pub tone_map: ToneMap,
    /// Whether the gizmos pass runs (axes, light directions, point-light markers).
    pub gizmos: bool,
    /// Debug outputs `shadow_term_<light>`: each shadowed light's shadow term per pixel, as the
    /// lighting pass computes it (for the ray-cast reference).
    pub debug_shadow_terms: bool,
    /// How point-light shadow faces are drawn (default: six passes, the faster on llvmpipe).
    pub point_shadows: PointShadowPass,
    /// Image-based lighting precompute settings (used only with an environment).
    pub ibl: crate::ibl::IblSettings,
    /// G-buffer position storage and normal encoding.
    pub gbuffer: GbufferSettings,
}

impl Default for Quality {
    fn default() -> Self {
        Self {
            width: 512,
            height: 512,
            exposure: 1.0,
            tone_map: ToneMap::Aces,
            gizmos: false,
            debug_shadow_terms: false,
            point_shadows: PointShadowPass::SixPasses,
            ibl: crate::ibl::IblSettings::default(),
            gbuffer: GbufferSettings::default(),
        }
    }
}

/// Everything one frame depends on.
#[derive(Clone, Debug)]
pub struct Scene {
    /// Scene name (file stem for scene files).
    pub name: String,
    /// The camera.
    pub camera: Camera,
    /// Drawables.
    pub objects: Vec<Object>,
    /// Lights, any number.
    pub lights: Vec<Light>,
    /// Uniform ambient radiance from every direction (linear RGB); zero for none.
    pub ambient: [f32; 3],
    /// Environment map, if any.
    pub environment: Option<Environment>,
    /// Textures referenced by materials ([`TextureIndex`]).
    pub textures: Vec<Arc<TextureImage>>,
    /// Output size and quality knobs.
    pub quality: Quality,
}

impl Scene {
    /// The lighting models the scene's objects use, in mask-channel order, without duplicates.
    pub fn lighting_models(&self) -> Vec<LightingModel> {
        LightingModel::ALL
            .into_iter()
            .filter(|m| self.objects.iter().any(|o| o.lighting == *m))
            .collect()
    }

    /// The same scene moved by `offset` (objects, lights and camera).
    pub fn translated(&self, offset: DVec3) -> Scene {
        let mut moved = self.clone();
        moved.camera.position += offset;
        moved.camera.target += offset;
        for object in &mut moved.objects {
            object.transform.translation += offset;
        }
        for light in &mut moved.lights {
            if let Light::Point { position, .. } = light {
                *position += offset;
            }
        }
        moved
    }
}

//! The scene file's TOML schema: the serde structs a file parses into ([`SceneFile`] and its
//! tables), with their defaults. Nothing here loads an asset.

use std::collections::BTreeMap;
use std::path::PathBuf;

use serde::Deserialize;

use crate::scene::IblSettings;
use crate::scene::{
    GbufferSettings, LightingModel, PointShadowPass, ShadowFilter, SsaoSettings, ToneMap,
};

/// Exactly three numbers. A TOML document's list deserialized into `[T; 3]` keeps its first
/// three and drops the rest without a word, so a fourth (a typo, a NaN) would pass unseen.
fn three<'de, D, T>(deserializer: D) -> Result<[T; 3], D::Error>
where
    D: serde::Deserializer<'de>,
    T: Deserialize<'de>,
{
    let values = Vec::<T>::deserialize(deserializer)?;
    let found = values.len();
    values
        .try_into()
        .map_err(|_| serde::de::Error::invalid_length(found, &"3 numbers"))
}

/// [`three`] for an optional field.
fn three_or_none<'de, D, T>(deserializer: D) -> Result<Option<[T; 3]>, D::Error>
where
    D: serde::Deserializer<'de>,
    T: Deserialize<'de>,
{
    three(deserializer).map(Some)
}

fn default_up() -> [f64; 3] {
    [0.0, 1.0, 0.0]
}
fn default_fov() -> f64 {
    45.0
}
fn default_near() -> f64 {
    0.05
}
fn default_far() -> f64 {
    100.0
}
fn default_one() -> f32 {
    1.0
}
fn default_true() -> bool {
    true
}

/// `[camera]`.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct CameraSpec {
    /// Eye position.
    #[serde(deserialize_with = "three")]
    pub position: [f64; 3],
    /// Point looked at.
    #[serde(deserialize_with = "three")]
    pub target: [f64; 3],
    /// Up vector (default +Y).
    #[serde(default = "default_up", deserialize_with = "three")]
    pub up: [f64; 3],
    /// Vertical field of view, degrees (default 45).
    #[serde(default = "default_fov")]
    pub fov_y: f64,
    /// Near plane (default 0.05).
    #[serde(default = "default_near")]
    pub near: f64,
    /// Far plane (default 100).
    #[serde(default = "default_far")]
    pub far: f64,
}

/// `[quality]`.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct QualitySpec {
    /// Output width (default 512).
    pub width: Option<u32>,
    /// Output height (default 512).
    pub height: Option<u32>,
    /// Linear exposure (default 1).
    pub exposure: Option<f32>,
    /// `aces` (default), `reinhard` or `clamp`.
    pub tone_map: Option<ToneMap>,
    /// Draw gizmos (default false).
    pub gizmos: Option<bool>,
    /// Write `shadow_term_<light>` debug outputs (default false).
    pub debug_shadow_terms: Option<bool>,
    /// `six-passes` (default) or `geometry-shader` (gl only).
    pub point_shadows: Option<PointShadowPass>,
    /// `[quality.ibl]`: image-based lighting precompute (defaults in [`IblSettings`]).
    pub ibl: Option<IblSettings>,
    /// `[quality.gbuffer]`: position storage and normal encoding (defaults: camera-relative,
    /// fp16).
    pub gbuffer: Option<GbufferSettings>,
    /// `[quality.ssao]`: screen-space ambient occlusion, `radius` (m, default 0.5) and
    /// `samples` (1..=64, default 32); none without the table.
    pub ssao: Option<SsaoSettings>,
}

/// `[environment]`.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct EnvironmentSpec {
    /// Equirectangular EXR or Radiance `.hdr`, relative to the scene file.
    pub path: PathBuf,
    /// Rotation about +Y in degrees.
    #[serde(default)]
    pub rotation: f32,
    /// Radiance multiplier (default 1).
    #[serde(default = "default_one")]
    pub intensity: f32,
}

/// Material overrides; every field is optional and replaces the MTL's value or the default.
#[derive(Clone, Debug, Default, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct MaterialSpec {
    /// Linear base color.
    #[serde(default, deserialize_with = "three_or_none")]
    pub base_color: Option<[f32; 3]>,
    /// Perceptual roughness.
    pub roughness: Option<f32>,
    /// Metallic.
    pub metallic: Option<f32>,
    /// Specular.
    pub specular: Option<f32>,
    /// Anisotropy -1..1.
    pub anisotropy: Option<f32>,
    /// Clearcoat strength.
    pub clearcoat: Option<f32>,
    /// Clearcoat roughness.
    pub clearcoat_roughness: Option<f32>,
    /// Blinn-Phong exponent.
    pub specular_exponent: Option<f32>,
    /// Set false to ignore the MTL's maps (scalars only).
    pub use_maps: Option<bool>,
}

/// A scale: one number or three.
#[derive(Clone, Copy, Debug, Deserialize)]
#[serde(untagged, expecting = "`scale` must be one number or a list of three")]
pub enum ScaleSpec {
    /// Uniform.
    Uniform(f64),
    /// Per axis.
    PerAxis([f64; 3]),
}

/// `[[objects]]`.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ObjectSpec {
    /// Name (default: the mesh file stem and index).
    pub name: Option<String>,
    /// OBJ path relative to the scene file, or `builtin:sphere` / `builtin:plane`.
    pub mesh: String,
    /// World position.
    #[serde(default, deserialize_with = "three")]
    pub position: [f64; 3],
    /// Euler angles in degrees, applied X, then Y, then Z.
    #[serde(default, deserialize_with = "three")]
    pub rotation: [f64; 3],
    /// Scale (default 1).
    pub scale: Option<ScaleSpec>,
    /// Lighting model (default `pbr`).
    pub lighting: Option<LightingModel>,
    /// Drawn into shadow maps (default true).
    #[serde(default = "default_true")]
    pub casts_shadows: bool,
    /// Overrides for every mesh of the object.
    #[serde(default)]
    pub material: MaterialSpec,
    /// Overrides per MTL material name (applied after `material`).
    #[serde(default)]
    pub materials: BTreeMap<String, MaterialSpec>,
}

/// `[lights.shadow]`.
#[derive(Clone, Copy, Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ShadowSpec {
    /// Map size in texels (default 1024).
    pub map_size: Option<u32>,
    /// Constant bias.
    pub bias: Option<f32>,
    /// Slope-scaled bias (texels, scaled by tan(angle)).
    pub slope_bias: Option<f32>,
    /// Normal offset in shadow-map texels.
    pub normal_offset: Option<f32>,
    /// `hard`, `pcf3` (default), `bilinear`, `pcf3-bilinear`, `soft`, `soft-full`,
    /// `soft-reference`, `vogel` or `vsm`.
    pub filter: Option<ShadowFilter>,
    /// Sample-disk radius of the soft filters, in texels (default 2.5).
    pub soft_radius: Option<f32>,
    /// Samples of the `vogel` filter (default 64).
    pub soft_samples: Option<u32>,
    /// VSM blur radius in texels (default 2).
    pub vsm_blur_radius: Option<u32>,
    /// VSM minimum variance (default 1e-6).
    pub vsm_min_variance: Option<f32>,
    /// VSM light-bleeding reduction, 0..1 (default 0.2).
    pub vsm_bleeding_reduction: Option<f32>,
}

/// `[[lights]]`, by its `type`.
#[derive(Debug, Deserialize)]
#[serde(tag = "type", rename_all = "kebab-case")]
pub enum LightSpec {
    /// A directional light.
    Directional(DirectionalLightSpec),
    /// A point light with the io7m r2 renderer's attenuation.
    Point(PointLightSpec),
}

/// `[[lights]]` with `type = "directional"`.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct DirectionalLightSpec {
    /// Direction from the scene towards the light.
    #[serde(deserialize_with = "three")]
    pub direction: [f64; 3],
    /// Linear color (default white).
    #[serde(default, deserialize_with = "three_or_none")]
    pub color: Option<[f32; 3]>,
    /// Intensity (default 1).
    pub intensity: Option<f32>,
    /// Shadow settings; absent means no shadows.
    pub shadow: Option<ShadowSpec>,
}

/// `[[lights]]` with `type = "point"`.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct PointLightSpec {
    /// Position.
    #[serde(deserialize_with = "three")]
    pub position: [f64; 3],
    /// Linear color (default white).
    #[serde(default, deserialize_with = "three_or_none")]
    pub color: Option<[f32; 3]>,
    /// Intensity (default 1).
    pub intensity: Option<f32>,
    /// Radius where the light reaches zero.
    pub radius: f32,
    /// Falloff exponent shape (default 1, linear).
    pub falloff: Option<f32>,
    /// Shadow settings; absent means no shadows.
    pub shadow: Option<ShadowSpec>,
}

/// A parsed scene file, before any asset is loaded.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct SceneFile {
    /// Scene name (default: file stem).
    pub name: Option<String>,
    /// One-line description shown by `harness inspect` and the report.
    pub description: Option<String>,
    /// Uniform ambient radiance (default black).
    #[serde(default, deserialize_with = "three")]
    pub ambient: [f32; 3],
    /// Camera.
    pub camera: CameraSpec,
    /// Quality.
    #[serde(default = "QualitySpec::empty")]
    pub quality: QualitySpec,
    /// Environment.
    pub environment: Option<EnvironmentSpec>,
    /// Objects.
    #[serde(default)]
    pub objects: Vec<ObjectSpec>,
    /// Lights.
    #[serde(default)]
    pub lights: Vec<LightSpec>,
    /// Per-pass tolerances, parsed by the harness.
    #[serde(default)]
    pub tolerances: toml::Table,
}

impl QualitySpec {
    fn empty() -> Self {
        Self {
            width: None,
            height: None,
            exposure: None,
            tone_map: None,
            gizmos: None,
            debug_shadow_terms: None,
            point_shadows: None,
            ibl: None,
            gbuffer: None,
            ssao: None,
        }
    }
}

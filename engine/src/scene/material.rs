//! How a surface looks: its [`LightingModel`] (which lighting pass shades it) and its
//! [`Material`] parameters and texture maps.

use std::fmt;
use std::str::FromStr;

use serde::{Deserialize, Serialize};

/// How the pixels of an object are lit. Each model used in a scene gets one shader-mask channel
/// and one full-screen lighting pass.
#[derive(Clone, Copy, Debug, PartialEq, Eq, PartialOrd, Ord, Hash, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum LightingModel {
    /// Filament's PBR: Lambert diffuse, GGX/Smith/Schlick specular, clearcoat, anisotropy.
    Pbr,
    /// Lambert diffuse plus Blinn-Phong specular with an exponent (the io7m r2 renderer's model).
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

/// Index of a texture in [`Scene::textures`](super::Scene::textures).
pub type TextureIndex = usize;

/// Surface parameters. Where a map is present it replaces the scalar (the Quarantamaula engine
/// document's rule: per-object parameters are the fallback where a material has no map).
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

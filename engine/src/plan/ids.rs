//! The typed identities of a frame: every render target ([`TargetId`]) and every pass
//! ([`PassId`]) of a [`RenderPlan`](super::RenderPlan), with the light or mask index they carry.
//!
//! This is the only module that turns an identity into a name or a name back into an identity.
//! Names exist at the edges only (the CLI's `--pass`, golden file names, JSON and TOML keys,
//! backend debug labels), through `Display` and `FromStr`; everything in between matches on the
//! enums. The names are those the goldens, the noise model and the plan snapshots have always
//! used (`gbuffer_normal`, `shadow_0`, `shadow_term_0`, `mask_1`, `lighting_blinn_phong`, ...).
//!
//! The model is bevy's typed `RenderLabel`, which replaced string node names: a misspelt target
//! is a compile error, and a new target is a new variant that every `match` has to place.

use std::fmt;
use std::str::FromStr;

use crate::scene::LightingModel;

/// One of the five G-buffer targets, in attachment order.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub enum GBufferTarget {
    /// xyz camera-relative position, w roughness.
    Position,
    /// xyz normal (normal-mapped), w specular.
    Normal,
    /// xyz tangent, w handedness.
    Tangent,
    /// rgb base color, a anisotropy.
    Albedo,
    /// r metallic, g clearcoat, b clearcoat roughness, a specular exponent.
    Material,
}

impl GBufferTarget {
    /// Every G-buffer target, in attachment order.
    pub const ALL: [GBufferTarget; 5] = [
        GBufferTarget::Position,
        GBufferTarget::Normal,
        GBufferTarget::Tangent,
        GBufferTarget::Albedo,
        GBufferTarget::Material,
    ];

    fn suffix(self) -> &'static str {
        match self {
            GBufferTarget::Position => "position",
            GBufferTarget::Normal => "normal",
            GBufferTarget::Tangent => "tangent",
            GBufferTarget::Albedo => "albedo",
            GBufferTarget::Material => "material",
        }
    }

    /// Whether the target holds unit vectors (normals, tangents), which a viewer maps from
    /// [-1, 1] to [0, 1].
    pub fn holds_directions(self) -> bool {
        matches!(self, GBufferTarget::Normal | GBufferTarget::Tangent)
    }
}

/// A render target of the plan. Every one can be read back; which of them get goldens, and
/// how they are compared, follows from [`TargetId::content`].
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub enum TargetId {
    /// A G-buffer target.
    GBuffer(GBufferTarget),
    /// The camera's depth.
    Depth,
    /// Shader-mask target `index` (four lighting models per target).
    Mask(usize),
    /// The lighting passes' routing depth: each lighting pass clears it, marks its model's
    /// pixels (from the mask) at depth 0, and draws its lights with an equal-depth test, so that
    /// the depth test skips other pixels before any shading.
    Route,
    /// The HDR light buffer.
    Light,
    /// The tone-mapped output.
    Final,
    /// The shadow map of light `light` (a point light's six faces in one atlas).
    Shadow {
        /// Index into the scene's lights.
        light: usize,
    },
    /// The VSM moments of light `light`.
    ShadowMoments {
        /// Index into the scene's lights.
        light: usize,
    },
    /// The VSM blur's intermediate target of light `light`.
    ShadowBlur {
        /// Index into the scene's lights.
        light: usize,
    },
    /// Debug: light `light`'s shadow term per pixel.
    ShadowTerm {
        /// Index into the scene's lights.
        light: usize,
    },
    /// Screen-space ambient occlusion: 1 unoccluded .. 0 occluded, in rgb.
    AmbientOcclusion,
}

/// What a target holds, which decides whether it gets a golden and how it is compared and
/// shown. A new target picks one of these, and the harness needs no change.
#[derive(Clone, Copy, Debug, PartialEq, Eq, PartialOrd, Ord)]
pub enum TargetContent {
    /// Surface attributes in fp16 (positions compare relatively, unit quantities absolutely).
    SurfaceAttributes,
    /// Depth in [0, 1] (the camera's, or a light's shadow map).
    Depth,
    /// One-hot channels in RGBA8.
    Mask,
    /// A visibility in [0, 1] per pixel (1 = fully lit or unoccluded), in the red channel.
    Visibility,
    /// HDR radiance.
    Radiance,
    /// The tone-mapped sRGB image.
    Display,
    /// Scratch data between passes (routing depth, VSM moments and blur): no golden.
    Intermediate,
}

impl TargetId {
    /// The G-buffer targets, in attachment order.
    pub const GBUFFER: [TargetId; 5] = [
        TargetId::GBuffer(GBufferTarget::Position),
        TargetId::GBuffer(GBufferTarget::Normal),
        TargetId::GBuffer(GBufferTarget::Tangent),
        TargetId::GBuffer(GBufferTarget::Albedo),
        TargetId::GBuffer(GBufferTarget::Material),
    ];

    /// What the target holds.
    pub fn content(self) -> TargetContent {
        match self {
            TargetId::GBuffer(_) => TargetContent::SurfaceAttributes,
            TargetId::Depth | TargetId::Shadow { .. } => TargetContent::Depth,
            TargetId::Mask(_) => TargetContent::Mask,
            TargetId::ShadowTerm { .. } | TargetId::AmbientOcclusion => TargetContent::Visibility,
            TargetId::Light => TargetContent::Radiance,
            TargetId::Final => TargetContent::Display,
            TargetId::Route | TargetId::ShadowMoments { .. } | TargetId::ShadowBlur { .. } => {
                TargetContent::Intermediate
            }
        }
    }

    /// The light whose shadow this target holds or derives from, if any.
    pub fn shadowed_light(self) -> Option<usize> {
        match self {
            TargetId::Shadow { light }
            | TargetId::ShadowMoments { light }
            | TargetId::ShadowBlur { light }
            | TargetId::ShadowTerm { light } => Some(light),
            _ => None,
        }
    }
}

impl TargetId {
    /// The target's name: in file names, JSON and TOML keys, and on the command line.
    fn name(self) -> String {
        match self {
            TargetId::GBuffer(g) => format!("gbuffer_{}", g.suffix()),
            TargetId::Depth => "depth".to_owned(),
            TargetId::Mask(0) => "mask".to_owned(),
            TargetId::Mask(index) => format!("mask_{index}"),
            TargetId::Route => "route".to_owned(),
            TargetId::Light => "light".to_owned(),
            TargetId::Final => "final".to_owned(),
            TargetId::Shadow { light } => format!("shadow_{light}"),
            TargetId::ShadowMoments { light } => format!("shadow_{light}_moments"),
            TargetId::ShadowBlur { light } => format!("shadow_{light}_blur"),
            TargetId::ShadowTerm { light } => format!("shadow_term_{light}"),
            TargetId::AmbientOcclusion => "ambient_occlusion".to_owned(),
        }
    }
}

impl fmt::Display for TargetId {
    /// The name, padded like a string (`{:<17}` lines up tables).
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.pad(&self.name())
    }
}

/// A name that is no target or pass of any plan.
#[derive(Clone, Debug, PartialEq, Eq, thiserror::Error)]
#[error("`{name}` is not a {what} name")]
pub struct UnknownName {
    /// The name given.
    pub name: String,
    /// "target" or "pass".
    pub what: &'static str,
}

/// `digits` as an index: ASCII digits only, no sign, no leading `+`.
fn index(digits: &str) -> Option<usize> {
    if digits.is_empty() || !digits.bytes().all(|b| b.is_ascii_digit()) {
        return None;
    }
    let value: usize = digits.parse().ok()?;
    // One spelling per index: `shadow_01` is not `shadow_1`.
    (value.to_string() == digits).then_some(value)
}

/// The light index and the rest of a `shadow_<light>[_<tail>]` name (`tail` empty when absent).
fn shadow_light_and_tail(name: &str) -> Option<(usize, &str)> {
    let rest = name.strip_prefix("shadow_")?;
    let (digits, tail) = rest.split_once('_').unwrap_or((rest, ""));
    Some((index(digits)?, tail))
}

impl FromStr for TargetId {
    type Err = UnknownName;

    fn from_str(name: &str) -> Result<Self, Self::Err> {
        let fixed = match name {
            "depth" => Some(TargetId::Depth),
            "mask" => Some(TargetId::Mask(0)),
            "route" => Some(TargetId::Route),
            "light" => Some(TargetId::Light),
            "final" => Some(TargetId::Final),
            "ambient_occlusion" => Some(TargetId::AmbientOcclusion),
            _ => None,
        };
        let gbuffer = || {
            let suffix = name.strip_prefix("gbuffer_")?;
            GBufferTarget::ALL
                .into_iter()
                .find(|g| g.suffix() == suffix)
                .map(TargetId::GBuffer)
        };
        let mask = || {
            index(name.strip_prefix("mask_")?)
                .filter(|&i| i > 0)
                .map(TargetId::Mask)
        };
        let shadow_term = || {
            Some(TargetId::ShadowTerm {
                light: index(name.strip_prefix("shadow_term_")?)?,
            })
        };
        let shadow = || {
            let (light, tail) = shadow_light_and_tail(name)?;
            match tail {
                "" => Some(TargetId::Shadow { light }),
                "moments" => Some(TargetId::ShadowMoments { light }),
                "blur" => Some(TargetId::ShadowBlur { light }),
                _ => None,
            }
        };
        fixed
            .or_else(gbuffer)
            .or_else(mask)
            .or_else(shadow_term)
            .or_else(shadow)
            .ok_or_else(|| UnknownName {
                name: name.to_owned(),
                what: "target",
            })
    }
}

/// The axis of one half of a separable blur.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub enum BlurAxis {
    /// Along x (first).
    X,
    /// Along y (second).
    Y,
}

/// A pass of the plan: what it does, and the light or lighting model it does it for.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub enum PassId {
    /// Draws the shadow casters into the depth map of light `light` (a point light's six atlas
    /// faces are six recorded passes, one viewport each), and for VSM into its moments too.
    Shadow {
        /// Index into the scene's lights.
        light: usize,
    },
    /// VSM: one direction of the separable Gaussian blur of light `light`'s moments.
    ShadowBlur {
        /// Index into the scene's lights.
        light: usize,
        /// The direction.
        axis: BlurAxis,
    },
    /// Draws every object into the G-buffer and depth.
    Geometry,
    /// Draws every object's one-hot lighting-model channel into the mask targets.
    ShaderMask,
    /// Screen-space ambient occlusion from the depth and normals (the io7m r2 renderer's
    /// filter).
    AmbientOcclusion,
    /// On the CPU, before any GPU pass: the environment's IBL maps (prefiltered specular,
    /// irradiance, DFG), read by the lighting passes; cached in memory and on disk.
    IblPrecompute,
    /// Fills uncovered pixels of the light buffer from the environment.
    Skybox,
    /// Shades one lighting model's pixels into the light buffer.
    Lighting(LightingModel),
    /// Clears the light buffer to black where nothing else writes it (no objects, no
    /// environment).
    ClearLight,
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

impl PassId {
    /// The pass's name: in timings, JSON, the plan's text and backend debug labels.
    fn name(self) -> String {
        match self {
            PassId::Shadow { light } => format!("shadow_{light}"),
            PassId::ShadowBlur { light, axis } => {
                let axis = match axis {
                    BlurAxis::X => "x",
                    BlurAxis::Y => "y",
                };
                format!("shadow_{light}_blur_{axis}")
            }
            PassId::Geometry => "geometry".to_owned(),
            PassId::ShaderMask => "mask".to_owned(),
            PassId::AmbientOcclusion => "ambient_occlusion".to_owned(),
            PassId::IblPrecompute => "ibl_precompute".to_owned(),
            PassId::Skybox => "skybox".to_owned(),
            PassId::Lighting(model) => format!("lighting_{}", model.name().replace('-', "_")),
            PassId::ClearLight => "clear_light".to_owned(),
            PassId::ShadowTerm { light } => format!("shadow_term_{light}"),
            PassId::ToneMap => "tonemap".to_owned(),
            PassId::Gizmos => "gizmos".to_owned(),
        }
    }
}

impl fmt::Display for PassId {
    /// The name, padded like a string.
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.pad(&self.name())
    }
}

impl FromStr for PassId {
    type Err = UnknownName;

    fn from_str(name: &str) -> Result<Self, Self::Err> {
        let fixed = match name {
            "geometry" => Some(PassId::Geometry),
            "mask" => Some(PassId::ShaderMask),
            "ambient_occlusion" => Some(PassId::AmbientOcclusion),
            "ibl_precompute" => Some(PassId::IblPrecompute),
            "skybox" => Some(PassId::Skybox),
            "clear_light" => Some(PassId::ClearLight),
            "tonemap" => Some(PassId::ToneMap),
            "gizmos" => Some(PassId::Gizmos),
            _ => None,
        };
        let lighting = || {
            let model = name.strip_prefix("lighting_")?;
            LightingModel::ALL
                .into_iter()
                .find(|m| m.name().replace('-', "_") == model)
                .map(PassId::Lighting)
        };
        let shadow_term = || {
            Some(PassId::ShadowTerm {
                light: index(name.strip_prefix("shadow_term_")?)?,
            })
        };
        let shadow = || {
            let (light, tail) = shadow_light_and_tail(name)?;
            match tail {
                "" => Some(PassId::Shadow { light }),
                "blur_x" => Some(PassId::ShadowBlur {
                    light,
                    axis: BlurAxis::X,
                }),
                "blur_y" => Some(PassId::ShadowBlur {
                    light,
                    axis: BlurAxis::Y,
                }),
                _ => None,
            }
        };
        fixed
            .or_else(lighting)
            .or_else(shadow_term)
            .or_else(shadow)
            .ok_or_else(|| UnknownName {
                name: name.to_owned(),
                what: "pass",
            })
    }
}

/// Identities in files and JSON are their names.
macro_rules! serde_by_name {
    ($id:ty) => {
        impl serde::Serialize for $id {
            fn serialize<S: serde::Serializer>(&self, s: S) -> Result<S::Ok, S::Error> {
                s.collect_str(self)
            }
        }

        impl<'de> serde::Deserialize<'de> for $id {
            fn deserialize<D: serde::Deserializer<'de>>(d: D) -> Result<Self, D::Error> {
                let name = String::deserialize(d)?;
                name.parse().map_err(serde::de::Error::custom)
            }
        }
    };
}

serde_by_name!(TargetId);
serde_by_name!(PassId);

#[cfg(test)]
mod tests {
    use super::*;

    fn every_target() -> Vec<TargetId> {
        let mut all: Vec<TargetId> = TargetId::GBUFFER.to_vec();
        all.extend([
            TargetId::Depth,
            TargetId::Route,
            TargetId::Light,
            TargetId::Final,
            TargetId::AmbientOcclusion,
        ]);
        for i in [0, 1, 7, 12] {
            all.extend([
                TargetId::Mask(i),
                TargetId::Shadow { light: i },
                TargetId::ShadowMoments { light: i },
                TargetId::ShadowBlur { light: i },
                TargetId::ShadowTerm { light: i },
            ]);
        }
        all
    }

    fn every_pass() -> Vec<PassId> {
        let mut all = vec![
            PassId::Geometry,
            PassId::ShaderMask,
            PassId::AmbientOcclusion,
            PassId::IblPrecompute,
            PassId::Skybox,
            PassId::ClearLight,
            PassId::ToneMap,
            PassId::Gizmos,
        ];
        all.extend(LightingModel::ALL.map(PassId::Lighting));
        for light in [0, 3, 10] {
            all.extend([
                PassId::Shadow { light },
                PassId::ShadowTerm { light },
                PassId::ShadowBlur {
                    light,
                    axis: BlurAxis::X,
                },
                PassId::ShadowBlur {
                    light,
                    axis: BlurAxis::Y,
                },
            ]);
        }
        all
    }

    #[test]
    fn every_name_parses_back_to_its_identity() {
        for id in every_target() {
            assert_eq!(id.to_string().parse::<TargetId>(), Ok(id), "{id}");
        }
        for id in every_pass() {
            assert_eq!(id.to_string().parse::<PassId>(), Ok(id), "{id}");
        }
    }

    #[test]
    fn the_names_are_the_goldens_names() {
        let names: Vec<String> = TargetId::GBUFFER.iter().map(ToString::to_string).collect();
        assert_eq!(
            names,
            [
                "gbuffer_position",
                "gbuffer_normal",
                "gbuffer_tangent",
                "gbuffer_albedo",
                "gbuffer_material"
            ]
        );
        assert_eq!(TargetId::Mask(0).to_string(), "mask");
        assert_eq!(TargetId::Mask(1).to_string(), "mask_1");
        assert_eq!(
            TargetId::ShadowTerm { light: 2 }.to_string(),
            "shadow_term_2"
        );
        assert_eq!(
            TargetId::ShadowMoments { light: 0 }.to_string(),
            "shadow_0_moments"
        );
        assert_eq!(
            PassId::Lighting(LightingModel::BlinnPhong).to_string(),
            "lighting_blinn_phong"
        );
        assert_eq!(
            PassId::ShadowBlur {
                light: 1,
                axis: BlurAxis::Y
            }
            .to_string(),
            "shadow_1_blur_y"
        );
    }

    #[test]
    fn names_that_are_no_identity_are_refused() {
        for name in [
            "",
            "gbuffer_",
            "gbuffer_colour",
            "mask_0",
            "mask_",
            "mask_x",
            "shadow_",
            "shadow_-1",
            "shadow_01",
            "shadow_+1",
            "shadow_1_blur_z",
            "shadow_term_",
            "shadow_term_a",
            "lighting_",
            "lighting_blinn-phong",
            "Final",
            " final",
        ] {
            assert!(
                name.parse::<TargetId>().is_err() || name == "mask_0",
                "{name:?} as target"
            );
            assert!(name.parse::<PassId>().is_err(), "{name:?} as pass");
        }
        assert!(
            "mask_0".parse::<TargetId>().is_err(),
            "mask 0 is spelt `mask`"
        );
    }

    #[test]
    fn names_pad_like_strings_in_tables() {
        assert_eq!(format!("{:<8}|", TargetId::Light), "light   |");
        assert_eq!(format!("{:>10}|", PassId::ToneMap), "   tonemap|");
    }

    #[test]
    fn identities_are_their_names_in_json() {
        let json =
            serde_json::to_string(&[TargetId::ShadowTerm { light: 0 }, TargetId::Final]).unwrap();
        assert_eq!(json, r#"["shadow_term_0","final"]"#);
        let back: Vec<TargetId> = serde_json::from_str(&json).unwrap();
        assert_eq!(back, [TargetId::ShadowTerm { light: 0 }, TargetId::Final]);
        assert!(serde_json::from_str::<TargetId>(r#""bogus""#).is_err());
    }
}

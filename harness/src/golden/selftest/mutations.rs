//! The known changes of the self-test: what each is, the pass where it must be caught, and how
//! it changes a scene (or the renderer, through an injected fault).

use engine::plan::{GBufferTarget, TargetId};
use engine::renderer::Variations;
use engine::scene::{Light, LightingModel, Material, Scene};
use glam::DQuat;

/// A known change.
#[derive(Clone, Copy, Debug, PartialEq, Eq, PartialOrd, Ord, serde::Serialize)]
pub enum Mutation {
    /// Every light's intensity x1.02.
    LightIntensity,
    /// Exposure x1.03.
    Exposure,
    /// The first point light moved 1 cm along +X.
    PointLightMoved,
    /// Environment intensity x1.02.
    EnvironmentIntensity,
    /// Environment rotated 2 degrees.
    EnvironmentRotation,
    /// Every shadow's constant and slope-scaled bias x4.
    ShadowBias,
    /// Roughness ±0.05 (down where up would pass 1) on the first PBR object whose roughness is a
    /// scalar.
    Roughness,
    /// Metallic ±0.05 on the first PBR object whose metallic is a scalar.
    Metallic,
    /// Clearcoat ±0.05 on the first PBR object whose clearcoat is a scalar.
    Clearcoat,
    /// Specular ±0.05 on the first PBR object whose specular is a scalar.
    Specular,
    /// Base color x0.97 on the first PBR object whose base color is a scalar.
    BaseColor,
    /// Albedo red and blue swapped in the G-buffer (an injected fault).
    GbufferChannelSwap,
    /// Camera turned 0.25 degrees about its up axis.
    CameraYaw,
    /// The last object drawn with another lighting model (PBR <-> Lambert).
    LightingModel,
    /// The tone-mapping pass scales its input by 1.03 (an injected fault: the light buffer is
    /// untouched).
    ToneCurve,
    /// The screen-space ambient occlusion's radius x1.1.
    OcclusionRadius,
}

impl Mutation {
    /// Every mutation.
    pub const ALL: [Mutation; 16] = [
        Mutation::LightIntensity,
        Mutation::Exposure,
        Mutation::PointLightMoved,
        Mutation::EnvironmentIntensity,
        Mutation::EnvironmentRotation,
        Mutation::ShadowBias,
        Mutation::Roughness,
        Mutation::Metallic,
        Mutation::Clearcoat,
        Mutation::Specular,
        Mutation::BaseColor,
        Mutation::GbufferChannelSwap,
        Mutation::CameraYaw,
        Mutation::LightingModel,
        Mutation::ToneCurve,
        Mutation::OcclusionRadius,
    ];

    /// Short description.
    pub fn describe(self) -> &'static str {
        match self {
            Mutation::LightIntensity => "light intensity x1.02",
            Mutation::Exposure => "exposure x1.03",
            Mutation::PointLightMoved => "point light moved 1 cm",
            Mutation::EnvironmentIntensity => "environment intensity x1.02",
            Mutation::EnvironmentRotation => "environment rotated 2 deg",
            Mutation::ShadowBias => "shadow bias x4",
            Mutation::Roughness => "roughness ±0.05 on one material",
            Mutation::Metallic => "metallic ±0.05 on one material",
            Mutation::Clearcoat => "clearcoat ±0.05 on one material",
            Mutation::Specular => "specular ±0.05 on one material",
            Mutation::BaseColor => "base color x0.97 on one material",
            Mutation::GbufferChannelSwap => "G-buffer albedo R<->B swapped",
            Mutation::CameraYaw => "camera yaw 0.25 deg",
            Mutation::LightingModel => "one object's lighting model",
            Mutation::ToneCurve => "tone-map input x1.03",
            Mutation::OcclusionRadius => "ssao radius x1.1",
        }
    }

    /// The golden pass where the change first shows, and so must be caught: lighting changes in
    /// the light buffer, material changes in the G-buffer target that holds them, geometry in
    /// depth, the lighting model in the mask, tone mapping in the final image, the occlusion's
    /// radius in the occlusion.
    pub fn origin(self) -> TargetId {
        match self {
            Mutation::LightIntensity
            | Mutation::Exposure
            | Mutation::PointLightMoved
            | Mutation::EnvironmentIntensity
            | Mutation::EnvironmentRotation
            | Mutation::ShadowBias => TargetId::Light,
            Mutation::Roughness => TargetId::GBuffer(GBufferTarget::Position),
            Mutation::Metallic | Mutation::Clearcoat => TargetId::GBuffer(GBufferTarget::Material),
            Mutation::Specular => TargetId::GBuffer(GBufferTarget::Normal),
            Mutation::BaseColor | Mutation::GbufferChannelSwap => {
                TargetId::GBuffer(GBufferTarget::Albedo)
            }
            Mutation::CameraYaw => TargetId::Depth,
            Mutation::LightingModel => TargetId::Mask(0),
            Mutation::ToneCurve => TargetId::Final,
            Mutation::OcclusionRadius => TargetId::AmbientOcclusion,
        }
    }

    /// Whether the mutation changes the environment, which the IBL maps and an extracted sun
    /// derive from: it applies to the scene as loaded, which is then prepared anew. Every other
    /// mutation applies to the scene as drawn, an extracted sun's light included.
    pub fn changes_environment(self) -> bool {
        matches!(
            self,
            Mutation::EnvironmentIntensity | Mutation::EnvironmentRotation
        )
    }

    /// Applies the mutation; `None` when the scene has nothing it could change (no lights, no
    /// environment, no shadow-casting light, no scalar material parameter, ...).
    pub fn apply(self, scene: &Scene) -> Option<(Scene, Variations)> {
        let mut s = scene.clone();
        let mut variations = Variations::default();
        match self {
            Mutation::LightIntensity => {
                if s.lights.is_empty() {
                    return None;
                }
                for light in &mut s.lights {
                    match light {
                        Light::Directional { intensity, .. } | Light::Point { intensity, .. } => {
                            *intensity *= 1.02
                        }
                    }
                }
            }
            Mutation::Exposure => s.quality.exposure *= 1.03,
            Mutation::PointLightMoved => {
                let position = s.lights.iter_mut().find_map(|l| match l {
                    Light::Point { position, .. } => Some(position),
                    Light::Directional { .. } => None,
                })?;
                position.x += 0.01;
            }
            Mutation::EnvironmentIntensity => s.environment.as_mut()?.intensity *= 1.02,
            Mutation::EnvironmentRotation => {
                s.environment.as_mut()?.rotation_degrees += 2.0;
            }
            Mutation::ShadowBias => {
                let mut any = false;
                for light in &mut s.lights {
                    match light {
                        Light::Directional { shadow, .. } | Light::Point { shadow, .. } => {
                            if let Some(shadow) = shadow {
                                shadow.bias *= 4.0;
                                shadow.slope_bias *= 4.0;
                                any = true;
                            }
                        }
                    }
                }
                if !any {
                    return None;
                }
            }
            Mutation::Roughness => {
                let m = scalar_material(&mut s, |m| m.roughness_map.is_none())?;
                m.roughness = nudge(m.roughness);
            }
            Mutation::Metallic => {
                let m = scalar_material(&mut s, |m| m.metallic_map.is_none())?;
                m.metallic = nudge(m.metallic);
            }
            Mutation::Clearcoat => {
                let m = scalar_material(&mut s, |m| m.clearcoat_map.is_none())?;
                m.clearcoat = nudge(m.clearcoat);
            }
            Mutation::Specular => {
                let m = scalar_material(&mut s, |m| m.specular_map.is_none())?;
                m.specular = nudge(m.specular);
            }
            Mutation::BaseColor => {
                let m = scalar_material(&mut s, |m| m.base_color_map.is_none())?;
                m.base_color = m.base_color.map(|c| c * 0.97);
            }
            Mutation::GbufferChannelSwap => variations.swap_albedo_red_blue = true,
            Mutation::CameraYaw => {
                let c = &mut s.camera;
                let rotation = DQuat::from_axis_angle(c.up.normalize(), 0.25f64.to_radians());
                c.target = c.position + rotation * (c.target - c.position);
            }
            Mutation::LightingModel => {
                let object = s.objects.last_mut()?;
                object.lighting = if object.lighting == LightingModel::Pbr {
                    LightingModel::Lambert
                } else {
                    LightingModel::Pbr
                };
            }
            Mutation::ToneCurve => variations.tonemap_input_scale = Some(1.03),
            Mutation::OcclusionRadius => s.quality.ssao.as_mut()?.radius *= 1.1,
        }
        Some((s, variations))
    }
}

/// A 0..1 material parameter moved by 0.05: up, or down where up would leave the range.
fn nudge(value: f32) -> f32 {
    if value <= 0.95 {
        value + 0.05
    } else {
        value - 0.05
    }
}

/// The material of the first PBR object for which `scalar` holds (the parameter is not a map).
fn scalar_material(scene: &mut Scene, scalar: impl Fn(&Material) -> bool) -> Option<&mut Material> {
    scene
        .objects
        .iter_mut()
        .find(|o| o.lighting == LightingModel::Pbr && scalar(&o.material))
        .map(|o| &mut o.material)
}

impl Mutation {
    /// Whether `pass` is where this mutation originates (any shadow term, for the shadow bias).
    pub fn is_origin(self, pass: TargetId) -> bool {
        match self {
            Mutation::ShadowBias => matches!(pass, TargetId::ShadowTerm { .. }),
            _ => pass == self.origin(),
        }
    }

    /// Whether this mutation reaches `output` directly, not through another output: where
    /// `check`'s verdict may say it starts. Its origin, and for a change that two passes read
    /// on their own, the other: the shadow bias also in the light buffer (the lighting passes
    /// apply it), a moved point light also in its shadow maps (drawn from the light).
    pub fn starts_in(self, output: TargetId) -> bool {
        match self {
            Mutation::ShadowBias => self.is_origin(output) || output == TargetId::Light,
            Mutation::PointLightMoved => {
                self.is_origin(output) || matches!(output, TargetId::Shadow { .. })
            }
            _ => self.is_origin(output),
        }
    }
}

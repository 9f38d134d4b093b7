//! Output size and the knobs that trade time for error: [`Quality`], with its tone mapping,
//! point-shadow drawing and G-buffer precision settings.

use serde::{Deserialize, Serialize};

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
    /// The Quarantamaula engine's single pass (its Listing 2): a geometry shader emits each
    /// caster triangle once per face and routes it to that face's viewport (`gl_ViewportIndex`).
    /// Backends with geometry shaders only (`gl`); the same depth values as six passes.
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

/// Screen-space ambient occlusion (`[quality.ssao]`; the io7m r2 renderer's filter): a
/// hemisphere of `samples` kernel points of radius `radius` around each pixel's surface, each
/// tested against the depth buffer. Its occlusion scales the ambient and IBL diffuse light.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct SsaoSettings {
    /// Hemisphere radius in meters (world units).
    pub radius: f32,
    /// Kernel points, 1..=64.
    pub samples: u32,
}

impl Default for SsaoSettings {
    fn default() -> Self {
        Self {
            radius: 0.5,
            samples: 32,
        }
    }
}

impl SsaoSettings {
    /// Most kernel points a scene may ask for (the kernel is a uniform array of this size).
    pub const MAX_SAMPLES: u32 = 64;

    /// Why these settings cannot be used, if they cannot.
    pub fn problem(&self) -> Option<String> {
        if !(self.radius.is_finite() && self.radius > 0.0) {
            return Some(format!(
                "ssao radius {} must be finite and positive",
                self.radius
            ));
        }
        if !(1..=Self::MAX_SAMPLES).contains(&self.samples) {
            return Some(format!(
                "ssao samples {} must be in 1..={}",
                self.samples,
                Self::MAX_SAMPLES
            ));
        }
        None
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
    pub ibl: super::IblSettings,
    /// G-buffer position storage and normal encoding.
    pub gbuffer: GbufferSettings,
    /// Screen-space ambient occlusion; none (the default) plans no occlusion pass.
    pub ssao: Option<SsaoSettings>,
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
            ibl: super::IblSettings::default(),
            gbuffer: GbufferSettings::default(),
            ssao: None,
        }
    }
}

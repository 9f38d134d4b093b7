//! The image-based lighting's quality knobs (`[quality.ibl]` in scene files), and their
//! checks. The precompute that reads them is in [`crate::ibl`].

use serde::{Deserialize, Serialize};

/// How the diffuse irradiance map is built.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum IrradianceMethod {
    /// Exact cosine convolution of a 32 x 32 source mip.
    Convolution,
    /// Nine spherical-harmonic coefficients (order 2).
    Sh9,
}

impl IrradianceMethod {
    /// Name in scene files and plans.
    pub fn name(self) -> &'static str {
        match self {
            IrradianceMethod::Convolution => "convolution",
            IrradianceMethod::Sh9 => "sh9",
        }
    }
}

/// Where the split sum looks up its prefiltered lobe: the reflection vector leaned towards the
/// normal as roughness grows, by one of two published rules.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum DominantDirection {
    /// Filament's getSpecularDominantDirection: `mix(R, N, roughness^4)`.
    #[default]
    Filament,
    /// Lagarde and de Rousiers, "Moving Frostbite to PBR" (2014): `mix(N, R, (1 - a)(sqrt(1 - a)
    /// + a))` with `a = roughness^2`, which leans further towards N.
    Frostbite,
}

/// How the split sum reads an anisotropic pixel's lobe.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum AnisotropicLookup {
    /// One lookup about a normal bent towards the anisotropic direction (Filament's
    /// getReflectedVector).
    #[default]
    BentNormal,
    /// Four lookups at half vectors spread along the axis with the larger alpha, each leaned by
    /// Frostbite's rule and weighted down where it reflects below the surface (measured in
    /// docs/renderer.md).
    Taps,
}

/// How many times its own solid angle a filtered importance sample reads (`[quality.ibl]
/// runtime_footprint`): a power of two from 1/16 to 64, kept as its exponent so that settings
/// compare and hash exactly. Written and read in scene files as the number (`0.25`, `1`, `4`).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, Serialize, Deserialize)]
#[serde(try_from = "f64", into = "f64")]
pub struct Footprint {
    log2: i8,
}

impl Footprint {
    /// A read the size of the sample's solid angle.
    pub const ONE: Self = Self { log2: 0 };

    /// The footprint `2^log2`, if `log2` is in -4..=6.
    pub fn from_log2(log2: i8) -> Option<Self> {
        (-4..=6).contains(&log2).then_some(Self { log2 })
    }

    /// The factor.
    pub fn factor(self) -> f64 {
        2f64.powi(i32::from(self.log2))
    }
}

impl TryFrom<f64> for Footprint {
    type Error = String;

    fn try_from(value: f64) -> Result<Self, String> {
        let log2 = value.log2();
        if value > 0.0 && log2.fract() == 0.0 {
            if let Some(footprint) = Self::from_log2(log2 as i8) {
                return Ok(footprint);
            }
        }
        Err(format!(
            "runtime_footprint {value} must be a power of two from 1/16 to 64 (0.0625 .. 64)"
        ))
    }
}

impl From<Footprint> for f64 {
    fn from(footprint: Footprint) -> f64 {
        footprint.factor()
    }
}

impl std::fmt::Display for Footprint {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "{}", self.factor())
    }
}

/// The most suns `extracted_lights` may ask for.
pub const MAX_EXTRACTED_LIGHTS: u32 = 8;

/// The IBL quality knobs (`[quality.ibl]` in scene files).
#[derive(Clone, Debug, PartialEq, Eq, Hash, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct IblSettings {
    /// Face size of the environment cube the prefilter reads (power of two).
    pub source_size: u32,
    /// Face size of the prefiltered specular cube's level 0 (power of two, at most
    /// `source_size`); levels go down to 4 x 4.
    pub specular_size: u32,
    /// GGX samples per texel of level 1; each level after it takes four times more (see
    /// [`samples_at`](crate::ibl::specular::samples_at)).
    pub specular_samples: u32,
    /// Face size of the irradiance cube.
    pub irradiance_size: u32,
    /// How irradiance is computed.
    pub irradiance: IrradianceMethod,
    /// Seed of the sample pattern (0: plain Hammersley; others add a seeded Cranley-Patterson
    /// rotation), to check that the result does not depend on the pattern.
    pub seed: u32,
    /// Specular IBL at render time: 0 uses the split sum (one lookup in the prefiltered cube
    /// with the DFG table); N > 0 integrates the full GGX lobe (anisotropic where the surface
    /// is) with N filtered importance samples per pixel, each read from the environment's
    /// box-filtered mip chain at the level whose texels cover `runtime_footprint` times the
    /// sample's solid angle (Krivanek and Colbert, "Real-time Shading with Filtered Importance
    /// Sampling", 2008). Lobes narrower than a level-0 texel of the prefiltered cube (alpha <
    /// 2 / `specular_size`) keep the split sum's lookup. It changes no precomputed map.
    pub runtime_samples: u32,
    /// How many times its own solid angle a filtered importance sample's read covers (a power
    /// of two from 1/16 to 64; Krivanek and Colbert read 4, one level up). It changes no
    /// precomputed map.
    pub runtime_footprint: Footprint,
    /// With `runtime_samples` 0: this many filtered importance samples for the anisotropic
    /// pixels only (0: the split sum there too), where the split sum's isotropic prefilter is
    /// furthest off. It changes no precomputed map.
    pub anisotropic_samples: u32,
    /// The split sum's dominant direction (`filament` or `frostbite`). It changes no
    /// precomputed map.
    pub dominant_direction: DominantDirection,
    /// How the split sum reads anisotropic pixels (`bent-normal` or `taps`). It changes no
    /// precomputed map.
    pub anisotropic_lookup: AnisotropicLookup,
    /// Cut the environment's sun out of the maps and light it as a directional light instead
    /// ([`crate::ibl::sun`]).
    pub extract_sun: bool,
    /// With `extract_sun`: how many suns to cut out, one after another (each time the region
    /// around the brightest texel left), each lit as a directional light of its own (1, the
    /// default: the sun alone; an interior's lamps need more). A region is taken only while it
    /// is a sun by [`crate::ibl::sun`]'s rule, so an image with fewer gives fewer lights.
    pub extracted_lights: u32,
    /// Whether the extracted sun casts a shadow (with the default [`ShadowSettings`]). It
    /// changes no precomputed map.
    ///
    /// [`ShadowSettings`]: crate::scene::ShadowSettings
    pub sun_shadow: bool,
}

impl Default for IblSettings {
    fn default() -> Self {
        Self {
            source_size: 256,
            specular_size: 128,
            specular_samples: 256,
            irradiance_size: 32,
            irradiance: IrradianceMethod::Convolution,
            seed: 0,
            runtime_samples: 0,
            runtime_footprint: Footprint::ONE,
            anisotropic_samples: 0,
            dominant_direction: DominantDirection::Filament,
            anisotropic_lookup: AnisotropicLookup::BentNormal,
            extract_sun: false,
            extracted_lights: 1,
            sun_shadow: true,
        }
    }
}

impl IblSettings {
    /// These settings with every knob that changes no precomputed map (the ones read at render
    /// time: samples, footprint, dominant direction, anisotropic lookup, the sun's shadow; and
    /// the count of suns when none is extracted) at its default: what the maps are a function
    /// of, so settings that differ only there share maps. A new render-time field belongs here
    /// too.
    pub fn precomputed_part(&self) -> IblSettings {
        let d = IblSettings::default();
        IblSettings {
            extracted_lights: if self.extract_sun {
                self.extracted_lights
            } else {
                d.extracted_lights
            },
            runtime_samples: d.runtime_samples,
            runtime_footprint: d.runtime_footprint,
            anisotropic_samples: d.anisotropic_samples,
            dominant_direction: d.dominant_direction,
            anisotropic_lookup: d.anisotropic_lookup,
            sun_shadow: d.sun_shadow,
            ..self.clone()
        }
    }

    /// Why these settings cannot be used, if they cannot.
    pub fn problem(&self) -> Option<String> {
        let pow2 = |v: u32| v.is_power_of_two();
        if !pow2(self.source_size) || !(16..=2048).contains(&self.source_size) {
            return Some(format!(
                "ibl source_size {} must be a power of two in 16..2048",
                self.source_size
            ));
        }
        if !pow2(self.specular_size)
            || self.specular_size < 8
            || self.specular_size > self.source_size
        {
            return Some(format!(
                "ibl specular_size {} must be a power of two from 8 to source_size {}",
                self.specular_size, self.source_size
            ));
        }
        if !(1..=65536).contains(&self.specular_samples) {
            return Some(format!(
                "ibl specular_samples {} must be in 1..65536",
                self.specular_samples
            ));
        }
        if self.anisotropic_samples > 1024 {
            return Some(format!(
                "ibl anisotropic_samples {} must be at most 1024",
                self.anisotropic_samples
            ));
        }
        if self.runtime_samples > 1024 {
            return Some(format!(
                "ibl runtime_samples {} must be at most 1024",
                self.runtime_samples
            ));
        }
        if !(1..=MAX_EXTRACTED_LIGHTS).contains(&self.extracted_lights) {
            return Some(format!(
                "ibl extracted_lights {} must be from 1 to {MAX_EXTRACTED_LIGHTS}",
                self.extracted_lights
            ));
        }
        if !(1..=256).contains(&self.irradiance_size) {
            return Some(format!(
                "ibl irradiance_size {} must be in 1..256",
                self.irradiance_size
            ));
        }
        None
    }
}

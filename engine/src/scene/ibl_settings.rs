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
    /// is) with N filtered importance samples per pixel, each read from the prefiltered cube at
    /// the roughness whose lobe covers the sample's solid angle (Krivanek and Colbert, "Real-time
    /// Shading with Filtered Importance Sampling", 2008). Lobes narrower than a level-0 texel
    /// of the prefiltered cube (alpha < 2 / `specular_size`) keep the split sum's lookup. It
    /// changes no precomputed map.
    pub runtime_samples: u32,
    /// Cut the environment's sun out of the maps and light it as a directional light instead
    /// ([`crate::ibl::sun`]).
    pub extract_sun: bool,
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
            extract_sun: false,
            sun_shadow: true,
        }
    }
}

impl IblSettings {
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
        if self.runtime_samples > 1024 {
            return Some(format!(
                "ibl runtime_samples {} must be at most 1024",
                self.runtime_samples
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

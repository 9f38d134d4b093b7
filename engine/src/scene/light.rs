//! Lights and their shadows: [`Light`], its [`ShadowSettings`], and the [`ShadowFilter`] that
//! turns a shadow map into a visibility.

use glam::DVec3;
use serde::{Deserialize, Serialize};

/// How a shadow map is filtered.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum ShadowFilter {
    /// One depth comparison (hard shadows).
    Hard,
    /// 3x3 percentage-closer filtering (nine comparisons, one texel apart).
    Pcf3,
    /// Stratified soft shadows (GPU Gems 2, ch. 17, as the Quarantamaula engine uses them): 16
    /// samples in 4 concentric rings of 4 sectors within `soft_radius` texels, jittered per pixel
    /// from a precomputed texture; the outer ring is tested first and, when its 4 samples agree,
    /// that answer is returned.
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
    /// Variance shadow maps (GPU Gems 3, ch. 8, as the io7m r2 renderer implements them;
    /// directional lights only): the map stores depth and depth squared, blurred by a separable
    /// Gaussian, sampled bilinearly, and turned into a visibility by Chebyshev's bound with a
    /// minimum variance and light-bleeding reduction.
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

impl Light {
    /// What is wrong with a light's shadow settings, if anything: map size 64..8192, biases and
    /// radii finite and non-negative, VSM only on directional lights with its blur radius at most 16
    /// texels and its light-bleeding reduction below 1.
    pub fn shadow_problem(&self) -> Option<String> {
        let light = self;
        let (Light::Directional {
            shadow: Some(s), ..
        }
        | Light::Point {
            shadow: Some(s), ..
        }) = light
        else {
            return None;
        };
        if !(64..=8192).contains(&s.map_size) {
            return Some(format!(
                "shadow map_size {} must be in 64..8192",
                s.map_size
            ));
        }
        let values = [
            ("bias", s.bias),
            ("slope_bias", s.slope_bias),
            ("normal_offset", s.normal_offset),
            ("soft_radius", s.soft_radius),
            ("vsm_min_variance", s.vsm_min_variance),
            ("vsm_bleeding_reduction", s.vsm_bleeding_reduction),
        ];
        if let Some((name, value)) = values.iter().find(|(_, v)| !(v.is_finite() && *v >= 0.0)) {
            return Some(format!(
                "shadow {name} {value} must be finite and not negative"
            ));
        }
        if !(1..=4096).contains(&s.soft_samples) {
            return Some(format!(
                "soft_samples {} must be in 1..4096",
                s.soft_samples
            ));
        }
        if s.filter == ShadowFilter::Vsm {
            if matches!(light, Light::Point { .. }) {
                return Some(
                    "filter `vsm` is for directional lights; point lights take every other filter"
                        .to_owned(),
                );
            }
            if s.vsm_blur_radius > 16 || s.vsm_bleeding_reduction >= 1.0 {
                return Some(format!(
                    "vsm_blur_radius {} must be at most 16 and vsm_bleeding_reduction {} below 1",
                    s.vsm_blur_radius, s.vsm_bleeding_reduction
                ));
            }
        }
        None
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn vsm_is_refused_on_point_lights_and_checked_for_range() {
        let point = |settings: ShadowSettings| Light::Point {
            position: DVec3::ZERO,
            color: [1.0; 3],
            intensity: 1.0,
            radius: 1.0,
            falloff: 1.0,
            shadow: Some(settings),
        };
        let vsm = ShadowSettings {
            filter: ShadowFilter::Vsm,
            ..ShadowSettings::default()
        };
        assert!(point(vsm).shadow_problem().unwrap().contains("directional"));
        assert!(point(ShadowSettings::default()).shadow_problem().is_none());
        let directional = |settings: ShadowSettings| Light::Directional {
            direction: DVec3::Y,
            color: [1.0; 3],
            intensity: 1.0,
            angular_radius: 0.0,
            shadow: Some(settings),
        };
        assert!(directional(vsm).shadow_problem().is_none());
        let wide = ShadowSettings {
            vsm_blur_radius: 17,
            ..vsm
        };
        assert!(directional(wide).shadow_problem().is_some());
        let nan = ShadowSettings {
            vsm_min_variance: f32::NAN,
            ..vsm
        };
        assert!(directional(nan).shadow_problem().is_some());
    }
}

//! Test and benchmark hooks: deliberate departures from the scene that no scene file can
//! express. The harness's mutation self-test injects faults (proof that the golden tolerances
//! catch a broken pass), and the bench's cost breakdown takes lighting work away. A plain
//! render has none; they reach a frame only through
//! [`PreparedFrame::with_variations`](super::PreparedFrame::with_variations), never through the
//! renderer's main signatures.

use crate::plan::{LightingFeature, PassId};

/// What a frame does differently from its scene. All off by default.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Variations {
    /// Fault: the geometry pass writes albedo with red and blue swapped.
    pub swap_albedo_red_blue: bool,
    /// Fault: the tone-mapping pass scales the light buffer by this before its curve (a fault
    /// in the last pass only: the light buffer stays as it was).
    pub tonemap_input_scale: Option<f32>,
    /// Bench: the lighting passes run without this part of their work (see
    /// [`RenderPlan::remove_lighting_feature`](crate::plan::RenderPlan::remove_lighting_feature)).
    pub remove_lighting: Option<LightingFeature>,
    /// Fault: the light uniforms carry each light's radiance times this, a fault in the uniform
    /// packing that only a reference deriving the lights from the scene itself catches.
    pub light_radiance_scale: Option<f32>,
    /// Speed: one plan pass does more work, the slowdown the speed self-test injects (see
    /// [`SlowPass`]). A pass that adds into its target adds more than once: its pixels are not
    /// the point.
    pub slow_pass: Option<SlowPass>,
    /// Speed: the lighting passes lose their specialisation, a real regression reproduced
    /// (`harness check --debug-unspecialised-lighting`): every draw compiles the one generic
    /// variant, with every light slot a draw holds, both light types, the IBL, and the sun
    /// disc, clearcoat and anisotropy chosen per pixel (see
    /// [`RenderPlan::unspecialise_lighting`](crate::plan::RenderPlan::unspecialise_lighting)).
    /// The picture is the same; only the time changes.
    pub unspecialised_lighting: bool,
}

/// An injected slowdown of one plan pass: its render passes are submitted `factor` times over.
/// The whole part of `factor - 1` adds whole copies; the fraction adds one more copy whose
/// viewports are centred boxes of that fraction of their area, so ×1.5 rasterises the middle
/// half of the pass again (about half its fragment work where the subject is framed in the
/// middle; a vertex-bound pass slows by more, and a pass whose cost lies at the edges by less).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SlowPass {
    /// The pass slowed down.
    pub pass: PassId,
    /// How many times over its work is submitted (at least 1).
    pub factor: f32,
}

impl SlowPass {
    /// The extra copies: one viewport height fraction (0..=1] per copy beyond the original.
    pub fn extra_copies(&self) -> Vec<f32> {
        let extra = (self.factor - 1.0).max(0.0);
        let whole = extra.floor();
        let mut copies = vec![1.0; whole as usize];
        let fraction = extra - whole;
        if fraction > 1e-3 {
            copies.push(fraction);
        }
        copies
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_slowdown_adds_whole_copies_then_a_fraction() {
        let slow = |factor| SlowPass {
            pass: PassId::ToneMap,
            factor,
        };
        assert_eq!(slow(1.0).extra_copies(), Vec::<f32>::new());
        assert_eq!(slow(2.0).extra_copies(), vec![1.0]);
        assert_eq!(slow(1.5).extra_copies(), vec![0.5]);
        assert_eq!(slow(3.25).extra_copies(), vec![1.0, 1.0, 0.25]);
        assert_eq!(slow(0.5).extra_copies(), Vec::<f32>::new());
    }
}

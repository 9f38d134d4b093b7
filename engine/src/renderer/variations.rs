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
    /// Speed: the render passes of this plan pass are submitted this many times in a row
    /// (`harness bench --repeat-pass`): a slowdown of about that factor in that pass alone, to
    /// see how a slower pass shows. A pass that adds into its target adds more than once: its
    /// pixels are not the point.
    pub repeat_pass: Option<(PassId, u32)>,
}

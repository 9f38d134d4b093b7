//! Which of a plan's targets get goldens (by what they hold, [`TargetContent`], which the plan
//! gives every [`TargetId`]), and the shape of the rule each kind is checked with: which
//! metrics, and the limit each falls back to without noise figures. A new target picks its
//! content in the engine and needs nothing here.

use engine::plan::{TargetContent, TargetId};

use crate::golden::metrics::Channels;
use crate::golden::tolerance::Metric;

/// What a golden pass holds, which decides the shape of its rule: the plan's
/// [`TargetContent`] of every target but intermediates.
pub type PassKind = TargetContent;

/// The kind of a golden pass, or `None` for an output that gets no golden (the routing depth,
/// VSM moments, blur targets: scratch data between passes).
pub fn pass_kind(target: TargetId) -> Option<PassKind> {
    Some(target.content()).filter(|c| *c != TargetContent::Intermediate)
}

/// The checks of a kind of pass (all must pass), each with the limit used when the noise model
/// has no figure for it in any scene (only a scene-less model: `golden/noise.toml` normally
/// gives every limit; see [`crate::golden::noise`]).
///
/// - G-buffer: pixels with a channel more than 0.01 off, relative above 1 (so positions far
///   away compare relatively and unit quantities absolutely; one fp16 step is at most 1e-3).
/// - depth and shadow maps: pixels more than 1e-4 off, relative above 1e-3 (the rasterizers
///   disagree by up to 1e-5 in lavapipe's shadow maps; 1e-4 of depth is about 0.1 mm at the
///   canonical scenes' distances).
/// - mask, shadow term: pixels with a channel flipped (0.5) or a visibility more than 0.01 off.
/// - light buffer: pixels whose RGB radiance moved more than 0.5% relative, above a floor of
///   0.01 (a change of a few fp16 steps, which no rounding of one value makes; radiance below
///   0.01 is near black after tone mapping, so its changes count in absolute terms).
/// - final: pixels with a channel more than 0.006 (1.53/255) off (±1 LSB is rounding; 2 is a
///   change), and the mean FLIP error (a perceptual last net; ±1 LSB of rounding on 13-17% of
///   the pixels gives 6.4e-3 to 6.9e-3).
pub fn rule_shape(kind: PassKind) -> Vec<(Metric, f64)> {
    let pixels_over =
        |threshold: f64, floor: Option<f64>, channels: Channels| Metric::FractionOver {
            threshold,
            floor,
            shift: 0,
            channels,
        };
    match kind {
        PassKind::SurfaceAttributes => {
            vec![(pixels_over(0.01, Some(1.0), Channels::All), 1.2e-4)]
        }
        PassKind::Depth => vec![(pixels_over(1e-4, Some(1e-3), Channels::All), 1.2e-4)],
        PassKind::Mask => vec![(pixels_over(0.5, None, Channels::All), 1.2e-4)],
        PassKind::Visibility => vec![(pixels_over(0.01, None, Channels::Rgb), 1.2e-4)],
        PassKind::Radiance => vec![(pixels_over(0.005, Some(0.01), Channels::Rgb), 3.5e-4)],
        PassKind::Display => vec![
            (pixels_over(0.006, None, Channels::Rgb), 1.2e-4),
            (Metric::FlipMean, 0.021),
        ],
        // Scratch data gets no golden (see `pass_kind`), so no rule either.
        PassKind::Intermediate => Vec::new(),
    }
}

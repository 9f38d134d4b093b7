//! What a golden pass holds (its [`PassKind`], from its name) and the shape of the rule it is
//! checked with: which metrics, and the limit each falls back to without noise figures.

use engine::plan;

use crate::golden::metrics::Channels;
use crate::golden::tolerance::Metric;

/// What a golden pass holds, which decides the shape of its rule.
#[derive(Clone, Copy, Debug, PartialEq, Eq, PartialOrd, Ord, serde::Serialize)]
pub enum PassKind {
    /// A G-buffer target (RGBA16F): positions, normals, tangents, albedo, material.
    GBuffer,
    /// Depth: the camera's (`depth`) or a light's shadow map (`shadow_<light>`), D32F.
    Depth,
    /// The lighting-model mask (RGBA8, one-hot).
    Mask,
    /// A shadowed light's visibility per pixel (`shadow_term_<light>`).
    ShadowTerm,
    /// The HDR light buffer (RGBA16F).
    Light,
    /// The tone-mapped sRGB image.
    Final,
}

fn numbered(pass: &str, prefix: &str) -> bool {
    pass.strip_prefix(prefix)
        .is_some_and(|n| !n.is_empty() && n.bytes().all(|b| b.is_ascii_digit()))
}

/// The kind of a golden pass, or `None` for an output that gets no golden (VSM moments, blur
/// targets, ...).
pub fn pass_kind(pass: &str) -> Option<PassKind> {
    Some(match pass {
        p if p.starts_with("gbuffer_") => PassKind::GBuffer,
        plan::DEPTH => PassKind::Depth,
        p if numbered(p, "shadow_") => PassKind::Depth,
        p if numbered(p, "shadow_term_") => PassKind::ShadowTerm,
        "mask" | "mask_1" => PassKind::Mask,
        plan::LIGHT => PassKind::Light,
        plan::FINAL => PassKind::Final,
        _ => return None,
    })
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
        PassKind::GBuffer => vec![(pixels_over(0.01, Some(1.0), Channels::All), 1.2e-4)],
        PassKind::Depth => vec![(pixels_over(1e-4, Some(1e-3), Channels::All), 1.2e-4)],
        PassKind::Mask => vec![(pixels_over(0.5, None, Channels::All), 1.2e-4)],
        PassKind::ShadowTerm => vec![(pixels_over(0.01, None, Channels::Rgb), 1.2e-4)],
        PassKind::Light => vec![(pixels_over(0.005, Some(0.01), Channels::Rgb), 3.5e-4)],
        PassKind::Final => vec![
            (pixels_over(0.006, None, Channels::Rgb), 1.2e-4),
            (Metric::FlipMean, 0.021),
        ],
    }
}

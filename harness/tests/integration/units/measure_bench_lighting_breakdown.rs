//! Tests of `harness::measure::bench::lighting_breakdown`.

use engine::backend::BackendKind;
use engine::plan::{LightingFeature, PassId};
use engine::renderer::{PassTimes, PreparedFrame};
use harness::measure::bench::lighting_breakdown::*;

/// One frame's timings: the pass `pass` took `ms`.
fn frame(pass: PassId, ms: f64) -> PassTimes {
    PassTimes {
        passes: vec![engine::backend::PassTiming {
            name: pass.to_string(),
            gpu_ns: Some(ms * 1e6),
        }],
        owners: vec![pass],
    }
}

/// Eight frames of a variant whose work takes `ms`: two at `ms`, the others in a slower
/// cluster 0.2 ms up (scheduling), `slow` of them.
fn frames(name: PassId, ms: f64, slow: usize) -> Vec<PassTimes> {
    (0..8)
        .map(|i| {
            frame(
                name,
                if (2..2 + slow).contains(&i) {
                    ms + 0.2
                } else {
                    ms
                },
            )
        })
        .collect()
}

/// The arrow's Blinn-Phong pass with bimodal frame times, as llvmpipe gives them. Its
/// parts are the input floor, the setup (the light-less variant less the floor) and its one
/// light (the pass less the pass without it): they add up to the pass when the light-less
/// variant and the pass without its only light, the same work, are timed alike. With
/// medians they are not when one falls in the slow cluster and the other in the fast; the
/// lower quartiles all measure the work, so the parts add up exactly.
#[test]
fn parts_add_up_over_bimodal_frames() {
    let scene = harness::load_scene("arrow").unwrap().scene;
    let prepared = PreparedFrame::new(&scene).unwrap();
    let plan = prepared.plan();
    let removals = removals(&scene, plan);
    let name = PassId::Lighting(engine::scene::LightingModel::BlinnPhong);
    let spec = plan.pass(name).unwrap();
    // (work ms, frames in the slow cluster) of each variant.
    let variant = |feature: LightingFeature| match feature {
        LightingFeature::Shading => (0.30, 3),
        LightingFeature::Lighting => (0.34, 5),
        LightingFeature::Light(0) => (0.34, 1),
        _ => (0.40, 2),
    };
    let full = frames(name, 0.45, 4);
    let without: Vec<_> = removals
        .iter()
        .map(|(_, feature, _)| {
            let (ms, slow) = variant(*feature);
            frames(name, ms, slow)
        })
        .collect();
    // Re-reading the inputs costs nothing here: the baseline is the pass as it is.
    let timed = VariantFrames {
        kept_inputs: full.clone(),
        full: full.clone(),
        without: without.clone(),
    };
    let b = pass_breakdown(&scene, BackendKind::Gl, plan, spec, &removals, &timed).unwrap();
    assert_eq!(b.frames, 8);
    // Input floor, setup, the light (and, not summed, its shadow lookups), the re-reads.
    assert_eq!(b.rows.iter().filter(|r| r.summed).count(), 4, "{b:?}");
    assert!((b.total_ms.unwrap() - 0.45).abs() < 1e-9, "{b:?}");
    assert!((b.sum_to_total.unwrap() - 1.0).abs() < 1e-9, "{b:?}");
    // The same frames by their medians (rank 4 of 8): the light-less variant is slow,
    // the pass without its light fast, and the parts come to 0.2 ms more than the pass.
    let median = |timings: &[PassTimes]| {
        let ms = timings
            .iter()
            .map(|t| t.passes[0].gpu_ns.unwrap() / 1e6)
            .collect();
        engine::stats::median(ms).unwrap()
    };
    let index = |feature| removals.iter().position(|(_, f, _)| *f == feature).unwrap();
    let floor = median(&without[index(LightingFeature::Shading)]);
    let setup = median(&without[index(LightingFeature::Lighting)]) - floor;
    let light = median(&full) - median(&without[index(LightingFeature::Light(0))]);
    assert!((floor + setup + light - median(&full) - 0.2).abs() < 1e-9);

    // Where the variants' re-read of the inputs costs 0.1 ms (a baseline 0.1 ms slower than
    // the pass), each part is still its own cost, and the last row takes the re-read away.
    let timed = VariantFrames {
        kept_inputs: frames(name, 0.55, 4),
        full,
        without: without
            .iter()
            .zip(&removals)
            .map(|(timings, (_, feature, _))| match feature {
                LightingFeature::Shading => timings.clone(),
                _ => {
                    let (ms, slow) = variant(*feature);
                    frames(name, ms + 0.1, slow)
                }
            })
            .collect(),
    };
    let b = pass_breakdown(&scene, BackendKind::Gl, plan, spec, &removals, &timed).unwrap();
    let light_row = b
        .rows
        .iter()
        .find(|r| r.what.starts_with("light 0"))
        .unwrap();
    assert!((light_row.ms.unwrap() - 0.11).abs() < 1e-9, "{b:?}");
    let reread = b.rows.last().unwrap();
    assert!((reread.ms.unwrap() + 0.1).abs() < 1e-9, "{b:?}");
    assert!((b.sum_to_total.unwrap() - 1.0).abs() < 1e-9, "{b:?}");
}

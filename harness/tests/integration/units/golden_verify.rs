//! Tests of `harness::golden::verify`.

use engine::backend::BackendKind;
use engine::plan::TargetId;
use harness::golden::verify::*;

fn disagreement(pass: Option<TargetId>) -> Disagreement {
    Disagreement {
        source: "cpu-avx".to_owned(),
        backend: Some(BackendKind::WgpuVulkan),
        pass,
        detail: "moved".to_owned(),
    }
}

/// A record of light and final: it speaks for either alone only with the same inputs and
/// files; a refusal about final does not refuse light (nor verify it: it was not tried under
/// every source), and a render failure refuses both.
#[test]
fn a_recorded_verification_speaks_only_for_what_it_verified() {
    let (light, last) = (TargetId::Light, TargetId::Final);
    let record = |disagreements| Verification {
        scene: "arrow".to_owned(),
        backend: BackendKind::Gl,
        passes: vec![light, last],
        inputs: "in".to_owned(),
        kept: vec![(light, "l".to_owned()), (last, "f".to_owned())],
        disagreements,
    };
    let kept_light = [(light, Some("l".to_owned()))];
    let verified = record(vec![]);
    assert_eq!(verified.verdict_on("in", &kept_light), Some(vec![]));
    assert_eq!(verified.verdict_on("other", &kept_light), None);
    assert_eq!(
        verified.verdict_on("in", &[(light, Some("x".to_owned()))]),
        None
    );
    assert_eq!(verified.verdict_on("in", &[(light, None)]), None);
    assert_eq!(
        verified.verdict_on("in", &[(TargetId::Depth, Some("l".to_owned()))]),
        None
    );
    let final_refused = record(vec![disagreement(Some(last))]);
    assert_eq!(final_refused.verdict_on("in", &kept_light), None);
    let both = [(light, Some("l".to_owned())), (last, Some("f".to_owned()))];
    assert_eq!(
        final_refused.verdict_on("in", &both),
        Some(vec![disagreement(Some(last))])
    );
    let render_failed = record(vec![disagreement(None)]);
    assert_eq!(
        render_failed.verdict_on("in", &kept_light),
        Some(vec![disagreement(None)])
    );
}

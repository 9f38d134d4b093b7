//! The speed checks end to end: a pass slowed down fails its own speed check and no other, the
//! verdict `harness check` and the golden tests give.

use engine::backend::BackendKind;
use engine::plan::PassId;
use engine::renderer::{SlowPass, Variations};
use harness::golden::speed::{check_scenes, start_check, SpeedOutcome};

use crate::common;

/// Chess on gl with tone mapping submitted three times over: the tone-mapping check fails, and
/// every other pass of the frame passes (or is untimed), on this host or any other (x3 is
/// beyond every limit the timing-noise model allows chess's tone mapping anywhere).
#[test]
fn a_slowed_pass_fails_its_own_speed_check_and_no_other() {
    if !common::gl_available() {
        return;
    }
    let store = harness::golden::GoldenStore::workspace();
    let driver = engine::backend::probe(BackendKind::Gl)
        .info
        .map(|info| harness::golden::fingerprint(&info))
        .unwrap_or_default();
    let scenes = [("chess".to_owned(), "chess".to_owned())];
    let started = start_check(
        std::path::Path::new(env!("CARGO_BIN_EXE_harness")),
        &scenes,
        &[BackendKind::Gl],
        Variations {
            slow_pass: Some(SlowPass {
                pass: PassId::ToneMap,
                factor: 3.0,
            }),
            ..Default::default()
        },
        &[],
    );
    let run = check_scenes(
        started,
        store.root(),
        &scenes,
        &[(BackendKind::Gl, driver)],
        |_| {},
    );
    assert!(run.errors.is_empty(), "{:?}", run.errors);
    let tonemap = run
        .checks
        .iter()
        .find(|c| c.pass == PassId::ToneMap)
        .unwrap();
    assert_eq!(
        tonemap.outcome,
        SpeedOutcome::Slower,
        "{}",
        tonemap.describe()
    );
    assert!(tonemap.slowdown().unwrap() > 2.0, "{}", tonemap.describe());
    for other in run.checks.iter().filter(|c| c.pass != PassId::ToneMap) {
        assert!(!other.failed(), "{}: {}", other.pass, other.describe());
    }
    assert!(!run.passed());
}

//! Tests of `harness::measure::speed`.

use engine::backend::BackendKind;
use engine::plan::PassId;
use harness::measure::speed::*;

#[test]
fn a_pass_settles_once_its_last_rounds_find_nothing_faster() {
    let speed = |pass_ms: &[f64], floor_ms: &[f64]| PassSpeed {
        pass: PassId::ToneMap,
        pass_ms: pass_ms.to_vec(),
        floor_ms: floor_ms.to_vec(),
        targets: None,
        unslowed_ms: Vec::new(),
    };
    let floor = [1.0; 4];
    assert!(!settled(&speed(&[2.0, 2.0, 2.0], &floor[..3])));
    assert!(settled(&speed(&[2.0, 1.9, 2.1, 1.95], &floor)));
    assert!(!settled(&speed(&[2.0, 2.0, 2.0, 1.5], &floor)));
    assert!(!settled(&speed(&[2.0; 4], &[1.0, 1.0, 0.9, 1.0])));
}

#[test]
fn short_floors_are_repeated_to_a_millisecond() {
    assert_eq!(floor_copies(2.0), 1);
    assert_eq!(floor_copies(0.3), 4);
    assert_eq!(floor_copies(0.01), MAX_FLOOR_COPIES);
    assert_eq!(floor_copies(0.0), MAX_FLOOR_COPIES);
}

#[test]
fn merged_probes_keep_every_sample() {
    let probe = |pass_ms: f64| SceneSpeed {
        scene: "s".to_owned(),
        backend: BackendKind::Gl,
        rounds: 4,
        passes: vec![PassSpeed {
            pass: PassId::ToneMap,
            pass_ms: vec![pass_ms],
            floor_ms: vec![1.0],
            targets: None,
            unslowed_ms: Vec::new(),
        }],
    };
    let merged = probe(3.0).merged(&probe(2.0));
    assert_eq!(merged.rounds, 8);
    assert_eq!(merged.passes[0].pass_ms, vec![3.0, 2.0]);
    assert_eq!(merged.passes[0].ratio(), Some(2.0));
}

#[test]
fn the_ratio_is_fastest_over_fastest() {
    let speed = PassSpeed {
        pass: PassId::ToneMap,
        pass_ms: vec![3.0, 2.0, 9.0],
        floor_ms: vec![1.0, 4.0, 0.5],
        targets: None,
        unslowed_ms: Vec::new(),
    };
    assert_eq!(speed.ratio(), Some(4.0));
    let empty = PassSpeed {
        pass: PassId::ToneMap,
        pass_ms: vec![],
        floor_ms: vec![],
        targets: None,
        unslowed_ms: Vec::new(),
    };
    assert_eq!(empty.ratio(), None);
}

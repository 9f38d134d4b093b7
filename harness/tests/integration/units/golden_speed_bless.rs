//! Tests of `harness::golden::speed::bless`.

use engine::backend::BackendKind;
use engine::plan::PassId;
use harness::golden::speed::bless::*;
use harness::measure::speed::{PassSpeed, SceneSpeed};

#[test]
fn the_median_probe_takes_each_pass_from_its_median_run() {
    let probe = |tonemap: f64, geometry: f64| SceneSpeed {
        scene: "s".to_owned(),
        backend: BackendKind::Gl,
        rounds: 1,
        passes: vec![
            PassSpeed {
                pass: PassId::ToneMap,
                pass_ms: vec![tonemap],
                floor_ms: vec![1.0],
            },
            PassSpeed {
                pass: PassId::Geometry,
                pass_ms: vec![geometry],
                floor_ms: vec![1.0],
            },
        ],
    };
    let median = median_probe(&[probe(3.0, 1.0), probe(1.0, 2.0), probe(2.0, 9.0)]).unwrap();
    assert_eq!(median.passes[0].ratio(), Some(2.0));
    assert_eq!(median.passes[1].ratio(), Some(2.0));
    assert!(median_probe(&[]).is_none());
}

//! Tests of `harness::golden::speed::goldens`.

use engine::backend::BackendKind;
use engine::plan::PassId;
use harness::golden::speed::goldens::*;
use harness::measure::speed::PassSpeed;
use harness::measure::speed::SceneSpeed;

#[test]
fn goldens_round_trip_and_a_partial_bless_keeps_the_other_passes() {
    let dir = tempfile::tempdir().unwrap();
    let probe = |ratio: f64| SceneSpeed {
        scene: "s".to_owned(),
        backend: BackendKind::Gl,
        rounds: 3,
        passes: vec![
            PassSpeed {
                pass: PassId::Geometry,
                pass_ms: vec![ratio, ratio * 2.0],
                floor_ms: vec![1.0],
            },
            PassSpeed {
                pass: PassId::ToneMap,
                pass_ms: vec![ratio],
                floor_ms: vec![1.0],
            },
        ],
    };
    let mut goldens = TimingGoldens::default();
    goldens.record(&probe(2.0), &[], "host a", "t0");
    goldens.save(dir.path(), "s").unwrap();
    let mut loaded = TimingGoldens::load(dir.path(), "s").unwrap();
    assert_eq!(loaded, goldens);
    loaded.record(&probe(3.0), &[PassId::ToneMap], "host b", "t1");
    let gl = &loaded.backends[&BackendKind::Gl];
    assert_eq!(gl.passes[&PassId::Geometry].ratio, 2.0);
    assert_eq!(gl.passes[&PassId::ToneMap].ratio, 3.0);
    assert_eq!(gl.host, "host b");
    assert_eq!(
        TimingGoldens::load(dir.path(), "none").unwrap(),
        TimingGoldens::default()
    );
    std::fs::write(TimingGoldens::path(dir.path(), "s"), "[gl]\nblessed = 3").unwrap();
    let error = TimingGoldens::load(dir.path(), "s")
        .unwrap_err()
        .to_string();
    assert!(error.contains("timing.toml"), "{error}");
}

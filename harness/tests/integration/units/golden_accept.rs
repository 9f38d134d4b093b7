//! Tests of `harness::golden::accept`.

use engine::backend::BackendKind;
use engine::plan::PassId;
use harness::golden::accept::accept_timings;
use harness::golden::speed::{SpeedCheck, SpeedOutcome, Stamp, Tier, TimingGoldens};
use harness::golden::GoldenStore;
use harness::measure::speed::{PassSpeed, SceneSpeed};

/// A slower check of arrow's geometry on gl, at `tier`.
fn slower(tier: Tier) -> SpeedCheck {
    SpeedCheck {
        scene: "arrow".to_owned(),
        backend: BackendKind::Gl,
        pass: PassId::Geometry,
        ratio: 6.0,
        ms: 3.0,
        golden: Some(2.0),
        limit: Some(1.44),
        noise: None,
        borrowed: false,
        tier,
        outcome: SpeedOutcome::Slower,
    }
}

/// Accepting a speed check from the last check writes the ratio it measured (with the reason)
/// where this host blessed the backend's timing goldens, and is refused, writing nothing, where
/// another host did (it would put this host's ratio among that host's) or where the backend
/// has no timing goldens yet (a first golden comes from a bless's probes, not one check).
#[test]
fn a_timing_golden_is_accepted_only_on_the_host_that_blessed_it() {
    let dir = tempfile::tempdir().unwrap();
    let store = GoldenStore::new(dir.path());
    std::fs::create_dir_all(dir.path().join("arrow")).unwrap();
    let mut goldens = TimingGoldens::default();
    let probe = SceneSpeed {
        scene: "arrow".to_owned(),
        backend: BackendKind::Gl,
        rounds: 4,
        passes: vec![PassSpeed {
            pass: PassId::Geometry,
            pass_ms: vec![2.0],
            floor_ms: vec![1.0],
        }],
    };
    let stamp = Stamp {
        host: "the EPYC",
        cpu: "family 23 model 49 stepping 0",
        blessed: "t0",
        reason: None,
    };
    goldens.record(&probe, &[], &stamp);
    goldens.save(dir.path(), "arrow").unwrap();
    let file = TimingGoldens::path(dir.path(), "arrow");
    let before = std::fs::read_to_string(&file).unwrap();
    let lock = store.lock_scene("arrow", |_| {}).unwrap();

    for tier in [Tier::OtherHost, Tier::RecordedHost] {
        let why = accept_timings(&store, &lock, &[slower(tier)], false, None).unwrap_err();
        assert!(
            why.contains("did not bless gl's timing goldens (blessed t0)")
                && why.contains("--speed-only --every-pass"),
            "{why}"
        );
        assert_eq!(std::fs::read_to_string(&file).unwrap(), before);
    }
    let mut vulkan = slower(Tier::OtherHost);
    vulkan.backend = BackendKind::WgpuVulkan;
    let why = accept_timings(&store, &lock, &[vulkan], false, None).unwrap_err();
    assert!(why.contains("no timing goldens there yet"), "{why}");
    assert_eq!(std::fs::read_to_string(&file).unwrap(), before);

    let lines =
        accept_timings(&store, &lock, &[slower(Tier::SameHost)], false, Some("why")).unwrap();
    assert_eq!(
        lines,
        ["arrow/geometry on gl (speed): ratio 6.000 as the check measured it; written"]
    );
    let after = TimingGoldens::load(dir.path(), "arrow").unwrap();
    let gl = &after.backends[&BackendKind::Gl];
    assert_eq!((gl.host.as_str(), gl.cpu.as_str()), (stamp.host, stamp.cpu));
    let geometry = &gl.passes[&PassId::Geometry];
    assert_eq!(
        (geometry.ratio, geometry.reason.as_deref()),
        (6.0, Some("why"))
    );
}

//! Tests of `harness::golden::accept`.

use engine::backend::BackendKind;
use engine::plan::PassId;
use harness::golden::accept::{accept_timings, CheckContext};
use harness::golden::speed::TimingGoldens;
use harness::golden::speed::{cpu_signature, SpeedCheck, SpeedOutcome, Stamp, Tier};
use harness::golden::GoldenStore;
use harness::measure::speed::{PassSpeed, SceneSpeed};

/// A slower check of arrow's geometry on `backend`.
fn slower(backend: BackendKind) -> SpeedCheck {
    SpeedCheck {
        scene: "arrow".to_owned(),
        backend,
        pass: PassId::Geometry,
        ratio: 6.0,
        ms: 3.0,
        targets: None,
        delivered: None,
        golden: Some(2.0),
        limit: Some(1.44),
        noise: None,
        borrowed: false,
        tier: Tier::SameHost,
        outcome: SpeedOutcome::Slower,
    }
}

/// The last check: every backend on `host`, arrow named by its file's path.
fn on(host: &str) -> CheckContext {
    CheckContext {
        hosts: BackendKind::ALL
            .into_iter()
            .map(|kind| (kind, host.to_owned()))
            .collect(),
        arguments: [("arrow".to_owned(), "scenes/arrow.toml".to_owned())].into(),
        inputs: Vec::new(),
        out: "out".into(),
    }
}

/// Accepting a speed check from the last check writes the ratio it measured (with the reason)
/// where the check's host blessed the backend's timing goldens, asked of the file as it is now
/// (a section re-blessed elsewhere since the check is not written into), and keeps it out,
/// writing nothing, where another host did (it would put this host's ratio among that host's)
/// or where the backend has no timing goldens yet (a first golden comes from a bless's probes,
/// not one check); per check, so one kept out does not stop another. The command it prints
/// names the scene as the check was given it.
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
            targets: None,
            unslowed_ms: Vec::new(),
        }],
    };
    let cpu = cpu_signature();
    let stamp = Stamp {
        host: "the EPYC",
        cpu: &cpu,
        blessed: "t0",
        reason: None,
    };
    goldens.record(&probe, &[], &stamp);
    goldens.save(dir.path(), "arrow").unwrap();
    let file = TimingGoldens::path(dir.path(), "arrow");
    let before = std::fs::read_to_string(&file).unwrap();
    let lock = store.lock_scene("arrow", |_| {}).unwrap();

    let gl = [slower(BackendKind::Gl)];
    let done = accept_timings(&store, &lock, &gl, &on("host-c"), false, None).unwrap();
    let [kept] = &done.kept[..] else {
        panic!("{done:?}")
    };
    let why = &kept.why;
    assert_eq!(
        (kept.pass, kept.backend),
        (PassId::Geometry, BackendKind::Gl)
    );
    assert!(
        done.written.is_empty()
            && why.starts_with("arrow/geometry on gl (speed): not accepted")
            && why.contains(&format!(
                "did not bless gl's timing goldens (blessed on the EPYC, {cpu})"
            ))
            && why.contains("bless --scene scenes/arrow.toml --speed-only --every-pass"),
        "{why}"
    );
    assert_eq!(std::fs::read_to_string(&file).unwrap(), before);

    // Beside one that is accepted (and in a dry run, nothing is written).
    let both = [slower(BackendKind::WgpuVulkan), slower(BackendKind::Gl)];
    let done = accept_timings(&store, &lock, &both, &on("the EPYC"), true, None).unwrap();
    assert!(
        done.kept[0].why.contains("no timing goldens there yet"),
        "{done:?}"
    );
    assert_eq!(
        done.written,
        ["arrow/geometry on gl (speed): ratio 6.000 as the check measured it; would be written"]
    );
    assert_eq!(std::fs::read_to_string(&file).unwrap(), before);

    let done = accept_timings(&store, &lock, &both, &on("the EPYC"), false, Some("why")).unwrap();
    assert_eq!(
        done.written,
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
    assert!(!after.backends.contains_key(&BackendKind::WgpuVulkan));
}

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

/// A probe of arrow on gl: its geometry pass at twice its floor.
fn arrow_geometry_probe() -> SceneSpeed {
    SceneSpeed {
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
    let probe = arrow_geometry_probe();
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
    // One check's sample written among the section's passes leaves its probe's rounds.
    assert_eq!(
        (gl.host.as_str(), gl.cpu.as_str(), gl.rounds),
        (stamp.host, stamp.cpu, 4)
    );
    let geometry = &gl.passes[&PassId::Geometry];
    assert_eq!(
        (geometry.ratio, geometry.reason.as_deref()),
        (6.0, Some("why"))
    );
    assert!(!after.backends.contains_key(&BackendKind::WgpuVulkan));
}

/// On a host recorded against the blessing host's timing goldens, a check is read against its
/// own recording (`Tier::RecordedHost`): accepting it writes the slowdown it measured there
/// (its ratio over the recording's median) times the golden, in the blessing host's terms,
/// leaving the section's host, CPU and rounds as they were and saying where the figure came
/// from; while that recording is still of the golden there, and not after the golden moved.
#[test]
fn a_recorded_host_accepts_a_slowdown_scaled_into_the_blessing_hosts_terms() {
    use harness::golden::speed::recorded::{RecordedPass, RecordedTimings};
    use std::collections::BTreeMap;
    let dir = tempfile::tempdir().unwrap();
    let store = GoldenStore::new(dir.path());
    std::fs::create_dir_all(dir.path().join("arrow")).unwrap();
    let cpu = cpu_signature();
    let probe = arrow_geometry_probe();
    let stamp = Stamp {
        host: "the EPYC",
        cpu: "family 25 model 1 stepping 1",
        blessed: "t0",
        reason: None,
    };
    let mut goldens = TimingGoldens::default();
    goldens.record(&probe, &[], &stamp);
    goldens.save(dir.path(), "arrow").unwrap();
    // host-d reads the geometry at x1.2 of the golden (2.0): its median 2.4.
    let recording = RecordedTimings {
        recorded: "t1".to_owned(),
        commit: None,
        probes: BTreeMap::from([("runs".to_owned(), 3)]),
        hosts: BTreeMap::from([(BackendKind::Gl, "host-d".to_owned())]),
        cpu: cpu.clone(),
        scenes: BTreeMap::from([(
            "arrow".to_owned(),
            BTreeMap::from([(
                BackendKind::Gl,
                BTreeMap::from([(
                    PassId::Geometry,
                    RecordedPass {
                        ratios: BTreeMap::from([("runs".to_owned(), vec![2.3, 2.4, 2.5])]),
                        golden: 2.0,
                    },
                )]),
            )]),
        )]),
    };
    let evidence = RecordedTimings::path(dir.path(), "host-d");
    std::fs::create_dir_all(evidence.parent().unwrap()).unwrap();
    recording.save(&evidence).unwrap();
    let lock = store.lock_scene("arrow", |_| {}).unwrap();
    // The check: x3 against host-d's recording (7.2 over 2.4).
    let check = SpeedCheck {
        ratio: 7.2,
        golden: Some(2.4),
        limit: Some(1.69),
        noise: Some((1.04, "host-d's recording".to_owned())),
        tier: Tier::RecordedHost,
        ..slower(BackendKind::Gl)
    };
    let done = accept_timings(
        &store,
        &lock,
        std::slice::from_ref(&check),
        &on("host-d"),
        false,
        Some("why"),
    )
    .unwrap();
    assert!(done.kept.is_empty(), "{done:?}");
    let [written] = &done.written[..] else {
        panic!("{done:?}")
    };
    assert!(
        written.starts_with("arrow/geometry on gl (speed): x3.000 against host-d's recording")
            && written.contains("as ratio 6.0000; written")
            && written.contains("--record-host host-d"),
        "{written}"
    );
    let after = TimingGoldens::load(dir.path(), "arrow").unwrap();
    let gl = &after.backends[&BackendKind::Gl];
    assert_eq!(
        (
            gl.host.as_str(),
            gl.cpu.as_str(),
            gl.rounds,
            gl.blessed.as_str()
        ),
        (stamp.host, stamp.cpu, 4, "t0")
    );
    let geometry = &gl.passes[&PassId::Geometry];
    assert_eq!(
        (geometry.ratio, geometry.reason.as_deref()),
        (6.0, Some("why"))
    );
    let scaled = geometry.scaled.as_deref().unwrap_or_default();
    assert!(
        scaled.contains("x3.000 against host-d's recording (ratio 7.200 over its median 2.400)")
            && scaled.contains("the golden before, 2.0000"),
        "{scaled}"
    );
    // The golden is 6.0 now, and host-d's recording of it is of 2.0: the same check (read
    // against the recording then) is not carried over again.
    let done = accept_timings(&store, &lock, &[check], &on("host-d"), false, None).unwrap();
    assert!(
        done.written.is_empty() && done.kept[0].why.contains("changed since: check again"),
        "{done:?}"
    );
    assert_eq!(
        TimingGoldens::load(dir.path(), "arrow").unwrap(),
        after,
        "nothing written"
    );
}

/// A check's numbers come back from last-check.json bit for bit: the accept compares the
/// recording's reference a check read against with the one it reads now exactly, and serde_json
/// without `float_roundtrip` parsed about one 17-digit value in ten a bit off (a median such as
/// 9.577200000000001 read back as 9.5772), so such a pass was refused as "changed since" on
/// every accept.
#[test]
fn a_checks_numbers_come_back_from_its_json_bit_for_bit() {
    let mut check = slower(BackendKind::Gl);
    check.golden = Some((9.5771 + 9.5773) / 2.0);
    check.ratio = 1.8654000000000002;
    let text = serde_json::to_string(&check).unwrap();
    let back: SpeedCheck = serde_json::from_str(&text).unwrap();
    assert_eq!(
        back.golden.map(f64::to_bits),
        check.golden.map(f64::to_bits),
        "{text}"
    );
    assert_eq!(back.ratio.to_bits(), check.ratio.to_bits(), "{text}");
}

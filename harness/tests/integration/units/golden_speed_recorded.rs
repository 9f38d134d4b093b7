//! Tests of `harness::golden::speed::recorded`, and of merging a source into the model
//! (`harness::golden::speed::measure::merged`).

use std::collections::BTreeMap;

use engine::backend::BackendKind;
use engine::plan::PassId;
use harness::golden::speed::measure::{merged, model_from, remeasured, TimingMeasurement};
use harness::golden::speed::recorded::*;
use harness::golden::speed::{PassNoise, Tier, TimingNoise};

fn host(ratios: &[f64], golden: f64) -> RecordedTimings {
    let pass = RecordedPass {
        ratios: BTreeMap::from([
            ("runs".to_owned(), ratios[1..].to_vec()),
            ("busy-neighbour".to_owned(), ratios[..1].to_vec()),
        ]),
        golden,
    };
    RecordedTimings {
        recorded: "2026-11-26T18:30:00Z".to_owned(),
        commit: Some("078b7c1".to_owned()),
        probes: BTreeMap::from([
            ("runs".to_owned(), ratios.len() - 1),
            ("busy-neighbour".to_owned(), 1),
        ]),
        hosts: BTreeMap::from([(
            BackendKind::Gl,
            "llvmpipe | CPU Intel(R) Xeon(R)".to_owned(),
        )]),
        cpu: "family 6 model 207 stepping 2".to_owned(),
        scenes: BTreeMap::from([(
            "ibl".to_owned(),
            BTreeMap::from([(BackendKind::Gl, BTreeMap::from([(PassId::ToneMap, pass)]))]),
        )]),
    }
}

#[test]
fn a_recorded_host_counts_its_largest_ratio_over_the_golden_as_another_hosts_figure() {
    let root = tempfile::tempdir().unwrap();
    std::fs::create_dir_all(root.path().join("evidence/host-c")).unwrap();
    host(&[3.0, 3.3, 2.4], 2.0)
        .save(&RecordedTimings::path(root.path(), "host-c"))
        .unwrap();
    // A host folder without timing figures (host-b's renders) is not a timing source.
    std::fs::create_dir_all(root.path().join("evidence/host-b")).unwrap();
    let hosts = recorded_hosts(root.path()).unwrap();
    assert_eq!(hosts.len(), 1);
    let (source, measurements) = &hosts[0];
    assert_eq!(
        (source.name.as_str(), source.tier),
        ("host-c", Tier::OtherHost)
    );
    assert_eq!(
        source.probes, 0,
        "nothing to probe: the figures are recorded"
    );
    assert!(
        source.description.contains("Intel(R) Xeon(R)"),
        "{}",
        source.description
    );
    assert_eq!(measurements.len(), 1);
    assert!((measurements[0].factor - 1.65).abs() < 1e-12);
    let pass = &host(&[3.0, 3.3, 2.4], 2.0).scenes["ibl"][&BackendKind::Gl][&PassId::ToneMap];
    assert_eq!(pass.factor(), (1.65, "runs"));
    assert!((pass.lowest() - 1.2).abs() < 1e-12);
    assert_eq!(
        host(&[3.4, 3.3], 2.0).scenes["ibl"][&BackendKind::Gl][&PassId::ToneMap].factor(),
        (1.7, "busy-neighbour")
    );
    assert_eq!(measurements[0].tier, Tier::OtherHost);
}

#[test]
fn a_malformed_recording_is_an_error_naming_the_file_and_the_pass() {
    let root = tempfile::tempdir().unwrap();
    std::fs::create_dir_all(root.path().join("evidence/host-c")).unwrap();
    let path = RecordedTimings::path(root.path(), "host-c");
    host(&[2.0, -1.0], 2.0).save(&path).unwrap();
    let e = recorded_hosts(root.path()).unwrap_err().to_string();
    assert!(
        e.contains("host-c/timing.toml") && e.contains("ibl gl tonemap"),
        "{e}"
    );
    std::fs::write(&path, "probes = \"five\"").unwrap();
    let e = recorded_hosts(root.path()).unwrap_err().to_string();
    assert!(e.contains("host-c/timing.toml"), "{e}");
}

#[test]
fn merging_a_source_raises_figures_where_it_measures_more_and_keeps_the_rest() {
    let noise = |host, drivers, at: &str| PassNoise {
        host,
        host_at: "runs".to_owned(),
        drivers,
        drivers_at: at.to_owned(),
    };
    let mut old = TimingNoise::default();
    let gl = old
        .scenes
        .entry("ibl".to_owned())
        .or_default()
        .entry(BackendKind::Gl)
        .or_default();
    gl.insert(PassId::ToneMap, noise(1.1, 1.2, "cpu-avx"));
    gl.insert(PassId::Geometry, noise(1.05, 1.3, "cpu-sse4.1"));
    let m = |pass, factor| TimingMeasurement {
        source: "host-c".to_owned(),
        tier: Tier::OtherHost,
        scene: "ibl".to_owned(),
        backend: BackendKind::Gl,
        pass,
        factor,
    };
    let (source, _) = &recorded_hosts_of(host(&[1.0, 1.0], 1.0))[0];
    let measured = model_from(
        &[m(PassId::ToneMap, 1.65), m(PassId::Geometry, 0.6)],
        std::slice::from_ref(source),
        2.0,
    );
    let model = merged(old, measured);
    let gl = &model.scenes["ibl"][&BackendKind::Gl];
    assert_eq!(gl[&PassId::ToneMap], noise(1.1, 1.65, "host-c"));
    assert_eq!(gl[&PassId::Geometry], noise(1.05, 1.3, "cpu-sse4.1"));
    assert!(model.sources.contains_key("host-c"));
}

/// A scene new to the model, measured here by its same-host sources only (what the check's
/// note offers without the second Mesa), starts from what its checks borrowed: its own
/// same-host figure, and for any host at least the borrowed figure (no other host recorded
/// it). A tier with neither measured nor borrowed leaves the pass out, and a model with a
/// figure of 0 is not written (reading it back would refuse it, and every speed check with it).
#[test]
fn a_new_scene_measured_here_keeps_the_borrowed_figure_for_other_hosts() {
    let mut old = TimingNoise::default();
    old.scenes
        .entry("ibl".to_owned())
        .or_default()
        .entry(BackendKind::Gl)
        .or_default()
        .insert(
            PassId::ToneMap,
            PassNoise {
                host: 1.1,
                host_at: "busy-neighbour".to_owned(),
                drivers: 1.5,
                drivers_at: "host-c".to_owned(),
            },
        );
    let m = |backend, factor| TimingMeasurement {
        source: "runs".to_owned(),
        tier: Tier::SameHost,
        scene: "mine".to_owned(),
        backend,
        pass: PassId::ToneMap,
        factor,
    };
    // A second new scene in the same run, with a larger figure for other hosts: the first
    // borrows from the model as it was, not from it.
    let another = TimingMeasurement {
        source: "cpu-avx".to_owned(),
        tier: Tier::OtherHost,
        scene: "another".to_owned(),
        ..m(BackendKind::Gl, 1.9)
    };
    let another_here = TimingMeasurement {
        scene: "another".to_owned(),
        ..m(BackendKind::Gl, 1.1)
    };
    let measured = model_from(
        &[
            m(BackendKind::Gl, 1.2),
            m(BackendKind::WgpuVulkan, 1.3),
            another,
            another_here,
        ],
        &[],
        2.0,
    );
    let model = merged(old.clone(), measured.clone());
    assert_eq!(
        model.scenes["another"][&BackendKind::Gl][&PassId::ToneMap].drivers,
        1.9
    );
    assert_eq!(
        model.scenes["mine"][&BackendKind::Gl][&PassId::ToneMap],
        PassNoise {
            host: 1.2,
            host_at: "runs".to_owned(),
            drivers: 1.5,
            drivers_at: "host-c, borrowed".to_owned(),
        }
    );
    assert!(
        !model.scenes["mine"].contains_key(&BackendKind::WgpuVulkan),
        "nothing to borrow on wgpu-vulkan: left out"
    );
    // A full measurement (no --source) gives the new scene the same start, keeps what it did
    // not measure, and labels a figure borrowed from a borrowed one once.
    let full = remeasured(measured.clone(), old.clone());
    assert_eq!(
        full.scenes["mine"][&BackendKind::Gl][&PassId::ToneMap],
        model.scenes["mine"][&BackendKind::Gl][&PassId::ToneMap]
    );
    assert_eq!(full.scenes["ibl"], old.scenes["ibl"]);
    let mut lender = TimingNoise::default();
    lender
        .scenes
        .insert("ibl".to_owned(), model.scenes["mine"].clone());
    let again = remeasured(model_from(&[m(BackendKind::Gl, 1.2)], &[], 2.0), lender);
    assert_eq!(
        again.scenes["mine"][&BackendKind::Gl][&PassId::ToneMap].drivers_at,
        "host-c, borrowed"
    );
    let dir = tempfile::tempdir().unwrap();
    model.save(dir.path()).unwrap();
    assert_eq!(TimingNoise::load(dir.path()).unwrap(), model);
    // The placeholders of the measurement alone (no driver figure) are refused, not written.
    let why = measured.save(dir.path()).unwrap_err().to_string();
    assert!(
        why.contains("not written: mine") && why.contains("drivers x0"),
        "{why}"
    );
    assert_eq!(
        TimingNoise::load(dir.path()).unwrap(),
        model,
        "the file as it was"
    );
}

/// The timing sources of one recorded host, read back from a temporary golden root.
fn recorded_hosts_of(
    recorded: RecordedTimings,
) -> Vec<(
    harness::golden::speed::measure::TimingSource,
    Vec<TimingMeasurement>,
)> {
    let root = tempfile::tempdir().unwrap();
    std::fs::create_dir_all(root.path().join("evidence/host-c")).unwrap();
    recorded
        .save(&RecordedTimings::path(root.path(), "host-c"))
        .unwrap();
    recorded_hosts(root.path()).unwrap()
}

/// The committed model counts every host recorded in golden/evidence/: each of its ratios sits
/// at or below half its limit on a host that did not bless, as host-b's renders do in the image
/// model. A recording added without merging it fails here, naming the command.
#[test]
fn the_committed_model_holds_every_recorded_host_at_half_its_limits() {
    let store = harness::golden::GoldenStore::workspace();
    let model = TimingNoise::load(store.root()).unwrap();
    let hosts = recorded_hosts(store.root()).unwrap();
    assert!(
        hosts.iter().any(|(s, _)| s.name == "host-c"),
        "host-c's speed ratios are kept in golden/evidence/host-c/timing.toml"
    );
    for (source, measurements) in &hosts {
        assert!(
            model.sources.contains_key(&source.name),
            "golden/timing-noise.toml does not list {}: run `harness noise --timing --source {} --write`",
            source.name,
            source.name
        );
        let scored = harness::golden::speed::measure::scores(&model, measurements);
        assert_eq!(scored.len(), measurements.len());
        for (m, limit, score) in scored {
            assert!(
                score <= 0.5 + 1e-9,
                "{} {} {} recorded on {} at x{:.3}, {score:.2} of its limit x{limit:.2} elsewhere: \
                 run `harness noise --timing --source {} --write`",
                m.scene,
                m.backend,
                m.pass,
                m.source,
                m.factor,
                m.source
            );
        }
    }
}

#[test]
fn a_second_recording_of_a_host_adds_to_the_first_and_takes_the_check_history_anew() {
    let pass = |golden, runs: &[f64], checks: &[f64]| RecordedPass {
        ratios: BTreeMap::from([
            ("runs".to_owned(), runs.to_vec()),
            (CHECKS_SOURCE.to_owned(), checks.to_vec()),
        ]),
        golden,
    };
    let recording = |tonemap: RecordedPass, geometry: RecordedPass, checks| RecordedTimings {
        recorded: "t".to_owned(),
        commit: None,
        probes: BTreeMap::from([("runs".to_owned(), 1), (CHECKS_SOURCE.to_owned(), checks)]),
        hosts: BTreeMap::new(),
        cpu: String::new(),
        scenes: BTreeMap::from([(
            "ibl".to_owned(),
            BTreeMap::from([(
                BackendKind::Gl,
                BTreeMap::from([(PassId::ToneMap, tonemap), (PassId::Geometry, geometry)]),
            )]),
        )]),
    };
    let earlier = recording(pass(2.0, &[2.1], &[2.2]), pass(3.0, &[3.5], &[3.1]), 1);
    let mut later = recording(
        pass(2.0, &[1.9], &[2.2, 2.3]),
        pass(4.0, &[4.1], &[4.2, 4.0]),
        2,
    );
    let dropped = later.absorb(earlier);
    assert_eq!(
        dropped,
        ["ibl gl geometry"],
        "geometry's golden changed in between"
    );
    let gl = &later.scenes["ibl"][&BackendKind::Gl];
    assert_eq!(gl[&PassId::ToneMap].ratios["runs"], [2.1, 1.9]);
    assert_eq!(gl[&PassId::ToneMap].ratios[CHECKS_SOURCE], [2.2, 2.3]);
    assert_eq!(gl[&PassId::Geometry].ratios["runs"], [4.1]);
    assert_eq!(later.probes["runs"], 2);
    assert_eq!(later.probes[CHECKS_SOURCE], 2);
}

/// A host whose CPU a recording has but whose driver fingerprint differs (a variable that
/// points the loader at a driver file, another Mesa) is told what differs, per backend: the
/// parts found only here and only in the recording. Nothing where one matches, or none has
/// this CPU.
#[test]
fn a_recording_of_this_cpu_that_does_not_match_says_what_differs() {
    use harness::golden::speed::near_recordings;
    use harness::golden::speed::recorded::RecordedTimings;
    let recording = |host: &str, cpu: &str| RecordedTimings {
        recorded: "t".to_owned(),
        commit: None,
        probes: Default::default(),
        hosts: [(BackendKind::WgpuVulkan, host.to_owned())]
            .into_iter()
            .collect(),
        cpu: cpu.to_owned(),
        scenes: Default::default(),
    };
    let there = "Vulkan Mesa 22.3.6 | llvmpipe | Mesa 22.3.6 | CPU Xeon";
    let here = "Vulkan Mesa 22.3.6 | llvmpipe | Mesa 22.3.6 | VK_DRIVER_FILES=/x.json | CPU Xeon";
    let recordings = vec![("host-c".to_owned(), recording(there, "family 6"))];
    let note =
        near_recordings(&recordings, BackendKind::WgpuVulkan, here, "family 6").expect("a note");
    assert!(
        note.starts_with(
            "wgpu-vulkan: host-c's recording has this CPU, but here \
             `VK_DRIVER_FILES=/x.json` where it has nothing"
        ),
        "{note}"
    );
    assert_eq!(
        near_recordings(&recordings, BackendKind::WgpuVulkan, there, "family 6"),
        None
    );
    assert_eq!(
        near_recordings(&recordings, BackendKind::WgpuVulkan, here, "family 25"),
        None
    );
    assert_eq!(
        near_recordings(&recordings, BackendKind::Gl, here, "family 6"),
        None
    );
}

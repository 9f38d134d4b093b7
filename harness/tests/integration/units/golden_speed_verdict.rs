//! Tests of `harness::golden::speed::verdict`.

use engine::backend::BackendKind;
use engine::plan::PassId;
use harness::golden::speed::cpu_signature;
use harness::golden::speed::verdict::*;
use harness::golden::speed::PassNoise;
use harness::golden::speed::{Tier, TimingGoldens, TimingNoise};
use harness::measure::speed::PassSpeed;
use harness::measure::speed::SceneSpeed;

fn probe(tonemap_ms: f64, geometry_ms: f64) -> SceneSpeed {
    SceneSpeed {
        scene: "s".to_owned(),
        backend: BackendKind::Gl,
        rounds: 1,
        passes: vec![
            PassSpeed {
                pass: PassId::ToneMap,
                pass_ms: vec![tonemap_ms],
                floor_ms: vec![0.5],
                targets: None,
                unslowed_ms: Vec::new(),
            },
            PassSpeed {
                pass: PassId::Geometry,
                pass_ms: vec![geometry_ms],
                floor_ms: vec![1.0],
                targets: None,
                unslowed_ms: Vec::new(),
            },
        ],
    }
}

/// The model, its same-host figures measured on host "here" (this CPU).
fn model() -> TimingNoise {
    model_measured_on("here")
}

/// The model, its same-host figures measured on `host` (this CPU).
fn model_measured_on(host: &str) -> TimingNoise {
    let mut model = TimingNoise::default();
    model.stamp_measured_on("s", BackendKind::Gl, host, &cpu_signature());
    let figures = |host: f64, drivers: f64| PassNoise {
        host,
        host_at: "busy".to_owned(),
        drivers,
        drivers_at: "cpu-sse4.1".to_owned(),
    };
    model.scenes.entry("s".to_owned()).or_default().insert(
        BackendKind::Gl,
        [
            (PassId::ToneMap, figures(1.1, 1.2)),
            (PassId::Geometry, figures(1.1, 1.5)),
        ]
        .into_iter()
        .collect(),
    );
    model
}

#[test]
fn a_slower_pass_fails_a_faster_one_is_a_note_and_noise_decides_what_is_timed() {
    // Tone mapping takes 3 ms (its floor 0.5 ms), geometry 4 ms (its floor 1 ms).
    let mut goldens = TimingGoldens::default();
    goldens.record(&probe(3.0, 4.0), &[], &stamp("here", &cpu_signature()));
    let noise = model();
    let verdict = |p: &SceneSpeed, host: &str, pass: PassId| {
        check_speed(p, &goldens, &noise, host)
            .into_iter()
            .find(|c| c.pass == pass)
            .unwrap()
    };
    let same = verdict(&probe(3.0, 4.0), "here", PassId::ToneMap);
    assert_eq!(
        (same.outcome.clone(), same.tier),
        (SpeedOutcome::Passed, Tier::SameHost)
    );
    assert_eq!(same.score(), Some(0.0));
    // Limit 1.2^2 (the noise floor) = 1.44 here: x1.5 fails, x1.3 passes, x0.65 (geometry)
    // is a note.
    assert_eq!(
        verdict(&probe(4.5, 4.0), "here", PassId::ToneMap).outcome,
        SpeedOutcome::Slower
    );
    let within = verdict(&probe(3.9, 4.0), "here", PassId::ToneMap);
    assert_eq!(within.outcome, SpeedOutcome::Passed);
    let limit = harness::golden::speed::MIN_NOISE.powi(2);
    assert!((within.score().unwrap() - 1.3f64.ln() / limit.ln()).abs() < 1e-9);
    assert_eq!(
        verdict(&probe(3.0, 2.6), "here", PassId::Geometry).outcome,
        SpeedOutcome::Faster
    );
    // Another host: geometry's drivers figure (1.5, limit 2.25) leaves it untimed there.
    let other = verdict(&probe(3.9, 4.0), "there", PassId::ToneMap);
    assert_eq!(
        (other.outcome, other.tier),
        (SpeedOutcome::Passed, Tier::OtherHost)
    );
    let noisy = verdict(&probe(3.0, 8.0), "there", PassId::Geometry);
    assert!(
        matches!(&noisy.outcome, SpeedOutcome::Untimed(why) if why.contains("x1.50 (cpu-sse4.1)")),
        "{noisy:?}"
    );
    assert!(!noisy.failed());
    // Untimed for a doubling, it still fails beyond its wide limit: x3 is no noise measured.
    let far = verdict(&probe(3.0, 12.0), "there", PassId::Geometry);
    assert_eq!(
        (far.outcome.clone(), far.tier),
        (SpeedOutcome::Slower, Tier::OtherHost)
    );
    assert!(far.failed() && far.score().unwrap() > 1.0, "{far:?}");
    assert_eq!(
        verdict(&probe(3.0, 8.0), "here", PassId::Geometry).outcome,
        SpeedOutcome::Slower
    );
    // A short pass (under 2 ms) has a noise floor of 1.3: limit 1.69 even here.
    let mut short_goldens = TimingGoldens::default();
    short_goldens.record(&probe(1.0, 4.0), &[], &stamp("here", &cpu_signature()));
    let short_pass = |ms: f64| {
        check_speed(&probe(ms, 4.0), &short_goldens, &noise, "here")
            .into_iter()
            .find(|c| c.pass == PassId::ToneMap)
            .unwrap()
    };
    assert_eq!(short_pass(1.6).outcome, SpeedOutcome::Passed);
    assert_eq!(short_pass(1.8).outcome, SpeedOutcome::Slower);
    // Too short, and no golden.
    let short = verdict(&probe(0.1, 4.0), "here", PassId::ToneMap);
    assert!(matches!(short.outcome, SpeedOutcome::Untimed(ref why) if why.contains("too short")));
    let missing = check_speed(&probe(1.0, 4.0), &TimingGoldens::default(), &noise, "here");
    assert!(missing
        .iter()
        .all(|c| c.outcome == SpeedOutcome::MissingGolden && c.failed()));
}

/// On a host recorded in golden/evidence/ (same fingerprint), a pass is checked against that
/// host's own median ratio and spread; a pass whose golden changed since the recording, and
/// every other host, fall back to the blessing host's golden and the other-host figures.
#[test]
fn a_recorded_host_is_checked_against_its_own_recording_while_it_is_current() {
    use harness::golden::speed::recorded::{RecordedPass, RecordedTimings, CHECKS_SOURCE};
    use std::collections::BTreeMap;
    // The goldens: tone mapping 6, geometry 4 (blessed "there").
    let mut goldens = TimingGoldens::default();
    goldens.record(&probe(3.0, 4.0), &[], &stamp("there", &cpu_signature()));
    let recorded = |golden: f64, runs: &[f64], busy: &[f64]| RecordedPass {
        ratios: BTreeMap::from([
            ("runs".to_owned(), runs.to_vec()),
            (CHECKS_SOURCE.to_owned(), vec![runs[0]]),
            ("busy-neighbour".to_owned(), busy.to_vec()),
            // Another code path is another host's figure, not this one's.
            ("cpu-sse4.1".to_owned(), vec![golden * 5.0]),
        ]),
        golden,
    };
    // This host reads tone mapping at half the golden (3, 2.8, 3.2 and a busy 3.6); geometry's
    // recording was measured against a golden of 5, since re-blessed as 4.
    let recording = RecordedTimings {
        recorded: "t".to_owned(),
        commit: None,
        probes: BTreeMap::new(),
        hosts: BTreeMap::from([(BackendKind::Gl, "recorded".to_owned())]),
        cpu: harness::golden::speed::cpu_signature(),
        scenes: BTreeMap::from([(
            "s".to_owned(),
            BTreeMap::from([(
                BackendKind::Gl,
                BTreeMap::from([
                    (PassId::ToneMap, recorded(6.0, &[3.0, 2.8, 3.2], &[3.6])),
                    (PassId::Geometry, recorded(5.0, &[4.0], &[4.0])),
                ]),
            )]),
        )]),
    };
    let tonemap = &recording.scenes["s"][&BackendKind::Gl][&PassId::ToneMap];
    let (reference, spread) = tonemap.reference(6.0).unwrap();
    assert_eq!(
        reference, 3.0,
        "the median of the plain probes and the checks"
    );
    assert!(
        (spread - 1.2).abs() < 1e-12,
        "the busy probe, not the SSE4.1 one: {spread}"
    );
    assert_eq!(tonemap.reference(6.5), None, "stale once the golden moved");
    // The same fingerprint on another CPU (a generic model name under a virtual machine): not
    // this recording's host.
    let mut elsewhere_cpu = recording.clone();
    elsewhere_cpu.cpu = "family 25 model 17 stepping 1".to_owned();
    let other_cpu = check_speed_with(
        &probe(3.0, 4.0),
        &goldens,
        &model(),
        "recorded",
        &[("host-c".to_owned(), elsewhere_cpu)],
    );
    assert!(other_cpu.iter().all(|c| c.tier == Tier::OtherHost));
    let recordings = [("host-c".to_owned(), recording)];
    let noise = model_measured_on("there");
    let check = |tonemap_ms: f64, host: &str, pass: PassId| {
        check_speed_with(&probe(tonemap_ms, 4.0), &goldens, &noise, host, &recordings)
            .into_iter()
            .find(|c| c.pass == pass)
            .unwrap()
    };
    // Doubled on the recorded host (ratio 6 against its own 3): slower, though it equals the
    // blessing host's golden.
    let doubled = check(3.0, "recorded", PassId::ToneMap);
    assert_eq!(doubled.tier, Tier::RecordedHost);
    assert_eq!(doubled.golden, Some(3.0));
    assert_eq!(
        doubled.outcome,
        SpeedOutcome::Slower,
        "{}",
        doubled.describe()
    );
    assert!(
        doubled.describe().contains("host-c's recording"),
        "{}",
        doubled.describe()
    );
    let unchanged = check(1.5, "recorded", PassId::ToneMap);
    assert_eq!(
        unchanged.outcome,
        SpeedOutcome::Passed,
        "{}",
        unchanged.describe()
    );
    // Geometry's recording is stale: the other-host figures against the golden.
    let geometry = check(1.5, "recorded", PassId::Geometry);
    assert_eq!(
        (geometry.tier, geometry.golden),
        (Tier::OtherHost, Some(4.0))
    );
    // A host nobody recorded: the other-host tier, against the golden.
    let elsewhere = check(3.0, "unrecorded", PassId::ToneMap);
    assert_eq!(
        (elsewhere.tier, elsewhere.golden),
        (Tier::OtherHost, Some(6.0))
    );
    // The host that blessed is never read against a recording.
    let here = check(3.0, "there", PassId::ToneMap);
    assert_eq!(here.tier, Tier::SameHost);
}

/// The blessing host is its fingerprint and its CPU signature: another CPU behind the same
/// generic model name ("AMD EPYC") is another host, checked at the other-host tier.
#[test]
fn the_blessing_host_is_its_fingerprint_and_its_cpu() {
    let noise = model();
    let tier = |cpu: &str| {
        let mut goldens = TimingGoldens::default();
        goldens.record(&probe(3.0, 4.0), &[], &stamp("here", cpu));
        check_speed(&probe(3.0, 4.0), &goldens, &noise, "here")[0].tier
    };
    assert_eq!(tier(&cpu_signature()), Tier::SameHost);
    assert_eq!(tier("family 0 model 0 stepping 0"), Tier::OtherHost);
    // Goldens that kept no signature: no host can show it blessed them.
    assert_eq!(tier(""), Tier::OtherHost);
}

/// Goldens moved to this host (blessed here) are read at the limits for any host until the
/// model's same-host figures are measured here too ([`Tier::MovedHere`]): figures measured where
/// the goldens were blessed before are that host's noise, not this one's. The check's note says
/// so once per scene and names the command; a model stamped here, on this CPU, gives the
/// same-host tier.
#[test]
fn same_host_figures_count_only_on_the_host_that_measured_them() {
    let mut goldens = TimingGoldens::default();
    goldens.record(&probe(3.0, 4.0), &[], &stamp("here", &cpu_signature()));
    let checks = |noise: &TimingNoise| check_speed(&probe(3.0, 4.0), &goldens, noise, "here");
    let tier = |noise: &TimingNoise| checks(noise)[0].tier;
    assert_eq!(tier(&model()), Tier::SameHost);
    let before = model_measured_on("the previous blessing host");
    assert_eq!(tier(&before), Tier::MovedHere);
    assert!(Tier::MovedHere.blessed_here() && !Tier::OtherHost.blessed_here());
    // At the limits for any host: geometry's drivers figure (1.5, limit 2.25) leaves it untimed.
    let geometry = checks(&before)
        .into_iter()
        .find(|c| c.pass == PassId::Geometry)
        .unwrap();
    assert!(
        matches!(&geometry.outcome, SpeedOutcome::Untimed(why) if why.contains("not measured yet")),
        "{geometry:?}"
    );
    let mut unstamped = model();
    unstamped.measured_on.clear();
    assert_eq!(tier(&unstamped), Tier::MovedHere);
    // The same fingerprint, measured on a CPU it could not read or on another.
    for cpu in ["", "family 0 model 0 stepping 0"] {
        let mut elsewhere = model();
        elsewhere
            .measured_on
            .get_mut("s")
            .unwrap()
            .get_mut(&BackendKind::Gl)
            .unwrap()
            .cpu = cpu.to_owned();
        assert_eq!(tier(&elsewhere), Tier::MovedHere, "{cpu:?}");
    }
    // One note per scene, whatever the passes and backends.
    let mut moved = checks(&before);
    moved.extend(checks(&before));
    let notes = harness::golden::speed::moved_here_notes(&moved);
    assert_eq!(notes.len(), 1, "{notes:?}");
    assert!(
        notes[0].contains("s's timing goldens on gl were blessed on this host")
            && notes[0].contains("read at the limits for any host")
            && notes[0].contains(" noise --timing --write --scene s`")
            && notes[0].contains("were measured on another host")
            && !notes[0].contains("  "),
        "{}",
        notes[0]
    );
    // A scene with no figures of its own (a new one, borrowing every scene's) is told so.
    for check in &mut moved {
        check.borrowed = true;
    }
    let notes = harness::golden::speed::moved_here_notes(&moved);
    assert!(
        notes[0].contains("has no figures of its own for it yet: it borrows every scene's"),
        "{}",
        notes[0]
    );
    assert!(harness::golden::speed::moved_here_notes(&checks(&model())).is_empty());
    // Goldens blessed elsewhere: the other-host tier, and no such note.
    let there = check_speed(&probe(3.0, 4.0), &goldens, &before, "there");
    assert_eq!(there[0].tier, Tier::OtherHost);
    assert!(harness::golden::speed::moved_here_notes(&there).is_empty());
    // A stamp names one scene, backend, host and CPU.
    let stamped = model();
    assert!(stamped.measured_on_host("s", BackendKind::Gl, "here", &cpu_signature()));
    assert!(!stamped.measured_on_host("s", BackendKind::Gl, "there", &cpu_signature()));
    assert!(!stamped.measured_on_host("s", BackendKind::WgpuVulkan, "here", &cpu_signature()));
    assert!(!stamped.measured_on_host("t", BackendKind::Gl, "here", &cpu_signature()));
}

fn covered(
    backend: BackendKind,
    tier: Tier,
    outcome: SpeedOutcome,
    limit: Option<f64>,
) -> SpeedCheck {
    SpeedCheck {
        scene: "s".to_owned(),
        backend,
        pass: PassId::ToneMap,
        ratio: 2.0,
        ms: 1.0,
        targets: None,
        delivered: None,
        golden: Some(2.0),
        limit,
        noise: None,
        borrowed: false,
        tier,
        outcome,
    }
}

#[test]
fn coverage_counts_the_timed_and_untimed_passes_per_backend_and_tier() {
    use BackendKind::{Gl, WgpuVulkan};
    let untimed = || SpeedOutcome::Untimed("too short to time".to_owned());
    let checks = [
        covered(Gl, Tier::SameHost, SpeedOutcome::Passed, Some(1.44)),
        covered(WgpuVulkan, Tier::OtherHost, untimed(), Some(2.5)),
        covered(Gl, Tier::SameHost, SpeedOutcome::Slower, Some(1.8)),
        covered(Gl, Tier::SameHost, SpeedOutcome::Faster, Some(1.6)),
        covered(Gl, Tier::SameHost, untimed(), Some(2.2)),
        covered(Gl, Tier::SameHost, SpeedOutcome::MissingGolden, None),
        covered(WgpuVulkan, Tier::OtherHost, SpeedOutcome::Passed, Some(1.5)),
        covered(Gl, Tier::RecordedHost, SpeedOutcome::Passed, Some(1.69)),
    ];
    let found: Vec<_> = coverage(&checks)
        .iter()
        .map(|c| {
            (
                c.backend,
                c.tier,
                c.timed,
                c.untimed,
                c.not_compared,
                c.limits,
            )
        })
        .collect();
    assert_eq!(
        found,
        [
            (Gl, Tier::SameHost, 3, 1, 1, Some([1.44, 1.6, 1.8])),
            (WgpuVulkan, Tier::OtherHost, 1, 1, 0, Some([1.5; 3])),
            (Gl, Tier::RecordedHost, 1, 0, 0, Some([1.69; 3])),
        ]
    );
    // The pass without a golden is neither timed nor untimed, and said apart.
    assert_eq!(
        coverage(&checks)[0].describe(),
        "3 passes timed on the host that blessed, limits x1.44 to x1.80 (median x1.60); \
         1 untimed; 1 without a timing golden of the same targets to compare with"
    );
    // A recording's limits are named by the recording.
    let mut recorded = covered(Gl, Tier::RecordedHost, SpeedOutcome::Passed, Some(1.69));
    recorded.noise = Some((1.3, "host-d's recording".to_owned()));
    assert_eq!(
        coverage(&[recorded])[0].describe(),
        "1 pass timed against host-d's recording, limits x1.69; 0 untimed"
    );
    let none_timed = coverage(&[covered(Gl, Tier::OtherHost, untimed(), None)]);
    assert_eq!(
        none_timed[0].describe(),
        "0 passes timed on a host that did not bless; 1 untimed"
    );
    assert!(coverage(&[]).is_empty());
    // Passes running below their goldens (another host's ratios): the limits say x1.5, but
    // from here a pass must get x3 slower (ratio at half its golden) to fail, and it is said.
    let mut below = covered(Gl, Tier::OtherHost, SpeedOutcome::Passed, Some(1.5));
    below.ratio = 1.0;
    let at = covered(Gl, Tier::OtherHost, SpeedOutcome::Passed, Some(1.5));
    let found = coverage(&[below, at]);
    assert_eq!(found[0].fails_beyond, Some([1.5, 3.0, 3.0]));
    assert_eq!(
        found[0].describe(),
        "2 passes timed on a host that did not bless, limits x1.50; from their speed in this \
         run a pass fails only beyond x1.50 to x3.00 slower; 0 untimed"
    );
    // A pass failing already has no room left to report (it read "beyond x0.20 slower").
    let mut failing = covered(Gl, Tier::OtherHost, SpeedOutcome::Slower, Some(1.5));
    failing.ratio = 15.0;
    let mut below = covered(Gl, Tier::OtherHost, SpeedOutcome::Passed, Some(1.5));
    below.ratio = 1.0;
    let found = coverage(&[failing, below]);
    assert_eq!(found[0].fails_beyond, Some([3.0, 3.0, 3.0]));
    // A pass too noisy to catch a doubling is untimed, also when it fails beyond its limit.
    let beyond = covered(Gl, Tier::OtherHost, SpeedOutcome::Slower, Some(3.2));
    let found = coverage(&[beyond]);
    assert_eq!((found[0].timed, found[0].untimed), (0, 1));
}

/// The advice under the coverage: none where every pass was read at this host's own limits;
/// record this host where some were read at any host's and it has no recording; and where it
/// has one (by fingerprint and CPU, on any backend, whether or not any pass of this run was read
/// against it: a scene newer than the recording has none), record it again, by its name, naming
/// the backends it lacks.
#[test]
fn the_advice_under_the_coverage_says_whether_to_record_this_host_or_record_it_again() {
    use harness::golden::speed::verdict::record_this_host;
    use std::collections::BTreeMap;
    use BackendKind::{Gl, WgpuVulkan};
    let mut recorded = covered(Gl, Tier::RecordedHost, SpeedOutcome::Passed, Some(1.69));
    recorded.noise = Some((1.3, "host-d's recording".to_owned()));
    let stale = covered(Gl, Tier::OtherHost, SpeedOutcome::Passed, Some(1.8));
    let elsewhere = covered(WgpuVulkan, Tier::OtherHost, SpeedOutcome::Passed, Some(1.8));
    let on_gl = BTreeMap::from([(Gl, "host-d".to_owned())]);
    let nowhere = BTreeMap::new();
    // A new scene before its bless: nothing to record yet.
    let new = covered(Gl, Tier::OtherHost, SpeedOutcome::MissingGolden, Some(1.8));
    assert_eq!(record_advice(&coverage(&[new]), &nowhere), None);
    assert_eq!(
        record_advice(&coverage(std::slice::from_ref(&recorded)), &on_gl),
        None
    );
    // Recorded on gl, not on wgpu-vulkan, which was read at any host's limits: record it again.
    let partly = record_advice(&coverage(&[recorded.clone(), elsewhere]), &on_gl).unwrap();
    assert!(
        partly.contains("this host is recorded (host-d's recording, not on wgpu-vulkan)"),
        "{partly}"
    );
    // A last-check.json from before `recorded_as`: the recording named by a pass read
    // against it.
    let older = record_advice(&coverage(&[recorded.clone(), stale.clone()]), &nowhere).unwrap();
    assert!(older.contains("--record-host host-d`"), "{older}");
    assert_eq!(
        record_advice(&coverage(std::slice::from_ref(&stale)), &nowhere).as_deref(),
        Some(record_this_host().as_str())
    );
    // Recorded on gl: whether or not a pass was read against the recording (a new scene's
    // passes alone are not), the advice is to record it again, by its name.
    for run in [vec![recorded, stale.clone()], vec![stale]] {
        let again = record_advice(&coverage(&run), &on_gl).unwrap();
        assert!(
            again.contains(
                "this host is recorded (host-d's recording), but it does not hold some passes' \
                 timing goldens as they are"
            ) && again.contains(" noise --timing --record-host host-d`"),
            "{again}"
        );
    }
}

/// A timing bless's stamp at time "t", without a reason.
fn stamp<'a>(host: &'a str, cpu: &'a str) -> harness::golden::speed::Stamp<'a> {
    harness::golden::speed::Stamp {
        host,
        cpu,
        blessed: "t",
        reason: None,
    }
}

/// A pass whose targets changed since its golden (a smaller shadow map: its floor shrinks with
/// it) is not compared, whichever way its ratio moved: it fails as not comparable, naming both,
/// and its ratio is not called slower or faster. Goldens that kept no targets compare the ratio
/// alone, as before.
#[test]
fn a_pass_whose_targets_changed_is_not_compared_with_its_golden() {
    let with_targets = |tonemap_ms: f64, targets: &str| {
        let mut p = probe(tonemap_ms, 4.0);
        for pass in &mut p.passes {
            pass.targets = Some(format!("{} {targets}", pass.pass));
        }
        p
    };
    let mut goldens = TimingGoldens::default();
    goldens.record(
        &with_targets(3.0, "1024x1024 depth32f"),
        &[],
        &stamp("here", &cpu_signature()),
    );
    let noise = model();
    let tonemap = |p: &SceneSpeed, goldens: &TimingGoldens| {
        check_speed(p, goldens, &noise, "here")
            .into_iter()
            .find(|c| c.pass == PassId::ToneMap)
            .unwrap()
    };
    let same = tonemap(&with_targets(3.0, "1024x1024 depth32f"), &goldens);
    assert_eq!(same.outcome, SpeedOutcome::Passed);
    for ms in [1.0, 3.0, 9.0] {
        let other = tonemap(&with_targets(ms, "256x256 depth32f"), &goldens);
        let SpeedOutcome::TargetsChanged(what) = &other.outcome else {
            panic!("{:?}", other.outcome);
        };
        assert!(
            what.contains("tonemap 256x256 depth32f") && what.contains("tonemap 1024x1024"),
            "{what}"
        );
        assert!(other.failed());
        assert!(
            other.describe().starts_with("not comparable: ")
                && other
                    .describe()
                    .contains("bless its timing with the change"),
            "{}",
            other.describe()
        );
    }
    // Blessed before targets were kept: the ratio alone.
    let mut old = goldens.clone();
    for timings in old.backends.values_mut() {
        for pass in timings.passes.values_mut() {
            pass.targets = None;
        }
    }
    let slower = tonemap(&with_targets(9.0, "256x256 depth32f"), &old);
    assert_eq!(slower.outcome, SpeedOutcome::Slower);
}

/// A scene outside the canonical set has no figures of its own and borrows every scene's: on
/// the blessing host its figures count as measured here when every scene it borrows from was
/// measured here (it was `moved-here` for ever before, whatever the model said).
#[test]
fn a_scene_that_borrows_figures_is_read_as_the_hosts_that_measured_them() {
    let mut goldens = TimingGoldens::default();
    let mut other = probe(3.0, 4.0);
    other.scene = "elsewhere.toml".to_owned();
    goldens.record(&other, &[], &stamp("here", &cpu_signature()));
    let tier = |noise: &TimingNoise| {
        let checks = check_speed(&other, &goldens, noise, "here");
        (checks[0].tier, checks[0].borrowed)
    };
    assert_eq!(tier(&model()), (Tier::SameHost, true));
    assert_eq!(
        tier(&model_measured_on("the previous blessing host")),
        (Tier::MovedHere, true)
    );
    let mut unstamped = model();
    unstamped.measured_on.clear();
    assert_eq!(tier(&unstamped), (Tier::MovedHere, true));
}

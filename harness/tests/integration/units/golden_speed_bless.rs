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
                targets: None,
                unslowed_ms: Vec::new(),
            },
            PassSpeed {
                pass: PassId::Geometry,
                pass_ms: vec![geometry],
                floor_ms: vec![1.0],
                targets: None,
                unslowed_ms: Vec::new(),
            },
        ],
    };
    let median = median_probe(&[probe(3.0, 1.0), probe(1.0, 2.0), probe(2.0, 9.0)]).unwrap();
    assert_eq!(median.passes[0].ratio(), Some(2.0));
    assert_eq!(median.passes[1].ratio(), Some(2.0));
    assert!(median_probe(&[]).is_none());
}

/// A bless writes a backend's timing goldens where there are none, where this host blessed
/// them, or when they are asked to move here (`--speed-only --every-pass`); otherwise it keeps
/// them (one backend's goldens are one host's ratios) and says how to move them all here.
#[test]
fn a_bless_keeps_another_hosts_timing_goldens_unless_every_pass_moves() {
    use harness::golden::speed::BackendTimings;
    let section = BackendTimings {
        blessed: "2026-11-25T10:00:00Z".to_owned(),
        host: "the EPYC".to_owned(),
        cpu: "family 23 model 49 stepping 0".to_owned(),
        rounds: 12,
        passes: Default::default(),
    };
    let here = ("host-c", "family 6 model 207 stepping 2");
    assert_eq!(kept_as_another_hosts(None, here.0, here.1, false), None);
    assert_eq!(
        kept_as_another_hosts(Some(&section), "the EPYC", &section.cpu, false),
        None
    );
    assert_eq!(
        kept_as_another_hosts(Some(&section), here.0, here.1, true),
        None
    );
    let why = kept_as_another_hosts(Some(&section), here.0, here.1, false).unwrap();
    assert!(
        why.starts_with(
            "blessed on another host (the EPYC, family 23 model 49 stepping 0, \
             2026-11-25T10:00:00Z)"
        ),
        "{why}"
    );
    // The same fingerprint on another CPU is another host.
    assert!(kept_as_another_hosts(Some(&section), "the EPYC", here.1, false).is_some());
    // Goldens that keep no CPU are kept on every host, and the refusal says why.
    let unsigned = BackendTimings {
        cpu: String::new(),
        ..section.clone()
    };
    let why = kept_as_another_hosts(Some(&unsigned), "the EPYC", here.1, false).unwrap();
    assert!(why.contains("a CPU they do not record"), "{why}");
}

/// A bless that keeps another host's timing goldens in several scenes says so once per
/// backend, naming the scenes, and gives one command that moves them all (after a driver
/// change every scene is another host's: one line each made eight near-identical paragraphs).
#[test]
fn another_hosts_goldens_kept_are_said_once_per_backend_with_one_command() {
    let kept = |scene: &str, backend: BackendKind, why: &str| SpeedBlessed {
        scene: scene.to_owned(),
        backend,
        pass: None,
        previous: why.to_owned(),
        fate: Fate::KeptAsAnotherHosts,
        moved_here: false,
        refused: true,
    };
    let mut lines = Vec::new();
    for scene in ["arrow", "chess", "mine"] {
        lines.push(kept(
            scene,
            BackendKind::Gl,
            "blessed on another host (gl's)",
        ));
        lines.push(kept(
            scene,
            BackendKind::WgpuVulkan,
            "blessed on another host (vk's)",
        ));
    }
    // A line of another fate is not among them.
    lines.push(SpeedBlessed {
        fate: Fate::Kept,
        ..kept("corner", BackendKind::Gl, "within its limit")
    });
    let arguments = [
        ("arrow".to_owned(), "arrow".to_owned()),
        ("chess".to_owned(), "chess".to_owned()),
        ("mine".to_owned(), "/tmp/my scenes/mine.toml".to_owned()),
    ];
    let said = another_hosts_lines(&lines, &arguments);
    assert_eq!(said.len(), 3, "{said:#?}");
    assert_eq!(
        said[0],
        "arrow, chess, mine on gl (speed): kept: blessed on another host (gl's)"
    );
    assert_eq!(
        said[1],
        "arrow, chess, mine on wgpu-vulkan (speed): kept: blessed on another host (vk's)"
    );
    assert!(
        said[2].contains("--record-host NAME")
            && said[2].ends_with(
                "bless --scene arrow --scene chess --scene '/tmp/my scenes/mine.toml' \
                 --speed-only --every-pass"
            ),
        "{}",
        said[2]
    );
    assert!(another_hosts_lines(&lines[6..], &arguments).is_empty());
}

/// A check read against this host's recording carries its slowdown into the blessing host's
/// terms (golden x slowdown), with where it came from; a check at any other tier, or of a pass
/// with no golden, writes nothing and says why.
#[test]
fn a_recorded_hosts_slowdown_is_written_as_the_golden_times_it() {
    use harness::golden::speed::{SpeedCheck, SpeedOutcome, Tier, TimingGoldens};
    let mut goldens = TimingGoldens::default();
    goldens.record(&probe_of(&[(PassId::ToneMap, 3.0)]), &[], &epyc("t0"));
    let check = SpeedCheck {
        scene: "s".to_owned(),
        backend: BackendKind::Gl,
        pass: PassId::ToneMap,
        ratio: 5.0,
        ms: 5.0,
        targets: None,
        delivered: None,
        golden: Some(2.5),
        limit: Some(1.69),
        noise: Some((1.1, "host-d's recording".to_owned())),
        borrowed: false,
        tier: Tier::RecordedHost,
        outcome: SpeedOutcome::Slower,
    };
    let mut written = goldens.clone();
    assert_eq!(
        record_scaled_check(&mut written, &check, "t1", Some("on purpose")),
        Ok(6.0)
    );
    let pass = &written.backends[&BackendKind::Gl].passes[&PassId::ToneMap];
    assert_eq!(
        (pass.ratio, pass.ms, pass.floor_ms, pass.reason.as_deref()),
        (6.0, 5.0, 1.0, Some("on purpose"))
    );
    assert_eq!(
        pass.scaled.as_deref(),
        Some(
            "t1: x2.000 against host-d's recording (ratio 5.000 over its median 2.500) times \
             the golden before, 3.0000"
        )
    );
    assert_eq!(
        written.backends[&BackendKind::Gl].host,
        "the EPYC",
        "the section stays the blessing host's"
    );
    for tier in [Tier::OtherHost, Tier::SameHost, Tier::MovedHere] {
        let mut untouched = goldens.clone();
        let other = SpeedCheck {
            tier,
            ..check.clone()
        };
        let why = record_scaled_check(&mut untouched, &other, "t1", None).unwrap_err();
        assert!(
            why.contains("not read against a current recording"),
            "{why}"
        );
        assert_eq!(untouched, goldens);
    }
    let geometry = SpeedCheck {
        pass: PassId::Geometry,
        ..check
    };
    assert_eq!(
        record_scaled_check(&mut goldens.clone(), &geometry, "t1", None),
        Err("no timing golden to scale".to_owned())
    );
}

/// A dry run's lines say what would be written, not that it was.
#[test]
fn a_timing_bless_line_says_what_became_of_the_golden() {
    let line = |pass, fate| {
        SpeedBlessed {
            scene: "arrow".to_owned(),
            backend: BackendKind::Gl,
            pass,
            previous: "x1.02 of golden".to_owned(),
            fate,
            moved_here: false,
            refused: false,
        }
        .to_string()
    };
    assert_eq!(
        line(Some(PassId::Geometry), Fate::WouldBeRewritten),
        "arrow/geometry on gl (speed): x1.02 of golden; would be rewritten (dry run)"
    );
    assert_eq!(
        line(Some(PassId::Geometry), Fate::Rewritten),
        "arrow/geometry on gl (speed): x1.02 of golden; rewritten"
    );
    assert_eq!(
        line(None, Fate::Kept),
        "arrow on gl (speed): kept: x1.02 of golden"
    );
}

/// A check of `pass` on gl at `tier` with `outcome`: ratio 5 against a reference of 2.5.
fn check_of(
    pass: PassId,
    tier: harness::golden::speed::Tier,
    outcome: harness::golden::speed::SpeedOutcome,
) -> harness::golden::speed::SpeedCheck {
    harness::golden::speed::SpeedCheck {
        scene: "s".to_owned(),
        backend: BackendKind::Gl,
        pass,
        ratio: 5.0,
        ms: 5.0,
        targets: None,
        delivered: None,
        golden: Some(2.5),
        limit: Some(1.69),
        noise: Some((1.1, "host-d's recording".to_owned())),
        borrowed: false,
        tier,
        outcome,
    }
}

/// Goldens of tone mapping (3.0) and geometry (2.0) on gl, blessed on the EPYC.
fn two_goldens() -> harness::golden::speed::TimingGoldens {
    let mut goldens = harness::golden::speed::TimingGoldens::default();
    let probe = probe_of(&[(PassId::ToneMap, 3.0), (PassId::Geometry, 2.0)]);
    goldens.record(&probe, &[], &epyc("t0"));
    goldens
}

/// A probe of scene "s" on gl, 12 rounds: each pass at its ms over a floor of 1 ms.
fn probe_of(passes: &[(PassId, f64)]) -> SceneSpeed {
    SceneSpeed {
        scene: "s".to_owned(),
        backend: BackendKind::Gl,
        rounds: 12,
        passes: passes
            .iter()
            .map(|&(pass, ms)| PassSpeed {
                pass,
                pass_ms: vec![ms],
                floor_ms: vec![1.0],
                targets: None,
                unslowed_ms: Vec::new(),
            })
            .collect(),
    }
}

/// The blessing EPYC's stamp at time `blessed`, without a reason.
fn epyc(blessed: &'static str) -> harness::golden::speed::Stamp<'static> {
    harness::golden::speed::Stamp {
        host: "the EPYC",
        cpu: "family 23 model 49 stepping 0",
        blessed,
        reason: None,
    }
}

/// `--every-pass` with `--pass` on the host that blessed rewrites the passes named and keeps
/// the others (the section is replaced whole only when every pass is written).
#[test]
fn every_pass_with_named_passes_keeps_the_other_goldens() {
    use harness::golden::speed::{SpeedOutcome, Tier};
    let mut goldens = two_goldens();
    let probe = probe_of(&[(PassId::ToneMap, 4.0)]);
    let checks = [check_of(
        PassId::ToneMap,
        Tier::SameHost,
        SpeedOutcome::Passed,
    )];
    let stamp = epyc("t1");
    let options = TimingBless {
        every_pass: true,
        passes: &[PassId::ToneMap],
        ..TimingBless::default()
    };
    let lines = bless_own(
        &mut goldens,
        &probe,
        &checks,
        false,
        options,
        &stamp,
        Fate::Rewritten,
    );
    assert_eq!(lines.len(), 1);
    assert_eq!(lines[0].fate, Fate::Rewritten);
    let gl = &goldens.backends[&BackendKind::Gl];
    assert_eq!(gl.passes[&PassId::ToneMap].ratio, 4.0);
    assert_eq!(gl.passes[&PassId::Geometry].ratio, 2.0, "kept");
}

/// From a recorded host, only what moved (or is named) is carried over: `--every-pass` adds
/// nothing (a pass within its limit has only this host's noise to carry). A pass whose targets
/// changed cannot be carried over: refused, saying why and what writes it. A dry run writes
/// nothing.
#[test]
fn a_recorded_host_carries_over_only_what_moved() {
    use harness::golden::speed::{SpeedOutcome, Tier};
    let checks = [
        check_of(PassId::ToneMap, Tier::RecordedHost, SpeedOutcome::Passed),
        check_of(
            PassId::Geometry,
            Tier::RecordedHost,
            SpeedOutcome::TargetsChanged("it writes depth 512x512".to_owned()),
        ),
    ];
    let every_pass = TimingBless {
        every_pass: true,
        ..TimingBless::default()
    };
    let mut goldens = two_goldens();
    let lines = bless_scaled(&mut goldens, &checks, every_pass, "t1", Fate::Rewritten);
    assert_eq!(goldens, two_goldens(), "nothing within its limit written");
    assert_eq!(
        lines
            .iter()
            .map(|l| (l.fate, l.refused))
            .collect::<Vec<_>>(),
        [(Fate::Kept, false), (Fate::Kept, true)]
    );
    assert!(
        lines[1]
            .previous
            .contains("not written: it writes depth 512x512")
            && lines[1].previous.contains("--speed-only --every-pass"),
        "{}",
        lines[1].previous
    );
    assert!(!checks[1].bless_writes_here() && checks[0].bless_writes_here());
    // Slower: written (x2 of 3.0), not in a dry run.
    let slower = [check_of(
        PassId::ToneMap,
        Tier::RecordedHost,
        SpeedOutcome::Slower,
    )];
    let dry = TimingBless {
        dry_run: true,
        ..TimingBless::default()
    };
    let lines = bless_scaled(&mut goldens, &slower, dry, "t1", Fate::WouldBeRewritten);
    assert_eq!(lines[0].fate, Fate::WouldBeRewritten);
    assert_eq!(goldens, two_goldens(), "a dry run writes nothing");
    let lines = bless_scaled(
        &mut goldens,
        &slower,
        TimingBless::default(),
        "t1",
        Fate::Rewritten,
    );
    assert_eq!((lines[0].fate, lines[0].refused), (Fate::Rewritten, false));
    assert_eq!(
        goldens.backends[&BackendKind::Gl].passes[&PassId::ToneMap].ratio,
        6.0
    );
}

/// A pass without a timing golden is written new, and its line says so ("written (new)", not
/// "rewritten").
#[test]
fn a_pass_without_a_golden_is_written_new() {
    use harness::golden::speed::{SpeedOutcome, Tier};
    let mut goldens = two_goldens();
    let probe = probe_of(&[(PassId::Skybox, 2.5)]);
    let checks = [check_of(
        PassId::Skybox,
        Tier::SameHost,
        SpeedOutcome::MissingGolden,
    )];
    let stamp = epyc("t1");
    let lines = bless_own(
        &mut goldens,
        &probe,
        &checks,
        false,
        TimingBless::default(),
        &stamp,
        Fate::Rewritten,
    );
    assert_eq!(lines[0].fate, Fate::Written);
    assert!(lines[0].fate.written());
    assert!(
        lines[0].to_string().ends_with("; written (new)"),
        "{}",
        lines[0]
    );
    let gl = &goldens.backends[&BackendKind::Gl];
    assert_eq!(gl.passes[&PassId::Skybox].ratio, 2.5);
    assert_eq!(gl.passes.len(), 3, "the others kept");
    // A dry run says the same of it, and writes nothing.
    let mut untouched = two_goldens();
    let dry = TimingBless {
        dry_run: true,
        ..TimingBless::default()
    };
    let lines = bless_own(
        &mut untouched,
        &probe,
        &checks,
        false,
        dry,
        &stamp,
        Fate::WouldBeRewritten,
    );
    assert_eq!(lines[0].fate, Fate::WouldBeWritten);
    assert!(!lines[0].fate.written());
    assert!(
        lines[0]
            .to_string()
            .ends_with("; would be written (new; dry run)"),
        "{}",
        lines[0]
    );
    assert_eq!(untouched, two_goldens());
}

/// After goldens move here whole, the note to measure this host's timing noise names the
/// scenes whose same-host figures were measured elsewhere, once each, and not one whose figures
/// this host measured already (an earlier move): there the checks read its own limits at once.
#[test]
fn the_measure_noise_note_names_only_moved_scenes_measured_elsewhere() {
    use harness::golden::speed::{cpu_signature, TimingNoise};
    let line = |scene: &str, backend: BackendKind, fate: Fate, moved_here: bool| SpeedBlessed {
        scene: scene.to_owned(),
        backend,
        pass: None,
        previous: String::new(),
        fate,
        moved_here,
        refused: false,
    };
    let lines = [
        line("measured-here", BackendKind::Gl, Fate::Rewritten, true),
        line("measured-elsewhere", BackendKind::Gl, Fate::Rewritten, true),
        line(
            "measured-elsewhere",
            BackendKind::WgpuVulkan,
            Fate::Rewritten,
            true,
        ),
        line("not-moved", BackendKind::Gl, Fate::Rewritten, false),
        line("dry-run", BackendKind::Gl, Fate::WouldBeRewritten, true),
    ];
    let cpu = cpu_signature();
    let mut model = TimingNoise::default();
    for (scene, host) in [
        ("measured-here", "this host"),
        ("measured-elsewhere", "another host"),
        ("not-moved", "another host"),
        ("dry-run", "another host"),
    ] {
        for backend in [BackendKind::Gl, BackendKind::WgpuVulkan] {
            model
                .scenes
                .entry(scene.to_owned())
                .or_default()
                .insert(backend, Default::default());
            model.stamp_measured_on(scene, backend, host, &cpu);
        }
    }
    let hosts = [
        (BackendKind::Gl, "this host".to_owned()),
        (BackendKind::WgpuVulkan, "this host".to_owned()),
    ];
    assert_eq!(
        moved_without_figures_here(&lines, &model, &hosts, &cpu),
        ["measured-elsewhere"]
    );
}

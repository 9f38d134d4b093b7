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
    assert_eq!(
        kept_as_another_hosts(None, here.0, here.1, false, "arrow"),
        None
    );
    assert_eq!(
        kept_as_another_hosts(Some(&section), "the EPYC", &section.cpu, false, "arrow"),
        None
    );
    assert_eq!(
        kept_as_another_hosts(Some(&section), here.0, here.1, true, "arrow"),
        None
    );
    let why = kept_as_another_hosts(Some(&section), here.0, here.1, false, "arrow").unwrap();
    assert!(
        why.contains(
            "blessed on another host (the EPYC, family 23 model 49 stepping 0, \
             2026-11-25T10:00:00Z)"
        ) && why.ends_with("bless --scene arrow --speed-only --every-pass"),
        "{why}"
    );
    // The same fingerprint on another CPU is another host.
    assert!(kept_as_another_hosts(Some(&section), "the EPYC", here.1, false, "arrow").is_some());
    // Goldens that keep no CPU are kept on every host, and the refusal says why.
    let unsigned = BackendTimings {
        cpu: String::new(),
        ..section.clone()
    };
    let why = kept_as_another_hosts(Some(&unsigned), "the EPYC", here.1, false, "arrow").unwrap();
    assert!(why.contains("a CPU they do not record"), "{why}");
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

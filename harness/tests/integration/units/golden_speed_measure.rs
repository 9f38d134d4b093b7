//! Tests of `harness::golden::speed::measure`.

use engine::backend::BackendKind;
use engine::plan::PassId;
use harness::golden::speed::measure::*;
use harness::golden::speed::Tier;

#[test]
fn the_model_keeps_each_tiers_worst_source_and_scores_stay_at_half_the_limit() {
    let m = |source: &str, tier, factor| TimingMeasurement {
        source: source.to_owned(),
        tier,
        scene: "s".to_owned(),
        backend: BackendKind::Gl,
        pass: PassId::ToneMap,
        factor,
    };
    let measurements = vec![
        m("runs", Tier::SameHost, 1.1),
        m("busy-neighbour", Tier::SameHost, 1.2),
        m("cpu-avx", Tier::OtherHost, 1.3),
        m("cpu-sse4.1", Tier::OtherHost, 0.9),
    ];
    let (sources, _) = timing_sources();
    let model = model_from(&measurements, &sources, 2.0);
    let noise = &model.scenes["s"][&BackendKind::Gl][&PassId::ToneMap];
    assert_eq!(
        (noise.host, noise.host_at.as_str()),
        (1.2, "busy-neighbour")
    );
    assert_eq!((noise.drivers, noise.drivers_at.as_str()), (1.3, "cpu-avx"));
    for (m, _, score) in scores(&model, &measurements) {
        assert!(score <= 0.5 + 1e-9, "{m:?}: {score}");
    }
}

/// Timing noise is measured on a quiet machine only: from half the CPUs busy with other tasks
/// (at least one), `noise --timing --write` and `--record-host` refuse, saying why and how to
/// measure anyway; the reading works where /proc/stat exists.
#[test]
fn timing_noise_is_not_measured_on_a_busy_machine() {
    use harness::golden::speed::measure::{machine_load, too_busy};
    assert_eq!(too_busy(0, 2), None);
    let why = too_busy(1, 2).expect("one other task on two CPUs is busy");
    assert!(
        why.contains("1 other task(s) running on its 2 CPU(s)") && why.contains("--busy-ok"),
        "{why}"
    );
    assert_eq!(too_busy(0, 1), None);
    assert!(too_busy(1, 1).is_some());
    assert_eq!(too_busy(7, 16), None);
    assert!(too_busy(8, 16).is_some());
    if cfg!(target_os = "linux") {
        let (_, cpus) = machine_load(1).expect("/proc/stat");
        assert!(cpus >= 1);
    }
}

/// A probe of other targets than its golden's measures no noise: named, not counted.
#[test]
fn a_probe_of_other_targets_is_not_a_noise_measurement() {
    use harness::golden::speed::measure::targets_changed;
    use harness::golden::speed::PassTiming;
    use harness::measure::speed::PassSpeed;
    let probe = |targets: Option<&str>| PassSpeed {
        pass: engine::plan::PassId::Geometry,
        pass_ms: vec![2.0],
        floor_ms: vec![1.0],
        targets: targets.map(str::to_owned),
        unslowed_ms: Vec::new(),
    };
    let golden = |targets: Option<&str>| PassTiming {
        ratio: 2.0,
        ms: 2.0,
        floor_ms: 1.0,
        targets: targets.map(str::to_owned),
        reason: None,
        scaled: None,
    };
    let gl = engine::backend::BackendKind::Gl;
    let why = targets_changed(
        "s",
        gl,
        &probe(Some("depth 256x256")),
        &golden(Some("depth 1024x1024")),
    )
    .expect("other targets");
    assert!(
        why.contains("s geometry on gl: it writes depth 256x256")
            && why.contains("wrote depth 1024x1024"),
        "{why}"
    );
    assert_eq!(
        targets_changed("s", gl, &probe(Some("a")), &golden(Some("a"))),
        None
    );
    assert_eq!(
        targets_changed("s", gl, &probe(None), &golden(Some("a"))),
        None
    );
    assert_eq!(
        targets_changed("s", gl, &probe(Some("a")), &golden(None)),
        None
    );
}

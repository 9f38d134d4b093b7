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
    use harness::golden::speed::measure::{others_running, too_busy};
    assert_eq!(too_busy(0, 2), None);
    let why = too_busy(1, 2).expect("one other task on two CPUs is busy");
    assert!(
        why.contains("1 other task(s) running on 2 CPU(s)") && why.contains("--busy-ok"),
        "{why}"
    );
    assert_eq!(too_busy(0, 1), None);
    assert!(too_busy(1, 1).is_some());
    assert_eq!(too_busy(7, 16), None);
    assert!(too_busy(8, 16).is_some());
    if cfg!(target_os = "linux") {
        assert!(others_running(1).is_some());
    }
}

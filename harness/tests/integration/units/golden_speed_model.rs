//! Tests of `harness::golden::speed::model`.

use engine::backend::BackendKind;
use engine::plan::PassId;
use harness::golden::speed::model::*;
use harness::golden::speed::{MIN_NOISE, MIN_NOISE_SHORT};
use std::collections::BTreeMap;

fn noise(host: f64, drivers: f64) -> PassNoise {
    PassNoise {
        host,
        host_at: "busy".to_owned(),
        drivers,
        drivers_at: "cpu-avx".to_owned(),
    }
}

#[test]
fn limits_are_noise_to_the_margin_and_another_host_counts_the_drivers() {
    let mut model = TimingNoise::default();
    model.scenes.entry("a".to_owned()).or_default().insert(
        BackendKind::Gl,
        BTreeMap::from([(PassId::ToneMap, noise(1.2, 1.3))]),
    );
    model.scenes.entry("b".to_owned()).or_default().insert(
        BackendKind::Gl,
        BTreeMap::from([(PassId::ToneMap, noise(1.1, 1.5))]),
    );
    assert!((model.limit(1.2) - 1.44).abs() < 1e-12);
    assert!((model.limit(1.01) - MIN_NOISE * MIN_NOISE).abs() < 1e-12);
    assert_eq!(model.limit_for(1.2, 5.0), model.limit(1.2));
    assert!((model.limit_for(1.1, 0.5) - MIN_NOISE_SHORT.powi(2)).abs() < 1e-12);
    let (own, borrowed) = model
        .figures("a", BackendKind::Gl, PassId::ToneMap)
        .unwrap();
    assert!(!borrowed);
    assert_eq!(own.noise(Tier::SameHost).0, 1.2);
    assert_eq!(own.noise(Tier::OtherHost), (1.3, "cpu-avx"));
    let (worst, borrowed) = model
        .figures("new", BackendKind::Gl, PassId::ToneMap)
        .unwrap();
    assert!(borrowed);
    assert_eq!((worst.host, worst.drivers), (1.2, 1.5));
    assert!(model
        .figures("a", BackendKind::WgpuGl, PassId::ToneMap)
        .is_none());
    // Where the same-host figures were measured survives the file, and a merge keeps it.
    model.measured_on.entry("a".to_owned()).or_default().insert(
        BackendKind::Gl,
        MeasuredOn {
            host: "gl on here".to_owned(),
            cpu: "family 26 model 2 stepping 1".to_owned(),
        },
    );
    let dir = tempfile::tempdir().unwrap();
    model.save(dir.path()).unwrap();
    assert_eq!(TimingNoise::load(dir.path()).unwrap(), model);
    let merged = harness::golden::speed::measure::merged(TimingNoise::default(), model.clone());
    assert_eq!(merged.measured_on, model.measured_on);
    // A margin that makes every limit infinite (none could fire) is refused, naming it.
    let path = TimingNoise::path(dir.path());
    let text = std::fs::read_to_string(&path).unwrap();
    let margin = text.lines().find(|l| l.starts_with("margin = ")).unwrap();
    std::fs::write(&path, text.replace(margin, "margin = 5000.0")).unwrap();
    let error = TimingNoise::load(dir.path()).unwrap_err().to_string();
    assert!(
        error.contains("timing-noise.toml") && error.contains("margin 5000 makes even"),
        "{error}"
    );
}

/// Measuring this host's noise for goldens moved here replaces the previous host's same-host
/// figures of those scenes and backends (a merge only raises them); other figures merge as
/// before.
#[test]
fn figures_measured_for_goldens_moved_here_replace_the_previous_hosts() {
    let model_with = |host: f64, drivers: f64| {
        let mut model = TimingNoise::default();
        for scene in ["a", "b"] {
            model.scenes.entry(scene.to_owned()).or_default().insert(
                BackendKind::Gl,
                BTreeMap::from([(PassId::ToneMap, noise(host, drivers))]),
            );
        }
        model
    };
    let figure = |model: &TimingNoise, scene: &str| {
        let n = &model.scenes[scene][&BackendKind::Gl][&PassId::ToneMap];
        (n.host, n.drivers)
    };
    let old = model_with(1.5, 1.3);
    let measured = model_with(1.1, 1.4);
    let raised = harness::golden::speed::measure::merged(old.clone(), measured.clone());
    assert_eq!(figure(&raised, "a"), (1.5, 1.4));
    let moved = [("a".to_owned(), BackendKind::Gl)];
    let replaced = harness::golden::speed::measure::merged_replacing(old, measured, &moved);
    assert_eq!(figure(&replaced, "a"), (1.1, 1.4));
    assert_eq!(figure(&replaced, "b"), (1.5, 1.4));
    // A pass no same-host source measured in this run (a placeholder) replaces nothing.
    let mut placeholder = model_with(1.1, 1.4);
    let entry = placeholder
        .scenes
        .get_mut("a")
        .unwrap()
        .get_mut(&BackendKind::Gl)
        .unwrap()
        .get_mut(&PassId::ToneMap)
        .unwrap();
    entry.host = 0.0;
    entry.host_at = "-".to_owned();
    let kept = harness::golden::speed::measure::merged_replacing(
        model_with(1.5, 1.3),
        placeholder,
        &moved,
    );
    assert_eq!(figure(&kept, "a"), (1.5, 1.4));
}

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
}

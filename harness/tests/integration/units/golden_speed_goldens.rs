//! Tests of `harness::golden::speed::goldens`.

use engine::backend::BackendKind;
use engine::plan::PassId;
use harness::golden::speed::goldens::*;
use harness::measure::speed::PassSpeed;
use harness::measure::speed::SceneSpeed;

#[test]
fn goldens_round_trip_and_a_partial_bless_keeps_the_other_passes() {
    let dir = tempfile::tempdir().unwrap();
    let probe = |ratio: f64| SceneSpeed {
        scene: "s".to_owned(),
        backend: BackendKind::Gl,
        rounds: 3,
        passes: vec![
            PassSpeed {
                pass: PassId::Geometry,
                pass_ms: vec![ratio, ratio * 2.0],
                floor_ms: vec![1.0],
                targets: None,
                unslowed_ms: Vec::new(),
            },
            PassSpeed {
                pass: PassId::ToneMap,
                pass_ms: vec![ratio],
                floor_ms: vec![1.0],
                targets: None,
                unslowed_ms: Vec::new(),
            },
        ],
    };
    let mut goldens = TimingGoldens::default();
    let stamp = Stamp {
        host: "host a",
        cpu: "family 1 model 2 stepping 3",
        blessed: "t0",
        reason: Some("the G-buffer packs normals now"),
    };
    goldens.record(&probe(2.0), &[], &stamp);
    goldens.save(dir.path(), "s").unwrap();
    let mut loaded = TimingGoldens::load(dir.path(), "s").unwrap();
    assert_eq!(loaded, goldens);
    assert_eq!(
        loaded.backends[&BackendKind::Gl].passes[&PassId::ToneMap]
            .reason
            .as_deref(),
        Some("the G-buffer packs normals now")
    );
    let stamp = Stamp {
        host: "host b",
        cpu: "family 4 model 5 stepping 6",
        blessed: "t1",
        reason: None,
    };
    loaded.record(&probe(3.0), &[PassId::ToneMap], &stamp);
    let gl = &loaded.backends[&BackendKind::Gl];
    assert_eq!(gl.passes[&PassId::Geometry].ratio, 2.0);
    assert_eq!(gl.passes[&PassId::ToneMap].ratio, 3.0);
    // A pass recorded again without a reason drops the old one (it was about the old ratio);
    // the pass not recorded keeps its own.
    assert_eq!(gl.passes[&PassId::ToneMap].reason, None);
    assert!(gl.passes[&PassId::Geometry].reason.is_some());
    assert_eq!(gl.host, "host b");
    assert_eq!(gl.cpu, "family 4 model 5 stepping 6");
    assert!(gl.blessed_on("host b", "family 4 model 5 stepping 6"));
    assert!(!gl.blessed_on("host b", "family 4 model 5 stepping 7"));
    assert!(!gl.blessed_on("host a", "family 4 model 5 stepping 6"));
    assert_eq!(
        TimingGoldens::load(dir.path(), "none").unwrap(),
        TimingGoldens::default()
    );
    std::fs::write(TimingGoldens::path(dir.path(), "s"), "[gl]\nblessed = 3").unwrap();
    let error = TimingGoldens::load(dir.path(), "s")
        .unwrap_err()
        .to_string();
    assert!(error.contains("timing.toml"), "{error}");
    // A ratio that is not a finite positive number is an error at its key, not a verdict.
    let text = toml::to_string(&goldens).unwrap();
    for bad in ["nan", "-2.0", "0.0", "inf"] {
        let broken = text.replacen("ratio = 2.0", &format!("ratio = {bad}"), 1);
        assert_ne!(broken, text);
        std::fs::write(TimingGoldens::path(dir.path(), "s"), broken).unwrap();
        let error = TimingGoldens::load(dir.path(), "s")
            .unwrap_err()
            .to_string();
        assert!(
            error.contains("timing.toml") && error.contains("not a finite positive number"),
            "{bad}: {error}"
        );
    }
}

/// Goldens blessed before the CPU signature was kept name no host: the same fingerprint is not
/// enough (a generic model name covers CPUs that time unlike each other).
#[test]
fn goldens_without_a_cpu_signature_were_blessed_on_no_host_a_check_can_name() {
    let dir = tempfile::tempdir().unwrap();
    std::fs::create_dir_all(dir.path().join("s")).unwrap();
    std::fs::write(
        TimingGoldens::path(dir.path(), "s"),
        "[gl]\nblessed = \"t\"\nhost = \"h\"\nrounds = 4\n\n\
         [gl.passes.tonemap]\nratio = 2.0\nms = 1.0\nfloor_ms = 0.5\n",
    )
    .unwrap();
    let old = TimingGoldens::load(dir.path(), "s").unwrap();
    let gl = &old.backends[&BackendKind::Gl];
    assert_eq!(gl.cpu, "");
    assert!(!gl.blessed_on("h", "family 6 model 207 stepping 2"));
    assert!(!gl.blessed_on("h", ""));
    // Nor does a signature with fields /proc/cpuinfo did not have.
    let unknown = BackendTimings {
        cpu: "family ? model ? stepping ?".to_owned(),
        ..gl.clone()
    };
    assert!(!unknown.blessed_on("h", "family ? model ? stepping ?"));
    assert!(!gl.blessed_on("another", "family 6 model 207 stepping 2"));
    // Written again, an empty signature stays out of the file.
    old.save(dir.path(), "s").unwrap();
    let text = std::fs::read_to_string(TimingGoldens::path(dir.path(), "s")).unwrap();
    assert!(!text.contains("cpu"), "{text}");
}

/// `noise --timing` asks which backend's goldens this host did not bless: another host's
/// fingerprint, another CPU behind it, or no CPU signature at all. Backends without goldens,
/// or not asked about, are not in question.
#[test]
fn the_backends_blessed_elsewhere_are_named() {
    let cpu = "family 26 model 2 stepping 1";
    let section = |host: &str, cpu: &str| BackendTimings {
        blessed: "t".to_owned(),
        host: host.to_owned(),
        cpu: cpu.to_owned(),
        rounds: 4,
        passes: Default::default(),
    };
    let goldens = TimingGoldens {
        backends: [
            (BackendKind::Gl, section("gl here", cpu)),
            (BackendKind::WgpuVulkan, section("vulkan here", "")),
        ]
        .into(),
    };
    let here = |kinds: &[(BackendKind, &str)]| -> Vec<(BackendKind, String)> {
        kinds.iter().map(|(k, h)| (*k, (*h).to_owned())).collect()
    };
    assert!(goldens
        .blessed_elsewhere(&here(&[(BackendKind::Gl, "gl here")]), cpu)
        .is_none());
    // No goldens for wgpu-gl: nothing to compare with.
    assert!(goldens
        .blessed_elsewhere(&here(&[(BackendKind::WgpuGl, "anything")]), cpu)
        .is_none());
    let elsewhere = |hosts, cpu| goldens.blessed_elsewhere(&here(hosts), cpu).map(|(k, _)| k);
    assert_eq!(
        elsewhere(&[(BackendKind::Gl, "gl there")], cpu),
        Some(BackendKind::Gl)
    );
    assert_eq!(
        elsewhere(
            &[(BackendKind::Gl, "gl here")],
            "family 25 model 17 stepping 1"
        ),
        Some(BackendKind::Gl)
    );
    assert_eq!(
        elsewhere(
            &[
                (BackendKind::Gl, "gl here"),
                (BackendKind::WgpuVulkan, "vulkan here")
            ],
            cpu
        ),
        Some(BackendKind::WgpuVulkan)
    );
}

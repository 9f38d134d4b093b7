//! The speed checks end to end: a pass slowed down fails its own speed check and no other, the
//! verdict `harness check` and the golden tests give; and the probe child takes no timed round
//! before it is told to (what lets `check` prepare it while it renders the images).

use engine::backend::BackendKind;
use engine::renderer::{SlowPass, Variations};
use harness::golden::speed::{check_scenes, start_check, SpeedOutcome, Tier, TimingNoise};

use crate::common;

/// Chess on gl with one pass submitted three times over: that pass's check fails, and every
/// other pass of the frame passes (or is untimed), on this host or any other. The pass is the
/// one the timing-noise model gives the tightest limit on a host that did not bless. x3 clears
/// it even where a host reads the pass low: tripled, chess's geometry read x1.85 of its golden
/// on host-c (limit x1.44), where unchanged ratios lie at x0.4 to x1.7 of the blessing host's.
#[test]
fn a_slowed_pass_fails_its_own_speed_check_and_no_other() {
    if !common::gl_available() {
        return;
    }
    let store = harness::golden::GoldenStore::workspace();
    let model = TimingNoise::load(store.root()).unwrap();
    let slowed = model.scenes["chess"][&BackendKind::Gl]
        .iter()
        .min_by(|a, b| {
            let noise = |n: &harness::golden::speed::PassNoise| n.noise(Tier::OtherHost).0;
            noise(a.1).total_cmp(&noise(b.1))
        })
        .map(|(pass, _)| *pass)
        .unwrap();
    let driver = engine::backend::probe(BackendKind::Gl)
        .info
        .map(|info| harness::golden::fingerprint(&info))
        .unwrap_or_default();
    let scenes = [("chess".to_owned(), "chess".to_owned())];
    let started = start_check(
        std::path::Path::new(env!("CARGO_BIN_EXE_harness")),
        &scenes,
        &[BackendKind::Gl],
        Variations {
            slow_pass: Some(SlowPass {
                pass: slowed,
                factor: 3.0,
            }),
            ..Default::default()
        },
        &[],
    );
    let run = check_scenes(
        started,
        store.root(),
        &scenes,
        &[(BackendKind::Gl, driver)],
        |_| {},
    );
    assert!(run.errors.is_empty(), "{:?}", run.errors);
    let check = run.checks.iter().find(|c| c.pass == slowed).unwrap();
    assert_eq!(
        check.outcome,
        SpeedOutcome::Slower,
        "{slowed}: {}",
        check.describe()
    );
    for other in run.checks.iter().filter(|c| c.pass != slowed) {
        assert!(!other.failed(), "{}: {}", other.pass, other.describe());
    }
    assert!(!run.passed());
}

/// The probe child (`speed --in-process --wait-for-go`) prepares its probes, then takes no timed
/// round until a line comes on its stdin, and then probes as it would have.
#[test]
fn the_probe_child_takes_no_timed_round_before_it_is_told_to() {
    use std::io::{BufRead, Read, Write};
    use std::time::Duration;
    if !common::gl_available() {
        return;
    }
    let mut child = std::process::Command::new(env!("CARGO_BIN_EXE_harness"))
        .args(["speed", "--in-process", "--json", "--wait-for-go"])
        .args(["--scene", "arrow", "--backend", "gl", "--rounds", "4"])
        .envs(harness::measure::speed::PROBE_ENV)
        .stdin(std::process::Stdio::piped())
        .stdout(std::process::Stdio::piped())
        .stderr(std::process::Stdio::piped())
        .spawn()
        .unwrap();
    let stderr = std::io::BufReader::new(child.stderr.take().unwrap());
    let (sender, lines) = std::sync::mpsc::channel::<String>();
    let reader = std::thread::spawn(move || {
        for line in stderr.lines().map_while(Result::ok) {
            let _ = sender.send(line);
        }
    });
    let waiting = lines
        .iter()
        .find(|line| line.starts_with("prepared 1 probe(s); waiting"));
    assert!(waiting.is_some(), "the child never said it was waiting");
    // Told nothing, it stays put (a child that did not wait would say `probing` within
    // milliseconds of being ready).
    let early: Vec<String> =
        std::iter::from_fn(|| lines.recv_timeout(Duration::from_millis(500)).ok()).collect();
    assert!(
        !early.iter().any(|line| line.starts_with("probing")),
        "a timed round before the go: {early:?}"
    );
    child.stdin.take().unwrap().write_all(b"go\n").unwrap();
    let mut json = String::new();
    child
        .stdout
        .take()
        .unwrap()
        .read_to_string(&mut json)
        .unwrap();
    assert!(child.wait().unwrap().success());
    reader.join().unwrap();
    let after: Vec<String> = lines.try_iter().collect();
    assert!(
        after
            .iter()
            .any(|line| line.starts_with("probing arrow on gl")),
        "{after:?}"
    );
    let probes: Vec<harness::measure::speed::SceneSpeed> = serde_json::from_str(&json).unwrap();
    assert_eq!(probes.len(), 1);
    assert_eq!(
        (probes[0].scene.as_str(), probes[0].backend),
        ("arrow", BackendKind::Gl)
    );
    assert!(probes[0].passes.len() >= 5, "{:?}", probes[0].passes);
}

/// `noise --timing --write` measures and writes the blessing host's own noise: on a host that
/// did not bless (here every host: the copy's corner goldens name another), it refuses before
/// probing, names the scene, backend and host, and points at recording the host instead; the
/// model is left as it was. Without `--write` it measures with a note saying the same.
#[test]
fn timing_noise_is_written_only_on_the_host_that_blessed() {
    let root = common::temp_workspace();
    let timing = root.path().join("golden/corner/timing.toml");
    let text = std::fs::read_to_string(&timing).unwrap();
    std::fs::write(
        &timing,
        text.replace("host = \"", "host = \"another host | "),
    )
    .unwrap();
    let model = root.path().join("golden/timing-noise.toml");
    let before = std::fs::read(&model).unwrap();
    let output = common::harness_command()
        .args([
            "noise", "--timing", "--source", "runs", "--write", "--scene", "corner",
        ])
        .env("HARNESS_ROOT", root.path())
        .output()
        .unwrap();
    let stderr = String::from_utf8_lossy(&output.stderr);
    if common::available_backends().is_empty() {
        return;
    }
    assert_eq!(output.status.code(), Some(1), "{stderr}");
    // The copy's goldens keep no CPU signature (as the committed ones), so no host blessed
    // them; the remedies name the scene, and this host's recording where it has one.
    assert!(
        stderr.contains("corner's timing goldens on")
            && stderr.contains("keep no CPU signature")
            && stderr.contains("`harness bless --speed-only --every-pass --scene corner`")
            && stderr.contains("--record-host ")
            && !stderr.contains("timing noise: runs on"),
        "{stderr}"
    );
    assert_eq!(std::fs::read(&model).unwrap(), before);
}

/// `noise --timing --scene S` prints the model's rows of that scene only (it printed every
/// scene's), here from a recorded host's figures alone, which it reads without probing.
#[test]
fn timing_noise_of_one_scene_prints_that_scene_only() {
    let output = common::harness_command()
        .args([
            "noise", "--timing", "--source", "host-c", "--scene", "arrow",
        ])
        .output()
        .unwrap();
    let stdout = String::from_utf8_lossy(&output.stdout);
    assert!(output.status.success(), "{stdout}{output:?}");
    let rows: Vec<&str> = stdout
        .lines()
        .skip(1)
        .take_while(|l| !l.contains(" measurements, "))
        .collect();
    assert!(rows.len() >= 6, "{stdout}");
    assert!(rows.iter().all(|r| r.starts_with("arrow ")), "{stdout}");
}

/// Timing goldens blessed on this host, with the model's same-host figures from another (as
/// after `bless --speed-only --every-pass`): `check` reads them at the limits for any host as
/// `moved-here`, says so once with the command that measures this host, and does not take the
/// host for one to record.
#[test]
fn goldens_moved_here_are_read_at_any_hosts_limits_until_measured_here() {
    use engine::backend::BackendKind;
    if !common::gl_available() {
        return;
    }
    let root = common::temp_workspace();
    common::bless_timings_here(root.path(), "arrow", BackendKind::Gl, &[], 1.0);
    // The fixture stamps the model as measured here; the previous host measured it instead.
    let golden = root.path().join("golden");
    let mut model = harness::golden::speed::TimingNoise::load(&golden).unwrap();
    model.measured_on.clear();
    model.save(&golden).unwrap();
    let summary = root.path().join("summary.md");
    let output = common::harness_command()
        .args([
            "check",
            "--scene",
            "arrow",
            "--backend",
            "gl",
            "--json",
            "--summary",
        ])
        .arg(&summary)
        .arg("--out")
        .arg(root.path().join("out"))
        .env("HARNESS_ROOT", root.path())
        .output()
        .unwrap();
    let run: serde_json::Value = serde_json::from_slice(&output.stdout).unwrap();
    let checks = run["speed"]["checks"].as_array().unwrap();
    assert!(!checks.is_empty());
    assert!(
        checks.iter().all(|c| c["tier"] == "moved-here"),
        "{checks:?}"
    );
    let notes = run["speed"]["host_notes"].as_array().unwrap();
    assert_eq!(notes.len(), 1, "{notes:?}");
    let note = notes[0].as_str().unwrap();
    assert!(
        note.contains("arrow's timing goldens on gl were blessed on this host")
            && note.contains(" noise --timing --write --scene arrow`")
            && note.contains(&format!("HARNESS_ROOT={}", root.path().display())),
        "{note}"
    );
    let summary = std::fs::read_to_string(&summary).unwrap();
    assert!(
        summary.contains("on the host that blessed, at the limits for any host")
            && !summary.contains("neither the one that blessed"),
        "{summary}"
    );
}

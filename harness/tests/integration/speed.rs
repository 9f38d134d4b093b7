//! The speed checks end to end: a pass slowed down fails its own speed check and no other, the
//! verdict `harness check` and the golden tests give; and the probe child takes no timed round
//! before it is told to (what lets `check` prepare it while it renders the images).

use engine::backend::BackendKind;
use engine::plan::PassId;
use engine::renderer::{SlowPass, Variations};
use harness::golden::speed::{check_scenes, start_check, SpeedOutcome};

use crate::common;

/// Chess on gl with tone mapping submitted three times over: the tone-mapping check fails, and
/// every other pass of the frame passes (or is untimed), on this host or any other (x3 is
/// beyond every limit the timing-noise model allows chess's tone mapping anywhere).
#[test]
fn a_slowed_pass_fails_its_own_speed_check_and_no_other() {
    if !common::gl_available() {
        return;
    }
    let store = harness::golden::GoldenStore::workspace();
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
                pass: PassId::ToneMap,
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
    let tonemap = run
        .checks
        .iter()
        .find(|c| c.pass == PassId::ToneMap)
        .unwrap();
    assert_eq!(
        tonemap.outcome,
        SpeedOutcome::Slower,
        "{}",
        tonemap.describe()
    );
    assert!(tonemap.slowdown().unwrap() > 2.0, "{}", tonemap.describe());
    for other in run.checks.iter().filter(|c| c.pass != PassId::ToneMap) {
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

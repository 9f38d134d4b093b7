//! Faults in the middle of a run: a shader that fails to compile, a backend lost mid-run, a
//! failed readback, a full disk while writing a golden or the report, and a bless killed
//! mid-write. Each gives an error naming the scene, the pass (or output or file) and the
//! backend; a check run goes on with the other scenes and fails; no golden is ever left
//! half-written.

use crate::common;
use engine::plan::TargetId;
use std::path::{Path, PathBuf};
use std::process::Command;
use std::sync::atomic::{AtomicUsize, Ordering};
use std::time::{Duration, Instant};

use engine::backend::Backend;
use engine::renderer::{self, Readback};
use engine::BackendKind;
use harness::faults::FaultyBackend;

/// A real backend of `kind` with no fault on yet.
fn faulty(kind: BackendKind) -> FaultyBackend {
    FaultyBackend::new(engine::backend::create(kind).unwrap())
}

fn chess() -> engine::scene::Scene {
    harness::use_ibl_cache();
    harness::load_scene("chess").unwrap().scene
}

#[test]
fn a_shader_that_fails_to_compile_names_the_scene_the_shader_and_the_backend() {
    for kind in common::available_backends() {
        let mut backend = faulty(kind);
        backend.break_shader = Some("lighting.wgsl".to_owned());
        let before = backend.live_resources();
        let error = renderer::render(&mut backend, &chess(), Readback::All)
            .err()
            .expect("a broken shader must fail the render")
            .to_string();
        eprintln!("{kind}: {}", error.lines().next().unwrap_or_default());
        assert!(
            error.contains("scene `chess`")
                && error.contains("lighting.wgsl")
                && error.contains(kind.name()),
            "{kind}: {error}"
        );
        assert_eq!(backend.live_resources(), before, "{kind}: resources leaked");
    }
}

#[test]
fn a_failed_readback_names_the_scene_the_output_and_the_backend() {
    for kind in common::available_backends() {
        let mut backend = faulty(kind);
        backend.fail_readback = true;
        let error = renderer::render(&mut backend, &chess(), Readback::Only(&[TargetId::Light]))
            .err()
            .expect("a failed readback must fail the render")
            .to_string();
        eprintln!("{kind}: {error}");
        assert!(
            error.contains("scene `chess`")
                && error.contains("pass output `light`")
                && error.contains(kind.name()),
            "{kind}: {error}"
        );
    }
}

/// A check over every canonical scene on one backend, lost at its second render: that scene
/// fails with an error naming the scene, the first pass and the backend, the scenes after it
/// are rendered and checked as usual and pass, and the run as a whole fails. (One backend: the
/// fault is in one, and the golden suite checks every scene on every backend.)
#[test]
fn a_backend_lost_mid_run_fails_its_scene_and_the_run_goes_on() {
    harness::use_ibl_cache();
    let Some(&kind) = common::available_backends().first() else {
        return;
    };
    let cases = harness::golden::suite::canonical_cases().unwrap();
    let store = harness::golden::GoldenStore::workspace();
    let created = AtomicUsize::new(0);
    let create = |k: BackendKind| -> engine::backend::Result<Box<dyn Backend>> {
        let mut backend = faulty(k);
        backend.lose_device = k == kind && created.fetch_add(1, Ordering::SeqCst) == 1;
        Ok(Box::new(backend))
    };
    let failures = tempfile::tempdir().unwrap();
    let (run, _) = harness::golden::check::run_with(
        &cases,
        &store,
        &[kind],
        failures.path(),
        &create,
        |_, _, _| {},
    );
    assert!(!run.passed());
    assert_eq!(run.render_errors.len(), 1, "{:?}", run.render_errors);
    let (scene, backend, error) = &run.render_errors[0];
    eprintln!("{scene} on {backend}: {error}");
    assert_eq!(*backend, kind);
    assert!(
        error.contains(&format!("scene `{scene}`"))
            && error.contains("device lost")
            && error.contains(kind.name()),
        "{error}"
    );
    // The lost scene's first pass is named.
    let case = cases.iter().find(|c| c.name() == scene).unwrap();
    let first = case.frame.plan().passes[0].id;
    assert!(error.contains(&first.to_string()), "{error}");
    // Everything else was rendered and checked, and passed.
    let renders = cases.len();
    let checked: std::collections::BTreeSet<(&str, engine::backend::BackendKind)> = run
        .results
        .iter()
        .map(|r| (r.scene.as_str(), r.backend))
        .collect();
    assert_eq!(checked.len(), renders - 1);
    assert!(run.results.iter().all(|r| r.outcome.passed()));
}

fn harness_bin() -> Command {
    common::harness_command()
}

fn temporaries(dir: &Path) -> Vec<PathBuf> {
    std::fs::read_dir(dir)
        .unwrap()
        .flatten()
        .map(|e| e.path())
        .filter(|p| p.file_name().unwrap().to_string_lossy().contains(".tmp"))
        .collect()
}

/// Runs the harness with files limited to 4 KiB (`ulimit -f`, SIGXFSZ ignored so writes fail
/// with EFBIG instead): the nearest thing to a full disk a test can make without root.
fn with_full_disk(args: &[&str], root: Option<&Path>) -> std::process::Output {
    let mut command = Command::new("sh");
    command
        .arg("-c")
        .arg("trap '' XFSZ; ulimit -f 4; exec \"$0\" \"$@\"")
        .arg(env!("CARGO_BIN_EXE_harness"))
        .args(args)
        .env(
            "HARNESS_IBL_CACHE",
            harness::ibl_cache_dir().unwrap_or_default(),
        );
    if let Some(root) = root {
        command.env("HARNESS_ROOT", root);
    }
    command.output().unwrap()
}

#[test]
fn a_full_disk_while_blessing_keeps_the_old_golden_and_names_the_file() {
    if !common::gl_available() {
        return;
    }
    let root = common::temp_workspace();
    let golden = root.path().join("golden/chess");
    let before = std::fs::read(golden.join("final.png")).unwrap();
    let record = std::fs::read(golden.join("blessed.toml")).unwrap();
    let output = with_full_disk(
        &[
            "bless",
            "--scene",
            "chess",
            "--pass",
            "final",
            "--no-speed",
            "--unverified",
        ],
        Some(root.path()),
    );
    let stderr = String::from_utf8_lossy(&output.stderr);
    eprintln!("{stderr}");
    assert_eq!(output.status.code(), Some(1), "{stderr}");
    assert!(stderr.contains("final.png"), "{stderr}");
    assert_eq!(std::fs::read(golden.join("final.png")).unwrap(), before);
    assert_eq!(std::fs::read(golden.join("blessed.toml")).unwrap(), record);
    assert_eq!(temporaries(&golden), Vec::<PathBuf>::new());
}

#[test]
fn a_full_disk_while_writing_the_report_names_the_file_and_fails() {
    if !common::available_backends().contains(&BackendKind::Gl) {
        return;
    }
    let out = tempfile::tempdir().unwrap();
    // On gl only: the file-size limit that stands in for a full disk also caps memfd sizes, and
    // Mesa 25's lavapipe backs device memory with memfds (it dies of SIGBUS in vkCreateDevice).
    let output = with_full_disk(
        &[
            "check",
            "--no-speed",
            "--scene",
            "arrow",
            "--backend",
            "gl",
            "--out",
            out.path().to_str().unwrap(),
        ],
        None,
    );
    let stderr = String::from_utf8_lossy(&output.stderr);
    eprintln!("{stderr}");
    assert_eq!(output.status.code(), Some(1), "{stderr}");
    assert!(stderr.contains("report.html"), "{stderr}");
    assert!(!out.path().join("report.html").exists());
}

/// Kills `harness bless` while its new golden sits written but not yet renamed (the write is
/// held there by HARNESS_FAULT_WRITE_DELAY_MS): the old golden and blessed.toml are intact. The
/// next bless removes the dead process's temporary file. Images only (`--no-speed`): the
/// timing goldens are written through the same atomic write, tested in speed.rs.
#[test]
fn killing_a_bless_mid_write_leaves_the_old_golden_intact() {
    if !common::gl_available() {
        return;
    }
    let root = common::temp_workspace();
    let golden = root.path().join("golden/chess");
    let before = std::fs::read(golden.join("final.png")).unwrap();
    let record = std::fs::read(golden.join("blessed.toml")).unwrap();
    let mut child = harness_bin()
        .args([
            "bless",
            "--scene",
            "chess",
            "--pass",
            "final",
            "--no-speed",
            "--unverified",
        ])
        .env("HARNESS_ROOT", root.path())
        .env(harness::images::WRITE_DELAY_ENV, "60000")
        // No kept verifications or FLIP results: their files are written atomically too, and
        // the delay must hold the golden's write, not a cache's (the first write when this test
        // runs alone or in a process of its own, as under nextest).
        .env(harness::golden::verify_cache::CACHE_ENV, "")
        .stdout(std::process::Stdio::null())
        .stderr(std::process::Stdio::null())
        .spawn()
        .unwrap();
    let start = Instant::now();
    while temporaries(&golden).is_empty() {
        assert!(
            start.elapsed() < Duration::from_secs(60),
            "bless never started writing"
        );
        std::thread::sleep(Duration::from_millis(20));
    }
    child.kill().unwrap();
    child.wait().unwrap();
    assert_eq!(temporaries(&golden).len(), 1, "the kill came mid-write");
    assert_eq!(std::fs::read(golden.join("final.png")).unwrap(), before);
    assert_eq!(std::fs::read(golden.join("blessed.toml")).unwrap(), record);

    let status = harness_bin()
        .args([
            "bless",
            "--scene",
            "chess",
            "--pass",
            "final",
            "--no-speed",
            "--unverified",
        ])
        .env("HARNESS_ROOT", root.path())
        .output()
        .unwrap();
    assert!(status.status.success());
    assert_eq!(temporaries(&golden), Vec::<PathBuf>::new());
}

/// The backends a one-backend fault needs: wgpu-vulkan to perturb and at least one other.
fn perturbable() -> bool {
    let available = common::available_backends();
    available.contains(&BackendKind::WgpuVulkan) && available.len() >= 2
}

/// A real `check` with every output of wgpu-vulkan perturbed (`HARNESS_INJECT_FAULT`): only
/// wgpu-vulkan's passes fail, and each verdict says it moved alone, the others held; depth (the
/// geometry pass's) is an origin, the light buffer moved because of the passes before it.
#[test]
fn a_fault_in_one_backend_gets_the_verdict_that_it_moved_alone() {
    use harness::golden::diagnosis::{Agreement, Role};
    if !perturbable() {
        return;
    }
    let out = tempfile::tempdir().unwrap();
    let output = harness_bin()
        .args(["check", "--json", "--no-speed", "--no-verify"])
        .args(["--scene", "arrow", "--out"])
        .arg(out.path())
        .env(harness::faults::INJECT_FAULT, "wgpu-vulkan:perturb-output")
        .output()
        .unwrap();
    assert_eq!(output.status.code(), Some(1));
    let run: harness::golden::check::CheckRun = serde_json::from_slice(&output.stdout).unwrap();
    let failed: Vec<_> = run.results.iter().filter(|r| !r.outcome.passed()).collect();
    assert!(!failed.is_empty());
    assert!(failed.iter().all(|r| r.backend == BackendKind::WgpuVulkan));
    assert_eq!(run.diagnoses.len(), failed.len());
    let others: Vec<BackendKind> = common::available_backends()
        .into_iter()
        .filter(|&b| b != BackendKind::WgpuVulkan)
        .collect();
    for d in &run.diagnoses {
        assert_eq!(
            d.agreement,
            Agreement::Only {
                moved: vec![BackendKind::WgpuVulkan],
                held: others.clone()
            },
            "{}: {}",
            d.pass,
            d.headline()
        );
        if matches!(d.role, Role::Origin { .. }) {
            assert!(
                d.headline().contains("wgpu-vulkan alone"),
                "{}",
                d.headline()
            );
        }
    }
    // The geometry pass's outputs are origins; the light buffer only followed them.
    let role = |pass: TargetId| &run.diagnoses.iter().find(|d| d.pass == pass).unwrap().role;
    assert!(matches!(role(TargetId::Depth), Role::Origin { .. }));
    assert!(matches!(role(TargetId::Light), Role::Downstream { .. }));
}

/// A golden that no other backend reproduces: blessed from wgpu-vulkan with its outputs
/// perturbed, it is refused by the verification, which names the source (`drivers`) and a
/// backend that disagreed, and golden/ is left as it was.
#[test]
fn verified_bless_refuses_a_golden_only_one_backend_renders() {
    if !perturbable() {
        return;
    }
    let root = common::temp_workspace();
    let golden = root.path().join("golden/arrow");
    let before = crate::cli_bless::snapshot(&golden);
    let output = harness_bin()
        .args(["bless", "--scene", "arrow", "--pass", "final", "--no-speed"])
        .args(["--backend", "wgpu-vulkan"])
        .env("HARNESS_ROOT", root.path())
        .env(harness::faults::INJECT_FAULT, "wgpu-vulkan:perturb-output")
        .output()
        .unwrap();
    let stdout = String::from_utf8_lossy(&output.stdout);
    eprintln!("{stdout}");
    assert_eq!(output.status.code(), Some(1), "{stdout}");
    let refusal = stdout
        .lines()
        .find(|l| l.starts_with("REFUSED arrow/final does not reproduce under drivers on "))
        .unwrap_or_else(|| panic!("no refusal naming the source in:\n{stdout}"));
    assert!(!refusal.contains("on wgpu-vulkan"), "{refusal}");
    assert!(stdout.contains("nothing written"), "{stdout}");
    assert_eq!(crate::cli_bless::snapshot(&golden), before);
}

/// A bless that would stop half-way through a scene stops before it writes anything: a
/// blessed.toml that does not read, a folder where a golden belongs, a timing.toml that does
/// not read. Each names the file; the scene's goldens are as they were.
#[test]
fn a_bless_that_cannot_finish_a_scene_writes_none_of_it() {
    if !common::gl_available() {
        return;
    }
    let root = common::temp_workspace();
    // A change every pass from the light on shows: several goldens to write.
    common::brighten_corner(root.path());
    let golden = root.path().join("golden/corner");
    let bless = |args: &[&str]| {
        common::harness_command()
            .args(["bless", "--scene", "corner", "--unverified"])
            .args(args)
            .env("HARNESS_ROOT", root.path())
            .output()
            .unwrap()
    };
    // The file, how to break it and mend it, and the bless's flags.
    type Fault<'a> = (&'a str, &'a dyn Fn(), &'a dyn Fn(), &'a [&'a str]);
    let faults: [Fault; 3] = [
        (
            "blessed.toml",
            &|| {
                let path = golden.join("blessed.toml");
                let mut text = std::fs::read_to_string(&path).unwrap();
                text.push_str("\noops = \n");
                std::fs::write(path, text).unwrap();
            },
            &|| {
                let path = golden.join("blessed.toml");
                let text = std::fs::read_to_string(&path).unwrap();
                std::fs::write(path, text.replace("\noops = \n", "")).unwrap();
            },
            &["--no-speed"],
        ),
        (
            "final.exr",
            &|| std::fs::create_dir(golden.join("final.exr")).unwrap(),
            &|| std::fs::remove_dir(golden.join("final.exr")).unwrap(),
            &["--no-speed"],
        ),
        (
            "timing.toml",
            &|| {
                let path = golden.join("timing.toml");
                let mut text = std::fs::read_to_string(&path).unwrap();
                text.push_str("\n[[[\n");
                std::fs::write(path, text).unwrap();
            },
            &|| {
                let path = golden.join("timing.toml");
                let text = std::fs::read_to_string(&path).unwrap();
                std::fs::write(path, text.replace("\n[[[\n", "")).unwrap();
            },
            &[],
        ),
    ];
    for (file, break_it, mend_it, args) in faults {
        break_it();
        let before = super::cli_bless::snapshot(&golden);
        let output = bless(args);
        let stderr = String::from_utf8_lossy(&output.stderr);
        assert_eq!(output.status.code(), Some(1), "{file}: {stderr}");
        assert!(stderr.contains(file), "{file}: {stderr}");
        let after = super::cli_bless::snapshot(&golden);
        let changed = super::cli_bless::changed_files(&golden, &before, &after);
        assert!(changed.is_empty(), "{file}: {changed:?} written");
        mend_it();
    }
    // Mended, the same bless writes the change.
    let output = bless(&["--no-speed"]);
    let stdout = String::from_utf8_lossy(&output.stdout);
    assert!(output.status.success(), "{stdout}");
    assert!(stdout.contains("wrote "), "{stdout}");
}

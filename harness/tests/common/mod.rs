//! Shared helpers for the harness tests: which backends to run (and when a missing one is a
//! failure), and temporary copies of the workspace.

// Each test binary uses some of these helpers.
#![allow(dead_code)]

pub mod cli;

use engine::backend::{self, BackendKind};

/// Backends available here. A backend named in `REQUIRE_BACKENDS` (comma-separated; CI sets
/// `gl,wgpu-vulkan,wgpu-gl`) must be available, or the test fails; any other missing backend
/// is reported on stderr and left out.
pub fn available_backends() -> Vec<BackendKind> {
    let mut kinds = Vec::new();
    for kind in BackendKind::ALL {
        let status = backend::probe(kind);
        if status.available {
            kinds.push(kind);
        } else if required(kind) {
            panic!(
                "{kind} is required by REQUIRE_BACKENDS but unavailable: {} (fix: {})",
                status.reason.unwrap_or_default(),
                status.fix.unwrap_or_default()
            );
        } else {
            eprintln!(
                "note: {kind} skipped, unavailable: {} (fix: {})",
                status.reason.unwrap_or_default(),
                status.fix.unwrap_or_default()
            );
        }
    }
    kinds
}

/// Whether `REQUIRE_BACKENDS` names `kind`: then a test must fail rather than skip without it.
pub fn required(kind: BackendKind) -> bool {
    std::env::var("REQUIRE_BACKENDS")
        .unwrap_or_default()
        .split(',')
        .any(|r| r.trim() == kind.name())
}

/// Whether `gl` is available, for tests that need it and skip without it. Like
/// [`available_backends`], it panics instead when REQUIRE_BACKENDS names `gl`: a test must not
/// pass by skipping what CI requires.
pub fn gl_available() -> bool {
    let available = available_backends().contains(&BackendKind::Gl);
    if !available {
        eprintln!("gl unavailable here; skipped");
    }
    available
}

/// Copies a folder tree (for tests that write into a temporary copy of the workspace).
pub fn copy_tree(from: &std::path::Path, to: &std::path::Path) {
    std::fs::create_dir_all(to).unwrap();
    for entry in std::fs::read_dir(from).unwrap() {
        let entry = entry.unwrap();
        let target = to.join(entry.file_name());
        if entry.file_type().unwrap().is_dir() {
            copy_tree(&entry.path(), &target);
        } else {
            std::fs::copy(entry.path(), &target).unwrap();
        }
    }
}

/// A temporary copy of the workspace's scenes/ and golden/, to point HARNESS_ROOT at.
pub fn temp_workspace() -> tempfile::TempDir {
    let root = tempfile::tempdir().unwrap();
    let workspace = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("..");
    copy_tree(&workspace.join("scenes"), &root.path().join("scenes"));
    copy_tree(&workspace.join("golden"), &root.path().join("golden"));
    root
}

/// Brightens the corner scene of the workspace at `root` (exposure 1.0 to 1.7): a change every
/// pass from the light on shows, in the smallest canonical scene (256x256).
pub fn brighten_corner(root: &std::path::Path) {
    let scene = root.join("scenes/corner.toml");
    let text = std::fs::read_to_string(&scene).unwrap();
    assert!(text.contains("exposure = 1.0\n"), "{text}");
    std::fs::write(&scene, text.replace("exposure = 1.0\n", "exposure = 1.7\n")).unwrap();
}

/// The `harness` binary as a command that shares this workspace's IBL cache, also when the test
/// points HARNESS_ROOT at a temporary copy (the maps depend only on the environment image, the
/// IBL settings and the precompute's code; the cache itself is tested in
/// engine/tests/integration/ibl.rs). Without it, every run in a temporary workspace would
/// precompute the maps again. It also shares this test run's kept verifications
/// ([`verify_cache`]).
pub fn harness_command() -> std::process::Command {
    let mut command = std::process::Command::new(env!("CARGO_BIN_EXE_harness"));
    command.env(
        "HARNESS_IBL_CACHE",
        harness::ibl_cache_dir().unwrap_or_default(),
    );
    command.env(harness::golden::verify_cache::CACHE_ENV, verify_cache());
    command
}

/// The folder in which this test run's `harness` children keep their verifications
/// (`harness::golden::verify_cache`): several tests check, bless and accept the same change
/// (arrow's light brightened), and its candidates need rendering under every source once per
/// run. A folder per test process, under target/tmp, so each run verifies afresh; the folders
/// of runs that have ended are removed.
pub fn verify_cache() -> &'static std::path::Path {
    static FOLDER: std::sync::OnceLock<std::path::PathBuf> = std::sync::OnceLock::new();
    FOLDER.get_or_init(|| {
        let base = std::path::Path::new(env!("CARGO_TARGET_TMPDIR")).join("verify-cache");
        for entry in std::fs::read_dir(&base).into_iter().flatten().flatten() {
            let ended = entry
                .file_name()
                .to_str()
                .and_then(|name| name.parse::<u32>().ok())
                .is_some_and(|pid| !std::path::Path::new(&format!("/proc/{pid}")).exists());
            if ended {
                let _ = std::fs::remove_dir_all(entry.path());
            }
        }
        base.join(std::process::id().to_string())
    })
}

/// Writes `<dir>/<name>.toml`: the canonical ibl scene with `[quality.ibl] extract_sun = true`
/// (the environment's sun lit as a shadowed directional light), its asset paths made absolute
/// so that it renders from any folder. Returns its path.
pub fn ibl_with_extracted_sun(dir: &std::path::Path, name: &str) -> std::path::PathBuf {
    let scenes = harness::scenes_dir();
    let text = std::fs::read_to_string(scenes.join("ibl.toml")).unwrap();
    assert!(
        !text.contains("[quality.ibl]"),
        "ibl.toml grew a [quality.ibl]"
    );
    let assets = scenes.join("assets");
    let text = text
        .replace("\"assets/", &format!("\"{}/", assets.display()))
        .replace(
            "\n[environment]",
            "\n[quality.ibl]\nextract_sun = true\n\n[environment]",
        );
    let path = dir.join(format!("{name}.toml"));
    std::fs::write(&path, text).unwrap();
    path
}

/// Makes this host the one that blessed `scene`'s timing goldens on `kind` in the workspace
/// `root`: one probe here (`harness speed`, as a check probes), written as that backend's
/// section with this host's fingerprint and CPU signature, each pass's ratio times `scale`
/// (its pass) or `others` (every other pass), and the timing-noise model's same-host figures
/// for them stamped as measured here. A test that accepts a timing golden needs its
/// check to run on the blessing host (another host's accept is refused), and ratios measured
/// here, so that the passes it leaves alone are not judged against another CPU's.
pub fn bless_timings_here(
    root: &std::path::Path,
    scene: &str,
    kind: BackendKind,
    scale: &[(engine::plan::PassId, f64)],
    others: f64,
) {
    use harness::golden::speed::{cpu_signature, host_fingerprint, Stamp, TimingGoldens};
    use harness::measure::speed::SceneSpeed;
    let output = harness_command()
        .args([
            "speed",
            "--json",
            "--scene",
            scene,
            "--backend",
            kind.name(),
        ])
        .env("HARNESS_ROOT", root)
        .output()
        .unwrap();
    assert!(output.status.success(), "{output:?}");
    let mut probes: Vec<SceneSpeed> = serde_json::from_slice(&output.stdout).unwrap();
    let mut probe = probes.pop().expect("one probe");
    for pass in &mut probe.passes {
        let factor = scale
            .iter()
            .find(|(p, _)| *p == pass.pass)
            .map_or(others, |(_, f)| *f);
        // The ratio is the fastest pass over the fastest floor: scale the floors.
        pass.floor_ms.iter_mut().for_each(|ms| *ms /= factor);
    }
    let info = backend::probe(kind).info.expect("the backend is available");
    let host = host_fingerprint(&harness::golden::fingerprint(&info));
    let cpu = cpu_signature();
    let golden = root.join("golden");
    let mut goldens = TimingGoldens::load(&golden, scene).unwrap();
    goldens.backends.remove(&kind);
    let stamp = Stamp {
        host: &host,
        cpu: &cpu,
        blessed: "2026-11-27T00:00:00Z",
        reason: None,
    };
    goldens.record(&probe, &[], &stamp);
    goldens.save(&golden, scene).unwrap();
    // The model's same-host figures count as this host's, as after `noise --timing --write`
    // here (the committed figures, not measured again).
    let mut model = harness::golden::speed::TimingNoise::load(&golden).unwrap();
    model.stamp_measured_on(scene, kind, &host, &cpu);
    model.save(&golden).unwrap();
}

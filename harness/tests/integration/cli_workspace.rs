//! The harness in its workspace: a private runtime directory when XDG_RUNTIME_DIR is unset,
//! unknown scene names answered with the canonical ones, and scene assets that regenerate
//! byte for byte.

use crate::common;
use std::path::Path;
use std::process::Command;

use common::cli::harness;

/// Without XDG_RUNTIME_DIR the drivers' window-system probes are not left to complain: the
/// harness gives itself a private runtime directory.
#[test]
fn no_runtime_dir_complaints_without_xdg_runtime_dir() {
    let output = common::harness_command()
        .arg("backends")
        .env_remove("XDG_RUNTIME_DIR")
        .output()
        .unwrap();
    let stderr = String::from_utf8_lossy(&output.stderr);
    assert!(output.status.success(), "{stderr}");
    assert!(!stderr.contains("XDG_RUNTIME_DIR"), "{stderr}");
}

#[test]
fn unknown_scene_names_list_the_canonical_scenes() {
    let (code, _, stderr) = harness(&["plan", "--scene", "chesss"]);
    assert_eq!(code, 1);
    assert!(stderr.contains("chess"), "{stderr}");
    // `check` of it (named twice: once) is a usage error, said once, before anything runs or
    // is written: a typo must not replace the last check (here a stand-in) that `harness
    // review` and `bless --from-last-check` read.
    let out = tempfile::tempdir().unwrap();
    let last_check = out.path().join("last-check.json");
    std::fs::write(&last_check, "the last check").unwrap();
    let out = out.path().to_str().unwrap();
    let args = [
        "check", "--scene", "chesss", "--scene", "chesss", "--out", out,
    ];
    let (code, stdout, stderr) = harness(&args);
    assert_eq!(code, 2, "{stderr}");
    assert_eq!(stderr.matches("no scene `chesss`").count(), 1, "{stderr}");
    assert!(
        stderr.contains("nothing checked") && stdout.is_empty(),
        "{stderr}"
    );
    // The default command takes its options without its name: `harness --scene X` is `check`.
    let (code, _, stderr) = harness(&["--scene", "chesss", "--out", out]);
    assert_eq!(code, 2, "{stderr}");
    assert!(stderr.contains("no scene `chesss`"), "{stderr}");
    assert_eq!(
        std::fs::read_to_string(&last_check).unwrap(),
        "the last check"
    );
}

/// What a check would fail at only after rendering everything is refused first, as a usage
/// error that writes nothing: `--out` a file, a JUnit or summary file under a file or at a
/// folder; and a suite with no scene (a mistyped HARNESS_ROOT), which would pass with no check.
#[test]
fn a_check_that_cannot_write_or_has_no_scene_is_refused_first() {
    let dir = tempfile::tempdir().unwrap();
    let file = dir.path().join("a-file");
    std::fs::write(&file, "").unwrap();
    let file = file.to_str().unwrap();
    let under = format!("{file}/report.xml");
    let folder = dir.path().to_str().unwrap();
    for (args, said) in [
        (vec!["--out", file], "--out "),
        (
            vec!["--junit", under.as_str()],
            "a-file is a file, not a folder",
        ),
        (vec!["--summary", folder], "is a folder, not a file"),
    ] {
        let all = [&["check", "--scene", "corner", "--no-speed"][..], &args].concat();
        let (code, stdout, stderr) = harness(&all);
        assert_eq!(code, 2, "{args:?}: {stderr}");
        assert!(
            stderr.contains(said) && stderr.contains("nothing checked") && stdout.is_empty(),
            "{args:?}: {stderr}"
        );
    }
    let (code, _, stderr) = harness(&["report", "--merge", folder, "--out", file]);
    assert_eq!(code, 2, "{stderr}");
    assert!(stderr.contains("nothing joined"), "{stderr}");
    // A workspace with no scene (the root mistyped).
    let empty = tempfile::tempdir().unwrap();
    let output = common::harness_command()
        .args(["check", "--no-speed"])
        .env("HARNESS_ROOT", empty.path())
        .output()
        .unwrap();
    let stderr = String::from_utf8_lossy(&output.stderr);
    assert_eq!(output.status.code(), Some(2), "{stderr}");
    assert!(
        stderr.contains("holds no scene (HARNESS_ROOT is "),
        "{stderr}"
    );
    assert_eq!(std::fs::read_dir(empty.path()).unwrap().count(), 0);
}

/// The committed scene assets are exactly what the generator writes, so they can be regenerated.
#[test]
fn scene_assets_regenerate_byte_for_byte() {
    let dir = tempfile::tempdir().unwrap();
    let status = Command::new(env!("CARGO_BIN_EXE_make_scene_assets"))
        .arg(dir.path())
        .output()
        .unwrap();
    assert!(status.status.success(), "{status:?}");
    let committed = Path::new(env!("CARGO_MANIFEST_DIR")).join("../scenes/assets");
    let mut compared = 0;
    for entry in std::fs::read_dir(dir.path()).unwrap() {
        let entry = entry.unwrap();
        let name = entry.file_name();
        let fresh = std::fs::read(entry.path()).unwrap();
        let old = std::fs::read(committed.join(&name))
            .unwrap_or_else(|e| panic!("{name:?} is generated but not committed: {e}"));
        assert!(
            fresh == old,
            "{name:?} differs from the generator's output; run make_scene_assets"
        );
        compared += 1;
    }
    assert!(compared >= 12, "only {compared} files generated");
}

/// A driver that is not found because a variable points the loader elsewhere: the fix names
/// the variable and its value before the install advice.
#[test]
fn an_unavailable_backend_names_the_variable_that_redirected_its_loader() {
    let output = common::harness_command()
        .arg("backends")
        .env("VK_DRIVER_FILES", "/nonexistent/icd.json")
        .output()
        .unwrap();
    let stdout = String::from_utf8_lossy(&output.stdout);
    let fix = stdout
        .lines()
        .skip_while(|l| !l.starts_with("wgpu-vulkan"))
        .nth(1)
        .unwrap_or_default();
    assert!(
        fix.contains("fix: check VK_DRIVER_FILES=/nonexistent/icd.json")
            && fix.contains("apt-get install"),
        "{stdout}"
    );
}

/// A dry run of a new scene's bless (or of accepting a check of it) says what it would write and
/// leaves nothing behind, not even a folder to lock (which `bless --prune` would call an
/// orphan).
#[test]
fn a_dry_run_bless_of_a_new_scene_leaves_no_folder() {
    if !common::gl_available() {
        return;
    }
    let root = common::temp_workspace();
    std::fs::copy(
        root.path().join("scenes/corner.toml"),
        root.path().join("scenes/fresh.toml"),
    )
    .unwrap();
    let output = common::harness_command()
        .args(["bless", "--scene", "fresh", "--dry-run", "--no-speed"])
        .env("HARNESS_ROOT", root.path())
        .output()
        .unwrap();
    let stdout = String::from_utf8_lossy(&output.stdout);
    assert!(output.status.success(), "{stdout}");
    assert!(stdout.contains("would be written (dry run)"), "{stdout}");
    assert!(!root.path().join("golden/fresh").exists());
    // Nor does a dry run of accepting what a check of it kept.
    let out = root.path().join("out");
    let run = |args: &[&str]| {
        common::harness_command()
            .args(args)
            .arg("--out")
            .arg(&out)
            .env("HARNESS_ROOT", root.path())
            .output()
            .unwrap()
    };
    let checked = run(&["check", "--scene", "fresh", "--backend", "gl", "--no-speed"]);
    assert_eq!(checked.status.code(), Some(1));
    let accepted = run(&["bless", "--from-last-check", "--dry-run", "--no-speed"]);
    let stdout = String::from_utf8_lossy(&accepted.stdout);
    assert!(
        accepted.status.success() && stdout.contains("(dry run)"),
        "{stdout}"
    );
    assert!(!root.path().join("golden/fresh").exists());
}

/// Two scene files outside scenes/ named alike share golden/<name>/: once one is blessed there,
/// blessing the other is refused, naming both, and the first's goldens stay as they were.
#[test]
fn a_scene_file_named_like_another_files_blessed_scene_is_refused() {
    if !common::gl_available() {
        return;
    }
    let root = common::temp_workspace();
    let corner = std::fs::read_to_string(root.path().join("scenes/corner.toml")).unwrap();
    let mine = root.path().join("mine");
    std::fs::create_dir_all(&mine).unwrap();
    let (first, second) = (mine.join("first.toml"), mine.join("second.toml"));
    std::fs::write(&first, format!("name = \"twin\"\n{corner}")).unwrap();
    let brighter = corner.replace("exposure = 1.0\n", "exposure = 1.7\n");
    std::fs::write(&second, format!("name = \"twin\"\n{brighter}")).unwrap();
    let bless = |file: &std::path::Path| {
        common::harness_command()
            .args(["bless", "--no-speed", "--unverified", "--scene"])
            .arg(file)
            .env("HARNESS_ROOT", root.path())
            .output()
            .unwrap()
    };
    assert!(bless(&first).status.success());
    let golden = root.path().join("golden/twin");
    let before = super::cli_bless::snapshot(&golden);
    let refused = bless(&second);
    let stderr = String::from_utf8_lossy(&refused.stderr);
    assert_eq!(refused.status.code(), Some(1), "{stderr}");
    assert!(
        stderr.contains("second.toml is named `twin`, as is ") && stderr.contains("first.toml"),
        "{stderr}"
    );
    let after = super::cli_bless::snapshot(&golden);
    assert!(super::cli_bless::changed_files(&golden, &before, &after).is_empty());
    // Renamed, the first file no longer holds the folder: the second may bless into it.
    std::fs::write(&first, format!("name = \"elsewhere\"\n{corner}")).unwrap();
    let blessed = bless(&second);
    let stderr = String::from_utf8_lossy(&blessed.stderr);
    assert!(blessed.status.success(), "{stderr}");
}

//! `harness render`: load warnings printed once, unknown passes refused before rendering, every
//! pass of a scene file written, and an IBL precompute said; and what other commands refuse
//! before any work (an unknown pass or scene, a flag that does nothing without another).

use crate::common;
use std::path::Path;

use common::cli::harness;

/// `harness render` of a scene with untidy assets prints each load warning once on stderr; a
/// canonical scene has none.
#[test]
fn render_prints_each_load_warning_once() {
    if !common::gl_available() {
        return;
    }
    let dir = tempfile::tempdir().unwrap();
    let scene = Path::new(env!("CARGO_MANIFEST_DIR")).join("../scenes/models/crate.toml");
    let out = dir.path().join("crate.png");
    let (code, stdout, stderr) = harness(&[
        "render",
        "--scene",
        scene.to_str().unwrap(),
        "--out",
        out.to_str().unwrap(),
    ]);
    assert_eq!(code, 0, "{stdout}\n{stderr}");
    assert!(out.is_file());
    for needle in [
        "crate.obj:2: not UTF-8",
        "crate.mtl:1: not UTF-8",
        "crate.obj:30: `usemtl` without a name",
        "usemtl `shipping_label` names no material",
    ] {
        let lines: Vec<&str> = stderr.lines().filter(|l| l.contains(needle)).collect();
        assert_eq!(lines.len(), 1, "`{needle}` once in\n{stderr}");
        assert!(lines[0].starts_with("warning: "), "{}", lines[0]);
    }
    let chess = Path::new(env!("CARGO_MANIFEST_DIR")).join("../scenes/chess.toml");
    let (code, stdout, _) = harness(&["inspect", "--json", chess.to_str().unwrap()]);
    assert_eq!(code, 0);
    let value: serde_json::Value = serde_json::from_str(&stdout).unwrap();
    assert_eq!(
        value["warnings"],
        serde_json::json!([]),
        "the canonical assets are tidy"
    );
}

/// A misspelt pass is refused before anything is rendered, with the scene's outputs listed.
#[test]
fn render_rejects_an_unknown_pass_before_rendering() {
    let (code, stdout, stderr) = harness(&["render", "--scene", "arrow", "--pass", "finall"]);
    assert_eq!(code, 1, "{stdout}\n{stderr}");
    assert!(
        stderr.contains("no pass output `finall`") && stderr.contains("final"),
        "{stderr}"
    );
    // The shadow terms, planned only when named, are listed with the other outputs.
    assert!(stderr.contains("shadow_0, shadow_term_0"), "{stderr}");
    assert!(!stderr.contains("rendering"), "rendered first:\n{stderr}");
}

/// So is one given to `check --pass`, with the golden passes listed, and nothing is written;
/// a known one is the only pass checked, without a verdict (which needs every pass).
#[test]
fn check_pass_checks_only_that_pass_and_rejects_an_unknown_one() {
    if !crate::common::gl_available() {
        return;
    }
    let out = tempfile::tempdir().unwrap();
    let out_arg = out.path().to_str().unwrap();
    let (code, stdout, stderr) = harness(&[
        "check", "--scene", "arrow", "--pass", "finall", "--out", out_arg,
    ]);
    assert_eq!(code, 1, "{stdout}\n{stderr}");
    assert!(
        stderr.contains("no scene checked has a golden pass `finall`")
            && stderr.contains("final, gbuffer_albedo"),
        "{stderr}"
    );
    assert!(
        !out.path().join("last-check.json").exists(),
        "it ran the check"
    );
    // A plan pass is a speed check's name: said so, since --pass does not narrow those.
    let (code, _, stderr) = harness(&["check", "--scene", "arrow", "--pass", "lighting_pbr"]);
    assert_eq!(code, 1, "{stderr}");
    assert!(stderr.contains("are run whole"), "{stderr}");
    let (code, stdout, stderr) = harness(&[
        "check",
        "--scene",
        "arrow",
        "--backend",
        "gl",
        "--pass",
        "light",
        "--no-speed",
        "--json",
        "--out",
        out_arg,
    ]);
    assert_eq!(code, 0, "{stdout}\n{stderr}");
    let run: harness::golden::check::CheckRun = serde_json::from_str(&stdout).unwrap();
    let checked: Vec<_> = run.results.iter().map(|r| r.pass.to_string()).collect();
    assert_eq!(checked, ["light"]);
    assert!(run.diagnoses.is_empty());
}

/// `render` takes a scene file path as well as a name, and writes every pass with `--pass all`
/// (PNG for 8-bit outputs, EXR for float ones; the shadow terms, which have goldens, too).
#[test]
fn render_writes_every_pass_of_a_scene_file() {
    if !common::gl_available() {
        return;
    }
    let dir = tempfile::tempdir().unwrap();
    let scene = Path::new(env!("CARGO_MANIFEST_DIR")).join("../scenes/arrow.toml");
    let (code, stdout, stderr) = harness(&[
        "render",
        "--scene",
        scene.to_str().unwrap(),
        "--backend",
        "gl",
        "--pass",
        "all",
        "--out",
        dir.path().to_str().unwrap(),
    ]);
    assert_eq!(code, 0, "{stdout}\n{stderr}");
    for file in [
        "final.png",
        "mask.png",
        "light.exr",
        "depth.exr",
        "gbuffer_position.exr",
        "gbuffer_normal.exr",
        "gbuffer_tangent.exr",
        "gbuffer_albedo.exr",
        "gbuffer_material.exr",
        "shadow_term_0.exr",
    ] {
        assert!(dir.path().join(file).is_file(), "{file} missing:\n{stdout}");
    }
    // A file's name where a folder is needed (also on the way to the file named), or the other
    // format's extension: refused before anything is rendered, and nothing is written.
    std::fs::write(dir.path().join("notes.txt"), "a file").unwrap();
    for (pass, out, says) in [
        (
            "final",
            "notes.txt/final.png",
            "notes.txt is a file, not a folder",
        ),
        (
            "all",
            "out.png",
            "names a file, but 12 outputs are asked for: give a folder",
        ),
        ("final", "final.exr", "final is 8-bit, written as .png"),
        (
            "light",
            "light.jpg",
            "light is floating point, written as .exr, or .png",
        ),
    ] {
        let out = dir.path().join(out);
        let args = ["render", "--scene", "arrow", "--pass", pass, "--out"];
        let (code, _, stderr) = harness(&[&args[..], &[out.to_str().unwrap()]].concat());
        assert_eq!(code, 1, "{stderr}");
        assert!(
            stderr.contains(says) && !stderr.contains("rendering ") && !out.exists(),
            "{stderr}"
        );
    }
    // A folder with a dot in its name is a folder.
    let folder = dir.path().join("run.1");
    std::fs::create_dir(&folder).unwrap();
    let args = [
        "render", "--scene", "arrow", "--pass", "mask", "--pass", "depth", "--out",
    ];
    let (code, _, stderr) = harness(&[&args[..], &[folder.to_str().unwrap()]].concat());
    assert_eq!(code, 0, "{stderr}");
    assert!(folder.join("mask.png").is_file() && folder.join("depth.exr").is_file());
    let (code, _, stderr) = harness(&["render", "--scene", "arrow", "--pass", "shadow"]);
    assert_eq!(code, 1);
    assert!(stderr.contains("no pass output `shadow`"), "{stderr}");
    // A shadow term, a golden pass that is a debug output of the plan, is planned when asked
    // for, so a failing shadow_term golden can be rendered again.
    let term = dir.path().join("term.exr");
    let (code, stdout, stderr) = harness(&[
        "render",
        "--scene",
        "arrow",
        "--pass",
        "shadow_term_0",
        "--out",
        term.to_str().unwrap(),
    ]);
    assert_eq!(code, 0, "{stdout}\n{stderr}");
    let golden = harness::images::read_exr(
        &Path::new(env!("CARGO_MANIFEST_DIR")).join("../golden/arrow/shadow_term_0.exr"),
    )
    .unwrap();
    let rendered = harness::images::read_exr(&term).unwrap();
    assert_eq!(
        (rendered.width, rendered.height),
        (golden.width, golden.height)
    );
}

/// With `[quality.ibl] extract_sun`, the environment's sun is lit as a shadowed directional
/// light: `harness plan` lists its shadow pass, and `harness render --pass` takes its map as
/// an output, as the render has them.
#[test]
fn plan_and_render_know_the_extracted_sun() {
    if !common::gl_available() {
        return;
    }
    let dir = tempfile::tempdir().unwrap();
    let assets = Path::new(env!("CARGO_MANIFEST_DIR")).join("../scenes/assets");
    let scene = dir.path().join("sun.toml");
    std::fs::write(
        &scene,
        format!(
            "[camera]\nposition = [0, 2, 4]\ntarget = [0, 0, 0]\n\n\
             [quality]\nwidth = 64\nheight = 64\n\n[quality.ibl]\nextract_sun = true\n\n\
             [environment]\npath = {:?}\n\n\
             [[objects]]\nmesh = \"builtin:sphere\"\n\n\
             [[objects]]\nmesh = \"builtin:plane\"\nposition = [0, -1, 0]\nscale = 6\n",
            assets.join("sunset.exr").to_str().unwrap()
        ),
    )
    .unwrap();
    let (code, stdout, stderr) = harness(&["plan", "--scene", scene.to_str().unwrap()]);
    assert_eq!(code, 0, "{stderr}");
    assert!(
        stdout.contains("shadow_0") && stdout.contains("directional"),
        "{stdout}"
    );
    // Its shadow term, a debug output with a golden, is named though not planned.
    assert!(
        stdout
            .lines()
            .last()
            .is_some_and(|l| l.starts_with("debug outputs (")
                && l.ends_with("golden outputs too): shadow_term_0")),
        "{stdout}"
    );
    let out = dir.path().join("shadow_0.exr");
    let (code, stdout, stderr) = harness(&[
        "render",
        "--scene",
        scene.to_str().unwrap(),
        "--backend",
        "gl",
        "--pass",
        "shadow_0",
        "--out",
        out.to_str().unwrap(),
    ]);
    assert_eq!(code, 0, "{stdout}\n{stderr}");
    assert!(out.is_file());
}

/// A scene that is none is one error, before any probe child starts (`speed`) or once
/// (`selftest --speed`); the debug slowdown of the lighting is refused without the speed
/// checks that show it.
#[test]
fn speed_commands_name_an_unknown_scene_once() {
    let (code, _, stderr) = harness(&["speed", "--scene", "nonexistent"]);
    assert_ne!(code, 0, "{stderr}");
    assert_eq!(
        stderr.matches("no scene `nonexistent`").count(),
        1,
        "{stderr}"
    );
    assert!(!stderr.contains("probe died"), "{stderr}");
    let (code, _, stderr) = harness(&["selftest", "--speed", "--scene", "nonexistent"]);
    assert_ne!(code, 0, "{stderr}");
    assert_eq!(
        stderr.matches("no scene `nonexistent`").count(),
        1,
        "{stderr}"
    );
    let (code, _, stderr) = harness(&["check", "--no-speed", "--debug-unspecialised-lighting"]);
    assert_eq!(code, 2, "{stderr}");
    assert!(stderr.contains("cannot be used with"), "{stderr}");
}

/// An IBL precompute the cache does not hold says so before it runs (with large settings it
/// takes minutes, and the command would print nothing meanwhile); once cached, nothing is said.
#[test]
fn an_ibl_precompute_that_is_not_cached_says_so() {
    if !common::gl_available() {
        return;
    }
    let dir = tempfile::tempdir().unwrap();
    // A small sky and small maps: the precompute takes a moment.
    let sky = Path::new(env!("CARGO_MANIFEST_DIR")).join("../engine/tests/fixtures/sky.hdr");
    std::fs::copy(sky, dir.path().join("sky.hdr")).unwrap();
    let scene = dir.path().join("sky.toml");
    let text = "[camera]\nposition = [0, 1, 3]\ntarget = [0, 0, 0]\n\n[quality]\nwidth = 64\n\
                height = 64\n\n[quality.ibl]\nsource_size = 16\nspecular_size = 8\n\
                specular_samples = 16\nirradiance_size = 8\n\n[environment]\n\
                path = \"sky.hdr\"\n\n[[objects]]\nmesh = \"builtin:sphere\"\n";
    std::fs::write(&scene, text).unwrap();
    let cache = dir.path().join("ibl-cache");
    let render = || {
        common::harness_command()
            .args(["render", "--backend", "gl", "--scene"])
            .arg(&scene)
            .arg("--out")
            .arg(dir.path().join("final.png"))
            .env("HARNESS_IBL_CACHE", &cache)
            .output()
            .unwrap()
    };
    let first = render();
    let stderr = String::from_utf8_lossy(&first.stderr);
    assert!(first.status.success(), "{stderr}");
    assert!(
        stderr.contains("precomputing the IBL maps of ") && stderr.contains("not cached yet) ..."),
        "{stderr}"
    );
    let second = render();
    let stderr = String::from_utf8_lossy(&second.stderr);
    assert!(
        second.status.success() && !stderr.contains("precomputing"),
        "{stderr}"
    );
}

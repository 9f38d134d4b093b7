//! The `harness` binary on bad and good input: `inspect` exits 1 with the loader's error (never
//! 101, a panic) on every malformed fixture, and 0 on fixtures that load with warnings.

mod common;

use std::path::{Path, PathBuf};
use std::process::Command;

fn fixture(name: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../engine/tests/fixtures")
        .join(name)
}

fn harness(args: &[&str]) -> (i32, String, String) {
    let output = common::harness_command()
        .args(args)
        .output()
        .expect("run harness");
    (
        output.status.code().unwrap_or(-1),
        String::from_utf8_lossy(&output.stdout).into_owned(),
        String::from_utf8_lossy(&output.stderr).into_owned(),
    )
}

#[test]
fn inspect_fails_cleanly_on_every_malformed_fixture() {
    let cases = [
        ("empty.obj", "no geometry"),
        ("truncated_face.obj", "truncated_face.obj:"),
        ("truncated_vertex.obj", "truncated_vertex.obj:"),
        ("out_of_range.obj", "out of range"),
        ("zero_index.obj", "zero_index.obj:"),
        ("nan_coord.obj", "nan_coord.obj:"),
        ("inf_coord.obj", "inf_coord.obj:"),
        ("missing_texture.obj", "missing_texture.mtl"),
        ("corrupt_texture.obj", "corrupt_texture.mtl"),
        ("huge_index.obj", "huge_index.obj:"),
        ("huge_index_2_40.obj", "huge_index_2_40.obj:"),
        ("huge_index_overflow.obj", "huge_index_overflow.obj:"),
        ("relative_out_of_range.obj", "relative_out_of_range.obj:"),
        ("corrupt.exr", "corrupt.exr"),
        ("textures/corrupt.png", "corrupt.png"),
        ("missing_texture.mtl", "missing_texture.mtl"),
        ("truncated.hdr", "truncated.hdr"),
    ];
    for (file, expected) in cases {
        let path = fixture(file);
        assert!(path.exists(), "fixture {file} missing");
        let (code, _, stderr) = harness(&["inspect", path.to_str().unwrap()]);
        assert_eq!(code, 1, "{file}: exit {code}, stderr:\n{stderr}");
        assert!(
            stderr.contains(expected),
            "{file}: error does not mention `{expected}`:\n{stderr}"
        );
        assert!(!stderr.contains("panicked"), "{file}: panicked:\n{stderr}");
    }
}

#[test]
fn inspect_loads_fixtures_that_only_warn() {
    for (file, warning) in [
        ("unknown_keys.obj", "unknown MTL key"),
        ("points_lines.obj", "skipped"),
        ("ngons.obj", "triangulated"),
        ("textured.mtl", ""),
        ("non_utf8.obj", "non_utf8.obj:4: not UTF-8"),
        ("missing_mtl.obj", "does_not_exist.mtl` cannot be read"),
        ("latin1_mtl.obj", "latin1.mtl:1: not UTF-8"),
        (
            "untidy_materials.obj",
            "untidy_materials.obj:7: `usemtl` without a name",
        ),
        ("textures/gradient.jpg", "gradient.jpg 8x4 8-bit 4 mips"),
        ("textures/gradient.tga", "gradient.tga 8x4 8-bit 4 mips"),
        ("textures/gradient.bmp", "gradient.bmp 8x4 8-bit 4 mips"),
        ("textures/fine16.png", "fine16.png 4x1 16-bit 3 mips"),
        ("sky.hdr", "sky.hdr 8x4, radiance"),
    ] {
        let (code, stdout, stderr) = harness(&["inspect", fixture(file).to_str().unwrap()]);
        assert_eq!(code, 0, "{file}: exit {code}\n{stdout}\n{stderr}");
        assert!(
            stdout.contains(warning),
            "{file}: no `{warning}` in\n{stdout}"
        );
    }
    let (code, stdout, _) = harness(&[
        "inspect",
        "--json",
        fixture("scenes/two_materials.toml").to_str().unwrap(),
    ]);
    assert_eq!(code, 0);
    let value: serde_json::Value = serde_json::from_str(&stdout).unwrap();
    assert_eq!(value["textures_decoded"], 3);
}

/// `harness inspect` on a JPEG-textured OBJ lists its textures with their sizes, bit depths and
/// color spaces, and its warnings (text and `--json`).
#[test]
fn inspect_lists_a_real_world_models_textures_and_warnings() {
    let crate_obj = Path::new(env!("CARGO_MANIFEST_DIR")).join("../scenes/assets/crate.obj");
    let (code, stdout, stderr) = harness(&["inspect", crate_obj.to_str().unwrap()]);
    assert_eq!(code, 0, "{stderr}");
    for line in [
        "crate_albedo.jpg 120x75 8-bit 7 mips Srgb",
        "crate_roughness.tga 64x64 8-bit 7 mips Linear",
        "crate_normal.png 64x64 16-bit 7 mips Linear",
        "crate_specular.bmp 64x64 8-bit 7 mips Linear",
        "crate.obj:2: not UTF-8",
        "usemtl `shipping_label` names no material",
    ] {
        assert!(stdout.contains(line), "no `{line}` in\n{stdout}");
    }
    let (code, stdout, _) = harness(&["inspect", "--json", crate_obj.to_str().unwrap()]);
    assert_eq!(code, 0);
    let value: serde_json::Value = serde_json::from_str(&stdout).unwrap();
    let textures = value["model"]["textures"].as_array().unwrap();
    assert_eq!(textures.len(), 4);
    assert_eq!(textures[0]["width"], 120);
    assert_eq!(textures[0]["height"], 75);
    assert_eq!(textures[0]["color_space"], "Srgb");
    assert_eq!(textures[2]["bits"], 16);
    assert!(value["model"]["warnings"]
        .as_array()
        .unwrap()
        .iter()
        .any(|w| w.as_str().unwrap().contains("crate.mtl:1: not UTF-8")));
}

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

/// A scene in scenes/ whose mesh does not load is one failed case: `check` reports it with its
/// error (once), checks every other scene as usual, writes the report, and exits 1.
#[test]
fn a_broken_scene_is_one_failed_case_and_the_others_are_checked() {
    if !common::gl_available() {
        return;
    }
    let root = common::temp_workspace();
    std::fs::write(
        root.path().join("scenes/broken.toml"),
        "[camera]\nposition = [0, 0, 1]\ntarget = [0, 0, 0]\n[[objects]]\nmesh = \"assets/gone.obj\"\n",
    )
    .unwrap();
    let out = root.path().join("out");
    // An earlier run's failure image of a checked scene, which this run must remove.
    let stale = out.join("failures/arrow/gl/final_diff.png");
    std::fs::create_dir_all(stale.parent().unwrap()).unwrap();
    std::fs::write(&stale, b"old").unwrap();
    let output = common::harness_command()
        .args(["check", "--backend", "gl", "--out", out.to_str().unwrap()])
        .env("HARNESS_ROOT", root.path())
        .output()
        .unwrap();
    let stdout = String::from_utf8_lossy(&output.stdout);
    let stderr = String::from_utf8_lossy(&output.stderr);
    assert_eq!(output.status.code(), Some(1), "{stdout}\n{stderr}");
    let load_lines: Vec<&str> = stdout
        .lines()
        .filter(|l| l.contains("FAILED   load:"))
        .collect();
    assert_eq!(load_lines.len(), 1, "{stdout}");
    assert!(
        load_lines[0].starts_with("broken") && load_lines[0].contains("gone.obj: cannot read file"),
        "{}",
        load_lines[0]
    );
    assert_eq!(
        load_lines[0].matches("os error 2").count(),
        1,
        "{}",
        load_lines[0]
    );
    for scene in ["arrow", "chess", "ibl"] {
        let rows: Vec<&str> = stdout
            .lines()
            .filter(|l| l.starts_with(scene) && l.contains(" gl "))
            .collect();
        assert!(rows.len() >= 8, "{scene} was not checked:\n{stdout}");
        assert!(
            rows.iter().all(|r| r.contains(" ok ")),
            "{scene}:\n{stdout}"
        );
    }
    assert!(stdout.contains("1 scene(s) did not load"), "{stdout}");
    let report = std::fs::read_to_string(out.join("report.html")).unwrap();
    assert!(report.contains("scene broken did not load"));
    // The canonical scenes pass: the review page shows them as thumbnails and stays small
    // (the thumbnails are per scene and pass, so more backends add only table rows).
    assert!(
        report.len() < 5_000_000,
        "report.html is {} bytes",
        report.len()
    );
    assert!(
        !stale.exists(),
        "the earlier run's failure image is still there"
    );
    // `harness scenes` does not list it as fine.
    let output = common::harness_command()
        .arg("scenes")
        .env("HARNESS_ROOT", root.path())
        .output()
        .unwrap();
    let stdout = String::from_utf8_lossy(&output.stdout);
    assert_eq!(output.status.code(), Some(1), "{stdout}");
    assert!(
        stdout
            .lines()
            .any(|l| l.starts_with("broken") && l.contains("DOES NOT LOAD")),
        "{stdout}"
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
    assert!(!stderr.contains("rendering"), "rendered first:\n{stderr}");
}

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

/// `render` takes a scene file path as well as a name, and writes every pass with `--pass all`
/// (PNG for 8-bit outputs, EXR for float ones).
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
    ] {
        assert!(dir.path().join(file).is_file(), "{file} missing:\n{stdout}");
    }
    let (code, _, stderr) = harness(&["render", "--scene", "arrow", "--pass", "shadow"]);
    assert_eq!(code, 1);
    assert!(stderr.contains("no pass output `shadow`"), "{stderr}");
}

fn snapshot(dir: &Path) -> std::collections::BTreeMap<PathBuf, (Vec<u8>, std::time::SystemTime)> {
    let mut out = std::collections::BTreeMap::new();
    for entry in std::fs::read_dir(dir).unwrap() {
        let entry = entry.unwrap();
        if entry.file_type().unwrap().is_dir() {
            out.extend(snapshot(&entry.path()));
        } else {
            let meta = entry.metadata().unwrap();
            out.insert(
                entry.path(),
                (
                    std::fs::read(entry.path()).unwrap(),
                    meta.modified().unwrap(),
                ),
            );
        }
    }
    out
}

/// Runs `harness bless ARGS` against the workspace copy at `root`; fails the test unless it
/// succeeds. Returns its stdout.
fn bless_in(root: &Path, args: &[&str]) -> String {
    let output = common::harness_command()
        .arg("bless")
        .args(args)
        .env("HARNESS_ROOT", root)
        .output()
        .unwrap();
    let stdout = String::from_utf8_lossy(&output.stdout).into_owned();
    assert!(
        output.status.success(),
        "{stdout}\n{}",
        String::from_utf8_lossy(&output.stderr)
    );
    stdout
}

/// The files under `dir` that differ between two snapshots (new ones too), relative to `dir`.
fn changed_files(
    dir: &Path,
    before: &std::collections::BTreeMap<PathBuf, (Vec<u8>, std::time::SystemTime)>,
    after: &std::collections::BTreeMap<PathBuf, (Vec<u8>, std::time::SystemTime)>,
) -> Vec<String> {
    after
        .iter()
        .filter(|(path, state)| before.get(*path) != Some(*state))
        .map(|(path, _)| path.strip_prefix(dir).unwrap().display().to_string())
        .collect()
}

/// `bless --scene chess --pass final` rewrites that golden and chess's blessed.toml, and nothing
/// else (run against a temporary copy of scenes/ and golden/ through HARNESS_ROOT).
#[test]
fn bless_rewrites_only_the_named_golden() {
    if !common::gl_available() {
        return;
    }
    let root = common::temp_workspace();
    let golden = root.path().join("golden");
    let before = snapshot(&golden);
    std::thread::sleep(std::time::Duration::from_millis(20));
    let stdout = bless_in(root.path(), &["--scene", "chess", "--pass", "final"]);
    assert!(
        stdout.contains("chess/final: within tolerance vs old golden"),
        "{stdout}"
    );
    let after = snapshot(&golden);
    assert_eq!(
        before.keys().collect::<Vec<_>>(),
        after.keys().collect::<Vec<_>>()
    );
    assert_eq!(
        changed_files(&golden, &before, &after),
        ["chess/blessed.toml", "chess/final.png"]
    );
    let record = std::fs::read_to_string(golden.join("chess/blessed.toml")).unwrap();
    assert!(
        record.contains("[passes.final]") && record.contains("driver = "),
        "{record}"
    );

    // Without --scene or --all, bless refuses.
    let output = common::harness_command()
        .arg("bless")
        .env("HARNESS_ROOT", root.path())
        .output()
        .unwrap();
    assert_eq!(output.status.code(), Some(1));
}

/// After a change to one light's intensity, `bless --scene arrow` rewrites only the passes that
/// light reaches (light and final) and their blessed.toml entries; the G-buffer, shadow and mask
/// goldens and their records stay as they were. A scene given by path gets a bless suggestion
/// with its path, which works.
#[test]
fn bless_after_a_light_change_rewrites_only_the_changed_passes() {
    if !common::gl_available() {
        return;
    }
    let root = common::temp_workspace();
    let scene = root.path().join("scenes/arrow.toml");
    let text = std::fs::read_to_string(&scene).unwrap();
    assert!(text.contains("intensity = 2.5"));
    std::fs::write(&scene, text.replace("intensity = 2.5", "intensity = 3.0")).unwrap();
    let golden = root.path().join("golden");
    let records_before = std::fs::read_to_string(golden.join("arrow/blessed.toml")).unwrap();
    let before = snapshot(&golden);
    std::thread::sleep(std::time::Duration::from_millis(20));
    let stdout = bless_in(root.path(), &["--scene", "arrow"]);
    let after = snapshot(&golden);
    assert_eq!(
        changed_files(&golden, &before, &after),
        ["arrow/blessed.toml", "arrow/final.png", "arrow/light.exr"],
        "{stdout}"
    );
    assert!(
        stdout.contains("arrow/light: CHANGED vs old golden"),
        "{stdout}"
    );
    assert!(
        stdout.contains("arrow/mask: within tolerance vs old golden"),
        "{stdout}"
    );
    // The records of the passes kept are the same lines as before.
    let records_after = std::fs::read_to_string(golden.join("arrow/blessed.toml")).unwrap();
    let section = |text: &str, pass: &str| {
        let start = text.find(&format!("[passes.{pass}]")).unwrap();
        let rest = &text[start..];
        let end = rest[1..].find("\n[").map_or(rest.len(), |e| e + 1);
        rest[..end].to_owned()
    };
    for pass in [
        "mask",
        "depth",
        "gbuffer_albedo",
        "shadow_0",
        "shadow_term_0",
    ] {
        assert_eq!(
            section(&records_before, pass),
            section(&records_after, pass),
            "{pass}"
        );
    }
    assert_ne!(
        section(&records_before, "light"),
        section(&records_after, "light")
    );

    // A second bless finds nothing to rewrite.
    let again = snapshot(&golden);
    bless_in(root.path(), &["--scene", "arrow"]);
    assert_eq!(snapshot(&golden), again);

    // A copy of the scene given by path: check suggests blessing it by path, and that works.
    let copy = root.path().join("elsewhere/arrow.toml");
    std::fs::create_dir_all(copy.parent().unwrap()).unwrap();
    let text = std::fs::read_to_string(&scene).unwrap();
    // Relative asset paths resolve against the scene file: point them back at scenes/. The
    // copy's light differs from the blessed one, so its light and final passes fail.
    let moved = text
        .replace("\"assets/", "\"../scenes/assets/")
        .replace("intensity = 3.0", "intensity = 2.0");
    std::fs::write(&copy, moved).unwrap();
    let output = common::harness_command()
        .args([
            "check",
            "--backend",
            "gl",
            "--scene",
            copy.to_str().unwrap(),
            "--out",
            root.path().join("out").to_str().unwrap(),
        ])
        .env("HARNESS_ROOT", root.path())
        .output()
        .unwrap();
    let stdout = String::from_utf8_lossy(&output.stdout);
    let suggestion = format!(
        "  cargo run --release -p harness -- bless --scene {}",
        copy.display()
    );
    assert!(stdout.lines().any(|l| l == suggestion), "{stdout}");
}

/// Darkens an 8-bit image's RGB by `steps` (of 255), in place.
fn darken(png: &Path, steps: u8) {
    let mut image = image::open(png).unwrap().to_rgba8();
    for pixel in image.pixels_mut() {
        for c in 0..3 {
            pixel[c] = pixel[c].saturating_sub(steps);
        }
    }
    image.save(png).unwrap();
}

/// A changed golden fails `check` with the metrics and leaves actual, golden, diff and the HTML
/// report on disk; a missing golden fails with the exact bless command.
#[test]
fn check_reports_failures_with_images_and_the_bless_command() {
    if !common::gl_available() {
        return;
    }
    let root = common::temp_workspace();
    // Darken the golden final image of `arrow` by 3/255: a change the tolerance must catch.
    darken(&root.path().join("golden/arrow/final.png"), 3);
    std::fs::remove_file(root.path().join("golden/arrow/light.exr")).unwrap();
    let out = root.path().join("out");
    let output = common::harness_command()
        .args(["check", "--scene", "arrow", "--out", out.to_str().unwrap()])
        .env("HARNESS_ROOT", root.path())
        .output()
        .unwrap();
    let stdout = String::from_utf8_lossy(&output.stdout);
    assert_eq!(output.status.code(), Some(1), "{stdout}");
    let line = |pass: &str| {
        stdout
            .lines()
            .find(|l| l.starts_with("arrow") && l.contains(pass) && l.contains(" gl "))
            .unwrap_or_default()
            .to_owned()
    };
    assert!(
        line("final").contains("FAILED") && line("final").contains("fraction_over"),
        "{stdout}"
    );
    // The failing check's value / limit, the pixels over its threshold, and where the largest
    // difference is (3/255 darker: a difference of 1.1765e-2 in 0..1 units).
    assert!(
        line("final").contains("px over")
            && line("final").contains("px differ, the most 1.1765e-2 at (")
            && line("final").contains("x) FAILED"),
        "{stdout}"
    );
    assert!(
        line("light").contains("MISSING") && line("light").contains("no golden at "),
        "{stdout}"
    );
    // One bless suggestion for the scene, not one per pass.
    let suggestions: Vec<&str> = stdout
        .lines()
        .filter(|l| l.contains("harness -- bless"))
        .collect();
    assert_eq!(
        suggestions,
        ["  cargo run --release -p harness -- bless --scene arrow"],
        "{stdout}"
    );
    assert!(line("mask").contains(" ok "), "{stdout}");
    // Under --out, not the workspace's target/.
    let failures = out.join("failures/arrow/gl");
    for file in [
        "final_actual.png",
        "final_golden.png",
        "final_diff.png",
        "light_actual.exr",
    ] {
        assert!(failures.join(file).is_file(), "{file} not written");
    }
    assert!(!root.path().join("target/harness/failures").exists());
    let report = std::fs::read_to_string(out.join("report.html")).unwrap();
    assert!(report.contains("data:image/png;base64,") && report.contains("FAILED"));
}

/// `harness bench --json`: for each scene, backend and pass, the median GPU time and its ratio
/// to the floor (a trivial pass writing the same targets), kept for the check report.
#[test]
fn bench_json_gives_each_pass_its_time_and_ratio_to_the_floor() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().to_str().unwrap();
    let (code, stdout, stderr) = harness(&[
        "bench",
        "--scene",
        "arrow",
        "--backend",
        "gl",
        "--frames",
        "1",
        "--json",
        "--out",
        out,
    ]);
    if code != 0 && stderr.contains("unavailable") && !common::required(engine::BackendKind::Gl) {
        eprintln!("skipping: gl unavailable: {stderr}");
        return;
    }
    assert_eq!(code, 0, "{stderr}");
    let json: serde_json::Value = serde_json::from_str(&stdout).unwrap();
    let scenes = json["scenes"].as_array().unwrap();
    assert_eq!(scenes.len(), 1);
    let arrow = &scenes[0];
    assert_eq!(arrow["backend"], "gl");
    let passes = arrow["passes"].as_array().unwrap();
    let names: Vec<&str> = passes.iter().map(|p| p["pass"].as_str().unwrap()).collect();
    assert_eq!(
        names,
        [
            "shadow_0",
            "geometry",
            "mask",
            "lighting_pbr",
            "lighting_blinn_phong",
            "tonemap"
        ]
    );
    for p in passes {
        let (ms, floor, ratio) = (
            p["median_ms"].as_f64().unwrap(),
            p["floor_ms"].as_f64().unwrap(),
            p["ratio"].as_f64().unwrap(),
        );
        assert!(ms > 0.0 && floor > 0.0, "{p}");
        assert!((ratio - ms / floor).abs() < 1e-9 * ratio, "{p}");
    }
    assert!(json["precompute"][0]["ms"].as_f64().unwrap() >= 0.0);
    assert!(dir.path().join("bench.json").is_file());
}

/// `harness bench --breakdown --json`: a row per part of each lighting pass (input floor,
/// setup, each light, and the parts of those), their sum and the pass as it is. Times vary;
/// only the shape and that every figure is a time are checked here.
#[test]
fn bench_breakdown_lists_the_parts_of_each_lighting_pass() {
    let (code, stdout, stderr) = harness(&[
        "bench",
        "--breakdown",
        "--scene",
        "arrow",
        "--backend",
        "gl",
        "--frames",
        "1",
        "--json",
    ]);
    if code != 0 && stderr.contains("unavailable") && !common::required(engine::BackendKind::Gl) {
        eprintln!("skipping: gl unavailable: {stderr}");
        return;
    }
    assert_eq!(code, 0, "{stderr}");
    let passes: serde_json::Value = serde_json::from_str(&stdout).unwrap();
    let names: Vec<&str> = passes
        .as_array()
        .unwrap()
        .iter()
        .map(|p| p["pass"].as_str().unwrap())
        .collect();
    assert_eq!(names, ["lighting_pbr", "lighting_blinn_phong"]);
    for pass in passes.as_array().unwrap() {
        let rows: Vec<&str> = pass["rows"]
            .as_array()
            .unwrap()
            .iter()
            .map(|r| r["what"].as_str().unwrap())
            .collect();
        assert_eq!(
            rows,
            [
                "G-buffer reads (input floor)",
                "per-pixel setup (view vector, ambient, output)",
                "light 0 (point, shadow pcf3)",
                "  of which shadow lookups",
            ]
            .into_iter()
            .chain((pass["pass"] == "lighting_pbr").then_some("  of which clearcoat"))
            .collect::<Vec<_>>(),
            "{pass}"
        );
        for key in ["total_ms", "sum_ms", "sum_to_total"] {
            assert!(pass[key].as_f64().unwrap().is_finite(), "{key}: {pass}");
        }
    }
}

/// `harness noise` measures a source in child processes (`check --json` per scene and backend)
/// and renders recorded on another host, and judges both against the limits; a golden that no
/// longer matches makes it exit 1. Refuses unknown sources and a partial `--write`.
#[test]
fn noise_measures_sources_and_fails_when_a_golden_moved() {
    let backends = common::available_backends();
    assert!(!backends.is_empty(), "no backend available");
    let (code, stdout, stderr) = harness(&[
        "noise",
        "--source",
        "cpu-sse4.1",
        "--source",
        "host-b",
        "--scene",
        "ibl",
        "--json",
    ]);
    assert_eq!(code, 0, "{stdout}\n{stderr}");
    let json: serde_json::Value = serde_json::from_str(&stdout).unwrap();
    let names: Vec<&str> = json["sources"]
        .as_array()
        .unwrap()
        .iter()
        .map(|s| s["name"].as_str().unwrap())
        .collect();
    assert_eq!(names, ["cpu-sse4.1", "host-b"]);
    let measurements = json["measurements"].as_array().unwrap();
    for backend in &backends {
        assert!(
            measurements
                .iter()
                .any(|m| m["source"] == "cpu-sse4.1" && m["backend"] == backend.name()),
            "no cpu-sse4.1 measurement on {backend}"
        );
    }
    assert!(measurements
        .iter()
        .any(|m| m["source"] == "host-b" && m["pass"] == "final"));
    for ratio in json["ratios"].as_array().unwrap() {
        assert!(ratio["ratio"].as_f64().unwrap() <= 0.5, "{ratio}");
    }

    let (code, _, stderr) = harness(&["noise", "--source", "nope"]);
    assert_eq!(code, 1);
    assert!(stderr.contains("unknown source `nope`"), "{stderr}");
    let (code, _, stderr) = harness(&["noise", "--source", "drivers", "--write"]);
    assert_eq!(code, 1);
    assert!(stderr.contains("--write records every source"), "{stderr}");

    // A golden darkened by 2/255 is no noise: the drivers source fails against it.
    let root = common::temp_workspace();
    darken(&root.path().join("golden/ibl/final.png"), 2);
    let output = common::harness_command()
        .args(["noise", "--source", "drivers", "--scene", "ibl"])
        .env("HARNESS_ROOT", root.path())
        .output()
        .unwrap();
    let stdout = String::from_utf8_lossy(&output.stdout);
    assert_eq!(output.status.code(), Some(1), "{stdout}");
    assert!(
        stdout
            .lines()
            .any(|l| l.starts_with("FAILED: drivers ibl final")),
        "{stdout}"
    );
}

/// When the driver differs from the one the goldens were blessed with, `check` says so, as
/// information: the run still passes.
#[test]
fn check_notes_a_driver_other_than_the_blessing_one() {
    if !common::available_backends().contains(&engine::BackendKind::Gl) {
        return;
    }
    let root = common::temp_workspace();
    let record = root.path().join("golden/arrow/blessed.toml");
    let text = std::fs::read_to_string(&record).unwrap();
    let moved: String = text
        .lines()
        .map(|l| {
            if l.starts_with("driver = ") {
                "driver = \"OpenGL 4.6 | some other GPU | Mesa 99.0\"".to_owned()
            } else {
                l.to_owned()
            }
        })
        .collect::<Vec<_>>()
        .join("\n");
    std::fs::write(&record, moved).unwrap();
    let out = root.path().join("out");
    let output = common::harness_command()
        .args(["check", "--scene", "arrow", "--backend", "gl", "--out"])
        .arg(&out)
        .env("HARNESS_ROOT", root.path())
        .output()
        .unwrap();
    let stderr = String::from_utf8_lossy(&output.stderr);
    assert!(output.status.success(), "{stderr}");
    assert!(
        stderr.contains(
            "note: goldens of arrow were blessed on gl with `OpenGL 4.6 | some other GPU"
        ) && stderr.contains("are not failures"),
        "{stderr}"
    );
    let report = std::fs::read_to_string(out.join("report.html")).unwrap();
    assert!(
        report.contains("some other GPU"),
        "the report does not say it"
    );
}

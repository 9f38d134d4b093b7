//! `harness inspect` on bad and good input: it exits 1 with the loader's error (never 101, a
//! panic) on every malformed fixture, and 0 on fixtures that load with warnings.

use crate::common;
use std::path::Path;

use common::cli::{fixture, harness};

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
        // A lone texture is held to the default limits, as a scene's are.
        (
            "textures/too_wide_16385x1.png",
            "too_wide_16385x1.png: image side (16385x1) 16385 is above the limit of 16384",
        ),
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
    // A scene whose tolerances `check` would refuse: a pass it has no golden of, a limit that
    // can never be exceeded.
    let dir = tempfile::tempdir().unwrap();
    let corner = std::fs::read_to_string(harness::scenes_dir().join("corner.toml")).unwrap();
    let corner = corner.replace(
        "\"assets/",
        &format!("\"{}/", harness::scenes_dir().join("assets").display()),
    );
    for (table, expected) in [
        (
            "[tolerances.finale]\nmetric = \"rmse\"\nmax = 0.1\n",
            "the scene has no golden pass `finale`",
        ),
        (
            "[tolerances.final]\nmetric = \"flip_mean\"\nmax = 5\n",
            "`max` 5 can never be exceeded",
        ),
    ] {
        let path = dir.path().join("tolerant.toml");
        std::fs::write(&path, format!("{corner}\n{table}")).unwrap();
        let (code, _, stderr) = harness(&["inspect", path.to_str().unwrap()]);
        assert_eq!(code, 1, "{stderr}");
        assert!(stderr.contains(expected), "{stderr}");
    }
}

#[test]
fn inspect_loads_fixtures_that_only_warn() {
    for (file, warning) in [
        ("unknown_keys.obj", "unknown MTL key"),
        ("points_lines.obj", "skipped"),
        ("ngons.obj", "triangulated"),
        // As text, not JSON; a `Kd` beside a `map_Kd` is said to be unused.
        (
            "textured.mtl",
            "  material brick  Kd [0.8, 0.7, 0.6] (unused: map_Kd replaces it)  Ns 32  maps base_color,",
        ),
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
    // Which values of an object its maps replace (its base_color is not what is drawn).
    let replaced: Vec<&serde_json::Value> = value["objects"]
        .as_array()
        .unwrap()
        .iter()
        .map(|o| &o["replaced_by_maps"])
        .collect();
    assert!(
        replaced
            .iter()
            .any(|r| r.as_array().unwrap().contains(&"base_color".into())),
        "{replaced:?}"
    );
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
    // A scene's lights read as their file wrote them (0.93, not f32's 0.9300000071525574).
    let arrow = Path::new(env!("CARGO_MANIFEST_DIR")).join("../scenes/arrow.toml");
    let (code, stdout, stderr) = harness(&["inspect", arrow.to_str().unwrap()]);
    assert_eq!(code, 0, "{stderr}");
    assert!(
        stdout.contains(r#"light {"color":[1.0,0.93,0.82],"falloff":1.0,"intensity":2.5,"#),
        "{stdout}"
    );
}

/// Output that cannot be written ends the run without a panic: quietly with status 141 when
/// the reader went away (`harness inspect ... | head`), with the cause and status 1 on a full
/// disk.
#[test]
fn a_closed_or_full_output_is_not_a_panic() {
    let scene = Path::new(env!("CARGO_MANIFEST_DIR")).join("../scenes/chess.toml");
    let (reader, writer) = std::io::pipe().unwrap();
    drop(reader);
    let closed = common::harness_command()
        .args(["inspect", scene.to_str().unwrap()])
        .stdout(writer)
        .output()
        .unwrap();
    let stderr = String::from_utf8_lossy(&closed.stderr);
    assert_eq!(closed.status.code(), Some(141), "{stderr}");
    assert!(stderr.is_empty(), "{stderr}");
    let full = common::harness_command()
        .args(["inspect", scene.to_str().unwrap()])
        .stdout(std::fs::File::create("/dev/full").unwrap())
        .output()
        .unwrap();
    let stderr = String::from_utf8_lossy(&full.stderr);
    assert_eq!(full.status.code(), Some(1), "{stderr}");
    assert!(
        stderr.contains("error: cannot write to standard output: No space left")
            && !stderr.contains("panicked"),
        "{stderr}"
    );
}

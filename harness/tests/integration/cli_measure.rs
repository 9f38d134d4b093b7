//! `harness bench` (pass times, their ratio to the floor, the lighting breakdown), `harness
//! sweep`'s results kept where `--out` says, and `harness noise` (sources measured and judged
//! against the limits).

use crate::common;
use common::cli::{darken, harness};

/// `harness bench --json`: for each scene, backend and pass, the median GPU time and its ratio
/// to the floor (a trivial pass writing the same targets): each frame's ratio, with the floor
/// submitted right after that frame, and their lower quartile; kept for the check report and
/// appended to the speed history, unless a slowdown was injected.
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
        "4",
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
        let mut frames: Vec<f64> = p["frame_ratios"]
            .as_array()
            .unwrap()
            .iter()
            .map(|r| r.as_f64().unwrap())
            .collect();
        assert_eq!(frames.len(), 4, "{p}");
        assert!(frames.iter().all(|r| *r > 0.0), "{p}");
        // The lower quartile by nearest rank: the first of four, sorted.
        frames.sort_by(f64::total_cmp);
        assert_eq!(ratio, frames[0], "{p}");
    }
    assert!(json["precompute"][0]["ms"].as_f64().unwrap() >= 0.0);
    assert!(dir.path().join("bench.json").is_file());
    // And the speed history has a `bench` entry with each pass's ratio.
    let (entries, skipped) = harness::golden::speed::history::read(dir.path());
    assert_eq!((entries.len(), skipped), (1, 0));
    assert_eq!(entries[0].command, "bench");
    assert_eq!(entries[0].ratios.len(), passes.len());
    assert!(entries[0].hosts.contains_key(&engine::BackendKind::Gl));

    // An injected slowdown is said, kept in bench.json for the page, and not appended to the
    // history (an unchanged build's series).
    let (code, stdout, stderr) = harness(&[
        "bench",
        "--scene",
        "arrow",
        "--backend",
        "gl",
        "--frames",
        "2",
        "--slow-pass",
        "tonemap",
        "--json",
        "--out",
        out,
    ]);
    assert_eq!(code, 0, "{stderr}");
    assert!(
        stderr.contains("note: injected slowdown: tonemap slowed x2 (--slow-pass)"),
        "{stderr}"
    );
    let json: serde_json::Value = serde_json::from_str(&stdout).unwrap();
    assert_eq!(json["injected"], "tonemap slowed x2 (--slow-pass)");
    let (entries, _) = harness::golden::speed::history::read(dir.path());
    assert_eq!(entries.len(), 1, "the injected run went into the history");
}

/// `harness sweep --out DIR` keeps its results in DIR, where `harness check --out DIR` finds
/// them for the report (a small scene file's G-buffer sweep: 64x64, one render per setting).
#[test]
fn sweep_keeps_its_results_where_out_says() {
    if !common::gl_available() {
        return;
    }
    let dir = tempfile::tempdir().unwrap();
    let scene = dir.path().join("tiny.toml");
    std::fs::write(
        &scene,
        "[camera]\nposition = [0, 2, 4]\ntarget = [0, 0, 0]\n\n[quality]\nwidth = 64\n\
         height = 64\n\n[[objects]]\nmesh = \"builtin:sphere\"\n\n[[lights]]\n\
         type = \"directional\"\ndirection = [0.3, 1, 0.2]\n",
    )
    .unwrap();
    let out = dir.path().join("out");
    let (code, stdout, stderr) = harness(&[
        "sweep",
        "--scene",
        scene.to_str().unwrap(),
        "--knob",
        "gbuffer",
        "--repeats",
        "1",
        "--out",
        out.to_str().unwrap(),
    ]);
    assert_eq!(code, 0, "{stdout}\n{stderr}");
    let kept = out.join("sweep_tiny_gbuffer.json");
    let text = std::fs::read_to_string(&kept).unwrap_or_else(|e| panic!("{kept:?}: {e}"));
    serde_json::from_str::<serde_json::Value>(&text).unwrap();
    assert!(stderr.contains(kept.to_str().unwrap()), "{stderr}");
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
        "4",
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
            .chain(["less the variants' re-read of the inputs"])
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

    // A golden darkened by 2/255 is no noise: a source fails against it (host-b's recorded
    // renders: the same comparison as a rendering source's, without rendering again).
    let root = common::temp_workspace();
    darken(&root.path().join("golden/ibl/final.png"), 2);
    let output = common::harness_command()
        .args(["noise", "--source", "host-b", "--scene", "ibl"])
        .env("HARNESS_ROOT", root.path())
        .output()
        .unwrap();
    let stdout = String::from_utf8_lossy(&output.stdout);
    assert_eq!(output.status.code(), Some(1), "{stdout}");
    assert!(
        stdout
            .lines()
            .any(|l| l.starts_with("FAILED: host-b ibl final")),
        "{stdout}"
    );
}

/// Closed sets of values are typed on the command line: an unknown knob or series is refused
/// before anything runs, with the values that exist.
#[test]
fn unknown_knobs_and_series_are_refused_with_the_known_ones() {
    let (code, _, stderr) = harness(&["sweep", "--knob", "shadows"]);
    assert_eq!(code, 2, "{stderr}");
    assert!(
        stderr.contains("shadow") && stderr.contains("ibl") && stderr.contains("gbuffer"),
        "{stderr}"
    );
    // A setting to try that is not one is refused before anything renders, naming the key.
    let (code, _, stderr) = harness(&["sweep", "--knob", "ibl", "--try", "samples = 4"]);
    assert_eq!(code, 1, "{stderr}");
    assert!(
        stderr.contains("--try") && stderr.contains("unknown field `samples`"),
        "{stderr}"
    );
    let (code, _, stderr) = harness(&["sweep", "--knob", "gbuffer", "--only", "fis"]);
    assert_eq!(code, 1, "{stderr}");
    assert!(stderr.contains("gbuffer sweep visits all"), "{stderr}");
    let (code, _, stderr) = harness(&["bench", "--series", "pixels"]);
    assert_eq!(code, 2, "{stderr}");
    assert!(
        stderr.contains("resolution") && stderr.contains("shadow-map") && stderr.contains("all"),
        "{stderr}"
    );
}

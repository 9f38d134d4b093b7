//! Helpers for the tests of the `harness` command line: running it, the engine's fixtures,
//! and editing golden images.

use std::path::{Path, PathBuf};

/// A file under engine/tests/fixtures.
pub fn fixture(name: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../engine/tests/fixtures")
        .join(name)
}

/// Runs the `harness` binary with `args`: its exit code (-1 when killed), stdout and stderr.
pub fn harness(args: &[&str]) -> (i32, String, String) {
    let output = super::harness_command()
        .args(args)
        .output()
        .expect("run harness");
    (
        output.status.code().unwrap_or(-1),
        String::from_utf8_lossy(&output.stdout).into_owned(),
        String::from_utf8_lossy(&output.stderr).into_owned(),
    )
}

/// Darkens an 8-bit image's RGB by `steps` (of 255), in place.
pub fn darken(png: &Path, steps: u8) {
    let mut image = image::open(png).unwrap().to_rgba8();
    for pixel in image.pixels_mut() {
        for c in 0..3 {
            pixel[c] = pixel[c].saturating_sub(steps);
        }
    }
    image.save(png).unwrap();
}

/// The passes whose image check did not pass in `harness check --json`'s output, in order.
pub fn failing_passes(json: &[u8]) -> Vec<String> {
    let run: serde_json::Value = serde_json::from_slice(json).unwrap();
    run["results"]
        .as_array()
        .unwrap()
        .iter()
        .filter(|r| r["outcome"].get("Passed").is_none())
        .map(|r| r["pass"].as_str().unwrap().to_owned())
        .collect()
}

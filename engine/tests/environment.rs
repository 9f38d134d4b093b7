//! EXR environment loading.

mod common;

use common::fixture;
use engine::assets::load_environment;

#[test]
fn sunset_exr_loads() {
    let env = load_environment(
        &std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../scenes/assets/sunset.exr"),
    )
    .unwrap();
    let s = env.summary();
    println!(
        "sunset.exr: {}x{}, radiance min {} max {} mean {} ({})",
        s.width, s.height, s.min_radiance, s.max_radiance, s.mean_radiance, s.radiance_measure
    );
    assert!(env.width > 0 && env.height > 0);
    assert_eq!(env.texels.len(), (env.width * env.height) as usize);
    assert!(env.min_radiance.is_finite() && env.max_radiance.is_finite());
    assert!(env.min_radiance <= s.mean_radiance && s.mean_radiance <= env.max_radiance);
    assert!(env.max_radiance > 0.0);
}

#[test]
fn missing_and_corrupt_exr() {
    let e = load_environment(&fixture("nope.exr"))
        .unwrap_err()
        .to_string();
    assert!(e.contains("nope.exr: cannot read file"), "{e}");
    let e = load_environment(&fixture("corrupt.exr"))
        .unwrap_err()
        .to_string();
    println!("{e}");
    assert!(e.contains("corrupt.exr: cannot decode EXR"), "{e}");
}

fn write_exr(path: &std::path::Path, w: usize, h: usize, bad: Option<(usize, usize, f32)>) {
    exr::prelude::write_rgba_file(path, w, h, move |x, y| {
        let v = match bad {
            Some((bx, by, v)) if (bx, by) == (x, y) => v,
            _ => 0.25,
        };
        (v, 0.5f32, 1.0f32, 1.0f32)
    })
    .unwrap();
}

#[test]
fn non_finite_texels_are_reported_with_position() {
    let dir = tempfile::tempdir().unwrap();
    for (name, value) in [("nan.exr", f32::NAN), ("inf.exr", f32::INFINITY)] {
        let path = dir.path().join(name);
        write_exr(&path, 8, 4, Some((5, 2, value)));
        let e = load_environment(&path).unwrap_err().to_string();
        println!("{e}");
        assert!(e.contains(name), "{e}");
        assert!(e.contains("non-finite texel at pixel (5, 2)"), "{e}");
    }
    // A clean file of the same shape loads, top row first.
    let path = dir.path().join("ok.exr");
    write_exr(&path, 8, 4, Some((1, 0, 3.0)));
    let env = load_environment(&path).unwrap();
    assert_eq!(env.texels[1], [3.0, 0.5, 1.0, 1.0]);
    assert_eq!((env.min_radiance, env.max_radiance), (1.0, 3.0));
}

/// EXR data windows are inclusive boxes, so a zero-size image cannot be
/// expressed (the `exr` crate reads every box as at least 1x1); the closest
/// malformed input, an inverted data window, must be rejected cleanly.
#[test]
fn inverted_data_window_exr_is_rejected() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("zero.exr");
    write_exr(&path, 1, 1, None);
    // Patch dataWindow (box2i: xMin yMin xMax yMax) to xMax = xMin - 1.
    let mut bytes = std::fs::read(&path).unwrap();
    let key = b"dataWindow\0box2i\0";
    let at = bytes.windows(key.len()).position(|w| w == key).unwrap() + key.len() + 4;
    bytes[at + 8..at + 12].copy_from_slice(&(-1i32).to_le_bytes());
    std::fs::write(&path, &bytes).unwrap();
    let e = load_environment(&path).unwrap_err().to_string();
    println!("{e}");
    assert!(e.contains("zero.exr"), "{e}");
}

//! Environment loading: EXR and Radiance `.hdr`.

use crate::common::fixture;
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

/// Found by fuzzing (`scripts/fuzz.sh`, target `images`): a corrupt DWAB file on which the
/// exr crate reserved ~2.3e14 bytes for one block's AC coefficients. Whether that aborted the
/// process or failed cleanly depended on the order of exr's parallel block decoding; it is an
/// error naming the file every time now.
#[test]
fn the_fuzzed_dwa_file_is_an_error_naming_it() {
    let path = fixture("fuzz/dwa_huge_ac_count.exr");
    let error = load_environment(&path).unwrap_err().to_string();
    assert!(error.contains("dwa_huge_ac_count.exr"), "{error}");
}

/// interior.exr (DWAB) with its first block's AC coefficient count set to 2^46: refused by the
/// DWA block check before the exr crate reserves memory for it.
#[test]
fn a_dwa_block_claiming_absurd_coefficient_counts_is_refused_before_decoding() {
    let source =
        std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../scenes/assets/interior.exr");
    let mut bytes = std::fs::read(source).unwrap();
    // Skip the magic number, version and header attributes (name\0 type\0 size value).
    let mut at = 8;
    let c_string = |at: &mut usize, bytes: &[u8]| {
        let end = *at + bytes[*at..].iter().position(|&b| b == 0).unwrap();
        let empty = end == *at;
        *at = end + 1;
        empty
    };
    while !c_string(&mut at, &bytes) {
        c_string(&mut at, &bytes);
        let size = i32::from_le_bytes(bytes[at..at + 4].try_into().unwrap()) as usize;
        at += 4 + size;
    }
    // The offset table's first entry is the first block: y (i32), size (i32), then the DWA
    // header's eleven u64 counters; the ninth is the AC coefficient count.
    let first = u64::from_le_bytes(bytes[at..at + 8].try_into().unwrap()) as usize;
    let counter = first + 8 + 8 * 8;
    bytes[counter..counter + 8].copy_from_slice(&(1u64 << 46).to_le_bytes());
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("huge_ac.exr");
    std::fs::write(&path, bytes).unwrap();
    let error = load_environment(&path).unwrap_err().to_string();
    assert!(
        error.contains("huge_ac.exr") && error.contains("corrupt DWA block at y 0: AC coefficient"),
        "{error}"
    );
}

/// The canonical environments (one of them DWA-compressed, like the fuzz seed above) still load
/// through the DWA block check.
#[test]
fn canonical_environments_pass_the_dwa_block_check() {
    for name in ["sunset.exr", "interior.exr"] {
        let path = std::path::Path::new(env!("CARGO_MANIFEST_DIR"))
            .join("../scenes/assets")
            .join(name);
        let env = load_environment(&path).unwrap_or_else(|e| panic!("{e}"));
        assert!(env.width > 0, "{name}");
    }
}

/// A Radiance `.hdr` environment (RGBE, written by hand: R = (x + 1) / 2, G = y + 1, B = 1/4 on
/// 8x4) loads like an EXR one, alpha 1.
#[test]
fn radiance_hdr_environment_loads() {
    let env = load_environment(&fixture("sky.hdr")).unwrap();
    assert_eq!((env.width, env.height), (8, 4));
    for y in 0..4 {
        for x in 0..8 {
            let texel = env.texels[y * 8 + x];
            let expected = [(x as f32 + 1.0) * 0.5, y as f32 + 1.0, 0.25, 1.0];
            for (got, want) in texel.iter().zip(expected) {
                // RGBE keeps 8 bits of mantissa relative to the texel's largest channel.
                assert!(
                    (got - want).abs() <= want.max(y as f32 + 1.0) / 128.0,
                    "({x}, {y}): {texel:?}"
                );
            }
        }
    }
    assert!((env.max_radiance - 4.0).abs() < 0.05);
}

/// A truncated `.hdr` and a file that is neither EXR nor Radiance are errors naming the file.
#[test]
fn truncated_hdr_and_unknown_environment_formats_are_errors() {
    let e = load_environment(&fixture("truncated.hdr"))
        .unwrap_err()
        .to_string();
    assert!(e.contains("truncated.hdr"), "{e}");
    let e = load_environment(&fixture("textures/gradient.bmp"))
        .unwrap_err()
        .to_string();
    assert!(
        e.contains("gradient.bmp") && e.contains("not an OpenEXR or Radiance"),
        "{e}"
    );
}

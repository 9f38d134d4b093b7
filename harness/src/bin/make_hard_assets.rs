//! `make_hard_assets`: generates the assets of the hard-case scenes (`scenes/hard/*.toml`).
//!
//! ```text
//! cargo run -p harness --bin make_hard_assets -- scenes/hard/assets
//! ```
//!
//! | file | contents |
//! | --- | --- |
//! | `uniform.exr` | 64x32 equirectangular environment of radiance exactly 1 (the white furnace) |
//! | `sun_1e5.exr` | 512x256 equirectangular sky (0.2 at the horizon to 1 at the zenith, 0.05 below) with a sun of radiance 1e5 and 0.5 degrees radius at elevation 35 degrees |
//! | `degenerate.obj` | a quad strip with a zero-area triangle, a triangle with collapsed UVs, a mirrored-UV quad and duplicated vertices |
//!
//! Deterministic: no clock, no randomness; EXRs are f32, losslessly compressed.

use std::f64::consts::PI;
use std::path::{Path, PathBuf};
use std::{env, fs, process};

fn write_exr(path: &Path, width: usize, height: usize, f: impl Fn(usize, usize) -> f32 + Sync) {
    use exr::prelude::*;
    let channels = SpecificChannels::rgba(|Vec2(x, y)| {
        let v = f(x, y);
        (v, v, v, 1.0f32)
    });
    let image = Image::from_encoded_channels((width, height), Encoding::SMALL_LOSSLESS, channels);
    image
        .write()
        .to_file(path)
        .unwrap_or_else(|e| panic!("{}: {e}", path.display()));
}

fn sun_sky(x: usize, y: usize, width: usize, height: usize) -> f32 {
    // Texel center direction (the renderer's convention: u = 0.5 + atan2(x, -z) / 2pi,
    // v = acos(y) / pi).
    let u = (x as f64 + 0.5) / width as f64;
    let v = (y as f64 + 0.5) / height as f64;
    let phi = (u - 0.5) * 2.0 * PI;
    let theta = v * PI;
    let d = [
        theta.sin() * phi.sin(),
        theta.cos(),
        -theta.sin() * phi.cos(),
    ];
    let elevation = 35f64.to_radians();
    let sun = [0.0, elevation.sin(), -elevation.cos()];
    let cosine = d[0] * sun[0] + d[1] * sun[1] + d[2] * sun[2];
    if cosine > 0.5f64.to_radians().cos() {
        return 1e5;
    }
    if d[1] < 0.0 {
        0.05
    } else {
        (0.2 + 0.8 * d[1]) as f32
    }
}

const DEGENERATE_OBJ: &str = "\
# Degenerate mesh for the hard cases (see make_hard_assets.rs): in the XZ plane, facing +Y.
# Triangle 1: zero area (three collinear points). Triangle 2: collapsed UVs (all the same).
# Quad 3: mirrored UVs (u runs against x). Quad 4: duplicated vertices (same position twice).
o degenerate
v -1.0 0.0 -1.0
v 0.0 0.0 -1.0
v 1.0 0.0 -1.0
v -1.0 0.0 0.0
v 0.0 0.0 0.0
v 1.0 0.0 0.0
v -1.0 0.0 1.0
v 0.0 0.0 1.0
v 1.0 0.0 1.0
v 0.0 0.0 0.0
vt 0.0 1.0
vt 0.5 1.0
vt 1.0 1.0
vt 0.0 0.5
vt 0.5 0.5
vt 1.0 0.5
vt 0.0 0.0
vt 0.5 0.0
vt 1.0 0.0
vn 0.0 1.0 0.0
f 1/1/1 2/2/1 3/3/1
f 1/5/1 4/5/1 5/5/1
f 1/1/1 5/5/1 2/2/1
f 2/3/1 5/6/1 6/9/1
f 2/3/1 6/9/1 3/1/1
f 4/4/1 7/7/1 8/8/1
f 4/4/1 8/8/1 10/5/1
f 10/5/1 8/8/1 9/9/1
f 10/5/1 9/9/1 6/6/1
";

fn write_assets(dir: &Path) -> std::io::Result<()> {
    fs::create_dir_all(dir)?;
    write_exr(&dir.join("uniform.exr"), 64, 32, |_, _| 1.0);
    write_exr(&dir.join("sun_1e5.exr"), 512, 256, |x, y| {
        sun_sky(x, y, 512, 256)
    });
    fs::write(dir.join("degenerate.obj"), DEGENERATE_OBJ)?;
    Ok(())
}

fn main() {
    let mut args = env::args_os().skip(1);
    let (Some(dir), None) = (args.next(), args.next()) else {
        eprintln!("usage: make_hard_assets OUT_DIR");
        process::exit(2);
    };
    if let Err(e) = write_assets(&PathBuf::from(dir)) {
        eprintln!("make_hard_assets: {e}");
        process::exit(1);
    }
}

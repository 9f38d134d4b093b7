//! OBJ + MTL loading: the input, split at its first NUL byte, is an OBJ file and the MTL file
//! `m.mtl` beside it (the OBJ may name it with `mtllib m.mtl`). Loading must return a model or
//! an error, never panic, hang or allocate past the limits.
#![no_main]

use std::path::PathBuf;
use std::sync::OnceLock;

use engine::assets::{load_obj, TextureCache};
use libfuzzer_sys::fuzz_target;

fn dir() -> &'static PathBuf {
    static DIR: OnceLock<PathBuf> = OnceLock::new();
    DIR.get_or_init(|| {
        let dir = std::env::temp_dir().join(format!("fuzz_obj_mtl_{}", std::process::id()));
        std::fs::create_dir_all(&dir).expect("temp dir");
        dir
    })
}

fuzz_target!(|data: &[u8]| {
    let (obj, mtl) = match data.iter().position(|&b| b == 0) {
        Some(i) => (&data[..i], &data[i + 1..]),
        None => (data, &[][..]),
    };
    let obj_path = dir().join("m.obj");
    std::fs::write(&obj_path, obj).expect("write obj");
    std::fs::write(dir().join("m.mtl"), mtl).expect("write mtl");
    let _ = load_obj(&obj_path, &mut TextureCache::new());
});

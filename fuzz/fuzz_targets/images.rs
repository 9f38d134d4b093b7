//! Image loading: the first byte picks the path, the rest is the file. Modulo 4: 0 a texture
//! named `.png` through the texture cache and its limits (PNG, JPEG and BMP are told by their
//! contents), 1 an environment named `.exr`, 2 a texture named `.tga` (TGA has no signature, so
//! only the name picks it), 3 an environment named `.hdr` (EXR and Radiance are told by their
//! contents). Loading must return an image or an error naming the file, never panic or allocate
//! past the limits.
#![no_main]

use std::path::PathBuf;
use std::sync::OnceLock;

use engine::assets::{load_environment, ColorSpace, TextureCache};
use libfuzzer_sys::fuzz_target;

fn dir() -> &'static PathBuf {
    static DIR: OnceLock<PathBuf> = OnceLock::new();
    DIR.get_or_init(|| {
        let dir = std::env::temp_dir().join(format!("fuzz_images_{}", std::process::id()));
        std::fs::create_dir_all(&dir).expect("temp dir");
        dir
    })
}

fuzz_target!(|data: &[u8]| {
    let Some((&selector, file)) = data.split_first() else {
        return;
    };
    let (name, texture) = match selector % 4 {
        0 => ("t.png", true),
        1 => ("e.exr", false),
        2 => ("t.tga", true),
        _ => ("e.hdr", false),
    };
    let path = dir().join(name);
    std::fs::write(&path, file).expect("write the input");
    if texture {
        let _ = TextureCache::new().load(&path, ColorSpace::Srgb);
    } else {
        let _ = load_environment(&path);
    }
});

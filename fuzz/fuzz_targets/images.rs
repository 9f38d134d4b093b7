//! Image loading: the first byte picks the path (even: a PNG texture through the texture cache
//! and its limits; odd: an EXR environment), the rest is the file. Loading must return an image
//! or an error naming the file, never panic or allocate past the limits.
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
    if selector % 2 == 0 {
        let path = dir().join("t.png");
        std::fs::write(&path, file).expect("write png");
        let _ = TextureCache::new().load(&path, ColorSpace::Srgb);
    } else {
        let path = dir().join("e.exr");
        std::fs::write(&path, file).expect("write exr");
        let _ = load_environment(&path);
    }
});

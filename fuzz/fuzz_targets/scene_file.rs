//! Scene files: the input is a scene file's text, loaded with every asset it names resolved
//! beside it (a small valid OBJ `a.obj` and PNG `a.png` are there to be found). Loading must
//! return a scene or an error naming the file, never panic.
#![no_main]

use std::path::PathBuf;
use std::sync::OnceLock;

use libfuzzer_sys::fuzz_target;

const CUBE_OBJ: &str = "v 0 0 0\nv 1 0 0\nv 0 1 0\nvt 0 0\nvt 1 0\nvt 0 1\nf 1/1 2/2 3/3\n";

fn dir() -> &'static PathBuf {
    static DIR: OnceLock<PathBuf> = OnceLock::new();
    DIR.get_or_init(|| {
        let dir = std::env::temp_dir().join(format!("fuzz_scene_file_{}", std::process::id()));
        std::fs::create_dir_all(&dir).expect("temp dir");
        std::fs::write(dir.join("a.obj"), CUBE_OBJ).expect("write obj");
        // A 1x1 RGBA PNG.
        let png: &[u8] = &[
            0x89, 0x50, 0x4e, 0x47, 0x0d, 0x0a, 0x1a, 0x0a, 0x00, 0x00, 0x00, 0x0d, 0x49, 0x48,
            0x44, 0x52, 0x00, 0x00, 0x00, 0x01, 0x00, 0x00, 0x00, 0x01, 0x08, 0x06, 0x00, 0x00,
            0x00, 0x1f, 0x15, 0xc4, 0x89, 0x00, 0x00, 0x00, 0x0d, 0x49, 0x44, 0x41, 0x54, 0x78,
            0x9c, 0x63, 0xf8, 0xcf, 0xc0, 0xf0, 0x1f, 0x00, 0x05, 0x00, 0x01, 0xff, 0x89, 0x99,
            0x3d, 0x1d, 0x00, 0x00, 0x00, 0x00, 0x49, 0x45, 0x4e, 0x44, 0xae, 0x42, 0x60, 0x82,
        ];
        std::fs::write(dir.join("a.png"), png).expect("write png");
        dir
    })
}

fuzz_target!(|data: &[u8]| {
    let path = dir().join("scene.toml");
    std::fs::write(&path, data).expect("write scene");
    if let Ok(loaded) = engine::scene_file::load(&path) {
        // A scene that loads must also pass the renderer's checks or fail them cleanly.
        let _ = engine::renderer::validate(&loaded.scene);
        if let Ok(frame) = engine::renderer::PreparedFrame::new(&loaded.scene) {
            let _ = frame.plan().to_string();
        }
    }
});

//! Loading limits: an OBJ with too many vertices, an image whose header is too large, and a
//! scene whose assets add up past the byte limit are refused with an error naming the file,
//! before anything is decoded; with the limits off, a scene loads and renders the same.

use crate::common;
use engine::assets::{self, AssetError, ColorSpace, Limits, TextureCache};
use engine::plan::TargetId;
use engine::renderer::{self, Readback};

fn crc32(bytes: &[u8]) -> u32 {
    let mut crc = 0xffff_ffffu32;
    for &b in bytes {
        crc ^= u32::from(b);
        for _ in 0..8 {
            crc = if crc & 1 != 0 {
                (crc >> 1) ^ 0xedb8_8320
            } else {
                crc >> 1
            };
        }
    }
    !crc
}

fn chunk(kind: &[u8; 4], data: &[u8]) -> Vec<u8> {
    let mut out = (data.len() as u32).to_be_bytes().to_vec();
    let mut body = kind.to_vec();
    body.extend_from_slice(data);
    out.extend_from_slice(&body);
    out.extend_from_slice(&crc32(&body).to_be_bytes());
    out
}

/// A 77-byte PNG whose header claims `width` x `height` RGBA8 texels, with an empty image
/// stream (no pixels).
fn png_header_only(width: u32, height: u32) -> Vec<u8> {
    let mut ihdr = width.to_be_bytes().to_vec();
    ihdr.extend_from_slice(&height.to_be_bytes());
    ihdr.extend_from_slice(&[8, 6, 0, 0, 0]);
    let mut png = b"\x89PNG\r\n\x1a\n".to_vec();
    png.extend(chunk(b"IHDR", &ihdr));
    png.extend(chunk(
        b"IDAT",
        &[0x78, 0x9c, 0x03, 0x00, 0x00, 0x00, 0x00, 0x01],
    ));
    png.extend(chunk(b"IEND", &[]));
    png
}

fn limited(edit: impl FnOnce(&mut Limits)) -> Limits {
    let mut limits = Limits::DEFAULT;
    edit(&mut limits);
    limits
}

#[test]
fn an_image_whose_header_is_too_large_is_refused_before_decoding() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("huge.png");
    std::fs::write(&path, png_header_only(100_000, 100_000)).unwrap();
    let error = TextureCache::new()
        .load(&path, ColorSpace::Srgb)
        .unwrap_err();
    assert!(
        matches!(error, AssetError::LimitExceeded { limit: 16384, .. }),
        "{error}"
    );
    let message = error.to_string();
    assert!(
        message.contains("huge.png") && message.contains("100000x100000"),
        "{message}"
    );
    // Without limits: an error, not an abort (the 40 GB the decoder would allocate are refused
    // where the process cannot allocate them, else the decoder fails on the missing pixels).
    let error = TextureCache::with_limits(Limits::NONE)
        .load(&path, ColorSpace::Srgb)
        .unwrap_err();
    assert!(error.to_string().contains("huge.png"), "{error}");
}

#[test]
fn an_obj_with_too_many_vertices_is_refused_before_parsing() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("many.obj");
    let mut obj = String::new();
    for i in 0..1000 {
        obj.push_str(&format!("v {i} 0 0\nv {i} 1 0\nv {i} 0 1\n"));
    }
    obj.push_str("f 1 2 3\n");
    std::fs::write(&path, obj).unwrap();
    let mut cache = TextureCache::with_limits(limited(|l| l.max_vertices = 2999));
    let error = assets::load_obj(&path, &mut cache).unwrap_err();
    assert!(
        matches!(
            error,
            AssetError::LimitExceeded {
                value: 3000,
                limit: 2999,
                ..
            }
        ),
        "{error}"
    );
    assert!(error.to_string().contains("many.obj"), "{error}");
    let mut cache = TextureCache::with_limits(limited(|l| l.max_vertices = 3000));
    assets::load_obj(&path, &mut cache).unwrap();
}

#[test]
fn a_scene_past_the_byte_limit_is_refused_naming_the_file() {
    let chess = harness::scenes_dir().join("chess.toml");
    let error =
        engine::scene_file::load_with_limits(&chess, limited(|l| l.max_total_bytes = 1 << 20))
            .err()
            .expect("chess's assets take more than 1 MiB")
            .to_string();
    eprintln!("{error}");
    assert!(
        error.contains("total decoded bytes")
            && error.contains("chess.toml")
            && error.contains("scenes/assets/"),
        "the scene and the asset file are named: {error}"
    );
}

/// Limits only refuse: with them off, chess loads to the same scene and renders bit for bit the
/// same as with the defaults.
#[test]
fn with_limits_off_rendering_is_unchanged() {
    // chess's sunset maps come from the IBL caches: the precompute is not under test here.
    harness::use_ibl_cache();
    let chess = harness::scenes_dir().join("chess.toml");
    let default = engine::scene_file::load(&chess).unwrap();
    let none = engine::scene_file::load_with_limits(&chess, Limits::NONE).unwrap();
    assert_eq!(default.textures_decoded, none.textures_decoded);
    let Some(&kind) = common::available_backends().first() else {
        return;
    };
    let mut backend = engine::backend::create(kind).unwrap();
    let render = |backend: &mut dyn engine::Backend, scene| {
        renderer::render(
            backend,
            scene,
            Readback::Only(&[TargetId::Final, TargetId::Light]),
        )
        .unwrap()
    };
    let a = render(backend.as_mut(), &default.scene);
    let b = render(backend.as_mut(), &none.scene);
    for name in [TargetId::Final, TargetId::Light] {
        assert!(
            a.outputs[&name] == b.outputs[&name],
            "{kind}: `{name}` differs with limits off"
        );
    }
}

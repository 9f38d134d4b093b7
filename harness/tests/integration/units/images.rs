//! Tests of `harness::images`.

use engine::backend::TextureFormat;
use engine::{Image, ImageData};
use harness::images::*;
use std::path::Path;

#[test]
fn exr_round_trips_fp16_values_and_depth_exactly() {
    let dir = std::env::temp_dir().join(format!("harness-images-{}", std::process::id()));
    let rgba = Image {
        width: 3,
        height: 2,
        format: TextureFormat::Rgba16Float,
        data: ImageData::F32(
            (0..24)
                .map(|i| half::f16::from_f32(i as f32 * 0.37 - 2.0).to_f32())
                .collect(),
        ),
    };
    let path = dir.join("rgba.exr");
    write_image(&rgba, &path, FileCompression::Fast).unwrap();
    let back = read_exr(&path).unwrap();
    assert_eq!(back.data, rgba.data);
    let depth = Image {
        width: 2,
        height: 2,
        format: TextureFormat::Depth32Float,
        data: ImageData::F32(vec![0.1234567, 1.0, 0.5, 0.999_999_9]),
    };
    let path = dir.join("depth.exr");
    write_image(&depth, &path, FileCompression::Fast).unwrap();
    assert_eq!(read_exr(&path).unwrap().data, depth.data);
    let _ = std::fs::remove_dir_all(&dir);
}

/// Many blocks compressed in parallel still give the same bytes every time (a golden
/// blessed twice from one render is one file).
#[test]
fn exr_bytes_are_the_same_on_every_encode() {
    let (width, height) = (64, 512);
    let image = Image {
        width,
        height,
        format: TextureFormat::Rgba16Float,
        data: ImageData::F32(
            (0..width * height * 4)
                .map(|i| ((i * 7919) % 1000) as f32 / 100.0)
                .collect(),
        ),
    };
    let path = Path::new("same.exr");
    let first = encode_exr(&image, path, FileCompression::Balanced).unwrap();
    for _ in 0..8 {
        assert!(encode_exr(&image, path, FileCompression::Balanced).unwrap() == first);
    }
}

#[test]
fn png_round_trips() {
    let dir = std::env::temp_dir().join(format!("harness-png-{}", std::process::id()));
    let image = Image {
        width: 2,
        height: 1,
        format: TextureFormat::Rgba8UnormSrgb,
        data: ImageData::U8(vec![1, 2, 3, 255, 250, 128, 0, 255]),
    };
    let path = dir.join("a.png");
    write_image(&image, &path, FileCompression::Fast).unwrap();
    assert_eq!(read_png(&path).unwrap().data, image.data);
    let _ = std::fs::remove_dir_all(&dir);
}

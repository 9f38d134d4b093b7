//! Tests of `harness::golden::check`.

use engine::backend::BackendKind;
use engine::backend::TextureFormat;
use engine::image::ImageData;
use engine::plan::TargetId;
use engine::Image;
use harness::golden::check::*;
use std::cell::Cell;

/// A 4x4 8-bit image whose first `changed` pixels are 10/255 brighter.
fn image(changed: usize) -> Image {
    let mut data = vec![100u8; 4 * 4 * 4];
    for pixel in data.chunks_exact_mut(4).take(changed) {
        pixel[0] += 10;
    }
    Image {
        width: 4,
        height: 4,
        format: TextureFormat::Rgba8UnormSrgb,
        data: ImageData::U8(data),
    }
}

#[test]
fn the_worst_pair_is_reported_and_only_its_tolerance_is_evaluated() {
    let (gl, vulkan, wgpu_gl) = (image(0), image(1), image(4));
    let outputs = [
        (BackendKind::Gl, &gl),
        (BackendKind::WgpuVulkan, &vulkan),
        (BackendKind::WgpuGl, &wgpu_gl),
    ];
    let evaluated = Cell::new(0);
    let worst = worst_pair("s", TargetId::Final, &outputs, |a, b| {
        evaluated.set(evaluated.get() + 1);
        a == &gl && b == &wgpu_gl
    })
    .unwrap();
    assert_eq!((worst.a, worst.b), (BackendKind::Gl, BackendKind::WgpuGl));
    assert_eq!(worst.fraction_over, 4.0 / 16.0);
    assert!(
        (worst.max_abs - 10.0 / 255.0).abs() < 1e-6,
        "{}",
        worst.max_abs
    );
    assert!(worst.within_tolerance);
    assert_eq!(evaluated.get(), 1, "the rule ran for a pair not reported");
}

#[test]
fn a_tie_in_fraction_goes_to_the_larger_difference() {
    let mut brighter = image(1);
    if let ImageData::U8(data) = &mut brighter.data {
        data[0] += 20;
    }
    let (gl, vulkan) = (image(0), image(1));
    let outputs = [
        (BackendKind::Gl, &gl),
        (BackendKind::WgpuVulkan, &vulkan),
        (BackendKind::WgpuGl, &brighter),
    ];
    let worst = worst_pair("s", TargetId::Final, &outputs, |_, _| false).unwrap();
    assert_eq!((worst.a, worst.b), (BackendKind::Gl, BackendKind::WgpuGl));
    assert!(!worst.within_tolerance);
}

/// A driver other than the blessing one is information on another software rasterizer, and a
/// warning that the noise model does not reach it on a GPU.
#[test]
fn the_driver_note_warns_when_goldens_of_a_software_rasterizer_meet_a_gpu() {
    let llvmpipe = "OpenGL 4.5 (Core Profile) Mesa 22.3.6 | llvmpipe (LLVM 15.0.6, 256 bits)";
    let mesa_25 = "OpenGL 4.5 (Core Profile) Mesa 25.0.7 | llvmpipe (LLVM 15.0.6, 256 bits)";
    let nvidia = "OpenGL 4.6.0 NVIDIA 580.159.04 | NVIDIA H200/PCIe/SSE2";
    assert!(is_software_rasterizer(llvmpipe) && !is_software_rasterizer(nvidia));
    let scenes = ["arrow".to_owned(), "ibl".to_owned()];
    let other_mesa = driver_note(&scenes, BackendKind::Gl, llvmpipe, mesa_25);
    assert!(
        other_mesa.starts_with("goldens of arrow, ibl were blessed on gl with")
            && other_mesa.ends_with("are expected, and are not failures"),
        "{other_mesa}"
    );
    let gpu = driver_note(&scenes, BackendKind::Gl, llvmpipe, nvidia);
    assert!(
        gpu.contains("which is not one") && gpu.contains("docs/2026-11-26-nvidia-gpu.md"),
        "{gpu}"
    );
    // Goldens blessed on a GPU and checked on llvmpipe: the plain note.
    let back = driver_note(&scenes, BackendKind::Gl, nvidia, llvmpipe);
    assert!(back.ends_with("are not failures"), "{back}");
}

//! Tests of `harness::faults`.

use engine::backend::BackendKind;
use engine::{Image, ImageData};
use harness::faults::*;

#[test]
fn an_injected_fault_names_a_backend_and_a_known_fault() {
    assert_eq!(
        "wgpu-vulkan:perturb-output".parse(),
        Ok(InjectedFault::PerturbOutput(BackendKind::WgpuVulkan))
    );
    for bad in ["wgpu-vulkan", "vulkan:perturb-output", "gl:explode"] {
        let error = bad.parse::<InjectedFault>().unwrap_err();
        assert!(
            error.contains(INJECT_FAULT) && error.contains(bad),
            "{error}"
        );
    }
}

#[test]
fn a_perturbed_output_moves_its_first_channel_only() {
    let mut image = Image {
        width: 2,
        height: 1,
        format: engine::backend::TextureFormat::Rgba8Unorm,
        data: ImageData::U8(vec![10, 20, 30, 255, 250, 0, 0, 255]),
    };
    perturb(&mut image);
    assert_eq!(
        image.data,
        ImageData::U8(vec![34, 20, 30, 255, 255, 0, 0, 255])
    );
}

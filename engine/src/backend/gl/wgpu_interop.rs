//! The one place the `wgpu-gl` backend reaches into wgpu's own GL context, kept here with the
//! rest of the GL calls so that `unsafe` stays in this folder.
//!
//! WebGPU filters cube maps across face edges (as Vulkan and GLES 3 always do), but wgpu-hal 30
//! leaves `GL_TEXTURE_CUBE_MAP_SEAMLESS` off on a desktop GL context. The IBL maps' small rough
//! mips (4 x 4 faces) then show seams on `wgpu-gl` that `gl` and `wgpu-vulkan` do not have.

use glow_wgpu::HasContext as _;

/// Turns on seamless cube-map filtering in the GL context behind a `wgpu` device. Returns
/// whether it is now on (false for non-GL devices; GLES contexts are seamless already and
/// refuse the enum, which is also reported as false).
pub fn enable_seamless_cube_maps(device: &wgpu::Device) -> bool {
    // SAFETY: `as_hal` hands out wgpu-hal's GL device; it is used only to lock wgpu's context
    // (which makes it current on this thread for the lock's lifetime) and set one piece of
    // global sampling state that wgpu-hal never reads or changes. No wgpu resource is touched
    // and nothing outlives the lock.
    unsafe {
        let Some(hal) = device.as_hal::<wgpu::hal::api::Gles>() else {
            return false;
        };
        let gl = hal.context().lock();
        gl.enable(glow_wgpu::TEXTURE_CUBE_MAP_SEAMLESS);
        gl.get_error() == glow_wgpu::NO_ERROR
    }
}

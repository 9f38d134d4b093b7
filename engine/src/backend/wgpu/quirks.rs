//! What opening wgpu takes on drivers other than Mesa's (found on NVIDIA's, 2026-11-26): no
//! indirect-call validation, a check of the GL context's version before the shaders meet it,
//! and a failed `wgpu-gl` that leaves the EGL display it may share with `gl` alone.

use ::wgpu;

use crate::backend::BackendKind;

/// wgpu's default instance flags without `VALIDATION_INDIRECT_CALL`. That validation builds
/// compute pipelines when a device opens, to check the arguments of indirect draws; the engine
/// issues none, and a context without compute shaders cannot build them, so the device fails to
/// open (wgpu's GL backend on NVIDIA's EGL: "Parent device is lost").
pub(super) fn instance_flags() -> wgpu::InstanceFlags {
    wgpu::InstanceFlags::default().difference(wgpu::InstanceFlags::VALIDATION_INDIRECT_CALL)
}

/// The oldest desktop OpenGL whose GLSL compiles the engine's shaders as naga writes them
/// (`reverseBits` is GLSL 4.00's bitfieldReverse, `textureNumLevels` 4.30's textureQueryLevels).
pub(super) const MIN_DESKTOP_GL: (u32, u32) = (4, 3);

/// The desktop OpenGL version at the start of wgpu's GL driver string ("3.3.0 NVIDIA
/// 580.159.04", "4.5 (Core Profile) Mesa 22.3.6") when it is older than [`MIN_DESKTOP_GL`];
/// `None` for a new enough one, an OpenGL ES context or a string that names no version.
pub(super) fn too_old_for_the_shaders(driver_info: &str) -> Option<String> {
    if driver_info.contains("OpenGL ES") {
        return None;
    }
    let version = driver_info.split_whitespace().next()?;
    let mut parts = version.split('.').map(str::parse::<u32>);
    let (Some(Ok(major)), Some(Ok(minor))) = (parts.next(), parts.next()) else {
        return None;
    };
    ((major, minor) < MIN_DESKTOP_GL).then(|| format!("{major}.{minor}"))
}

/// On a `wgpu-gl` that could not open, keeps its instance (and adapter) alive to the end of
/// the process instead of dropping them: dropping terminates their EGL display, and where the
/// driver gives one display per device (NVIDIA's, without Mesa's surfaceless platform) that is
/// the `gl` backend's display too, whose context then fails ("EGL is not initialized").
pub(super) fn keep_gl_display(
    kind: BackendKind,
    instance: &wgpu::Instance,
    adapter: Option<&wgpu::Adapter>,
) {
    if kind == BackendKind::WgpuGl {
        std::mem::forget(instance.clone());
        if let Some(adapter) = adapter {
            std::mem::forget(adapter.clone());
        }
    }
}

#[cfg(test)]
mod tests {
    use super::too_old_for_the_shaders;

    #[test]
    fn a_gl_context_older_than_4_3_is_named_and_newer_ones_pass() {
        assert_eq!(
            too_old_for_the_shaders("3.3.0 NVIDIA 580.159.04").as_deref(),
            Some("3.3")
        );
        assert_eq!(
            too_old_for_the_shaders("4.5 (Core Profile) Mesa 22.3.6"),
            None
        );
        assert_eq!(too_old_for_the_shaders("4.3.0 NVIDIA"), None);
        assert_eq!(too_old_for_the_shaders("OpenGL ES 3.2 Mesa 22.3.6"), None);
        assert_eq!(too_old_for_the_shaders("no version here"), None);
        assert_eq!(too_old_for_the_shaders(""), None);
    }
}

//! A headless OpenGL core context: EGL on Mesa's surfaceless platform, libEGL loaded at run time
//! (so building needs no -dev packages). Asks for 4.6 core, accepts 4.5 core, refuses older.

use std::sync::OnceLock;

use khronos_egl as egl;

use crate::backend::{BackendError, BackendKind};

/// `EGL_PLATFORM_SURFACELESS_MESA` (EGL_MESA_platform_surfaceless).
const PLATFORM_SURFACELESS_MESA: egl::Enum = 0x31DD;
/// `EGL_PLATFORM_DEVICE_EXT` (EGL_EXT_platform_device).
const PLATFORM_DEVICE_EXT: egl::Enum = 0x313F;
/// `eglQueryDevicesEXT` (EGL_EXT_device_enumeration), which khronos-egl does not wrap.
type QueryDevicesFn = unsafe extern "system" fn(
    max_devices: egl::Int,
    devices: *mut *mut std::ffi::c_void,
    num_devices: *mut egl::Int,
) -> egl::Boolean;
const FIX: &str =
    "install Mesa's EGL and llvmpipe: apt-get install -y libegl1 libegl-mesa0 libgl1-mesa-dri";

type Egl = egl::DynamicInstance<egl::EGL1_5>;

/// libEGL, loaded once per process and never unloaded: unloading a driver while other threads
/// hold contexts is not safe, and reloading it per backend would be slow.
fn egl_library() -> Result<&'static Egl, String> {
    static EGL: OnceLock<Result<Egl, String>> = OnceLock::new();
    EGL.get_or_init(|| {
        // SAFETY: loads the system libEGL (libEGL.so.1) and resolves the EGL 1.5 entry points;
        // khronos-egl checks every required symbol is present before returning it.
        unsafe { Egl::load_required() }
            .map_err(|e| format!("cannot load libEGL.so.1 with EGL 1.5: {e}"))
    })
    .as_ref()
    .map_err(Clone::clone)
}

fn unavailable(reason: String) -> BackendError {
    BackendError::Unavailable {
        backend: BackendKind::Gl.name(),
        reason,
        fix: crate::backend::unavailable_fix(BackendKind::Gl, FIX),
    }
}

/// An EGL display and OpenGL core context with no surface.
pub(super) struct EglContext {
    egl: &'static Egl,
    display: egl::Display,
    context: egl::Context,
}

/// `glClipControl`, which glow does not wrap.
pub(super) type ClipControlFn = extern "system" fn(origin: u32, depth: u32);

impl EglContext {
    /// Creates the context and makes it current on this thread.
    pub(super) fn new(debug: bool) -> Result<Self, BackendError> {
        let egl = egl_library().map_err(unavailable)?;
        // Our own display: the first EGL device (Mesa's software device on a CPU-only machine).
        // The surfaceless display is process-wide and shared with wgpu's GL backend, which calls
        // eglTerminate on it when its last instance drops, destroying our contexts with it.
        let display = match device_display(egl) {
            Some(display) => display,
            None => {
                // SAFETY: EGL_DEFAULT_DISPLAY with an empty attribute list is valid for the
                // surfaceless platform; failure returns an error, not an invalid display.
                unsafe {
                    egl.get_platform_display(
                        PLATFORM_SURFACELESS_MESA,
                        egl::DEFAULT_DISPLAY,
                        &[egl::ATTRIB_NONE],
                    )
                }
                .or_else(|_| {
                    // SAFETY: as above, for the implementation's default display (non-Mesa EGL).
                    unsafe { egl.get_display(egl::DEFAULT_DISPLAY) }.ok_or(egl::Error::BadDisplay)
                })
                .map_err(|e| {
                    unavailable(format!(
                        "no EGL display (device, surfaceless or default): {e}"
                    ))
                })?
            }
        };
        egl.initialize(display)
            .map_err(|e| unavailable(format!("eglInitialize failed: {e}")))?;
        egl.bind_api(egl::OPENGL_API)
            .map_err(|e| unavailable(format!("EGL has no desktop OpenGL API: {e}")))?;
        let extensions = egl
            .query_string(Some(display), egl::EXTENSIONS)
            .map(|e| e.to_string_lossy().into_owned())
            .unwrap_or_default();
        let config = if extensions
            .split(' ')
            .any(|e| e == "EGL_KHR_no_config_context")
        {
            // SAFETY: EGL_NO_CONFIG_KHR is the null config, valid for eglCreateContext when the
            // display has EGL_KHR_no_config_context (checked above); there is no surface.
            unsafe { egl::Config::from_ptr(std::ptr::null_mut()) }
        } else {
            egl.choose_first_config(display, &[egl::RENDERABLE_TYPE, egl::OPENGL_BIT, egl::NONE])
                .map_err(|e| unavailable(format!("eglChooseConfig failed: {e}")))?
                .ok_or_else(|| {
                    unavailable(
                        "EGL has neither EGL_KHR_no_config_context nor an OpenGL config".to_owned(),
                    )
                })?
        };
        let mut failures = Vec::new();
        for (major, minor) in [(4, 6), (4, 5)] {
            let mut attributes = vec![
                egl::CONTEXT_MAJOR_VERSION,
                major,
                egl::CONTEXT_MINOR_VERSION,
                minor,
                egl::CONTEXT_OPENGL_PROFILE_MASK,
                egl::CONTEXT_OPENGL_CORE_PROFILE_BIT,
            ];
            if debug {
                attributes.extend([egl::CONTEXT_OPENGL_DEBUG, egl::TRUE as egl::Int]);
            }
            attributes.push(egl::NONE);
            match egl.create_context(display, config, None, &attributes) {
                Ok(context) => {
                    let this = Self {
                        egl,
                        display,
                        context,
                    };
                    this.make_current()?;
                    return Ok(this);
                }
                Err(e) => failures.push(format!("{major}.{minor} core: {e}")),
            }
        }
        Err(unavailable(format!(
            "the driver offers no OpenGL 4.5+ core context ({}); llvmpipe from Mesa 20+ does",
            failures.join("; ")
        )))
    }

    /// Makes this context current on the calling thread if it is not already.
    pub(super) fn make_current(&self) -> Result<(), BackendError> {
        if self.egl.get_current_context() == Some(self.context) {
            return Ok(());
        }
        self.egl
            .make_current(self.display, None, None, Some(self.context))
            .map_err(|e| BackendError::Driver {
                backend: BackendKind::Gl.name(),
                context: "eglMakeCurrent".to_owned(),
                message: e.to_string(),
            })
    }

    /// A glow context over this EGL context's function pointers.
    pub(super) fn load_gl(&self) -> glow::Context {
        // SAFETY: the context is current on this thread (made so in `new`), and every pointer
        // comes from eglGetProcAddress for that context's API.
        unsafe {
            glow::Context::from_loader_function(|name| {
                self.egl
                    .get_proc_address(name)
                    .map_or(std::ptr::null(), |f| f as *const std::ffi::c_void)
            })
        }
    }

    /// `glClipControl` (core since 4.5), which glow does not wrap.
    pub(super) fn clip_control(&self) -> Option<ClipControlFn> {
        self.egl.get_proc_address("glClipControl").map(|f| {
            // SAFETY: glClipControl's C signature is `void (GLenum origin, GLenum depth)`, which
            // is `ClipControlFn`; the pointer came from EGL for the current GL context.
            unsafe { std::mem::transmute::<extern "system" fn(), ClipControlFn>(f) }
        })
    }
}

/// The EGL_EXT_platform_device display of the first enumerated device, if the extensions exist.
fn device_display(egl: &Egl) -> Option<egl::Display> {
    let client_extensions = egl
        .query_string(None, egl::EXTENSIONS)
        .ok()?
        .to_string_lossy()
        .into_owned();
    let has = |name: &str| client_extensions.split(' ').any(|e| e == name);
    if !has("EGL_EXT_platform_device") || !has("EGL_EXT_device_enumeration") {
        return None;
    }
    let query = egl.get_proc_address("eglQueryDevicesEXT")?;
    // SAFETY: eglQueryDevicesEXT's C signature is `EGLBoolean (EGLint, EGLDeviceEXT *, EGLint *)`,
    // which is `QueryDevicesFn`; the pointer came from EGL and the extension is advertised.
    let query = unsafe { std::mem::transmute::<extern "system" fn(), QueryDevicesFn>(query) };
    let mut devices = [std::ptr::null_mut(); 16];
    let mut count: egl::Int = 0;
    // SAFETY: `devices` has room for the 16 entries passed as the maximum; `count` is written.
    let ok = unsafe { query(devices.len() as egl::Int, devices.as_mut_ptr(), &mut count) };
    if ok != egl::TRUE || count < 1 {
        return None;
    }
    // SAFETY: the device handle came from eglQueryDevicesEXT; no attributes are passed.
    unsafe { egl.get_platform_display(PLATFORM_DEVICE_EXT, devices[0], &[egl::ATTRIB_NONE]) }.ok()
}

impl Drop for EglContext {
    fn drop(&mut self) {
        // The display stays initialised: eglTerminate would break other threads' contexts.
        let _ = self.egl.make_current(self.display, None, None, None);
        let _ = self.egl.destroy_context(self.display, self.context);
    }
}

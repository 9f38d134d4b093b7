//! The backend trait: the one list of operations every GPU backend implements.
//!
//! A backend is chosen at run time by name ([`BackendKind`]) and used as `Box<dyn Backend>`.
//! Resources are created from descriptors ([`desc`]) and referred to by typed [`Handle`]s; a frame
//! is a list of [`RenderPass`]es submitted at once, and any color or depth target can be read
//! back into an [`Image`]. Backends live in mirrored folders: [`gl`] (OpenGL core via glow and
//! EGL) and [`wgpu`] (wgpu pinned to Vulkan or to GL), each with a `conv.rs` mapping descriptors
//! onto the API.

pub mod desc;
pub mod gl;
mod pool;
mod scope;
mod serialized;
pub mod wgpu;

use std::collections::BTreeMap;
use std::fmt;
use std::str::FromStr;

pub use desc::*;
pub use scope::ResourceScope;

use crate::image::Image;

/// Errors from backends. Each names the backend and, where it applies, the resource or pass.
#[derive(Debug, thiserror::Error)]
pub enum BackendError {
    /// The backend cannot run on this machine.
    #[error("backend `{backend}` is unavailable: {reason} (fix: {fix})")]
    Unavailable {
        /// Backend name.
        backend: &'static str,
        /// What is missing.
        reason: String,
        /// How to get it.
        fix: String,
    },
    /// A shader failed to parse, validate, translate, compile or link.
    #[error("shader `{name}` on `{backend}`: {message}")]
    Shader {
        /// Backend name.
        backend: &'static str,
        /// Shader file (and entry point).
        name: String,
        /// Compiler output.
        message: String,
    },
    /// A descriptor asks for something the backend or driver cannot do.
    #[error("`{backend}` cannot create {what}: {message}")]
    Unsupported {
        /// Backend name.
        backend: &'static str,
        /// The resource being created.
        what: String,
        /// Why.
        message: String,
    },
    /// A handle does not refer to a live resource of this backend.
    #[error("invalid {kind} handle {handle} (destroyed, or from another backend)")]
    InvalidHandle {
        /// Resource kind.
        kind: &'static str,
        /// The handle.
        handle: String,
    },
    /// Data passed in does not match the resource (size, range).
    #[error("{0}")]
    InvalidData(String),
    /// The driver reported an error while executing work.
    #[error("`{backend}` driver error in {context}: {message}")]
    Driver {
        /// Backend name.
        backend: &'static str,
        /// Pass or operation.
        context: String,
        /// Driver message.
        message: String,
    },
}

/// Shorthand for backend results.
pub type Result<T, E = BackendError> = std::result::Result<T, E>;

/// The backends this crate provides.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub enum BackendKind {
    /// OpenGL 4.6/4.5 core through glow, headless via EGL surfaceless.
    Gl,
    /// wgpu pinned to Vulkan.
    WgpuVulkan,
    /// wgpu pinned to its GL (GLES) backend.
    WgpuGl,
}

impl BackendKind {
    /// Every backend, in report order.
    pub const ALL: [BackendKind; 3] = [Self::Gl, Self::WgpuVulkan, Self::WgpuGl];

    /// The name used on the command line, in test names and in reports.
    pub fn name(self) -> &'static str {
        match self {
            Self::Gl => "gl",
            Self::WgpuVulkan => "wgpu-vulkan",
            Self::WgpuGl => "wgpu-gl",
        }
    }
}

/// In files and JSON a backend is its name (`gl`, `wgpu-vulkan`, `wgpu-gl`).
impl serde::Serialize for BackendKind {
    fn serialize<S: serde::Serializer>(&self, s: S) -> std::result::Result<S::Ok, S::Error> {
        s.serialize_str(self.name())
    }
}

impl<'de> serde::Deserialize<'de> for BackendKind {
    fn deserialize<D: serde::Deserializer<'de>>(d: D) -> std::result::Result<Self, D::Error> {
        let name = String::deserialize(d)?;
        name.parse().map_err(serde::de::Error::custom)
    }
}

impl fmt::Display for BackendKind {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.pad(self.name())
    }
}

/// Error for an unknown backend name.
#[derive(Debug, thiserror::Error)]
#[error("unknown backend `{0}` (known: gl, wgpu-vulkan, wgpu-gl)")]
pub struct UnknownBackend(pub String);

impl FromStr for BackendKind {
    type Err = UnknownBackend;
    fn from_str(s: &str) -> std::result::Result<Self, Self::Err> {
        Self::ALL
            .into_iter()
            .find(|k| k.name() == s)
            .ok_or_else(|| UnknownBackend(s.to_owned()))
    }
}

/// A driver fingerprint: what produced an image. Recorded with goldens and reports.
#[derive(Clone, Debug, PartialEq, serde::Serialize)]
pub struct DriverInfo {
    /// Backend (its name in JSON: `gl`, `wgpu-vulkan`, `wgpu-gl`).
    pub backend: BackendKind,
    /// Graphics API (`OpenGL`, `Vulkan`, `OpenGL ES`).
    pub api: String,
    /// API version reported by the driver (e.g. `4.5 (Core Profile) Mesa 22.3.6`).
    pub api_version: String,
    /// Renderer / adapter name (e.g. `llvmpipe (LLVM 15.0.6, 256 bits)`).
    pub renderer: String,
    /// Vendor string.
    pub vendor: String,
    /// Driver name and info, where the API reports them.
    pub driver: String,
    /// Mesa version, if the driver is Mesa.
    pub mesa_version: Option<String>,
    /// LLVM version, if the driver is LLVM-based (llvmpipe, lavapipe).
    pub llvm_version: Option<String>,
    /// Whether per-pass GPU timestamps are available.
    pub timestamps: bool,
    /// Environment variables that change what the driver renders or how fast.
    pub env: BTreeMap<String, String>,
}

impl DriverInfo {
    /// `backend`'s fingerprint with nothing known yet (every string empty, no timestamps).
    pub fn new(backend: BackendKind) -> Self {
        Self {
            backend,
            api: String::new(),
            api_version: String::new(),
            renderer: String::new(),
            vendor: String::new(),
            driver: String::new(),
            mesa_version: None,
            llvm_version: None,
            timestamps: false,
            env: BTreeMap::new(),
        }
    }

    /// Fills `mesa_version`, `llvm_version` and `env` from the strings already set.
    pub(crate) fn complete(mut self) -> Self {
        let all = format!("{} {} {}", self.api_version, self.renderer, self.driver);
        self.mesa_version = version_after(&all, "Mesa ");
        self.llvm_version = version_after(&all, "LLVM ");
        self.env = result_env(self.backend);
        self
    }
}

/// The first version number after `marker` in `text` (`"Mesa 22.3.6"` -> `22.3.6`).
fn version_after(text: &str, marker: &str) -> Option<String> {
    let start = text.find(marker)? + marker.len();
    let version: String = text[start..]
        .chars()
        .take_while(|c| c.is_ascii_digit() || *c == '.')
        .collect();
    (!version.is_empty()).then_some(version)
}

/// Environment variables known to change software drivers' results or speed.
const RESULT_ENV_PREFIXES: &[&str] = &[
    "LP_",
    "GALLIUM_",
    "MESA_",
    "LIBGL_",
    "LVP_",
    "VK_ICD_FILENAMES",
    "VK_DRIVER_FILES",
    "VK_LOADER_",
    "__EGL_VENDOR_LIBRARY",
    "EGL_PLATFORM",
    "WGPU_",
];

/// Of [`RESULT_ENV_PREFIXES`], those that reach only the other kind of backend: the Vulkan
/// loader's and lavapipe's for the GL backends, EGL's and the GL drivers' for Vulkan, wgpu's
/// for `gl` (which does not use it). A variable set for one backend is no change of another's
/// driver (a `gl` fingerprint that named VK_DRIVER_FILES read as a driver change).
fn reaches_only_others(kind: BackendKind, name: &str) -> bool {
    const VULKAN_ONLY: [&str; 3] = ["VK_", "LVP_", "MESA_VK_"];
    const GL_ONLY: [&str; 5] = [
        "LIBGL_",
        "__EGL_VENDOR_LIBRARY",
        "EGL_PLATFORM",
        "MESA_GL",
        "MESA_LOADER_DRIVER_OVERRIDE",
    ];
    let others: &[&str] = match kind {
        BackendKind::Gl | BackendKind::WgpuGl => &VULKAN_ONLY,
        BackendKind::WgpuVulkan => &GL_ONLY,
    };
    others.iter().any(|p| name.starts_with(p))
        || (kind == BackendKind::Gl && name.starts_with("WGPU_"))
}

fn result_env(kind: BackendKind) -> BTreeMap<String, String> {
    std::env::vars()
        .filter(|(k, _)| RESULT_ENV_PREFIXES.iter().any(|p| k.starts_with(p)))
        .filter(|(k, _)| !reaches_only_others(kind, k))
        .collect()
}

/// The operations every backend implements. Object safe: use as `Box<dyn Backend>`.
///
/// Uploads (`write_*`) take effect before the next [`submit`](Backend::submit). Rendering is
/// deterministic: the same calls on the same driver give the same bytes.
pub trait Backend {
    /// Which backend this is.
    fn kind(&self) -> BackendKind;
    /// The driver fingerprint.
    fn info(&self) -> &DriverInfo;
    /// Optional capabilities.
    fn features(&self) -> Features;

    /// Creates a texture (contents undefined until written or rendered).
    fn create_texture(&mut self, desc: &TextureDesc) -> Result<Handle<Texture>>;
    /// Uploads one mip of one layer: tightly packed texels, top row first.
    fn write_texture(
        &mut self,
        texture: Handle<Texture>,
        at: Subresource,
        data: &[u8],
    ) -> Result<()>;
    /// Destroys a texture.
    fn destroy_texture(&mut self, texture: Handle<Texture>) -> Result<()>;

    /// Creates a zero-filled buffer.
    fn create_buffer(&mut self, desc: &BufferDesc) -> Result<Handle<Buffer>>;
    /// Writes bytes at `offset` (multiple of 4).
    fn write_buffer(&mut self, buffer: Handle<Buffer>, offset: u64, data: &[u8]) -> Result<()>;
    /// Destroys a buffer.
    fn destroy_buffer(&mut self, buffer: Handle<Buffer>) -> Result<()>;

    /// Creates a sampler.
    fn create_sampler(&mut self, desc: &SamplerDesc) -> Result<Handle<Sampler>>;
    /// Destroys a sampler.
    fn destroy_sampler(&mut self, sampler: Handle<Sampler>) -> Result<()>;

    /// Parses and validates a WGSL module.
    fn create_shader(&mut self, desc: &ShaderDesc) -> Result<Handle<Shader>>;
    /// Destroys a shader module (pipelines made from it stay valid).
    fn destroy_shader(&mut self, shader: Handle<Shader>) -> Result<()>;

    /// Creates a render pipeline.
    fn create_pipeline(&mut self, desc: &PipelineDesc) -> Result<Handle<Pipeline>>;
    /// Destroys a pipeline.
    fn destroy_pipeline(&mut self, pipeline: Handle<Pipeline>) -> Result<()>;

    /// Executes the passes in order, waits for them, and returns each pass's GPU time.
    fn submit(&mut self, passes: &[RenderPass]) -> Result<Vec<PassTiming>>;

    /// Reads one mip/layer of a color or depth texture back: tightly packed, top row first.
    fn read_texture(&mut self, texture: Handle<Texture>, at: Subresource) -> Result<Image>;

    /// Number of live resources of all kinds (for leak checks).
    fn live_resources(&self) -> usize;

    /// Pipelines compiled so far: a pipeline asked for again with the same shader and
    /// descriptor (constants included) comes from the backend's cache and is not counted.
    fn pipelines_compiled(&self) -> u64;
}

impl<'a> dyn Backend + 'a {
    /// Creates a buffer and fills it.
    pub fn create_buffer_with_data(
        &mut self,
        label: &str,
        usage: BufferUsage,
        data: &[u8],
    ) -> Result<Handle<Buffer>> {
        let size = (data.len() as u64).next_multiple_of(4).max(4);
        let buffer = self.create_buffer(&BufferDesc {
            label: label.to_owned(),
            size,
            usage,
        })?;
        let mut padded = data.to_vec();
        padded.resize(size as usize, 0);
        self.write_buffer(buffer, 0, &padded)?;
        Ok(buffer)
    }
}

/// Creates a backend by kind, or says why it cannot run here. The GL backends (`gl`,
/// `wgpu-gl`) come wrapped so that one thread at a time drives Mesa's GL driver in this
/// process (see `backend/serialized.rs`: Mesa 22.3's llvmpipe crashes otherwise).
pub fn create(kind: BackendKind) -> Result<Box<dyn Backend>> {
    match kind {
        BackendKind::Gl => serialized::Serialized::create(|| Ok(Box::new(gl::GlBackend::new()?))),
        BackendKind::WgpuGl => {
            serialized::Serialized::create(|| Ok(Box::new(wgpu::WgpuBackend::new(kind)?)))
        }
        BackendKind::WgpuVulkan => Ok(Box::new(wgpu::WgpuBackend::new(kind)?)),
    }
}

/// Whether a backend can run here, and its fingerprint if so.
#[derive(Clone, Debug, serde::Serialize)]
pub struct BackendStatus {
    /// Backend name.
    pub name: &'static str,
    /// Whether it could be created.
    pub available: bool,
    /// Why not, when unavailable.
    pub reason: Option<String>,
    /// What to install or set, when unavailable.
    pub fix: Option<String>,
    /// Driver fingerprint, when available.
    pub info: Option<DriverInfo>,
}

/// Tries to create a backend and reports the outcome.
pub fn probe(kind: BackendKind) -> BackendStatus {
    match create(kind) {
        Ok(backend) => BackendStatus {
            name: kind.name(),
            available: true,
            reason: None,
            fix: None,
            info: Some(backend.info().clone()),
        },
        Err(BackendError::Unavailable { reason, fix, .. }) => BackendStatus {
            name: kind.name(),
            available: false,
            reason: Some(reason),
            fix: Some(fix),
            info: None,
        },
        Err(other) => BackendStatus {
            name: kind.name(),
            available: false,
            reason: Some(other.to_string()),
            fix: Some("report this: the driver was found but failed to initialise".to_owned()),
            info: None,
        },
    }
}

/// Checks a texture descriptor has a size and at least one mip.
pub(crate) fn check_texture_desc(desc: &TextureDesc) -> Result<()> {
    if desc.width == 0 || desc.height == 0 || desc.mip_levels == 0 {
        return Err(BackendError::InvalidData(format!(
            "texture `{}`: zero size or no mips",
            desc.label
        )));
    }
    Ok(())
}

/// Checks a buffer descriptor's size (positive, a multiple of 4).
pub(crate) fn check_buffer_desc(desc: &BufferDesc) -> Result<()> {
    if desc.size == 0 || !desc.size.is_multiple_of(4) {
        return Err(BackendError::InvalidData(format!(
            "buffer `{}`: size {} is not a positive multiple of 4",
            desc.label, desc.size
        )));
    }
    Ok(())
}

/// Checks that a write of `len` bytes at `offset` is 4-byte aligned and fits a buffer of `size`.
pub(crate) fn check_buffer_write(
    usage: BufferUsage,
    size: u64,
    offset: u64,
    len: usize,
) -> Result<()> {
    if !offset.is_multiple_of(4) || !len.is_multiple_of(4) || offset + len as u64 > size {
        return Err(BackendError::InvalidData(format!(
            "{usage:?} buffer write of {len} bytes at {offset} does not fit its {size} bytes (4-byte aligned)"
        )));
    }
    Ok(())
}

/// Checks that `at` names an existing mip level and layer of `desc`.
pub(crate) fn check_subresource(desc: &TextureDesc, at: Subresource) -> Result<()> {
    if at.mip >= desc.mip_levels || at.layer >= desc.kind.layers() {
        return Err(BackendError::InvalidData(format!(
            "texture `{}` has {} mips and {} layers; mip {} layer {} requested",
            desc.label,
            desc.mip_levels,
            desc.kind.layers(),
            at.mip,
            at.layer
        )));
    }
    Ok(())
}

/// Checks that `data` holds exactly one tightly packed image of `desc` at mip `at.mip`.
pub(crate) fn check_upload(desc: &TextureDesc, at: Subresource, data: &[u8]) -> Result<(u32, u32)> {
    check_subresource(desc, at)?;
    let (w, h) = desc.mip_size(at.mip);
    let expected = w as usize * h as usize * desc.format.texel_size();
    if data.len() != expected {
        return Err(BackendError::InvalidData(format!(
            "texture `{}` mip {}: {} bytes given, {}x{} {:?} needs {}",
            desc.label,
            at.mip,
            data.len(),
            w,
            h,
            desc.format,
            expected
        )));
    }
    Ok((w, h))
}

/// The environment variables that point a backend's driver loader elsewhere than the system's
/// drivers (the Vulkan loader's, glvnd's EGL vendor files, Mesa's DRI path).
fn driver_variables(kind: BackendKind) -> &'static [&'static str] {
    match kind {
        BackendKind::WgpuVulkan => &[
            "VK_DRIVER_FILES",
            "VK_ICD_FILENAMES",
            "VK_ADD_DRIVER_FILES",
            "VK_LOADER_DRIVERS_SELECT",
            "VK_LOADER_DRIVERS_DISABLE",
        ],
        BackendKind::Gl | BackendKind::WgpuGl => &[
            "LIBGL_DRIVERS_PATH",
            "__EGL_VENDOR_LIBRARY_FILENAMES",
            "__EGL_VENDOR_LIBRARY_DIRS",
            "EGL_PLATFORM",
            "MESA_LOADER_DRIVER_OVERRIDE",
        ],
    }
}

/// An unavailable backend's `fix`: where this process sets variables that point the driver
/// loader elsewhere, those first (a driver they lead away from is not found), then `install`.
pub(crate) fn unavailable_fix(kind: BackendKind, install: &str) -> String {
    let set: Vec<String> = driver_variables(kind)
        .iter()
        .filter_map(|name| {
            std::env::var(name)
                .ok()
                .map(|value| format!("{name}={value}"))
        })
        .collect();
    if set.is_empty() {
        install.to_owned()
    } else {
        format!(
            "check {} (set here, pointing the driver loader away from the system's drivers; \
             unset to use those), or {install}",
            set.join(" ")
        )
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn backend_names_round_trip() {
        for kind in BackendKind::ALL {
            assert_eq!(kind.name().parse::<BackendKind>().unwrap(), kind);
        }
        assert!("vulkan".parse::<BackendKind>().is_err());
    }

    #[test]
    fn versions_are_parsed_from_driver_strings() {
        let info = DriverInfo {
            api_version: "4.5 (Core Profile) Mesa 22.3.6".into(),
            renderer: "llvmpipe (LLVM 15.0.6, 256 bits)".into(),
            ..DriverInfo::new(BackendKind::Gl)
        }
        .complete();
        assert_eq!(info.mesa_version.as_deref(), Some("22.3.6"));
        assert_eq!(info.llvm_version.as_deref(), Some("15.0.6"));
    }

    /// A variable that points one kind of backend's loader elsewhere is in that kind's
    /// fingerprint only; Mesa's own (llvmpipe's, under both) are in every one.
    #[test]
    fn a_loader_variable_is_in_its_own_backends_fingerprint_only() {
        use BackendKind::{Gl, WgpuGl, WgpuVulkan};
        for (name, kinds) in [
            ("VK_DRIVER_FILES", &[WgpuVulkan][..]),
            ("LVP_POISON_MEMORY", &[WgpuVulkan]),
            ("__EGL_VENDOR_LIBRARY_FILENAMES", &[Gl, WgpuGl]),
            ("LIBGL_DRIVERS_PATH", &[Gl, WgpuGl]),
            ("WGPU_BACKEND", &[WgpuGl, WgpuVulkan]),
            ("MESA_VK_WSI_DEBUG", &[WgpuVulkan]),
            ("MESA_GL_VERSION_OVERRIDE", &[Gl, WgpuGl]),
            ("MESA_GLSL_CACHE_DISABLE", &[Gl, WgpuGl]),
            ("MESA_SHADER_CACHE_DISABLE", &[Gl, WgpuGl, WgpuVulkan]),
            ("LP_NUM_THREADS", &[Gl, WgpuGl, WgpuVulkan]),
            ("GALLIUM_OVERRIDE_CPU_CAPS", &[Gl, WgpuGl, WgpuVulkan]),
        ] {
            for kind in BackendKind::ALL {
                assert_eq!(
                    !reaches_only_others(kind, name),
                    kinds.contains(&kind),
                    "{name} on {kind}"
                );
            }
        }
    }
}

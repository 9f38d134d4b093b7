//! Faults injected into real runs, for the tests that prove what the harness does when a backend
//! misbehaves. [`FaultyBackend`] forwards to a real backend with faults on request: a shader that
//! does not compile, a device lost at submit, a failed readback, or outputs perturbed on that
//! backend alone. [`create_backend`] is how the harness makes every backend it renders with
//! (`check`, `bless` and so the verification's child checks, `render`, the self-test, the speed
//! probes, bench, sweeps and hard cases): a real one, unless the environment, which child
//! processes inherit, asks otherwise:
//! - `HARNESS_INJECT_FAULT=<backend>:perturb-output`: that backend's readbacks are perturbed
//!   (8-bit red +24, float red x1.1 + 0.01), so its every pass moves and the others do not;
//! - `HARNESS_NO_RENDER=1`: making a backend fails, for tests that prove a command renders
//!   nothing (the review server's accept).

use engine::backend::{
    Backend, BackendError, BackendKind, Buffer, BufferDesc, DriverInfo, Features, Handle,
    PassTiming, Pipeline, PipelineDesc, RenderPass, Result, Sampler, SamplerDesc, Shader,
    ShaderDesc, Subresource, Texture, TextureDesc,
};
use engine::{Image, ImageData};

/// The variable that injects a fault into one backend of a real run.
pub const INJECT_FAULT: &str = "HARNESS_INJECT_FAULT";
/// The variable that forbids rendering in a process and its children.
pub const NO_RENDER: &str = "HARNESS_NO_RENDER";

/// A backend that forwards to a real one, with faults injected on request.
pub struct FaultyBackend {
    inner: Box<dyn Backend>,
    /// This shader file is replaced by WGSL that does not compile.
    pub break_shader: Option<String>,
    /// Every submit fails as if the device were lost.
    pub lose_device: bool,
    /// Every readback fails.
    pub fail_readback: bool,
    /// Every readback is perturbed (see [`perturb`]).
    pub perturb_readback: bool,
}

impl FaultyBackend {
    /// Wraps `inner` with no fault on.
    pub fn new(inner: Box<dyn Backend>) -> Self {
        Self {
            inner,
            break_shader: None,
            lose_device: false,
            fail_readback: false,
            perturb_readback: false,
        }
    }

    fn injected(&self, context: &str, message: &str) -> BackendError {
        BackendError::Driver {
            backend: self.inner.kind().name(),
            context: context.to_owned(),
            message: format!("{message} (injected)"),
        }
    }
}

/// Perturbs an output the way `perturb-output` does: the first channel of every pixel moves by
/// far more than any limit allows (8-bit +24, saturating; float x1.1 + 0.01).
pub fn perturb(image: &mut Image) {
    let channels = image.channels();
    match &mut image.data {
        ImageData::U8(values) => {
            for v in values.iter_mut().step_by(channels) {
                *v = v.saturating_add(24);
            }
        }
        ImageData::F32(values) => {
            for v in values.iter_mut().step_by(channels) {
                *v = *v * 1.1 + 0.01;
            }
        }
    }
}

/// A fault `HARNESS_INJECT_FAULT` names, as `<backend>:<fault>`.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum InjectedFault {
    /// `perturb-output`: every readback of the backend perturbed.
    PerturbOutput(BackendKind),
}

impl std::str::FromStr for InjectedFault {
    type Err = String;

    fn from_str(text: &str) -> std::result::Result<Self, String> {
        let (backend, fault) = text
            .split_once(':')
            .ok_or_else(|| format!("{INJECT_FAULT}={text:?}: expected <backend>:perturb-output"))?;
        let backend: BackendKind = backend
            .parse()
            .map_err(|e| format!("{INJECT_FAULT}={text:?}: {e}"))?;
        match fault {
            "perturb-output" => Ok(InjectedFault::PerturbOutput(backend)),
            other => Err(format!(
                "{INJECT_FAULT}={text:?}: no fault `{other}` (known: perturb-output)"
            )),
        }
    }
}

/// The fault the environment injects, if any (an error when the variable does not parse).
pub fn injected_fault() -> std::result::Result<Option<InjectedFault>, String> {
    match std::env::var(INJECT_FAULT) {
        Ok(text) if !text.is_empty() => text.parse().map(Some),
        _ => Ok(None),
    }
}

/// A backend of `kind` for a run: the real one, perturbed when `HARNESS_INJECT_FAULT` names
/// it, refused when `HARNESS_NO_RENDER` is set.
pub fn create_backend(kind: BackendKind) -> Result<Box<dyn Backend>> {
    if std::env::var_os(NO_RENDER).is_some_and(|v| !v.is_empty()) {
        return Err(BackendError::Unavailable {
            backend: kind.name(),
            reason: format!("rendering is off in this process ({NO_RENDER} is set)"),
            fix: format!("unset {NO_RENDER}"),
        });
    }
    let fault = injected_fault().map_err(|message| BackendError::Unavailable {
        backend: kind.name(),
        reason: message,
        fix: format!("unset {INJECT_FAULT} or correct it"),
    })?;
    let real = engine::backend::create(kind)?;
    match fault {
        Some(InjectedFault::PerturbOutput(faulty)) if faulty == kind => {
            let mut backend = FaultyBackend::new(real);
            backend.perturb_readback = true;
            Ok(Box::new(backend))
        }
        _ => Ok(real),
    }
}

impl Backend for FaultyBackend {
    fn kind(&self) -> BackendKind {
        self.inner.kind()
    }
    fn info(&self) -> &DriverInfo {
        self.inner.info()
    }
    fn features(&self) -> Features {
        self.inner.features()
    }
    fn create_texture(&mut self, desc: &TextureDesc) -> Result<Handle<Texture>> {
        self.inner.create_texture(desc)
    }
    fn write_texture(&mut self, t: Handle<Texture>, at: Subresource, data: &[u8]) -> Result<()> {
        self.inner.write_texture(t, at, data)
    }
    fn destroy_texture(&mut self, t: Handle<Texture>) -> Result<()> {
        self.inner.destroy_texture(t)
    }
    fn create_buffer(&mut self, desc: &BufferDesc) -> Result<Handle<Buffer>> {
        self.inner.create_buffer(desc)
    }
    fn write_buffer(&mut self, b: Handle<Buffer>, offset: u64, data: &[u8]) -> Result<()> {
        self.inner.write_buffer(b, offset, data)
    }
    fn destroy_buffer(&mut self, b: Handle<Buffer>) -> Result<()> {
        self.inner.destroy_buffer(b)
    }
    fn create_sampler(&mut self, desc: &SamplerDesc) -> Result<Handle<Sampler>> {
        self.inner.create_sampler(desc)
    }
    fn destroy_sampler(&mut self, s: Handle<Sampler>) -> Result<()> {
        self.inner.destroy_sampler(s)
    }
    fn create_shader(&mut self, desc: &ShaderDesc) -> Result<Handle<Shader>> {
        if self.break_shader.as_deref() == Some(desc.name.as_str()) {
            let broken = ShaderDesc {
                name: desc.name.clone(),
                wgsl: format!("{}\nfn broken( {{", desc.wgsl),
            };
            return self.inner.create_shader(&broken);
        }
        self.inner.create_shader(desc)
    }
    fn destroy_shader(&mut self, s: Handle<Shader>) -> Result<()> {
        self.inner.destroy_shader(s)
    }
    fn create_pipeline(&mut self, desc: &PipelineDesc) -> Result<Handle<Pipeline>> {
        self.inner.create_pipeline(desc)
    }
    fn destroy_pipeline(&mut self, p: Handle<Pipeline>) -> Result<()> {
        self.inner.destroy_pipeline(p)
    }
    fn submit(&mut self, passes: &[RenderPass]) -> Result<Vec<PassTiming>> {
        if self.lose_device {
            let first = passes.first().map_or("submit", |p| p.name.as_str());
            return Err(self.injected(first, "device lost"));
        }
        self.inner.submit(passes)
    }
    fn read_texture(&mut self, t: Handle<Texture>, at: Subresource) -> Result<Image> {
        if self.fail_readback {
            return Err(self.injected("read_texture", "readback failed"));
        }
        let mut image = self.inner.read_texture(t, at)?;
        if self.perturb_readback {
            perturb(&mut image);
        }
        Ok(image)
    }
    fn live_resources(&self) -> usize {
        self.inner.live_resources()
    }
    fn pipelines_compiled(&self) -> u64 {
        self.inner.pipelines_compiled()
    }
}

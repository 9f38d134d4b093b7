//! One thread at a time in Mesa's GL driver, per process.
//!
//! Every GL context of a process, `gl`'s and `wgpu-gl`'s alike, sits on one llvmpipe screen (EGL
//! gives one surfaceless display per process), and Mesa 22.3's llvmpipe is not safe for two of
//! them driven from two threads at once: reading or mapping a resource in one context walks the
//! queued scenes of *every* context on the screen (`llvmpipe_flush_resource` over the screen's
//! context list, `llvmpipe_is_resource_referenced` on each), while those contexts' own threads
//! reset and free them. The test suite, which renders on several threads, died of it about once
//! in 35 runs: SIGSEGV in `swrast_dri.so`, a read of a freed page in the loop over a scene's
//! resource references (offset 0x6e0219 in Debian's 22.3.6 build; 2026-11-26).
//!
//! [`Serialized`] wraps the backends that drive GL so that their creation, every call that
//! reaches the driver, and their drop hold one process-wide lock. A process rendering on one
//! thread (`harness check`, `render`) never waits on it; threads rendering GL at once take
//! turns, which on a software rasterizer already using every core costs little. The Vulkan
//! backend is not wrapped: lavapipe's contexts are its devices' own, and no crash was seen on a
//! Vulkan API thread.

use std::sync::{Mutex, MutexGuard};

use super::{
    Backend, BackendKind, Buffer, BufferDesc, DriverInfo, Features, Handle, Image, PassTiming,
    Pipeline, PipelineDesc, RenderPass, Result, Sampler, SamplerDesc, Shader, ShaderDesc,
    Subresource, Texture, TextureDesc,
};

/// Held by whoever is inside the GL driver.
static GL_DRIVER: Mutex<()> = Mutex::new(());

/// The driver lock (a panic while it was held leaves nothing of ours half-done: take it).
fn driver() -> MutexGuard<'static, ()> {
    GL_DRIVER.lock().unwrap_or_else(|e| e.into_inner())
}

/// A GL backend whose every driver call holds the process's GL driver lock.
pub(crate) struct Serialized {
    /// Always `Some` until dropped (taken in `drop`, under the lock).
    inner: Option<Box<dyn Backend>>,
}

impl Serialized {
    /// Creates the backend made by `make` under the lock, wrapped.
    pub(crate) fn create(
        make: impl FnOnce() -> Result<Box<dyn Backend>>,
    ) -> Result<Box<dyn Backend>> {
        let _driver = driver();
        let inner = make()?;
        Ok(Box::new(Serialized { inner: Some(inner) }))
    }

    fn inner(&self) -> &dyn Backend {
        self.inner.as_deref().expect("a backend until dropped")
    }

    fn inner_mut(&mut self) -> &mut dyn Backend {
        self.inner.as_deref_mut().expect("a backend until dropped")
    }
}

impl Drop for Serialized {
    fn drop(&mut self) {
        let _driver = driver();
        drop(self.inner.take());
    }
}

impl Backend for Serialized {
    fn kind(&self) -> BackendKind {
        self.inner().kind()
    }

    fn info(&self) -> &DriverInfo {
        self.inner().info()
    }

    fn features(&self) -> Features {
        self.inner().features()
    }

    fn create_texture(&mut self, desc: &TextureDesc) -> Result<Handle<Texture>> {
        let _driver = driver();
        self.inner_mut().create_texture(desc)
    }

    fn write_texture(
        &mut self,
        texture: Handle<Texture>,
        at: Subresource,
        data: &[u8],
    ) -> Result<()> {
        let _driver = driver();
        self.inner_mut().write_texture(texture, at, data)
    }

    fn destroy_texture(&mut self, texture: Handle<Texture>) -> Result<()> {
        let _driver = driver();
        self.inner_mut().destroy_texture(texture)
    }

    fn create_buffer(&mut self, desc: &BufferDesc) -> Result<Handle<Buffer>> {
        let _driver = driver();
        self.inner_mut().create_buffer(desc)
    }

    fn write_buffer(&mut self, buffer: Handle<Buffer>, offset: u64, data: &[u8]) -> Result<()> {
        let _driver = driver();
        self.inner_mut().write_buffer(buffer, offset, data)
    }

    fn destroy_buffer(&mut self, buffer: Handle<Buffer>) -> Result<()> {
        let _driver = driver();
        self.inner_mut().destroy_buffer(buffer)
    }

    fn create_sampler(&mut self, desc: &SamplerDesc) -> Result<Handle<Sampler>> {
        let _driver = driver();
        self.inner_mut().create_sampler(desc)
    }

    fn destroy_sampler(&mut self, sampler: Handle<Sampler>) -> Result<()> {
        let _driver = driver();
        self.inner_mut().destroy_sampler(sampler)
    }

    fn create_shader(&mut self, desc: &ShaderDesc) -> Result<Handle<Shader>> {
        let _driver = driver();
        self.inner_mut().create_shader(desc)
    }

    fn destroy_shader(&mut self, shader: Handle<Shader>) -> Result<()> {
        let _driver = driver();
        self.inner_mut().destroy_shader(shader)
    }

    fn create_pipeline(&mut self, desc: &PipelineDesc) -> Result<Handle<Pipeline>> {
        let _driver = driver();
        self.inner_mut().create_pipeline(desc)
    }

    fn destroy_pipeline(&mut self, pipeline: Handle<Pipeline>) -> Result<()> {
        let _driver = driver();
        self.inner_mut().destroy_pipeline(pipeline)
    }

    fn submit(&mut self, passes: &[RenderPass]) -> Result<Vec<PassTiming>> {
        let _driver = driver();
        self.inner_mut().submit(passes)
    }

    fn read_texture(&mut self, texture: Handle<Texture>, at: Subresource) -> Result<Image> {
        let _driver = driver();
        self.inner_mut().read_texture(texture, at)
    }

    fn live_resources(&self) -> usize {
        self.inner().live_resources()
    }

    fn pipelines_compiled(&self) -> u64 {
        self.inner().pipelines_compiled()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A `gl` backend is created (and so driven) only while no other thread is in the driver.
    #[test]
    fn a_gl_backend_waits_for_the_driver_lock() {
        if !super::super::probe(BackendKind::Gl).available {
            eprintln!("note: gl unavailable here; the driver lock is not exercised");
            return;
        }
        let created = std::sync::Arc::new(std::sync::atomic::AtomicBool::new(false));
        let held = driver();
        let flag = created.clone();
        let other = std::thread::spawn(move || {
            let backend = super::super::create(BackendKind::Gl);
            flag.store(true, std::sync::atomic::Ordering::SeqCst);
            backend.map(|b| b.kind())
        });
        std::thread::sleep(std::time::Duration::from_millis(300));
        assert!(
            !created.load(std::sync::atomic::Ordering::SeqCst),
            "a gl backend was created while another thread held the driver lock"
        );
        drop(held);
        assert_eq!(other.join().unwrap().unwrap(), BackendKind::Gl);
        assert!(created.load(std::sync::atomic::Ordering::SeqCst));
    }
}

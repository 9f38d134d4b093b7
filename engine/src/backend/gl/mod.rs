//! The OpenGL backend: OpenGL 4.6/4.5 core through glow, headless via EGL surfaceless.
//!
//! Conventions match wgpu so that one set of WGSL shaders and matrices serves both:
//! `glClipControl(GL_UPPER_LEFT, GL_ZERO_TO_ONE)` puts normalized-device y = +1 at image row 0
//! and maps depth 0..1, so textures, render targets and read-backs share wgpu's top-row-first
//! layout without any flips. Shaders come from naga as GLSL 4.50 core (see [`crate::shaders`]).
//!
//! Every `unsafe` block here is a GL or EGL call. They share one invariant, stated once: the
//! backend's context is made current on the calling thread at the start of each public method
//! (`EglContext::make_current`), and every GL object name used was created by this context and
//! is still alive (the pools hand out handles only for live objects).
//!
//! The files of this folder:
//! - `mod.rs`: the resource types, [`GlBackend`] and its [`Backend`] implementation, whose
//!   longer operations call into the files below as `file::operation(self, …)`, and freeing
//!   everything on drop;
//! - `context.rs`: the headless EGL context;
//! - `device.rs`: setting the context up, error checks, and creating and filling textures,
//!   buffers, samplers, shaders and pipelines (with the module and program caches);
//! - `commands.rs`: running render passes and their draws, and pass timestamps;
//! - `readback.rs`: reading textures back to the CPU;
//! - `conv.rs`: descriptors mapped onto GL enums;
//! - `wgpu_interop.rs`: the one GL call made in wgpu's own context.
//!
//! Helpers used by more than one file are methods of [`GlBackend`], or `device::driver_error`.

mod commands;
mod context;
mod conv;
mod device;
mod readback;
pub(crate) mod wgpu_interop;

use std::collections::HashMap;
use std::marker::PhantomData;
use std::rc::Rc;
use std::sync::{Arc, Mutex};

use glow::HasContext;

use self::context::EglContext;
use super::pool::Pool;
use super::*;
use crate::image::Image;
use crate::shaders::ValidatedModule;

/// A texture name and the description it was created from.
struct GlTexture {
    raw: glow::Texture,
    desc: TextureDesc,
}

/// A buffer name with the usage and size its writes are checked against.
struct GlBuffer {
    raw: glow::Buffer,
    usage: BufferUsage,
    size: u64,
}

/// A validated module and the hash of its name and source (the caches' key).
struct GlShader {
    module: Rc<ValidatedModule>,
    key: u64,
}

/// A linked program, shared by every pipeline made from the same stages and constants.
#[derive(Clone)]
struct LinkedProgram {
    program: glow::Program,
    /// (texture unit = texture binding, binding of the sampler used with it).
    sampler_units: Vec<(u32, Option<u32>)>,
}

/// A pipeline: its program, its vertex array and the description it was created from.
struct GlPipeline {
    /// Owned by the program cache, deleted when the backend is dropped.
    program: glow::Program,
    vao: glow::VertexArray,
    desc: PipelineDesc,
    /// (texture unit = texture binding, binding of the sampler used with it).
    sampler_units: Vec<(u32, Option<u32>)>,
}

/// An OpenGL core context and the resources created in it. Not `Send`: the context is current
/// on the thread that uses it.
pub struct GlBackend {
    gl: glow::Context,
    context: EglContext,
    info: DriverInfo,
    /// Messages of type error from GL debug output (debug builds), drained after each call.
    debug_errors: Arc<Mutex<Vec<String>>>,
    textures: Pool<GlTexture>,
    buffers: Pool<GlBuffer>,
    samplers: Pool<glow::Sampler>,
    shaders: Pool<GlShader>,
    pipelines: Pool<GlPipeline>,
    /// Validated modules and linked programs by source, stages and constants, kept for the
    /// backend's life as a driver's shader cache would be: renders ask for the same pipelines
    /// every frame, and llvmpipe takes tens of milliseconds to compile a lighting variant.
    module_cache: HashMap<u64, Rc<ValidatedModule>>,
    program_cache: HashMap<String, LinkedProgram>,
    /// Programs linked (cache misses), for [`Backend::pipelines_compiled`].
    pipelines_compiled: u64,
    _not_send: PhantomData<*const ()>,
}

impl Backend for GlBackend {
    fn kind(&self) -> BackendKind {
        BackendKind::Gl
    }

    fn info(&self) -> &DriverInfo {
        &self.info
    }

    fn features(&self) -> Features {
        // OpenGL 4.5 core has geometry shaders (3.2) and viewport arrays (4.1).
        Features {
            geometry_shaders: true,
        }
    }

    fn create_texture(&mut self, desc: &TextureDesc) -> Result<Handle<Texture>> {
        device::create_texture(self, desc)
    }

    fn write_texture(
        &mut self,
        texture: Handle<Texture>,
        at: Subresource,
        data: &[u8],
    ) -> Result<()> {
        device::write_texture(self, texture, at, data)
    }

    fn destroy_texture(&mut self, texture: Handle<Texture>) -> Result<()> {
        self.context.make_current()?;
        let tex = self.textures.remove(texture)?;
        // SAFETY: see module docs; the name is removed from the pool, so never used again.
        unsafe { self.gl.delete_texture(tex.raw) };
        Ok(())
    }

    fn create_buffer(&mut self, desc: &BufferDesc) -> Result<Handle<Buffer>> {
        device::create_buffer(self, desc)
    }

    fn write_buffer(&mut self, buffer: Handle<Buffer>, offset: u64, data: &[u8]) -> Result<()> {
        device::write_buffer(self, buffer, offset, data)
    }

    fn destroy_buffer(&mut self, buffer: Handle<Buffer>) -> Result<()> {
        self.context.make_current()?;
        let buf = self.buffers.remove(buffer)?;
        // SAFETY: see module docs; removed from the pool, never used again.
        unsafe { self.gl.delete_buffer(buf.raw) };
        Ok(())
    }

    fn create_sampler(&mut self, desc: &SamplerDesc) -> Result<Handle<Sampler>> {
        device::create_sampler(self, desc)
    }

    fn destroy_sampler(&mut self, sampler: Handle<Sampler>) -> Result<()> {
        self.context.make_current()?;
        let raw = self.samplers.remove(sampler)?;
        // SAFETY: see module docs; removed from the pool, never used again.
        unsafe { self.gl.delete_sampler(raw) };
        Ok(())
    }

    fn create_shader(&mut self, desc: &ShaderDesc) -> Result<Handle<Shader>> {
        device::create_shader(self, desc)
    }

    fn destroy_shader(&mut self, shader: Handle<Shader>) -> Result<()> {
        self.shaders.remove(shader).map(drop)
    }

    fn create_pipeline(&mut self, desc: &PipelineDesc) -> Result<Handle<Pipeline>> {
        device::create_pipeline(self, desc)
    }

    fn destroy_pipeline(&mut self, pipeline: Handle<Pipeline>) -> Result<()> {
        self.context.make_current()?;
        let p = self.pipelines.remove(pipeline)?;
        // SAFETY: see module docs; removed from the pool, never used again (its program stays
        // in the program cache).
        unsafe { self.gl.delete_vertex_array(p.vao) };
        Ok(())
    }

    fn submit(&mut self, passes: &[RenderPass]) -> Result<Vec<PassTiming>> {
        commands::submit(self, passes)
    }

    fn read_texture(&mut self, texture: Handle<Texture>, at: Subresource) -> Result<Image> {
        readback::read_texture(self, texture, at)
    }

    fn live_resources(&self) -> usize {
        self.textures.len()
            + self.buffers.len()
            + self.samplers.len()
            + self.shaders.len()
            + self.pipelines.len()
    }

    fn pipelines_compiled(&self) -> u64 {
        self.pipelines_compiled
    }
}

impl Drop for GlBackend {
    fn drop(&mut self) {
        if self.context.make_current().is_err() {
            log::error!("gl: cannot make the context current to free its objects");
            return;
        }
        let gl = &self.gl;
        // SAFETY: see module docs; every name below is drained from its pool, so none is used
        // again. Debug output is switched off first because the callback is freed with `gl`.
        unsafe {
            if cfg!(debug_assertions) {
                gl.disable(glow::DEBUG_OUTPUT);
            }
            self.textures.drain().for_each(|t| gl.delete_texture(t.raw));
            self.buffers.drain().for_each(|b| gl.delete_buffer(b.raw));
            self.samplers.drain().for_each(|s| gl.delete_sampler(s));
            self.pipelines
                .drain()
                .for_each(|p| gl.delete_vertex_array(p.vao));
            self.program_cache
                .drain()
                .for_each(|(_, linked)| gl.delete_program(linked.program));
            gl.finish();
        }
    }
}

//! The wgpu backend, pinned to one wgpu backend: Vulkan (`wgpu-vulkan`) or GL (`wgpu-gl`).
//!
//! wgpu is never allowed to fall back to another API: if the pinned one has no adapter, the
//! backend reports itself unavailable. Validation errors are caught with error scopes and
//! returned as [`BackendError`]s instead of panicking.
//!
//! The files of this folder:
//! - `mod.rs`: the resource types, [`WgpuBackend`] and its [`Backend`] implementation, whose
//!   longer operations call into the files below as `file::operation(self, …)`;
//! - `device.rs`: opening the device, error scopes, and creating and filling textures,
//!   buffers, samplers, shaders, pipelines and bind groups;
//! - `commands.rs`: recording and submitting render passes and their draws, and pass timestamps;
//! - `readback.rs`: copying textures (depth through a copy pass) and buffers back to the CPU;
//! - `conv.rs`: descriptors mapped onto wgpu's types.
//!
//! Helpers used by more than one file are methods of [`WgpuBackend`].

mod commands;
mod conv;
mod device;
mod quirks;
mod readback;

use ::wgpu;
use std::collections::HashMap;

use super::pool::Pool;
use super::*;
use crate::image::Image;

/// A texture and the description it was created from.
struct TextureResource {
    texture: wgpu::Texture,
    desc: TextureDesc,
}

/// A buffer with the usage and size its writes are checked against.
struct BufferResource {
    buffer: wgpu::Buffer,
    usage: BufferUsage,
    size: u64,
}

/// A render pipeline with its bind group 0 layout and declared bindings.
#[derive(Clone)]
struct PipelineResource {
    pipeline: wgpu::RenderPipeline,
    bind_group_layout: wgpu::BindGroupLayout,
    bindings: Vec<BindingLayout>,
    label: String,
}

/// A shader module and the hash of its name and source (the caches' key).
struct ShaderResource {
    module: wgpu::ShaderModule,
    key: u64,
}

/// Depth readback through a copy pass packing f32 bits into RGBA8 (created on first use).
struct DepthCopy {
    pipeline: wgpu::RenderPipeline,
    bind_group_layout: wgpu::BindGroupLayout,
}

/// A wgpu device on one pinned API.
pub struct WgpuBackend {
    kind: BackendKind,
    info: DriverInfo,
    device: wgpu::Device,
    queue: wgpu::Queue,
    timestamps: bool,
    textures: Pool<TextureResource>,
    buffers: Pool<BufferResource>,
    samplers: Pool<wgpu::Sampler>,
    shaders: Pool<ShaderResource>,
    pipelines: Pool<PipelineResource>,
    /// Compiled modules and pipelines by source and description, kept for the backend's life
    /// and shared by every handle made from the same inputs, as a driver's pipeline cache
    /// would. Renders create the same pipelines every frame, and on wgpu's Vulkan path (with
    /// lavapipe) each pipeline created and destroyed kept ~450 KiB (measured: 200 cycles of one
    /// pipeline, +88 MiB; wgpu-gl +1 MiB), so the cache bounds memory by the number of
    /// distinct pipelines instead of the number of frames.
    module_cache: HashMap<u64, wgpu::ShaderModule>,
    pipeline_cache: HashMap<String, PipelineResource>,
    /// Pipelines compiled (cache misses), for [`Backend::pipelines_compiled`].
    pipelines_compiled: u64,
    depth_copy: Option<DepthCopy>,
}

impl Backend for WgpuBackend {
    fn kind(&self) -> BackendKind {
        self.kind
    }

    fn info(&self) -> &DriverInfo {
        &self.info
    }

    fn features(&self) -> Features {
        Features::default()
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
        self.textures.remove(texture)?.texture.destroy();
        Ok(())
    }

    fn create_buffer(&mut self, desc: &BufferDesc) -> Result<Handle<Buffer>> {
        device::create_buffer(self, desc)
    }

    fn write_buffer(&mut self, buffer: Handle<Buffer>, offset: u64, data: &[u8]) -> Result<()> {
        device::write_buffer(self, buffer, offset, data)
    }

    fn destroy_buffer(&mut self, buffer: Handle<Buffer>) -> Result<()> {
        self.buffers.remove(buffer)?.buffer.destroy();
        Ok(())
    }

    fn create_sampler(&mut self, desc: &SamplerDesc) -> Result<Handle<Sampler>> {
        device::create_sampler(self, desc)
    }

    fn destroy_sampler(&mut self, sampler: Handle<Sampler>) -> Result<()> {
        self.samplers.remove(sampler).map(drop)
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
        self.pipelines.remove(pipeline).map(drop)
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

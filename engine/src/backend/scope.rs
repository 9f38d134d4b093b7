//! [`ResourceScope`]: records what a render creates so that all of it is destroyed afterwards,
//! on success and on error alike (a render must leave the backend as it found it).

use super::{Backend, Buffer, Handle, Pipeline, Result, Sampler, Shader, Texture};
use super::{BufferUsage, PipelineDesc, SamplerDesc, ShaderDesc, TextureDesc};

/// Creates resources through a backend and remembers them for [`ResourceScope::destroy`].
#[derive(Default)]
pub struct ResourceScope {
    textures: Vec<Handle<Texture>>,
    buffers: Vec<Handle<Buffer>>,
    samplers: Vec<Handle<Sampler>>,
    shaders: Vec<Handle<Shader>>,
    pipelines: Vec<Handle<Pipeline>>,
}

impl ResourceScope {
    /// Creates a texture and records it.
    pub fn texture(
        &mut self,
        backend: &mut dyn Backend,
        desc: &TextureDesc,
    ) -> Result<Handle<Texture>> {
        let handle = backend.create_texture(desc)?;
        self.textures.push(handle);
        Ok(handle)
    }

    /// Creates a buffer filled with `data` and records it.
    pub fn buffer(
        &mut self,
        backend: &mut dyn Backend,
        label: &str,
        usage: BufferUsage,
        data: &[u8],
    ) -> Result<Handle<Buffer>> {
        let handle = backend.create_buffer_with_data(label, usage, data)?;
        self.buffers.push(handle);
        Ok(handle)
    }

    /// Creates a sampler and records it.
    pub fn sampler(
        &mut self,
        backend: &mut dyn Backend,
        desc: &SamplerDesc,
    ) -> Result<Handle<Sampler>> {
        let handle = backend.create_sampler(desc)?;
        self.samplers.push(handle);
        Ok(handle)
    }

    /// Creates a shader module and records it.
    pub fn shader(
        &mut self,
        backend: &mut dyn Backend,
        desc: &ShaderDesc,
    ) -> Result<Handle<Shader>> {
        let handle = backend.create_shader(desc)?;
        self.shaders.push(handle);
        Ok(handle)
    }

    /// Creates a pipeline and records it.
    pub fn pipeline(
        &mut self,
        backend: &mut dyn Backend,
        desc: &PipelineDesc,
    ) -> Result<Handle<Pipeline>> {
        let handle = backend.create_pipeline(desc)?;
        self.pipelines.push(handle);
        Ok(handle)
    }

    /// Destroys everything recorded, pipelines first.
    pub fn destroy(self, backend: &mut dyn Backend) {
        // Errors here could only repeat an error already being returned (or a lost device).
        for h in self.pipelines {
            drop(backend.destroy_pipeline(h));
        }
        for h in self.shaders {
            drop(backend.destroy_shader(h));
        }
        for h in self.samplers {
            drop(backend.destroy_sampler(h));
        }
        for h in self.buffers {
            drop(backend.destroy_buffer(h));
        }
        for h in self.textures {
            drop(backend.destroy_texture(h));
        }
    }
}

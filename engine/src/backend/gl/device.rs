//! Making the OpenGL context and what lives in it: the context's setup, error checks, and the
//! creation and upload of textures, buffers, samplers, shaders and pipelines, with the shader
//! module and linked program caches. Destroying a resource takes a few lines and stays in
//! `mod.rs`.
//!
//! Every `unsafe` block here is a GL call and relies on the invariant stated in [`super`]: the
//! context is current on this thread and every GL name used is alive and was made by it.

use std::collections::HashMap;
use std::marker::PhantomData;
use std::rc::Rc;
use std::sync::{Arc, Mutex};

use glow::HasContext;

use super::context::EglContext;
use super::{conv, GlBackend, GlBuffer, GlPipeline, GlShader, GlTexture, LinkedProgram};
use crate::backend::pool::Pool;
use crate::backend::*;
use crate::shaders;

/// A [`BackendError::Driver`] of the `gl` backend about `context`.
pub(super) fn driver_error(context: impl Into<String>, message: impl Into<String>) -> BackendError {
    BackendError::Driver {
        backend: BackendKind::Gl.name(),
        context: context.into(),
        message: message.into(),
    }
}

impl GlBackend {
    /// Creates a headless OpenGL 4.6 or 4.5 core context.
    pub fn new() -> Result<Self> {
        let debug = cfg!(debug_assertions);
        let context = EglContext::new(debug)?;
        let mut gl = context.load_gl();
        let debug_errors = Arc::new(Mutex::new(Vec::new()));
        let clip_control = context
            .clip_control()
            .ok_or_else(|| BackendError::Unavailable {
                backend: BackendKind::Gl.name(),
                reason: "glClipControl is missing (needs OpenGL 4.5)".to_owned(),
                fix: "use Mesa 20 or newer".to_owned(),
            })?;
        // SAFETY: the context was made current by EglContext::new; these calls only query
        // strings and set global state.
        let info = unsafe {
            let version = gl.version();
            if !version.is_embedded && (version.major, version.minor) < (4, 5) {
                return Err(BackendError::Unavailable {
                    backend: BackendKind::Gl.name(),
                    reason: format!(
                        "driver gave OpenGL {}.{}, 4.5 core is required",
                        version.major, version.minor
                    ),
                    fix: "use Mesa 20 or newer (llvmpipe)".to_owned(),
                });
            }
            if debug && gl.supports_debug() {
                let sink = Arc::clone(&debug_errors);
                gl.enable(glow::DEBUG_OUTPUT);
                gl.enable(glow::DEBUG_OUTPUT_SYNCHRONOUS);
                gl.debug_message_callback(move |_source, ty, _id, severity, message| {
                    if ty == glow::DEBUG_TYPE_ERROR {
                        log::error!("gl: {message}");
                        sink.lock().expect("debug sink").push(message.to_owned());
                    } else if severity == glow::DEBUG_SEVERITY_HIGH
                        || severity == glow::DEBUG_SEVERITY_MEDIUM
                    {
                        log::warn!("gl: {message}");
                    } else {
                        log::debug!("gl: {message}");
                    }
                });
            }
            clip_control(glow::UPPER_LEFT, glow::ZERO_TO_ONE);
            // Writes to sRGB targets are encoded, as in wgpu.
            gl.enable(glow::FRAMEBUFFER_SRGB);
            // Cube maps filter across face edges, as Vulkan's always do.
            gl.enable(glow::TEXTURE_CUBE_MAP_SEAMLESS);
            gl.pixel_store_i32(glow::UNPACK_ALIGNMENT, 1);
            gl.pixel_store_i32(glow::PACK_ALIGNMENT, 1);
            DriverInfo {
                api: "OpenGL".to_owned(),
                api_version: gl.get_parameter_string(glow::VERSION),
                renderer: gl.get_parameter_string(glow::RENDERER),
                vendor: gl.get_parameter_string(glow::VENDOR),
                driver: format!(
                    "GLSL {}",
                    gl.get_parameter_string(glow::SHADING_LANGUAGE_VERSION)
                ),
                timestamps: true,
                ..DriverInfo::new(BackendKind::Gl)
            }
            .complete()
        };
        Ok(Self {
            gl,
            context,
            info,
            debug_errors,
            textures: Pool::new("texture"),
            buffers: Pool::new("buffer"),
            samplers: Pool::new("sampler"),
            shaders: Pool::new("shader"),
            pipelines: Pool::new("pipeline"),
            module_cache: HashMap::new(),
            program_cache: HashMap::new(),
            pipelines_compiled: 0,
            _not_send: PhantomData,
        })
    }

    /// Turns pending GL errors (glGetError and debug output) into a driver error for `what`.
    pub(super) fn check_errors(&self, what: &str) -> Result<()> {
        let mut messages: Vec<String> = self
            .debug_errors
            .lock()
            .expect("debug sink")
            .drain(..)
            .collect();
        loop {
            // SAFETY: see module docs; glGetError has no preconditions.
            let code = unsafe { self.gl.get_error() };
            if code == glow::NO_ERROR {
                break;
            }
            messages.push(format!("glGetError 0x{code:04x}"));
        }
        if messages.is_empty() {
            Ok(())
        } else {
            Err(driver_error(what, messages.join("; ")))
        }
    }

    /// Translates, compiles and links a pipeline's stages with its constants.
    fn link(&self, desc: &PipelineDesc) -> Result<LinkedProgram> {
        let module = &self.shaders.get(desc.shader)?.module;
        let translate = |stage, entry: &str| {
            shaders::to_glsl(module, stage, entry, &desc.constants).map_err(|e| {
                BackendError::Shader {
                    backend: BackendKind::Gl.name(),
                    name: format!("{}::{entry}", module.name),
                    message: e.to_string(),
                }
            })
        };
        let mut stages = vec![(
            glow::VERTEX_SHADER,
            desc.vertex_entry.as_str(),
            translate(naga::ShaderStage::Vertex, &desc.vertex_entry)?,
        )];
        if let Some(entry) = &desc.fragment_entry {
            stages.push((
                glow::FRAGMENT_SHADER,
                entry,
                translate(naga::ShaderStage::Fragment, entry)?,
            ));
        }
        let mut sampler_units: Vec<(u32, Option<u32>)> = stages
            .iter()
            .flat_map(|(_, _, s)| s.sampler_units.clone())
            .collect();
        sampler_units.sort();
        sampler_units.dedup();
        let mut sources: Vec<(u32, String, &str)> = stages
            .iter()
            .map(|(stage, entry, glsl)| {
                (
                    *stage,
                    format!("{}::{entry}", module.name),
                    glsl.source.as_str(),
                )
            })
            .collect();
        if let Some(geometry) = &desc.geometry {
            sources.push((
                glow::GEOMETRY_SHADER,
                geometry.name.clone(),
                geometry.glsl.as_str(),
            ));
        }
        let mut compiled = Vec::new();
        for (stage, name, source) in &sources {
            match self.compile(*stage, name, source) {
                Ok(shader) => compiled.push(shader),
                Err(e) => {
                    // SAFETY: see module docs; these shaders were created above.
                    unsafe { compiled.into_iter().for_each(|s| self.gl.delete_shader(s)) };
                    return Err(e);
                }
            }
        }
        let gl = &self.gl;
        // SAFETY: see module docs; the shaders were compiled above and are deleted once linked.
        let program = unsafe {
            let program = gl
                .create_program()
                .map_err(|e| driver_error(&desc.label, e))?;
            for &shader in &compiled {
                gl.attach_shader(program, shader);
            }
            gl.link_program(program);
            for shader in compiled {
                gl.detach_shader(program, shader);
                gl.delete_shader(shader);
            }
            if !gl.get_program_link_status(program) {
                let log = gl.get_program_info_log(program);
                gl.delete_program(program);
                return Err(BackendError::Shader {
                    backend: BackendKind::Gl.name(),
                    name: format!("{} ({})", module.name, desc.label),
                    message: format!("GLSL link failed: {log}"),
                });
            }
            gl.object_label(glow::PROGRAM, program.0.get(), Some(&desc.label));
            program
        };
        self.check_errors(&format!("pipeline `{}`", desc.label))?;
        Ok(LinkedProgram {
            program,
            sampler_units,
        })
    }

    /// Compiles one GLSL stage; a failure carries the log and the generated source.
    fn compile(&self, stage: u32, name: &str, source: &str) -> Result<glow::Shader> {
        // SAFETY: see module docs.
        unsafe {
            let shader = self
                .gl
                .create_shader(stage)
                .map_err(|e| driver_error(name, e))?;
            self.gl.shader_source(shader, source);
            self.gl.compile_shader(shader);
            if !self.gl.get_shader_compile_status(shader) {
                let log = self.gl.get_shader_info_log(shader);
                self.gl.delete_shader(shader);
                return Err(BackendError::Shader {
                    backend: BackendKind::Gl.name(),
                    name: name.to_owned(),
                    message: format!(
                        "GLSL compile failed: {log}\n--- generated GLSL ---\n{source}"
                    ),
                });
            }
            Ok(shader)
        }
    }
}

/// Creates a texture with immutable storage for all its mips and layers.
pub(super) fn create_texture(
    backend: &mut GlBackend,
    desc: &TextureDesc,
) -> Result<Handle<Texture>> {
    backend.context.make_current()?;
    check_texture_desc(desc)?;
    let target = conv::target(desc.kind);
    let gl = &backend.gl;
    // SAFETY: see module docs.
    let raw = unsafe {
        let raw = gl
            .create_texture()
            .map_err(|e| driver_error(&desc.label, e))?;
        gl.bind_texture(target, Some(raw));
        let format = conv::internal_format(desc.format);
        match desc.kind {
            TextureKind::D2 | TextureKind::Cube => gl.tex_storage_2d(
                target,
                desc.mip_levels as i32,
                format,
                desc.width as i32,
                desc.height as i32,
            ),
            TextureKind::D2Array { layers } => gl.tex_storage_3d(
                target,
                desc.mip_levels as i32,
                format,
                desc.width as i32,
                desc.height as i32,
                layers as i32,
            ),
        }
        // Complete with any sampler: the level range is exactly what was allocated, and
        // without a sampler object (texelFetch) nearest filtering applies.
        gl.tex_parameter_i32(target, glow::TEXTURE_MAX_LEVEL, desc.mip_levels as i32 - 1);
        gl.tex_parameter_i32(target, glow::TEXTURE_MIN_FILTER, glow::NEAREST as i32);
        gl.tex_parameter_i32(target, glow::TEXTURE_MAG_FILTER, glow::NEAREST as i32);
        gl.object_label(glow::TEXTURE, raw.0.get(), Some(&desc.label));
        gl.bind_texture(target, None);
        raw
    };
    backend.check_errors(&format!("texture `{}`", desc.label))?;
    Ok(backend.textures.insert(GlTexture {
        raw,
        desc: desc.clone(),
    }))
}

/// Uploads the texels of one mip/layer of a texture.
pub(super) fn write_texture(
    backend: &GlBackend,
    texture: Handle<Texture>,
    at: Subresource,
    data: &[u8],
) -> Result<()> {
    backend.context.make_current()?;
    let tex = backend.textures.get(texture)?;
    let (w, h) = check_upload(&tex.desc, at, data)?;
    let (format, ty) = conv::upload_format(tex.desc.format);
    let target = conv::target(tex.desc.kind);
    let pixels = glow::PixelUnpackData::Slice(Some(data));
    // SAFETY: see module docs; `data` holds exactly w*h texels (checked above).
    unsafe {
        backend.gl.bind_texture(target, Some(tex.raw));
        match tex.desc.kind {
            TextureKind::D2 | TextureKind::Cube => backend.gl.tex_sub_image_2d(
                if tex.desc.kind == TextureKind::Cube {
                    glow::TEXTURE_CUBE_MAP_POSITIVE_X + at.layer
                } else {
                    target
                },
                at.mip as i32,
                0,
                0,
                w as i32,
                h as i32,
                format,
                ty,
                pixels,
            ),
            TextureKind::D2Array { .. } => backend.gl.tex_sub_image_3d(
                target,
                at.mip as i32,
                0,
                0,
                at.layer as i32,
                w as i32,
                h as i32,
                1,
                format,
                ty,
                pixels,
            ),
        }
        backend.gl.bind_texture(target, None);
    }
    backend.check_errors(&format!("upload to `{}`", tex.desc.label))
}

/// Creates a buffer filled with zeros.
pub(super) fn create_buffer(backend: &mut GlBackend, desc: &BufferDesc) -> Result<Handle<Buffer>> {
    backend.context.make_current()?;
    check_buffer_desc(desc)?;
    let target = conv::buffer_target(desc.usage);
    // SAFETY: see module docs. An index buffer is bound to ARRAY_BUFFER for creation so that
    // no vertex array's element binding is touched.
    let raw = unsafe {
        let raw = backend
            .gl
            .create_buffer()
            .map_err(|e| driver_error(&desc.label, e))?;
        let bind_target = if target == glow::ELEMENT_ARRAY_BUFFER {
            glow::ARRAY_BUFFER
        } else {
            target
        };
        backend.gl.bind_buffer(bind_target, Some(raw));
        backend
            .gl
            .buffer_data_size(bind_target, desc.size as i32, glow::DYNAMIC_DRAW);
        let zeros = vec![0u8; desc.size as usize];
        backend.gl.buffer_sub_data_u8_slice(bind_target, 0, &zeros);
        backend.gl.bind_buffer(bind_target, None);
        raw
    };
    backend.check_errors(&format!("buffer `{}`", desc.label))?;
    Ok(backend.buffers.insert(GlBuffer {
        raw,
        usage: desc.usage,
        size: desc.size,
    }))
}

/// Writes `data` into a buffer at `offset`.
pub(super) fn write_buffer(
    backend: &GlBackend,
    buffer: Handle<Buffer>,
    offset: u64,
    data: &[u8],
) -> Result<()> {
    backend.context.make_current()?;
    let buf = backend.buffers.get(buffer)?;
    check_buffer_write(buf.usage, buf.size, offset, data.len())?;
    // SAFETY: see module docs; the range was checked against the buffer's size.
    unsafe {
        backend
            .gl
            .bind_buffer(glow::COPY_WRITE_BUFFER, Some(buf.raw));
        backend
            .gl
            .buffer_sub_data_u8_slice(glow::COPY_WRITE_BUFFER, offset as i32, data);
        backend.gl.bind_buffer(glow::COPY_WRITE_BUFFER, None);
    }
    backend.check_errors("buffer write")
}

/// Creates a sampler object.
pub(super) fn create_sampler(
    backend: &mut GlBackend,
    desc: &SamplerDesc,
) -> Result<Handle<Sampler>> {
    backend.context.make_current()?;
    let gl = &backend.gl;
    // SAFETY: see module docs.
    let raw = unsafe {
        let raw = gl
            .create_sampler()
            .map_err(|e| driver_error(&desc.label, e))?;
        let wrap = conv::address(desc.address_mode);
        gl.sampler_parameter_i32(raw, glow::TEXTURE_WRAP_S, wrap);
        gl.sampler_parameter_i32(raw, glow::TEXTURE_WRAP_T, wrap);
        gl.sampler_parameter_i32(raw, glow::TEXTURE_WRAP_R, wrap);
        gl.sampler_parameter_i32(
            raw,
            glow::TEXTURE_MAG_FILTER,
            conv::mag_filter(desc.mag_filter),
        );
        gl.sampler_parameter_i32(
            raw,
            glow::TEXTURE_MIN_FILTER,
            conv::min_filter(desc.min_filter, desc.mipmap_filter),
        );
        gl.sampler_parameter_f32(raw, glow::TEXTURE_MIN_LOD, 0.0);
        gl.sampler_parameter_f32(raw, glow::TEXTURE_MAX_LOD, 32.0);
        if let Some(compare) = desc.compare {
            gl.sampler_parameter_i32(
                raw,
                glow::TEXTURE_COMPARE_MODE,
                glow::COMPARE_REF_TO_TEXTURE as i32,
            );
            gl.sampler_parameter_i32(
                raw,
                glow::TEXTURE_COMPARE_FUNC,
                conv::compare(compare) as i32,
            );
        }
        raw
    };
    backend.check_errors(&format!("sampler `{}`", desc.label))?;
    Ok(backend.samplers.insert(raw))
}

/// Validates a WGSL module (once per source: later calls share the cached module).
pub(super) fn create_shader(backend: &mut GlBackend, desc: &ShaderDesc) -> Result<Handle<Shader>> {
    let key = desc.cache_key();
    let module = match backend.module_cache.get(&key) {
        Some(module) => module.clone(),
        None => {
            let module = Rc::new(shaders::validate(&desc.name, &desc.wgsl).map_err(|e| {
                BackendError::Shader {
                    backend: BackendKind::Gl.name(),
                    name: desc.name.clone(),
                    message: e.to_string(),
                }
            })?);
            backend.module_cache.insert(key, module.clone());
            module
        }
    };
    Ok(backend.shaders.insert(GlShader { module, key }))
}

/// Links a pipeline's program (or takes it from the program cache) and makes its vertex array.
pub(super) fn create_pipeline(
    backend: &mut GlBackend,
    desc: &PipelineDesc,
) -> Result<Handle<Pipeline>> {
    backend.context.make_current()?;
    let shader = backend.shaders.get(desc.shader)?;
    let cache_key = format!(
        "{:x}|{}|{:?}|{:?}|{:?}",
        shader.key,
        desc.vertex_entry,
        desc.fragment_entry,
        desc.geometry.as_ref().map(|g| (&g.name, &g.glsl)),
        desc.constants
    );
    let linked = match backend.program_cache.get(&cache_key) {
        Some(linked) => linked.clone(),
        None => {
            let linked = backend.link(desc)?;
            backend.program_cache.insert(cache_key, linked.clone());
            backend.pipelines_compiled += 1;
            linked
        }
    };
    let gl = &backend.gl;
    // SAFETY: see module docs; the VAO is created here and owned by the pipeline.
    let vao = unsafe {
        let vao = gl
            .create_vertex_array()
            .map_err(|e| driver_error(&desc.label, e))?;
        gl.bind_vertex_array(Some(vao));
        for (slot, layout) in desc.vertex_buffers.iter().enumerate() {
            for attribute in &layout.attributes {
                gl.enable_vertex_attrib_array(attribute.location);
                gl.vertex_attrib_format_f32(
                    attribute.location,
                    attribute.format.components() as i32,
                    glow::FLOAT,
                    false,
                    attribute.offset,
                );
                gl.vertex_attrib_binding(attribute.location, slot as u32);
            }
        }
        gl.bind_vertex_array(None);
        vao
    };
    backend.check_errors(&format!("pipeline `{}`", desc.label))?;
    Ok(backend.pipelines.insert(GlPipeline {
        program: linked.program,
        vao,
        desc: desc.clone(),
        sampler_units: linked.sampler_units,
    }))
}

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

mod context;
mod conv;
pub(crate) mod wgpu_interop;

use std::collections::HashMap;
use std::marker::PhantomData;
use std::rc::Rc;
use std::sync::{Arc, Mutex};

use glow::HasContext;

use self::context::EglContext;
use super::pool::Pool;
use super::*;
use crate::image::{Image, ImageData};
use crate::shaders::{self, ValidatedModule};

struct GlTexture {
    raw: glow::Texture,
    desc: TextureDesc,
}

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

fn driver_error(context: impl Into<String>, message: impl Into<String>) -> BackendError {
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
                backend: BackendKind::Gl.name().to_owned(),
                api: "OpenGL".to_owned(),
                api_version: gl.get_parameter_string(glow::VERSION),
                renderer: gl.get_parameter_string(glow::RENDERER),
                vendor: gl.get_parameter_string(glow::VENDOR),
                driver: format!(
                    "GLSL {}",
                    gl.get_parameter_string(glow::SHADING_LANGUAGE_VERSION)
                ),
                timestamps: true,
                ..Default::default()
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
    fn check_errors(&self, what: &str) -> Result<()> {
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

    /// Attaches one mip/layer of `texture` to `attachment` of the bound `target` framebuffer.
    fn attach(
        &self,
        target: u32,
        attachment: u32,
        texture: Handle<Texture>,
        at: Subresource,
    ) -> Result<(u32, u32)> {
        let tex = self.textures.get(texture)?;
        check_subresource(&tex.desc, at)?;
        // SAFETY: see module docs; a framebuffer is bound to `target` by the caller.
        unsafe {
            match tex.desc.kind {
                TextureKind::D2 => self.gl.framebuffer_texture_2d(
                    target,
                    attachment,
                    glow::TEXTURE_2D,
                    Some(tex.raw),
                    at.mip as i32,
                ),
                TextureKind::Cube => self.gl.framebuffer_texture_2d(
                    target,
                    attachment,
                    glow::TEXTURE_CUBE_MAP_POSITIVE_X + at.layer,
                    Some(tex.raw),
                    at.mip as i32,
                ),
                TextureKind::D2Array { .. } => self.gl.framebuffer_texture_layer(
                    target,
                    attachment,
                    Some(tex.raw),
                    at.mip as i32,
                    at.layer as i32,
                ),
            }
        }
        Ok(tex.desc.mip_size(at.mip))
    }

    /// Sets the fixed-function state and bindings of `draw`, then draws.
    fn execute_draw(&self, pass: &RenderPass, draw: &Draw) -> Result<()> {
        let pipeline = self.pipelines.get(draw.pipeline)?;
        let desc = &pipeline.desc;
        let gl = &self.gl;
        if draw.vertex_buffers.len() != desc.vertex_buffers.len() {
            return Err(BackendError::InvalidData(format!(
                "pass `{}`: pipeline `{}` needs {} vertex buffers, {} given",
                pass.name,
                desc.label,
                desc.vertex_buffers.len(),
                draw.vertex_buffers.len()
            )));
        }
        // SAFETY: see module docs; the pass's framebuffer is bound by `submit`.
        unsafe {
            gl.use_program(Some(pipeline.program));
            gl.bind_vertex_array(Some(pipeline.vao));
            match desc.depth {
                Some(depth) => {
                    gl.enable(glow::DEPTH_TEST);
                    gl.depth_func(conv::compare(depth.compare));
                    gl.depth_mask(depth.write);
                }
                None => gl.disable(glow::DEPTH_TEST),
            }
            match desc.cull {
                CullMode::None => gl.disable(glow::CULL_FACE),
                CullMode::Front | CullMode::Back => {
                    gl.enable(glow::CULL_FACE);
                    gl.cull_face(if desc.cull == CullMode::Front {
                        glow::FRONT
                    } else {
                        glow::BACK
                    });
                }
            }
            // Counter-clockwise in normalized device coordinates is front-facing, as in wgpu.
            // glClipControl(GL_UPPER_LEFT) flips window y but also flips the facing rule, so
            // the NDC winding keeps its meaning (pinned by the orientation test).
            gl.front_face(glow::CCW);
            for (index, target) in desc.color_targets.iter().enumerate() {
                let index = index as u32;
                gl.color_mask_draw_buffer(index, true, true, true, true);
                match target.blend {
                    Some(blend) => {
                        gl.enable_draw_buffer(glow::BLEND, index);
                        gl.blend_equation_separate_draw_buffer(
                            index,
                            conv::blend_op(blend.color.op),
                            conv::blend_op(blend.alpha.op),
                        );
                        let (src, dst) = conv::blend_factors(blend.color);
                        let (src_alpha, dst_alpha) = conv::blend_factors(blend.alpha);
                        gl.blend_func_separate_draw_buffer(index, src, dst, src_alpha, dst_alpha);
                    }
                    None => gl.disable_draw_buffer(glow::BLEND, index),
                }
            }
            for layout in &desc.bindings {
                let bound = draw
                    .bindings
                    .iter()
                    .find(|b| b.binding == layout.binding)
                    .ok_or_else(|| {
                        BackendError::InvalidData(format!(
                            "pass `{}`: pipeline `{}` has nothing bound to binding {}",
                            pass.name, desc.label, layout.binding
                        ))
                    })?;
                match bound.resource {
                    BindingResource::Buffer(b) => gl.bind_buffer_base(
                        if layout.kind == BindingKind::StorageBuffer {
                            glow::SHADER_STORAGE_BUFFER
                        } else {
                            glow::UNIFORM_BUFFER
                        },
                        layout.binding,
                        Some(self.buffers.get(b)?.raw),
                    ),
                    BindingResource::Texture(t) => {
                        let tex = self.textures.get(t)?;
                        gl.active_texture(glow::TEXTURE0 + layout.binding);
                        gl.bind_texture(conv::target(tex.desc.kind), Some(tex.raw));
                    }
                    BindingResource::Sampler(_) => {}
                }
            }
            for &(unit, sampler_binding) in &pipeline.sampler_units {
                let sampler = match sampler_binding {
                    Some(binding) => match draw.bindings.iter().find(|b| b.binding == binding) {
                        Some(Binding {
                            resource: BindingResource::Sampler(s),
                            ..
                        }) => Some(*self.samplers.get(*s)?),
                        _ => {
                            return Err(BackendError::InvalidData(format!(
                                "pass `{}`: pipeline `{}` needs a sampler at binding {binding}",
                                pass.name, desc.label
                            )))
                        }
                    },
                    None => None,
                };
                gl.bind_sampler(unit, sampler);
            }
            for (slot, (buffer, layout)) in draw
                .vertex_buffers
                .iter()
                .zip(&desc.vertex_buffers)
                .enumerate()
            {
                gl.bind_vertex_buffer(
                    slot as u32,
                    Some(self.buffers.get(*buffer)?.raw),
                    0,
                    layout.stride as i32,
                );
            }
            let mode = conv::topology(desc.topology);
            match draw.index_buffer {
                Some((buffer, format)) => {
                    gl.bind_buffer(
                        glow::ELEMENT_ARRAY_BUFFER,
                        Some(self.buffers.get(buffer)?.raw),
                    );
                    gl.draw_elements(mode, draw.count as i32, conv::index_type(format), 0);
                }
                None => gl.draw_arrays(mode, 0, draw.count as i32),
            }
        }
        Ok(())
    }

    /// Runs one pass into a temporary framebuffer.
    fn execute_pass(
        &self,
        pass: &RenderPass,
        queries: Option<(glow::Query, glow::Query)>,
    ) -> Result<()> {
        let gl = &self.gl;
        // SAFETY: see module docs.
        let framebuffer =
            unsafe { gl.create_framebuffer() }.map_err(|e| driver_error(&pass.name, e))?;
        let result = (|| {
            // SAFETY: see module docs; `framebuffer` was just created.
            unsafe { gl.bind_framebuffer(glow::DRAW_FRAMEBUFFER, Some(framebuffer)) };
            let mut size = None;
            for (index, attachment) in pass.color_attachments.iter().enumerate() {
                let s = self.attach(
                    glow::DRAW_FRAMEBUFFER,
                    glow::COLOR_ATTACHMENT0 + index as u32,
                    attachment.texture,
                    attachment.subresource,
                )?;
                size.get_or_insert(s);
            }
            if let Some(depth) = &pass.depth_attachment {
                let s = self.attach(
                    glow::DRAW_FRAMEBUFFER,
                    glow::DEPTH_ATTACHMENT,
                    depth.texture,
                    depth.subresource,
                )?;
                size.get_or_insert(s);
            }
            let (width, height) = size.ok_or_else(|| {
                BackendError::InvalidData(format!("pass `{}` has no attachments", pass.name))
            })?;
            let draw_buffers: Vec<u32> = (0..pass.color_attachments.len() as u32)
                .map(|i| glow::COLOR_ATTACHMENT0 + i)
                .collect();
            // SAFETY: see module docs; the framebuffer is bound and complete-checked below.
            unsafe {
                if draw_buffers.is_empty() {
                    gl.draw_buffers(&[glow::NONE]);
                } else {
                    gl.draw_buffers(&draw_buffers);
                }
                let status = gl.check_framebuffer_status(glow::DRAW_FRAMEBUFFER);
                if status != glow::FRAMEBUFFER_COMPLETE {
                    return Err(driver_error(
                        &pass.name,
                        format!("framebuffer incomplete (0x{status:04x})"),
                    ));
                }
                if let Some((begin, _)) = queries {
                    gl.query_counter(begin, glow::TIMESTAMP);
                }
                let whole = [Viewport {
                    x: 0.0,
                    y: 0.0,
                    width: width as f32,
                    height: height as f32,
                    min_depth: 0.0,
                    max_depth: 1.0,
                }];
                let viewports = if pass.viewports.is_empty() {
                    &whole[..]
                } else {
                    &pass.viewports[..]
                };
                let rects: Vec<[f32; 4]> = viewports
                    .iter()
                    .map(|v| [v.x, v.y, v.width, v.height])
                    .collect();
                // glViewport and glDepthRange set every viewport of the array; the array call
                // then sets the first `len` rectangles.
                let v = viewports[0];
                gl.viewport(v.x as i32, v.y as i32, v.width as i32, v.height as i32);
                gl.viewport_f32_slice(0, rects.len() as i32, &rects);
                gl.depth_range_f32(v.min_depth, v.max_depth);
                gl.disable(glow::SCISSOR_TEST);
                for (index, attachment) in pass.color_attachments.iter().enumerate() {
                    if let LoadOp::Clear(color) = attachment.load {
                        gl.color_mask_draw_buffer(index as u32, true, true, true, true);
                        gl.clear_buffer_f32_slice(glow::COLOR, index as u32, &color);
                    }
                }
                if let Some(DepthAttachment {
                    load: LoadOp::Clear(depth),
                    ..
                }) = pass.depth_attachment
                {
                    gl.depth_mask(true);
                    gl.clear_buffer_f32_slice(glow::DEPTH, 0, &[depth]);
                }
            }
            for draw in &pass.draws {
                self.execute_draw(pass, draw)?;
            }
            if let Some((_, end)) = queries {
                // SAFETY: see module docs.
                unsafe { gl.query_counter(end, glow::TIMESTAMP) };
            }
            Ok(())
        })();
        // SAFETY: see module docs; GL keeps the attachments' contents after the framebuffer goes.
        unsafe {
            gl.bind_framebuffer(glow::DRAW_FRAMEBUFFER, None);
            gl.delete_framebuffer(framebuffer);
        }
        result
    }
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
        self.context.make_current()?;
        check_texture_desc(desc)?;
        let target = conv::target(desc.kind);
        let gl = &self.gl;
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
        self.check_errors(&format!("texture `{}`", desc.label))?;
        Ok(self.textures.insert(GlTexture {
            raw,
            desc: desc.clone(),
        }))
    }

    fn write_texture(
        &mut self,
        texture: Handle<Texture>,
        at: Subresource,
        data: &[u8],
    ) -> Result<()> {
        self.context.make_current()?;
        let tex = self.textures.get(texture)?;
        let (w, h) = check_upload(&tex.desc, at, data)?;
        let (format, ty) = conv::upload_format(tex.desc.format);
        let target = conv::target(tex.desc.kind);
        let pixels = glow::PixelUnpackData::Slice(Some(data));
        // SAFETY: see module docs; `data` holds exactly w*h texels (checked above).
        unsafe {
            self.gl.bind_texture(target, Some(tex.raw));
            match tex.desc.kind {
                TextureKind::D2 | TextureKind::Cube => self.gl.tex_sub_image_2d(
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
                TextureKind::D2Array { .. } => self.gl.tex_sub_image_3d(
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
            self.gl.bind_texture(target, None);
        }
        self.check_errors(&format!("upload to `{}`", tex.desc.label))
    }

    fn destroy_texture(&mut self, texture: Handle<Texture>) -> Result<()> {
        self.context.make_current()?;
        let tex = self.textures.remove(texture)?;
        // SAFETY: see module docs; the name is removed from the pool, so never used again.
        unsafe { self.gl.delete_texture(tex.raw) };
        Ok(())
    }

    fn create_buffer(&mut self, desc: &BufferDesc) -> Result<Handle<Buffer>> {
        self.context.make_current()?;
        check_buffer_desc(desc)?;
        let target = conv::buffer_target(desc.usage);
        // SAFETY: see module docs. An index buffer is bound to ARRAY_BUFFER for creation so that
        // no vertex array's element binding is touched.
        let raw = unsafe {
            let raw = self
                .gl
                .create_buffer()
                .map_err(|e| driver_error(&desc.label, e))?;
            let bind_target = if target == glow::ELEMENT_ARRAY_BUFFER {
                glow::ARRAY_BUFFER
            } else {
                target
            };
            self.gl.bind_buffer(bind_target, Some(raw));
            self.gl
                .buffer_data_size(bind_target, desc.size as i32, glow::DYNAMIC_DRAW);
            let zeros = vec![0u8; desc.size as usize];
            self.gl.buffer_sub_data_u8_slice(bind_target, 0, &zeros);
            self.gl.bind_buffer(bind_target, None);
            raw
        };
        self.check_errors(&format!("buffer `{}`", desc.label))?;
        Ok(self.buffers.insert(GlBuffer {
            raw,
            usage: desc.usage,
            size: desc.size,
        }))
    }

    fn write_buffer(&mut self, buffer: Handle<Buffer>, offset: u64, data: &[u8]) -> Result<()> {
        self.context.make_current()?;
        let buf = self.buffers.get(buffer)?;
        check_buffer_write(buf.usage, buf.size, offset, data.len())?;
        // SAFETY: see module docs; the range was checked against the buffer's size.
        unsafe {
            self.gl.bind_buffer(glow::COPY_WRITE_BUFFER, Some(buf.raw));
            self.gl
                .buffer_sub_data_u8_slice(glow::COPY_WRITE_BUFFER, offset as i32, data);
            self.gl.bind_buffer(glow::COPY_WRITE_BUFFER, None);
        }
        self.check_errors("buffer write")
    }

    fn destroy_buffer(&mut self, buffer: Handle<Buffer>) -> Result<()> {
        self.context.make_current()?;
        let buf = self.buffers.remove(buffer)?;
        // SAFETY: see module docs; removed from the pool, never used again.
        unsafe { self.gl.delete_buffer(buf.raw) };
        Ok(())
    }

    fn create_sampler(&mut self, desc: &SamplerDesc) -> Result<Handle<Sampler>> {
        self.context.make_current()?;
        let gl = &self.gl;
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
        self.check_errors(&format!("sampler `{}`", desc.label))?;
        Ok(self.samplers.insert(raw))
    }

    fn destroy_sampler(&mut self, sampler: Handle<Sampler>) -> Result<()> {
        self.context.make_current()?;
        let raw = self.samplers.remove(sampler)?;
        // SAFETY: see module docs; removed from the pool, never used again.
        unsafe { self.gl.delete_sampler(raw) };
        Ok(())
    }

    fn create_shader(&mut self, desc: &ShaderDesc) -> Result<Handle<Shader>> {
        let key = desc.cache_key();
        let module = match self.module_cache.get(&key) {
            Some(module) => module.clone(),
            None => {
                let module = Rc::new(shaders::validate(&desc.name, &desc.wgsl).map_err(|e| {
                    BackendError::Shader {
                        backend: BackendKind::Gl.name(),
                        name: desc.name.clone(),
                        message: e.to_string(),
                    }
                })?);
                self.module_cache.insert(key, module.clone());
                module
            }
        };
        Ok(self.shaders.insert(GlShader { module, key }))
    }

    fn destroy_shader(&mut self, shader: Handle<Shader>) -> Result<()> {
        self.shaders.remove(shader).map(drop)
    }

    fn create_pipeline(&mut self, desc: &PipelineDesc) -> Result<Handle<Pipeline>> {
        self.context.make_current()?;
        let shader = self.shaders.get(desc.shader)?;
        let cache_key = format!(
            "{:x}|{}|{:?}|{:?}|{:?}",
            shader.key,
            desc.vertex_entry,
            desc.fragment_entry,
            desc.geometry.as_ref().map(|g| (&g.name, &g.glsl)),
            desc.constants
        );
        let linked = match self.program_cache.get(&cache_key) {
            Some(linked) => linked.clone(),
            None => {
                let linked = self.link(desc)?;
                self.program_cache.insert(cache_key, linked.clone());
                self.pipelines_compiled += 1;
                linked
            }
        };
        let gl = &self.gl;
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
        self.check_errors(&format!("pipeline `{}`", desc.label))?;
        Ok(self.pipelines.insert(GlPipeline {
            program: linked.program,
            vao,
            desc: desc.clone(),
            sampler_units: linked.sampler_units,
        }))
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
        self.context.make_current()?;
        let gl = &self.gl;
        let mut queries = Vec::with_capacity(passes.len());
        for pass in passes {
            // SAFETY: see module docs.
            let pair = unsafe {
                (
                    gl.create_query().map_err(|e| driver_error(&pass.name, e))?,
                    gl.create_query().map_err(|e| driver_error(&pass.name, e))?,
                )
            };
            queries.push(pair);
        }
        let mut outcome = Ok(());
        for (pass, &pair) in passes.iter().zip(&queries) {
            outcome = self
                .execute_pass(pass, Some(pair))
                .and_then(|()| self.check_errors(&format!("pass `{}`", pass.name)));
            if outcome.is_err() {
                break;
            }
        }
        // SAFETY: see module docs; glFinish waits for all work, so query results are ready.
        let timings = unsafe {
            gl.finish();
            let timings: Vec<PassTiming> = passes
                .iter()
                .zip(&queries)
                .map(|(pass, &(begin, end))| {
                    let gpu_ns = outcome.is_ok().then(|| {
                        let t0 = gl.get_query_parameter_u64(begin, glow::QUERY_RESULT);
                        let t1 = gl.get_query_parameter_u64(end, glow::QUERY_RESULT);
                        t1.saturating_sub(t0) as f64
                    });
                    PassTiming {
                        name: pass.name.clone(),
                        gpu_ns,
                    }
                })
                .collect();
            for (begin, end) in queries {
                gl.delete_query(begin);
                gl.delete_query(end);
            }
            timings
        };
        outcome?;
        self.check_errors("submit")?;
        Ok(timings)
    }

    fn read_texture(&mut self, texture: Handle<Texture>, at: Subresource) -> Result<Image> {
        self.context.make_current()?;
        let desc = &self.textures.get(texture)?.desc;
        let (format, label) = (desc.format, desc.label.clone());
        let gl = &self.gl;
        // SAFETY: see module docs.
        let framebuffer =
            unsafe { gl.create_framebuffer() }.map_err(|e| driver_error(&label, e))?;
        let result = (|| {
            // SAFETY: see module docs; `framebuffer` was just created.
            unsafe { gl.bind_framebuffer(glow::READ_FRAMEBUFFER, Some(framebuffer)) };
            let attachment = if format.is_depth() {
                glow::DEPTH_ATTACHMENT
            } else {
                glow::COLOR_ATTACHMENT0
            };
            let (w, h) = self.attach(glow::READ_FRAMEBUFFER, attachment, texture, at)?;
            let (gl_format, ty) = conv::readback_format(format);
            let bytes_per_value = if ty == glow::UNSIGNED_BYTE { 1 } else { 4 };
            let mut bytes =
                vec![0u8; w as usize * h as usize * format.channels() * bytes_per_value];
            // SAFETY: see module docs; `bytes` is exactly w*h pixels of (gl_format, ty) with
            // PACK_ALIGNMENT 1. sRGB encoding is switched off so sRGB values come back raw.
            unsafe {
                gl.read_buffer(if format.is_depth() {
                    glow::NONE
                } else {
                    glow::COLOR_ATTACHMENT0
                });
                let status = gl.check_framebuffer_status(glow::READ_FRAMEBUFFER);
                if status != glow::FRAMEBUFFER_COMPLETE {
                    return Err(driver_error(
                        format!("readback of `{label}`"),
                        format!("framebuffer incomplete (0x{status:04x})"),
                    ));
                }
                gl.disable(glow::FRAMEBUFFER_SRGB);
                gl.read_pixels(
                    0,
                    0,
                    w as i32,
                    h as i32,
                    gl_format,
                    ty,
                    glow::PixelPackData::Slice(Some(&mut bytes)),
                );
                gl.enable(glow::FRAMEBUFFER_SRGB);
            }
            // Window row 0 is the top (GL_UPPER_LEFT), so the rows are already top-first.
            let data = if format.is_8bit() {
                ImageData::U8(bytes)
            } else {
                ImageData::F32(
                    bytes
                        .chunks_exact(4)
                        .map(|b| f32::from_ne_bytes([b[0], b[1], b[2], b[3]]))
                        .collect(),
                )
            };
            Ok(Image {
                width: w,
                height: h,
                format,
                data,
            })
        })();
        // SAFETY: see module docs.
        unsafe {
            gl.bind_framebuffer(glow::READ_FRAMEBUFFER, None);
            gl.delete_framebuffer(framebuffer);
        }
        let image = result?;
        self.check_errors(&format!("readback of `{label}`"))?;
        Ok(image)
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

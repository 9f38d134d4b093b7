//! Recording and submitting a frame's render passes: each pass runs into a temporary
//! framebuffer with its attachments, viewports and clears, then its draws set the pipeline's
//! fixed-function state and bindings and draw; timestamp queries time each pass on the GPU.
//!
//! Every `unsafe` block here is a GL call and relies on the invariant stated in [`super`]: the
//! context is current on this thread and every GL name used is alive and was made by it.

use glow::HasContext;

use super::device::driver_error;
use super::{conv, GlBackend};
use crate::backend::*;

/// Runs `passes` in order, each timed by a pair of timestamp queries, waits for the GPU and
/// returns each pass's GPU time.
pub(super) fn submit(backend: &GlBackend, passes: &[RenderPass]) -> Result<Vec<PassTiming>> {
    backend.context.make_current()?;
    let gl = &backend.gl;
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
        outcome = backend
            .execute_pass(pass, Some(pair))
            .and_then(|()| backend.check_errors(&format!("pass `{}`", pass.name)));
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
    backend.check_errors("submit")?;
    Ok(timings)
}

impl GlBackend {
    /// Attaches one mip/layer of `texture` to `attachment` of the bound `target` framebuffer.
    pub(super) fn attach(
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

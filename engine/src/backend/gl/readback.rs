//! Reading a texture's mip/layer back to the CPU: it is attached to a temporary read
//! framebuffer and read with `glReadPixels`, rows already top-first.
//!
//! Every `unsafe` block here is a GL call and relies on the invariant stated in [`super`]: the
//! context is current on this thread and every GL name used is alive and was made by it.

use glow::HasContext;

use super::device::driver_error;
use super::{conv, GlBackend};
use crate::backend::*;
use crate::image::{Image, ImageData};

/// Reads one mip/layer of a texture back into an image through a temporary read framebuffer.
pub(super) fn read_texture(
    backend: &GlBackend,
    texture: Handle<Texture>,
    at: Subresource,
) -> Result<Image> {
    backend.context.make_current()?;
    let desc = &backend.textures.get(texture)?.desc;
    let (format, label) = (desc.format, desc.label.clone());
    let gl = &backend.gl;
    // SAFETY: see module docs.
    let framebuffer = unsafe { gl.create_framebuffer() }.map_err(|e| driver_error(&label, e))?;
    let result = (|| {
        // SAFETY: see module docs; `framebuffer` was just created.
        unsafe { gl.bind_framebuffer(glow::READ_FRAMEBUFFER, Some(framebuffer)) };
        let attachment = if format.is_depth() {
            glow::DEPTH_ATTACHMENT
        } else {
            glow::COLOR_ATTACHMENT0
        };
        let (w, h) = backend.attach(glow::READ_FRAMEBUFFER, attachment, texture, at)?;
        let (gl_format, ty) = conv::readback_format(format);
        let bytes_per_value = if ty == glow::UNSIGNED_BYTE { 1 } else { 4 };
        let mut bytes = vec![0u8; w as usize * h as usize * format.channels() * bytes_per_value];
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
    backend.check_errors(&format!("readback of `{label}`"))?;
    Ok(image)
}

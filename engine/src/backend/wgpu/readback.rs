//! Reading GPU data back to the CPU: textures into images (depth through a copy pass that
//! packs it into a color texture) and buffers into bytes.

use ::wgpu;
use std::borrow::Cow;

use super::{DepthCopy, WgpuBackend};
use crate::backend::*;
use crate::image::Image;
use crate::shaders;

impl WgpuBackend {
    /// Maps `buffer`, copies its bytes out, unmaps it.
    pub(super) fn read_buffer(&self, buffer: &wgpu::Buffer, context: &str) -> Result<Vec<u8>> {
        let slice = buffer.slice(..);
        let (sender, receiver) = std::sync::mpsc::channel();
        slice.map_async(wgpu::MapMode::Read, move |r| {
            let _ = sender.send(r);
        });
        self.wait(context)?;
        receiver
            .recv()
            .map_err(|e| self.driver_error(context, e.to_string()))?
            .map_err(|e| self.driver_error(context, e.to_string()))?;
        let bytes = slice
            .get_mapped_range()
            .map_err(|e| self.driver_error(context, e.to_string()))?
            .to_vec();
        buffer.unmap();
        Ok(bytes)
    }
}

/// Reads one mip/layer of a texture back into an image.
pub(super) fn read_texture(
    backend: &mut WgpuBackend,
    texture: Handle<Texture>,
    at: Subresource,
) -> Result<Image> {
    let desc = backend.textures.get(texture)?.desc.clone();
    let (w, h) = desc.mip_size(at.mip);
    check_subresource(&desc, at)?;
    if !desc.format.is_depth() {
        let bytes = read_color(backend, &backend.textures.get(texture)?.texture, &desc, at)?;
        return Ok(Image::from_texel_bytes(w, h, desc.format, &bytes));
    }
    read_depth(backend, texture, &desc, at)
}

/// Reads a depth texture's mip/layer: a copy pass packs it into an RGBA8 texture (see
/// `depth_copy.wgsl`), which is then read like a color texture.
fn read_depth(
    backend: &mut WgpuBackend,
    texture: Handle<Texture>,
    desc: &TextureDesc,
    at: Subresource,
) -> Result<Image> {
    let (w, h) = desc.mip_size(at.mip);
    let source = backend.target_view(texture, at)?;
    let context = format!("depth readback of `{}`", desc.label);
    let scratch = backend.scoped(&context, || {
        backend.device.create_texture(&wgpu::TextureDescriptor {
            label: Some("depth readback"),
            size: wgpu::Extent3d {
                width: w,
                height: h,
                depth_or_array_layers: 1,
            },
            mip_level_count: 1,
            sample_count: 1,
            dimension: wgpu::TextureDimension::D2,
            format: wgpu::TextureFormat::Rgba8Unorm,
            usage: wgpu::TextureUsages::RENDER_ATTACHMENT | wgpu::TextureUsages::COPY_SRC,
            view_formats: &[],
        })
    })?;
    let scratch_view = scratch.create_view(&Default::default());
    let copy = depth_copy(backend)?;
    let copy_pipeline = copy.pipeline.clone();
    let copy_layout = copy.bind_group_layout.clone();
    let bind_group = backend.scoped(&context, || {
        backend
            .device
            .create_bind_group(&wgpu::BindGroupDescriptor {
                label: Some("depth copy"),
                layout: &copy_layout,
                entries: &[wgpu::BindGroupEntry {
                    binding: 0,
                    resource: wgpu::BindingResource::TextureView(&source),
                }],
            })
    })?;
    backend.scoped(&context, || {
        let mut encoder = backend
            .device
            .create_command_encoder(&wgpu::CommandEncoderDescriptor {
                label: Some("depth copy"),
            });
        {
            let mut pass = encoder.begin_render_pass(&wgpu::RenderPassDescriptor {
                label: Some("depth copy"),
                color_attachments: &[Some(wgpu::RenderPassColorAttachment {
                    view: &scratch_view,
                    depth_slice: None,
                    resolve_target: None,
                    ops: wgpu::Operations {
                        load: wgpu::LoadOp::Clear(wgpu::Color::BLACK),
                        store: wgpu::StoreOp::Store,
                    },
                })],
                depth_stencil_attachment: None,
                timestamp_writes: None,
                occlusion_query_set: None,
                multiview_mask: None,
            });
            pass.set_pipeline(&copy_pipeline);
            pass.set_bind_group(0, &bind_group, &[]);
            pass.draw(0..3, 0..1);
        }
        backend.queue.submit([encoder.finish()]);
    })?;
    // Each RGBA8 texel holds the little-endian bytes of one f32 depth.
    let scratch_desc = TextureDesc::d2("depth readback", w, h, TextureFormat::Rgba8Unorm);
    let bytes = read_color(backend, &scratch, &scratch_desc, Subresource::default())?;
    scratch.destroy();
    Ok(Image::from_texel_bytes(
        w,
        h,
        TextureFormat::Depth32Float,
        &bytes,
    ))
}

/// Copies a color texture's subresource into a mappable buffer and returns its texels.
fn read_color(
    backend: &WgpuBackend,
    texture: &wgpu::Texture,
    desc: &TextureDesc,
    at: Subresource,
) -> Result<Vec<u8>> {
    let (w, h) = desc.mip_size(at.mip);
    let row = w as usize * desc.format.texel_size();
    let padded_row = row.next_multiple_of(wgpu::COPY_BYTES_PER_ROW_ALIGNMENT as usize);
    let context = format!("readback of `{}`", desc.label);
    let buffer = backend.device.create_buffer(&wgpu::BufferDescriptor {
        label: Some("readback"),
        size: (padded_row * h as usize) as u64,
        usage: wgpu::BufferUsages::COPY_DST | wgpu::BufferUsages::MAP_READ,
        mapped_at_creation: false,
    });
    backend.scoped(&context, || {
        let mut encoder = backend
            .device
            .create_command_encoder(&wgpu::CommandEncoderDescriptor {
                label: Some("readback"),
            });
        encoder.copy_texture_to_buffer(
            wgpu::TexelCopyTextureInfo {
                texture,
                mip_level: at.mip,
                origin: wgpu::Origin3d {
                    x: 0,
                    y: 0,
                    z: at.layer,
                },
                aspect: wgpu::TextureAspect::All,
            },
            wgpu::TexelCopyBufferInfo {
                buffer: &buffer,
                layout: wgpu::TexelCopyBufferLayout {
                    offset: 0,
                    bytes_per_row: Some(padded_row as u32),
                    rows_per_image: Some(h),
                },
            },
            wgpu::Extent3d {
                width: w,
                height: h,
                depth_or_array_layers: 1,
            },
        );
        backend.queue.submit([encoder.finish()]);
    })?;
    let padded = backend.read_buffer(&buffer, &context)?;
    // Row by row (a byte-wise iterator here cost a tenth of the self-test's time).
    let mut texels = Vec::with_capacity(row * h as usize);
    for padded_row in padded.chunks_exact(padded_row) {
        texels.extend_from_slice(&padded_row[..row]);
    }
    Ok(texels)
}

/// The depth copy pipeline, created on first use.
fn depth_copy(backend: &mut WgpuBackend) -> Result<&DepthCopy> {
    if backend.depth_copy.is_none() {
        let module = backend.scoped("depth copy shader", || {
            backend
                .device
                .create_shader_module(wgpu::ShaderModuleDescriptor {
                    label: Some(shaders::DEPTH_COPY.name),
                    source: wgpu::ShaderSource::Wgsl(Cow::Borrowed(shaders::DEPTH_COPY.wgsl)),
                })
        })?;
        let bind_group_layout =
            backend
                .device
                .create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
                    label: Some("depth copy"),
                    entries: &[wgpu::BindGroupLayoutEntry {
                        binding: 0,
                        visibility: wgpu::ShaderStages::FRAGMENT,
                        ty: wgpu::BindingType::Texture {
                            sample_type: wgpu::TextureSampleType::Float { filterable: false },
                            view_dimension: wgpu::TextureViewDimension::D2,
                            multisampled: false,
                        },
                        count: None,
                    }],
                });
        let layout = backend
            .device
            .create_pipeline_layout(&wgpu::PipelineLayoutDescriptor {
                label: Some("depth copy"),
                bind_group_layouts: &[Some(&bind_group_layout)],
                immediate_size: 0,
            });
        let pipeline = backend.scoped("depth copy pipeline", || {
            backend
                .device
                .create_render_pipeline(&wgpu::RenderPipelineDescriptor {
                    label: Some("depth copy"),
                    layout: Some(&layout),
                    vertex: wgpu::VertexState {
                        module: &module,
                        entry_point: Some("vs_fullscreen"),
                        compilation_options: Default::default(),
                        buffers: &[],
                    },
                    primitive: wgpu::PrimitiveState::default(),
                    depth_stencil: None,
                    multisample: wgpu::MultisampleState::default(),
                    fragment: Some(wgpu::FragmentState {
                        module: &module,
                        entry_point: Some("fs_copy"),
                        compilation_options: Default::default(),
                        targets: &[Some(wgpu::ColorTargetState {
                            format: wgpu::TextureFormat::Rgba8Unorm,
                            blend: None,
                            write_mask: wgpu::ColorWrites::ALL,
                        })],
                    }),
                    multiview_mask: None,
                    cache: None,
                })
        })?;
        backend.depth_copy = Some(DepthCopy {
            pipeline,
            bind_group_layout,
        });
    }
    Ok(backend.depth_copy.as_ref().expect("just created"))
}

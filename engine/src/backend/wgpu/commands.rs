//! Recording and submitting a frame's render passes: their attachments, viewport and draws,
//! and the timestamp queries that time each pass on the GPU.

use ::wgpu;

use super::{conv, WgpuBackend};
use crate::backend::*;

/// The views and bind groups of one pass, made before recording: they must outlive the pass
/// encoders that use them.
struct PreparedPass {
    colors: Vec<wgpu::TextureView>,
    depth: Option<wgpu::TextureView>,
    bind_groups: Vec<wgpu::BindGroup>,
}

/// Two timestamp queries per pass (its beginning and end), resolved into a buffer and copied
/// into a mappable one.
struct PassTimestamps {
    set: wgpu::QuerySet,
    resolve: wgpu::Buffer,
    read: wgpu::Buffer,
    /// Queries in `set`: twice the number of passes.
    count: u32,
}

/// Records `passes` into one command encoder, submits it, waits for the GPU and returns each
/// pass's GPU time (where the device has timestamp queries).
pub(super) fn submit(backend: &WgpuBackend, passes: &[RenderPass]) -> Result<Vec<PassTiming>> {
    let prepared = passes
        .iter()
        .map(|pass| prepare_pass(backend, pass))
        .collect::<Result<Vec<_>>>()?;
    let query_count = 2 * passes.len() as u32;
    let timestamps = backend.timestamps && query_count > 0;
    let queries = timestamps.then(|| PassTimestamps::new(&backend.device, query_count));
    let names: Vec<&str> = passes.iter().map(|p| p.name.as_str()).collect();
    let context = format!("passes [{}]", names.join(", "));
    backend.scoped(&context, || -> Result<()> {
        let mut encoder = backend
            .device
            .create_command_encoder(&wgpu::CommandEncoderDescriptor {
                label: Some("frame"),
            });
        for (index, (pass, views)) in passes.iter().zip(&prepared).enumerate() {
            let timestamp_writes = queries.as_ref().map(|q| q.writes(index));
            record_pass(backend, &mut encoder, pass, views, timestamp_writes)?;
        }
        if let Some(queries) = &queries {
            queries.resolve(&mut encoder);
        }
        backend.queue.submit([encoder.finish()]);
        Ok(())
    })??;
    let gpu_ns: Vec<Option<f64>> = match &queries {
        Some(queries) => queries.read_gpu_ns(backend, &context)?,
        None => {
            backend.wait(&context)?;
            vec![None; passes.len()]
        }
    };
    Ok(passes
        .iter()
        .zip(gpu_ns)
        .map(|(p, gpu_ns)| PassTiming {
            name: p.name.clone(),
            gpu_ns,
        })
        .collect())
}

/// Checks that `pass` has at most one viewport and makes its attachment views and its draws'
/// bind groups.
fn prepare_pass(backend: &WgpuBackend, pass: &RenderPass) -> Result<PreparedPass> {
    if pass.viewports.len() > 1 {
        return Err(BackendError::Unsupported {
            backend: backend.kind.name(),
            what: format!("pass `{}`", pass.name),
            message: "viewport arrays need a geometry stage, which wgpu lacks".to_owned(),
        });
    }
    let colors = pass
        .color_attachments
        .iter()
        .map(|a| backend.target_view(a.texture, a.subresource))
        .collect::<Result<Vec<_>>>()?;
    let depth = pass
        .depth_attachment
        .map(|d| backend.target_view(d.texture, d.subresource))
        .transpose()?;
    let bind_groups = pass
        .draws
        .iter()
        .map(|d| backend.bind_group(backend.pipelines.get(d.pipeline)?, d))
        .collect::<Result<Vec<_>>>()?;
    Ok(PreparedPass {
        colors,
        depth,
        bind_groups,
    })
}

/// Records one render pass into `encoder`: begins it on its attachments, sets its viewport and
/// records its draws.
fn record_pass(
    backend: &WgpuBackend,
    encoder: &mut wgpu::CommandEncoder,
    pass: &RenderPass,
    views: &PreparedPass,
    timestamp_writes: Option<wgpu::RenderPassTimestampWrites>,
) -> Result<()> {
    let color_attachments: Vec<_> = pass
        .color_attachments
        .iter()
        .zip(&views.colors)
        .map(|(a, view)| {
            Some(wgpu::RenderPassColorAttachment {
                view,
                depth_slice: None,
                resolve_target: None,
                ops: wgpu::Operations {
                    load: conv::color_load(a.load),
                    store: wgpu::StoreOp::Store,
                },
            })
        })
        .collect();
    let depth_stencil_attachment = pass
        .depth_attachment
        .as_ref()
        .zip(views.depth.as_ref())
        .map(|(d, view)| wgpu::RenderPassDepthStencilAttachment {
            view,
            depth_ops: Some(wgpu::Operations {
                load: conv::depth_load(d.load),
                store: wgpu::StoreOp::Store,
            }),
            stencil_ops: None,
        });
    let mut render_pass = encoder.begin_render_pass(&wgpu::RenderPassDescriptor {
        label: Some(&pass.name),
        color_attachments: &color_attachments,
        depth_stencil_attachment,
        timestamp_writes,
        occlusion_query_set: None,
        multiview_mask: None,
    });
    if let Some(v) = pass.viewports.first() {
        render_pass.set_viewport(v.x, v.y, v.width, v.height, v.min_depth, v.max_depth);
    }
    for (draw, bind_group) in pass.draws.iter().zip(&views.bind_groups) {
        record_draw(backend, &mut render_pass, draw, bind_group)?;
    }
    Ok(())
}

/// Records one draw: its pipeline, bind group 0, vertex buffers and (indexed) draw call.
fn record_draw(
    backend: &WgpuBackend,
    render_pass: &mut wgpu::RenderPass,
    draw: &Draw,
    bind_group: &wgpu::BindGroup,
) -> Result<()> {
    render_pass.set_pipeline(&backend.pipelines.get(draw.pipeline)?.pipeline);
    render_pass.set_bind_group(0, bind_group, &[]);
    for (slot, buffer) in draw.vertex_buffers.iter().enumerate() {
        render_pass.set_vertex_buffer(slot as u32, backend.buffers.get(*buffer)?.buffer.slice(..));
    }
    match draw.index_buffer {
        Some((buffer, format)) => {
            render_pass.set_index_buffer(
                backend.buffers.get(buffer)?.buffer.slice(..),
                conv::index_format(format),
            );
            render_pass.draw_indexed(0..draw.count, 0, 0..1);
        }
        None => render_pass.draw(0..draw.count, 0..1),
    }
    Ok(())
}

impl PassTimestamps {
    /// Creates the query set and both buffers for `count` queries.
    fn new(device: &wgpu::Device, count: u32) -> Self {
        let set = device.create_query_set(&wgpu::QuerySetDescriptor {
            label: Some("pass timestamps"),
            ty: wgpu::QueryType::Timestamp,
            count,
        });
        let size = count as u64 * 8;
        let resolve = device.create_buffer(&wgpu::BufferDescriptor {
            label: Some("timestamp resolve"),
            size,
            usage: wgpu::BufferUsages::QUERY_RESOLVE | wgpu::BufferUsages::COPY_SRC,
            mapped_at_creation: false,
        });
        let read = device.create_buffer(&wgpu::BufferDescriptor {
            label: Some("timestamp read"),
            size,
            usage: wgpu::BufferUsages::COPY_DST | wgpu::BufferUsages::MAP_READ,
            mapped_at_creation: false,
        });
        Self {
            set,
            resolve,
            read,
            count,
        }
    }

    /// Where the pass at `index` writes its beginning and end timestamps.
    fn writes(&self, index: usize) -> wgpu::RenderPassTimestampWrites<'_> {
        wgpu::RenderPassTimestampWrites {
            query_set: &self.set,
            beginning_of_pass_write_index: Some(2 * index as u32),
            end_of_pass_write_index: Some(2 * index as u32 + 1),
        }
    }

    /// Records resolving every query and copying the results into the mappable buffer.
    fn resolve(&self, encoder: &mut wgpu::CommandEncoder) {
        encoder.resolve_query_set(&self.set, 0..self.count, &self.resolve, 0);
        encoder.copy_buffer_to_buffer(&self.resolve, 0, &self.read, 0, self.count as u64 * 8);
    }

    /// Reads the submitted queries back: each pass's time between its two timestamps, in
    /// nanoseconds.
    fn read_gpu_ns(&self, backend: &WgpuBackend, context: &str) -> Result<Vec<Option<f64>>> {
        let bytes = backend.read_buffer(&self.read, context)?;
        let ticks: Vec<u64> = bytes
            .chunks_exact(8)
            .map(|b| u64::from_le_bytes(b.try_into().expect("8 bytes")))
            .collect();
        let period = backend.queue.get_timestamp_period() as f64;
        Ok(ticks
            .chunks_exact(2)
            .map(|t| Some(t[1].saturating_sub(t[0]) as f64 * period))
            .collect())
    }
}

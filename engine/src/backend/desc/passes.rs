//! Pass and draw descriptors: attachments and their load operations, viewports, the resources
//! bound for a [`Draw`], the [`RenderPass`] that groups draws, and the [`PassTiming`] a submitted
//! pass reports.

use super::{Buffer, Handle, Pipeline, Sampler, Subresource, Texture};

/// What happens to an attachment when a pass starts.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum LoadOp<T> {
    /// Clear to a value.
    Clear(T),
    /// Keep previous contents.
    Load,
}

/// A color attachment of a render pass.
#[derive(Clone, Copy, Debug)]
pub struct ColorAttachment {
    /// Target texture.
    pub texture: Handle<Texture>,
    /// Mip level and layer rendered to.
    pub subresource: Subresource,
    /// Clear or keep.
    pub load: LoadOp<[f32; 4]>,
}

/// The depth attachment of a render pass.
#[derive(Clone, Copy, Debug)]
pub struct DepthAttachment {
    /// Target texture (a depth format).
    pub texture: Handle<Texture>,
    /// Mip level and layer rendered to.
    pub subresource: Subresource,
    /// Clear or keep.
    pub load: LoadOp<f32>,
}

/// Viewport in pixels, origin top-left; depth range 0..1 by default.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Viewport {
    /// Left edge.
    pub x: f32,
    /// Top edge.
    pub y: f32,
    /// Width.
    pub width: f32,
    /// Height.
    pub height: f32,
    /// Near depth.
    pub min_depth: f32,
    /// Far depth.
    pub max_depth: f32,
}

/// A resource bound to a slot for one draw.
#[derive(Clone, Copy, Debug)]
pub enum BindingResource {
    /// A whole uniform buffer.
    Buffer(Handle<Buffer>),
    /// A texture, viewed with the pipeline's declared dimension.
    Texture(Handle<Texture>),
    /// A sampler.
    Sampler(Handle<Sampler>),
}

/// A resource for `@group(0) @binding(binding)`.
#[derive(Clone, Copy, Debug)]
pub struct Binding {
    /// Slot.
    pub binding: u32,
    /// Resource.
    pub resource: BindingResource,
}

/// Index element width.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum IndexFormat {
    /// u16 indices.
    U16,
    /// u32 indices.
    U32,
}

/// One draw call.
#[derive(Clone, Debug)]
pub struct Draw {
    /// Pipeline.
    pub pipeline: Handle<Pipeline>,
    /// Bind group 0 contents; must cover every slot the pipeline declares.
    pub bindings: Vec<Binding>,
    /// One buffer per vertex slot of the pipeline.
    pub vertex_buffers: Vec<Handle<Buffer>>,
    /// Indexed drawing, if set.
    pub index_buffer: Option<(Handle<Buffer>, IndexFormat)>,
    /// Vertices (or indices) to draw.
    pub count: u32,
}

/// One render pass: attachments, viewport and draws. Its GPU time is reported under `name`.
#[derive(Clone, Debug)]
pub struct RenderPass {
    /// Name used for timings and errors.
    pub name: String,
    /// Color attachments, in `@location` order.
    pub color_attachments: Vec<ColorAttachment>,
    /// Depth attachment.
    pub depth_attachment: Option<DepthAttachment>,
    /// Viewports: none covers the whole first attachment; one is the viewport; more are a
    /// viewport array, chosen per primitive by a geometry stage's `gl_ViewportIndex` (only with
    /// [`Features::geometry_shaders`](super::Features::geometry_shaders); every entry must
    /// share the first one's depth range).
    pub viewports: Vec<Viewport>,
    /// Draws, in order.
    pub draws: Vec<Draw>,
}

/// GPU time of one submitted pass.
#[derive(Clone, Debug, serde::Serialize)]
pub struct PassTiming {
    /// The pass's name.
    pub name: String,
    /// Nanoseconds between the pass's start and end timestamps; `None` when the backend has none.
    pub gpu_ns: Option<f64>,
}

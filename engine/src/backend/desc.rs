//! Typed handles and descriptor structs: the vocabulary every backend speaks.
//!
//! Descriptors are plain data. A backend turns them into driver objects (see each backend's
//! `conv.rs`) and hands back a [`Handle`], which is only meaningful to the backend that made it.

use std::fmt;
use std::marker::PhantomData;

/// A typed reference to a backend resource (index plus generation, so a stale handle is detected).
pub struct Handle<T> {
    pub(crate) index: u32,
    pub(crate) generation: u32,
    _marker: PhantomData<fn() -> T>,
}

impl<T> Handle<T> {
    pub(crate) fn new(index: u32, generation: u32) -> Self {
        Self {
            index,
            generation,
            _marker: PhantomData,
        }
    }
}

impl<T> Clone for Handle<T> {
    fn clone(&self) -> Self {
        *self
    }
}
impl<T> Copy for Handle<T> {}
impl<T> PartialEq for Handle<T> {
    fn eq(&self, other: &Self) -> bool {
        self.index == other.index && self.generation == other.generation
    }
}
impl<T> Eq for Handle<T> {}
impl<T> std::hash::Hash for Handle<T> {
    fn hash<H: std::hash::Hasher>(&self, state: &mut H) {
        self.index.hash(state);
        self.generation.hash(state);
    }
}
impl<T> fmt::Debug for Handle<T> {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "Handle({}v{})", self.index, self.generation)
    }
}

/// Marker for texture handles.
pub enum Texture {}
/// Marker for buffer handles.
pub enum Buffer {}
/// Marker for sampler handles.
pub enum Sampler {}
/// Marker for shader-module handles.
pub enum Shader {}
/// Marker for render-pipeline handles.
pub enum Pipeline {}

/// Pixel formats of textures and render targets.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, serde::Serialize)]
pub enum TextureFormat {
    /// 8-bit RGBA, linear.
    Rgba8Unorm,
    /// 8-bit RGBA, sRGB-encoded (decoded on sampling, encoded on write).
    Rgba8UnormSrgb,
    /// 16-bit float RGBA (HDR targets, the G-buffer).
    Rgba16Float,
    /// 32-bit float RGBA.
    Rgba32Float,
    /// 32-bit float, one channel.
    R32Float,
    /// 32-bit float depth.
    Depth32Float,
}

impl TextureFormat {
    /// Bytes of one texel as uploaded with [`Backend::write_texture`](super::Backend::write_texture).
    pub fn texel_size(self) -> usize {
        match self {
            Self::Rgba8Unorm | Self::Rgba8UnormSrgb => 4,
            Self::Rgba16Float => 8,
            Self::Rgba32Float => 16,
            Self::R32Float | Self::Depth32Float => 4,
        }
    }

    /// Channels per texel.
    pub fn channels(self) -> usize {
        match self {
            Self::R32Float | Self::Depth32Float => 1,
            _ => 4,
        }
    }

    /// Whether this is a depth format.
    pub fn is_depth(self) -> bool {
        matches!(self, Self::Depth32Float)
    }

    /// Whether texels are 8-bit normalized (read back as `u8`) rather than float.
    pub fn is_8bit(self) -> bool {
        matches!(self, Self::Rgba8Unorm | Self::Rgba8UnormSrgb)
    }
}

/// Shape of a texture.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum TextureKind {
    /// A single 2D image.
    D2,
    /// A cube map: six layers in the order +X, -X, +Y, -Y, +Z, -Z.
    Cube,
    /// An array of 2D layers.
    D2Array {
        /// Number of layers.
        layers: u32,
    },
}

impl TextureKind {
    /// Number of array layers (6 for a cube).
    pub fn layers(self) -> u32 {
        match self {
            Self::D2 => 1,
            Self::Cube => 6,
            Self::D2Array { layers } => layers,
        }
    }
}

/// Describes a texture. Every texture can be sampled, rendered to, uploaded to and read back.
#[derive(Clone, Debug)]
pub struct TextureDesc {
    /// Debug label, shown in errors and driver tools.
    pub label: String,
    /// Width of mip 0 in texels.
    pub width: u32,
    /// Height of mip 0 in texels.
    pub height: u32,
    /// 2D, cube or 2D array.
    pub kind: TextureKind,
    /// Number of mip levels (at least 1).
    pub mip_levels: u32,
    /// Texel format.
    pub format: TextureFormat,
}

impl TextureDesc {
    /// A single-mip 2D texture.
    pub fn d2(label: &str, width: u32, height: u32, format: TextureFormat) -> Self {
        Self {
            label: label.to_owned(),
            width,
            height,
            kind: TextureKind::D2,
            mip_levels: 1,
            format,
        }
    }

    /// Size of mip `level` (never below 1x1).
    pub fn mip_size(&self, level: u32) -> (u32, u32) {
        ((self.width >> level).max(1), (self.height >> level).max(1))
    }
}

/// One 2D image inside a texture: a mip level of one layer (or cube face).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash)]
pub struct Subresource {
    /// Mip level.
    pub mip: u32,
    /// Array layer or cube face.
    pub layer: u32,
}

/// How a buffer is used.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum BufferUsage {
    /// Vertex attributes.
    Vertex,
    /// 16- or 32-bit indices.
    Index,
    /// Uniform data (std140 / WGSL uniform layout).
    Uniform,
    /// Read-only storage data (`var<storage, read>`), for parameters a driver must not
    /// specialise shaders on (see [`BindingKind::StorageBuffer`]).
    Storage,
}

/// Describes a buffer.
#[derive(Clone, Debug)]
pub struct BufferDesc {
    /// Debug label.
    pub label: String,
    /// Size in bytes (a multiple of 4).
    pub size: u64,
    /// What it is bound as.
    pub usage: BufferUsage,
}

/// Texture filtering.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum FilterMode {
    /// Nearest texel.
    Nearest,
    /// Linear interpolation.
    Linear,
}

/// Texture coordinate wrapping.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum AddressMode {
    /// Clamp to the edge texel.
    ClampToEdge,
    /// Repeat.
    Repeat,
    /// Repeat mirrored.
    MirrorRepeat,
}

/// Comparison functions for depth tests and depth-compare samplers.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum CompareFunction {
    /// Never passes.
    Never,
    /// new < old.
    Less,
    /// new <= old.
    LessEqual,
    /// new == old.
    Equal,
    /// new > old.
    Greater,
    /// new >= old.
    GreaterEqual,
    /// new != old.
    NotEqual,
    /// Always passes.
    Always,
}

/// Describes a sampler.
#[derive(Clone, Debug)]
pub struct SamplerDesc {
    /// Debug label.
    pub label: String,
    /// Magnification filter.
    pub mag_filter: FilterMode,
    /// Minification filter.
    pub min_filter: FilterMode,
    /// Filter between mip levels.
    pub mipmap_filter: FilterMode,
    /// Wrapping for u, v and w.
    pub address_mode: AddressMode,
    /// Depth comparison (shadow lookups); `None` for an ordinary sampler.
    pub compare: Option<CompareFunction>,
}

impl SamplerDesc {
    /// Nearest-texel sampling, clamped: exact reads of render targets.
    pub fn nearest(label: &str) -> Self {
        Self {
            label: label.to_owned(),
            mag_filter: FilterMode::Nearest,
            min_filter: FilterMode::Nearest,
            mipmap_filter: FilterMode::Nearest,
            address_mode: AddressMode::ClampToEdge,
            compare: None,
        }
    }

    /// Trilinear sampling with the given wrapping.
    pub fn linear(label: &str, address_mode: AddressMode) -> Self {
        Self {
            label: label.to_owned(),
            mag_filter: FilterMode::Linear,
            min_filter: FilterMode::Linear,
            mipmap_filter: FilterMode::Linear,
            address_mode,
            compare: None,
        }
    }
}

/// A WGSL shader module (see [`crate::shaders`]); entry points are chosen per pipeline.
#[derive(Clone, Debug)]
pub struct ShaderDesc {
    /// File name under `engine/shaders/`, for messages.
    pub name: String,
    /// WGSL source.
    pub wgsl: String,
}

impl ShaderDesc {
    /// A hash of the name and source: the key of the backends' module and pipeline caches.
    pub fn cache_key(&self) -> u64 {
        use std::hash::{Hash, Hasher};
        let mut hasher = std::collections::hash_map::DefaultHasher::new();
        (&self.name, &self.wgsl).hash(&mut hasher);
        hasher.finish()
    }
}

/// Vertex attribute formats.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum VertexFormat {
    /// One f32.
    Float32,
    /// Two f32.
    Float32x2,
    /// Three f32.
    Float32x3,
    /// Four f32.
    Float32x4,
}

impl VertexFormat {
    /// Number of f32 components.
    pub fn components(self) -> u32 {
        match self {
            Self::Float32 => 1,
            Self::Float32x2 => 2,
            Self::Float32x3 => 3,
            Self::Float32x4 => 4,
        }
    }
}

/// One vertex attribute inside an interleaved buffer.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub struct VertexAttribute {
    /// `@location` in the WGSL vertex input.
    pub location: u32,
    /// Format.
    pub format: VertexFormat,
    /// Byte offset inside a vertex.
    pub offset: u32,
}

/// Layout of one vertex buffer slot.
#[derive(Clone, Debug, PartialEq, Eq, Hash)]
pub struct VertexBufferLayout {
    /// Bytes between consecutive vertices.
    pub stride: u32,
    /// Attributes read from this buffer.
    pub attributes: Vec<VertexAttribute>,
}

/// What a texture binding holds, as declared in WGSL.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum TextureSampleType {
    /// `texture_2d<f32>` etc., filterable.
    Float,
    /// Float texture that must not be filtered (e.g. RGBA32F on drivers without float32 filtering).
    UnfilterableFloat,
    /// `texture_depth_*`.
    Depth,
}

/// The dimension a texture binding is viewed with.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum TextureViewKind {
    /// `texture_2d`.
    D2,
    /// `texture_cube`.
    Cube,
    /// `texture_2d_array`.
    D2Array,
}

/// What a sampler binding is.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum SamplerBindingKind {
    /// Linear filtering allowed.
    Filtering,
    /// Nearest only.
    NonFiltering,
    /// `sampler_comparison`.
    Comparison,
}

/// One entry of a pipeline's (single) bind group: `@group(0) @binding(n)`.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum BindingKind {
    /// `var<uniform>`.
    UniformBuffer,
    /// `var<storage, read>`: read-only storage, for parameters a driver must not specialise
    /// shaders on. Mesa 22.3's lavapipe inlines uniform-buffer values that steer loops and
    /// branches, compiling a new shader for every draw that binds a new uniform buffer and never
    /// freeing the old one (~3.7 MiB per frame); it does not look into storage buffers. Costlier
    /// to read than uniforms on llvmpipe and lavapipe (a bounds-checked load per pixel).
    StorageBuffer,
    /// A sampled texture.
    Texture {
        /// Sample type.
        sample_type: TextureSampleType,
        /// View dimension.
        view: TextureViewKind,
    },
    /// A sampler.
    Sampler(SamplerBindingKind),
}

/// A binding slot declared by a pipeline.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub struct BindingLayout {
    /// `@binding(n)` in group 0.
    pub binding: u32,
    /// What the slot holds.
    pub kind: BindingKind,
}

/// Blend factors.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum BlendFactor {
    /// 0.
    Zero,
    /// 1.
    One,
    /// Source alpha.
    SrcAlpha,
    /// 1 - source alpha.
    OneMinusSrcAlpha,
    /// Destination alpha.
    DstAlpha,
    /// 1 - destination alpha.
    OneMinusDstAlpha,
}

/// Blend equations.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum BlendOperation {
    /// src + dst.
    Add,
    /// src - dst.
    Subtract,
    /// dst - src.
    ReverseSubtract,
    /// min(src, dst).
    Min,
    /// max(src, dst).
    Max,
}

/// One blend equation (color or alpha).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub struct BlendComponent {
    /// Source factor.
    pub src: BlendFactor,
    /// Destination factor.
    pub dst: BlendFactor,
    /// Operation.
    pub op: BlendOperation,
}

/// Blending for one color target.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub struct BlendState {
    /// RGB equation.
    pub color: BlendComponent,
    /// Alpha equation.
    pub alpha: BlendComponent,
}

impl BlendState {
    /// dst += src: accumulating light into an HDR buffer.
    pub const ADDITIVE: Self = Self {
        color: BlendComponent {
            src: BlendFactor::One,
            dst: BlendFactor::One,
            op: BlendOperation::Add,
        },
        alpha: BlendComponent {
            src: BlendFactor::One,
            dst: BlendFactor::One,
            op: BlendOperation::Add,
        },
    };
}

/// One color output of a pipeline.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub struct ColorTarget {
    /// Format of the attachment it writes.
    pub format: TextureFormat,
    /// Blending; `None` replaces.
    pub blend: Option<BlendState>,
}

/// Depth test and write.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub struct DepthState {
    /// Depth attachment format.
    pub format: TextureFormat,
    /// Write depth.
    pub write: bool,
    /// Test; `Always` disables testing.
    pub compare: CompareFunction,
}

/// Primitive topology.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum Topology {
    /// Independent triangles.
    TriangleList,
    /// Triangle strip.
    TriangleStrip,
    /// Independent lines.
    LineList,
}

/// Face culling.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum CullMode {
    /// Draw both faces.
    None,
    /// Cull front faces.
    Front,
    /// Cull back faces.
    Back,
}

/// Describes a render pipeline: a WGSL vertex/fragment pair and its fixed-function state.
#[derive(Clone, Debug)]
pub struct PipelineDesc {
    /// Debug label.
    pub label: String,
    /// Module holding both entry points.
    pub shader: Handle<Shader>,
    /// Vertex entry point.
    pub vertex_entry: String,
    /// Fragment entry point; `None` for depth-only pipelines.
    pub fragment_entry: Option<String>,
    /// Vertex buffer slots, in slot order.
    pub vertex_buffers: Vec<VertexBufferLayout>,
    /// Bind group 0.
    pub bindings: Vec<BindingLayout>,
    /// Color outputs, in `@location` order.
    pub color_targets: Vec<ColorTarget>,
    /// Depth state, if the pass has a depth attachment.
    pub depth: Option<DepthState>,
    /// Topology.
    pub topology: Topology,
    /// Culling; front faces are counter-clockwise in normalized device coordinates (y up).
    pub cull: CullMode,
    /// A geometry stage between vertex and fragment; only backends whose
    /// [`Features::geometry_shaders`] is true accept one (the others return
    /// [`BackendError::Unsupported`](super::BackendError::Unsupported)).
    pub geometry: Option<GeometryStage>,
    /// Values of the shader's pipeline-overridable constants (WGSL `override`), by name; every
    /// stage sees the same list. Pipelines that differ only here are different pipelines.
    pub constants: Vec<(String, f64)>,
}

/// A geometry stage. WGSL has none, so it is GLSL 4.50 core, for the GL backend only; it reads
/// the vertex stage's `gl_Position` and may route primitives with `gl_ViewportIndex`.
#[derive(Clone, Debug)]
pub struct GeometryStage {
    /// File name, for messages.
    pub name: String,
    /// GLSL source.
    pub glsl: String,
}

/// Optional capabilities of a backend.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, serde::Serialize)]
pub struct Features {
    /// Geometry stages ([`PipelineDesc::geometry`]) and viewport arrays (passes with more than
    /// one entry in [`RenderPass::viewports`]).
    pub geometry_shaders: bool,
}

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
    /// [`Features::geometry_shaders`]; every entry must share the first one's depth range).
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

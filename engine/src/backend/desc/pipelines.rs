//! Shader and pipeline descriptors: the WGSL module ([`ShaderDesc`]), vertex layouts, binding
//! layouts, blending, depth and rasterizer state gathered in a [`PipelineDesc`], the GL-only
//! [`GeometryStage`], and the optional [`Features`] a backend offers.

use super::{CompareFunction, Handle, Shader, TextureFormat};

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
    /// [`BackendError::Unsupported`](crate::backend::BackendError::Unsupported)).
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
    /// one entry in [`RenderPass::viewports`](super::RenderPass::viewports)).
    pub geometry_shaders: bool,
}

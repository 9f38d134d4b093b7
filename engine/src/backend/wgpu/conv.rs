//! Descriptor-to-wgpu conversions.

use crate::backend::desc::*;
use ::wgpu;

/// A texture format.
pub(super) fn format(f: TextureFormat) -> wgpu::TextureFormat {
    match f {
        TextureFormat::Rgba8Unorm => wgpu::TextureFormat::Rgba8Unorm,
        TextureFormat::Rgba8UnormSrgb => wgpu::TextureFormat::Rgba8UnormSrgb,
        TextureFormat::Rgba16Float => wgpu::TextureFormat::Rgba16Float,
        TextureFormat::Rgba32Float => wgpu::TextureFormat::Rgba32Float,
        TextureFormat::R32Float => wgpu::TextureFormat::R32Float,
        TextureFormat::Depth32Float => wgpu::TextureFormat::Depth32Float,
    }
}

/// A magnification or minification filter.
pub(super) fn filter(f: FilterMode) -> wgpu::FilterMode {
    match f {
        FilterMode::Nearest => wgpu::FilterMode::Nearest,
        FilterMode::Linear => wgpu::FilterMode::Linear,
    }
}

/// The filter between mip levels.
pub(super) fn mipmap_filter(f: FilterMode) -> wgpu::MipmapFilterMode {
    match f {
        FilterMode::Nearest => wgpu::MipmapFilterMode::Nearest,
        FilterMode::Linear => wgpu::MipmapFilterMode::Linear,
    }
}

/// An address (wrap) mode.
pub(super) fn address(a: AddressMode) -> wgpu::AddressMode {
    match a {
        AddressMode::ClampToEdge => wgpu::AddressMode::ClampToEdge,
        AddressMode::Repeat => wgpu::AddressMode::Repeat,
        AddressMode::MirrorRepeat => wgpu::AddressMode::MirrorRepeat,
    }
}

/// A depth or sampler comparison.
pub(super) fn compare(c: CompareFunction) -> wgpu::CompareFunction {
    match c {
        CompareFunction::Never => wgpu::CompareFunction::Never,
        CompareFunction::Less => wgpu::CompareFunction::Less,
        CompareFunction::LessEqual => wgpu::CompareFunction::LessEqual,
        CompareFunction::Equal => wgpu::CompareFunction::Equal,
        CompareFunction::Greater => wgpu::CompareFunction::Greater,
        CompareFunction::GreaterEqual => wgpu::CompareFunction::GreaterEqual,
        CompareFunction::NotEqual => wgpu::CompareFunction::NotEqual,
        CompareFunction::Always => wgpu::CompareFunction::Always,
    }
}

/// A vertex attribute format.
pub(super) fn vertex_format(f: VertexFormat) -> wgpu::VertexFormat {
    match f {
        VertexFormat::Float32 => wgpu::VertexFormat::Float32,
        VertexFormat::Float32x2 => wgpu::VertexFormat::Float32x2,
        VertexFormat::Float32x3 => wgpu::VertexFormat::Float32x3,
        VertexFormat::Float32x4 => wgpu::VertexFormat::Float32x4,
    }
}

/// The dimension a texture binding is viewed with.
pub(super) fn view_dimension(v: TextureViewKind) -> wgpu::TextureViewDimension {
    match v {
        TextureViewKind::D2 => wgpu::TextureViewDimension::D2,
        TextureViewKind::Cube => wgpu::TextureViewDimension::Cube,
        TextureViewKind::D2Array => wgpu::TextureViewDimension::D2Array,
    }
}

/// What a bind group slot holds.
pub(super) fn binding_type(kind: BindingKind) -> wgpu::BindingType {
    match kind {
        BindingKind::UniformBuffer => wgpu::BindingType::Buffer {
            ty: wgpu::BufferBindingType::Uniform,
            has_dynamic_offset: false,
            min_binding_size: None,
        },
        BindingKind::StorageBuffer => wgpu::BindingType::Buffer {
            ty: wgpu::BufferBindingType::Storage { read_only: true },
            has_dynamic_offset: false,
            min_binding_size: None,
        },
        BindingKind::Texture { sample_type, view } => wgpu::BindingType::Texture {
            sample_type: match sample_type {
                TextureSampleType::Float => wgpu::TextureSampleType::Float { filterable: true },
                TextureSampleType::UnfilterableFloat => {
                    wgpu::TextureSampleType::Float { filterable: false }
                }
                TextureSampleType::Depth => wgpu::TextureSampleType::Depth,
            },
            view_dimension: view_dimension(view),
            multisampled: false,
        },
        BindingKind::Sampler(kind) => wgpu::BindingType::Sampler(match kind {
            SamplerBindingKind::Filtering => wgpu::SamplerBindingType::Filtering,
            SamplerBindingKind::NonFiltering => wgpu::SamplerBindingType::NonFiltering,
            SamplerBindingKind::Comparison => wgpu::SamplerBindingType::Comparison,
        }),
    }
}

/// A blend factor.
fn blend_factor(f: BlendFactor) -> wgpu::BlendFactor {
    match f {
        BlendFactor::Zero => wgpu::BlendFactor::Zero,
        BlendFactor::One => wgpu::BlendFactor::One,
        BlendFactor::SrcAlpha => wgpu::BlendFactor::SrcAlpha,
        BlendFactor::OneMinusSrcAlpha => wgpu::BlendFactor::OneMinusSrcAlpha,
        BlendFactor::DstAlpha => wgpu::BlendFactor::DstAlpha,
        BlendFactor::OneMinusDstAlpha => wgpu::BlendFactor::OneMinusDstAlpha,
    }
}

/// The blend equation of the color or the alpha channel.
fn blend_component(c: BlendComponent) -> wgpu::BlendComponent {
    wgpu::BlendComponent {
        src_factor: blend_factor(c.src),
        dst_factor: blend_factor(c.dst),
        operation: match c.op {
            BlendOperation::Add => wgpu::BlendOperation::Add,
            BlendOperation::Subtract => wgpu::BlendOperation::Subtract,
            BlendOperation::ReverseSubtract => wgpu::BlendOperation::ReverseSubtract,
            BlendOperation::Min => wgpu::BlendOperation::Min,
            BlendOperation::Max => wgpu::BlendOperation::Max,
        },
    }
}

/// Color and alpha blending.
pub(super) fn blend(b: BlendState) -> wgpu::BlendState {
    wgpu::BlendState {
        color: blend_component(b.color),
        alpha: blend_component(b.alpha),
    }
}

/// A primitive topology.
pub(super) fn topology(t: Topology) -> wgpu::PrimitiveTopology {
    match t {
        Topology::TriangleList => wgpu::PrimitiveTopology::TriangleList,
        Topology::TriangleStrip => wgpu::PrimitiveTopology::TriangleStrip,
        Topology::LineList => wgpu::PrimitiveTopology::LineList,
    }
}

/// The faces culled (`None` culls nothing).
pub(super) fn cull(c: CullMode) -> Option<wgpu::Face> {
    match c {
        CullMode::None => None,
        CullMode::Front => Some(wgpu::Face::Front),
        CullMode::Back => Some(wgpu::Face::Back),
    }
}

/// A buffer's usage, always with `COPY_DST` so that it can be written.
pub(super) fn buffer_usage(u: BufferUsage) -> wgpu::BufferUsages {
    wgpu::BufferUsages::COPY_DST
        | match u {
            BufferUsage::Vertex => wgpu::BufferUsages::VERTEX,
            BufferUsage::Index => wgpu::BufferUsages::INDEX,
            BufferUsage::Uniform => wgpu::BufferUsages::UNIFORM,
            BufferUsage::Storage => wgpu::BufferUsages::STORAGE,
        }
}

/// An index element width.
pub(super) fn index_format(f: IndexFormat) -> wgpu::IndexFormat {
    match f {
        IndexFormat::U16 => wgpu::IndexFormat::Uint16,
        IndexFormat::U32 => wgpu::IndexFormat::Uint32,
    }
}

/// The load operation of a color attachment.
pub(super) fn color_load(op: LoadOp<[f32; 4]>) -> wgpu::LoadOp<wgpu::Color> {
    match op {
        LoadOp::Clear([r, g, b, a]) => wgpu::LoadOp::Clear(wgpu::Color {
            r: r as f64,
            g: g as f64,
            b: b as f64,
            a: a as f64,
        }),
        LoadOp::Load => wgpu::LoadOp::Load,
    }
}

/// The load operation of a depth attachment.
pub(super) fn depth_load(op: LoadOp<f32>) -> wgpu::LoadOp<f32> {
    match op {
        LoadOp::Clear(v) => wgpu::LoadOp::Clear(v),
        LoadOp::Load => wgpu::LoadOp::Load,
    }
}

/// A slot of a pipeline's bind group 0, visible to the vertex and fragment stages.
pub(super) fn bind_group_layout_entry(b: &BindingLayout) -> wgpu::BindGroupLayoutEntry {
    wgpu::BindGroupLayoutEntry {
        binding: b.binding,
        visibility: wgpu::ShaderStages::VERTEX_FRAGMENT,
        ty: binding_type(b.kind),
        count: None,
    }
}

/// The attributes read from one vertex buffer.
pub(super) fn vertex_attributes(layout: &VertexBufferLayout) -> Vec<wgpu::VertexAttribute> {
    layout
        .attributes
        .iter()
        .map(|a| wgpu::VertexAttribute {
            format: vertex_format(a.format),
            offset: a.offset as u64,
            shader_location: a.location,
        })
        .collect()
}

/// A color output, written to every channel.
pub(super) fn color_target(t: &ColorTarget) -> wgpu::ColorTargetState {
    wgpu::ColorTargetState {
        format: format(t.format),
        blend: t.blend.map(blend),
        write_mask: wgpu::ColorWrites::ALL,
    }
}

/// Filled, counter-clockwise-front primitives of a topology and cull mode.
pub(super) fn primitive(t: Topology, c: CullMode) -> wgpu::PrimitiveState {
    wgpu::PrimitiveState {
        topology: topology(t),
        strip_index_format: None,
        front_face: wgpu::FrontFace::Ccw,
        cull_mode: cull(c),
        unclipped_depth: false,
        polygon_mode: wgpu::PolygonMode::Fill,
        conservative: false,
    }
}

/// Depth test and write, without stencil or bias.
pub(super) fn depth_stencil(d: DepthState) -> wgpu::DepthStencilState {
    wgpu::DepthStencilState {
        format: format(d.format),
        depth_write_enabled: Some(d.write),
        depth_compare: Some(compare(d.compare)),
        stencil: Default::default(),
        bias: Default::default(),
    }
}

//! Descriptor-to-wgpu conversions.

use crate::backend::desc::*;
use ::wgpu;

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

pub(super) fn filter(f: FilterMode) -> wgpu::FilterMode {
    match f {
        FilterMode::Nearest => wgpu::FilterMode::Nearest,
        FilterMode::Linear => wgpu::FilterMode::Linear,
    }
}

pub(super) fn mipmap_filter(f: FilterMode) -> wgpu::MipmapFilterMode {
    match f {
        FilterMode::Nearest => wgpu::MipmapFilterMode::Nearest,
        FilterMode::Linear => wgpu::MipmapFilterMode::Linear,
    }
}

pub(super) fn address(a: AddressMode) -> wgpu::AddressMode {
    match a {
        AddressMode::ClampToEdge => wgpu::AddressMode::ClampToEdge,
        AddressMode::Repeat => wgpu::AddressMode::Repeat,
        AddressMode::MirrorRepeat => wgpu::AddressMode::MirrorRepeat,
    }
}

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

pub(super) fn vertex_format(f: VertexFormat) -> wgpu::VertexFormat {
    match f {
        VertexFormat::Float32 => wgpu::VertexFormat::Float32,
        VertexFormat::Float32x2 => wgpu::VertexFormat::Float32x2,
        VertexFormat::Float32x3 => wgpu::VertexFormat::Float32x3,
        VertexFormat::Float32x4 => wgpu::VertexFormat::Float32x4,
    }
}

pub(super) fn view_dimension(v: TextureViewKind) -> wgpu::TextureViewDimension {
    match v {
        TextureViewKind::D2 => wgpu::TextureViewDimension::D2,
        TextureViewKind::Cube => wgpu::TextureViewDimension::Cube,
        TextureViewKind::D2Array => wgpu::TextureViewDimension::D2Array,
    }
}

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

pub(super) fn blend(b: BlendState) -> wgpu::BlendState {
    wgpu::BlendState {
        color: blend_component(b.color),
        alpha: blend_component(b.alpha),
    }
}

pub(super) fn topology(t: Topology) -> wgpu::PrimitiveTopology {
    match t {
        Topology::TriangleList => wgpu::PrimitiveTopology::TriangleList,
        Topology::TriangleStrip => wgpu::PrimitiveTopology::TriangleStrip,
        Topology::LineList => wgpu::PrimitiveTopology::LineList,
    }
}

pub(super) fn cull(c: CullMode) -> Option<wgpu::Face> {
    match c {
        CullMode::None => None,
        CullMode::Front => Some(wgpu::Face::Front),
        CullMode::Back => Some(wgpu::Face::Back),
    }
}

pub(super) fn buffer_usage(u: BufferUsage) -> wgpu::BufferUsages {
    wgpu::BufferUsages::COPY_DST
        | match u {
            BufferUsage::Vertex => wgpu::BufferUsages::VERTEX,
            BufferUsage::Index => wgpu::BufferUsages::INDEX,
            BufferUsage::Uniform => wgpu::BufferUsages::UNIFORM,
            BufferUsage::Storage => wgpu::BufferUsages::STORAGE,
        }
}

pub(super) fn index_format(f: IndexFormat) -> wgpu::IndexFormat {
    match f {
        IndexFormat::U16 => wgpu::IndexFormat::Uint16,
        IndexFormat::U32 => wgpu::IndexFormat::Uint32,
    }
}

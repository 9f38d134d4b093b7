//! Descriptor-to-OpenGL enum conversions.

use crate::backend::desc::*;

/// Sized internal format for `glTexStorage*`.
pub(super) fn internal_format(f: TextureFormat) -> u32 {
    match f {
        TextureFormat::Rgba8Unorm => glow::RGBA8,
        TextureFormat::Rgba8UnormSrgb => glow::SRGB8_ALPHA8,
        TextureFormat::Rgba16Float => glow::RGBA16F,
        TextureFormat::Rgba32Float => glow::RGBA32F,
        TextureFormat::R32Float => glow::R32F,
        TextureFormat::Depth32Float => glow::DEPTH_COMPONENT32F,
    }
}

/// (format, type) of client data for uploads, matching [`TextureFormat::texel_size`].
pub(super) fn upload_format(f: TextureFormat) -> (u32, u32) {
    match f {
        TextureFormat::Rgba8Unorm | TextureFormat::Rgba8UnormSrgb => {
            (glow::RGBA, glow::UNSIGNED_BYTE)
        }
        TextureFormat::Rgba16Float => (glow::RGBA, glow::HALF_FLOAT),
        TextureFormat::Rgba32Float => (glow::RGBA, glow::FLOAT),
        TextureFormat::R32Float => (glow::RED, glow::FLOAT),
        TextureFormat::Depth32Float => (glow::DEPTH_COMPONENT, glow::FLOAT),
    }
}

/// (format, type) for `glReadPixels`: 8-bit stays 8-bit, everything else reads as f32.
pub(super) fn readback_format(f: TextureFormat) -> (u32, u32) {
    match f {
        TextureFormat::Rgba8Unorm | TextureFormat::Rgba8UnormSrgb => {
            (glow::RGBA, glow::UNSIGNED_BYTE)
        }
        TextureFormat::Rgba16Float | TextureFormat::Rgba32Float => (glow::RGBA, glow::FLOAT),
        TextureFormat::R32Float => (glow::RED, glow::FLOAT),
        TextureFormat::Depth32Float => (glow::DEPTH_COMPONENT, glow::FLOAT),
    }
}

/// Texture target for a texture kind.
pub(super) fn target(kind: TextureKind) -> u32 {
    match kind {
        TextureKind::D2 => glow::TEXTURE_2D,
        TextureKind::Cube => glow::TEXTURE_CUBE_MAP,
        TextureKind::D2Array { .. } => glow::TEXTURE_2D_ARRAY,
    }
}

pub(super) fn compare(c: CompareFunction) -> u32 {
    match c {
        CompareFunction::Never => glow::NEVER,
        CompareFunction::Less => glow::LESS,
        CompareFunction::LessEqual => glow::LEQUAL,
        CompareFunction::Equal => glow::EQUAL,
        CompareFunction::Greater => glow::GREATER,
        CompareFunction::GreaterEqual => glow::GEQUAL,
        CompareFunction::NotEqual => glow::NOTEQUAL,
        CompareFunction::Always => glow::ALWAYS,
    }
}

pub(super) fn address(a: AddressMode) -> i32 {
    (match a {
        AddressMode::ClampToEdge => glow::CLAMP_TO_EDGE,
        AddressMode::Repeat => glow::REPEAT,
        AddressMode::MirrorRepeat => glow::MIRRORED_REPEAT,
    }) as i32
}

pub(super) fn mag_filter(f: FilterMode) -> i32 {
    (match f {
        FilterMode::Nearest => glow::NEAREST,
        FilterMode::Linear => glow::LINEAR,
    }) as i32
}

pub(super) fn min_filter(min: FilterMode, mip: FilterMode) -> i32 {
    (match (min, mip) {
        (FilterMode::Nearest, FilterMode::Nearest) => glow::NEAREST_MIPMAP_NEAREST,
        (FilterMode::Linear, FilterMode::Nearest) => glow::LINEAR_MIPMAP_NEAREST,
        (FilterMode::Nearest, FilterMode::Linear) => glow::NEAREST_MIPMAP_LINEAR,
        (FilterMode::Linear, FilterMode::Linear) => glow::LINEAR_MIPMAP_LINEAR,
    }) as i32
}

fn blend_factor(f: BlendFactor) -> u32 {
    match f {
        BlendFactor::Zero => glow::ZERO,
        BlendFactor::One => glow::ONE,
        BlendFactor::SrcAlpha => glow::SRC_ALPHA,
        BlendFactor::OneMinusSrcAlpha => glow::ONE_MINUS_SRC_ALPHA,
        BlendFactor::DstAlpha => glow::DST_ALPHA,
        BlendFactor::OneMinusDstAlpha => glow::ONE_MINUS_DST_ALPHA,
    }
}

/// (src, dst) factors of a blend component.
pub(super) fn blend_factors(c: BlendComponent) -> (u32, u32) {
    (blend_factor(c.src), blend_factor(c.dst))
}

pub(super) fn blend_op(op: BlendOperation) -> u32 {
    match op {
        BlendOperation::Add => glow::FUNC_ADD,
        BlendOperation::Subtract => glow::FUNC_SUBTRACT,
        BlendOperation::ReverseSubtract => glow::FUNC_REVERSE_SUBTRACT,
        BlendOperation::Min => glow::MIN,
        BlendOperation::Max => glow::MAX,
    }
}

pub(super) fn topology(t: Topology) -> u32 {
    match t {
        Topology::TriangleList => glow::TRIANGLES,
        Topology::TriangleStrip => glow::TRIANGLE_STRIP,
        Topology::LineList => glow::LINES,
    }
}

pub(super) fn index_type(f: IndexFormat) -> u32 {
    match f {
        IndexFormat::U16 => glow::UNSIGNED_SHORT,
        IndexFormat::U32 => glow::UNSIGNED_INT,
    }
}

pub(super) fn buffer_target(u: BufferUsage) -> u32 {
    match u {
        BufferUsage::Vertex => glow::ARRAY_BUFFER,
        BufferUsage::Index => glow::ELEMENT_ARRAY_BUFFER,
        BufferUsage::Uniform => glow::UNIFORM_BUFFER,
        BufferUsage::Storage => glow::SHADER_STORAGE_BUFFER,
    }
}

//! Sampler descriptors: filtering, wrapping, the [`CompareFunction`] shared with depth tests,
//! and [`SamplerDesc`] with its common presets.

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

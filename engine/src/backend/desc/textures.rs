//! Texture descriptors: formats, shapes ([`TextureKind`]), [`TextureDesc`] and the
//! [`Subresource`] (mip and layer) that uploads, read-backs and attachments address.

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
    /// Bytes of one texel as uploaded with
    /// [`Backend::write_texture`](crate::backend::Backend::write_texture).
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

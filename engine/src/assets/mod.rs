//! Asset loading for the deferred renderer.
//!
//! - [`load_obj`]: Wavefront OBJ + MTL via `tobj`, with a line-accurate
//!   pre-scan, generated normals/UVs where missing and validated MikkTSpace
//!   tangents ([`Vertex`] is the 48-byte geometry-pass vertex).
//! - [`TextureCache`] / [`load_texture`]: PNG, JPEG, TGA and BMP textures (RGBA8, or RGBA16F
//!   for 16-bit files) with a CPU mip chain, decoded once per (file, colour space).
//! - [`load_environment`]: equirectangular OpenEXR or Radiance `.hdr` environment maps.
//!
//! Every failure is an [`AssetError`] naming the file (and line, where known);
//! no input makes these loaders panic.

#![forbid(unsafe_code)]
#![warn(missing_docs)]
#![cfg_attr(
    not(test),
    deny(
        clippy::unwrap_used,
        clippy::expect_used,
        clippy::panic,
        clippy::indexing_slicing
    )
)]

mod environment;
mod error;
mod limits;
mod mtl;
mod obj;
mod summary;
mod text;
mod texture;

// The mesh types the loaders build are defined in `crate::mesh` (with `MeshData::from_triangles`
// and its normal, UV and tangent processing); `super::mesh` in the loaders refers to it.
use crate::mesh;

pub use crate::mesh::{Aabb, MeshData, Vertex};
pub use environment::{
    environment_sizes, load_environment, radiance, Environment, MAX_ENVIRONMENT_TEXELS,
};
pub use error::AssetError;
pub use limits::{Budget, Limits};
pub use obj::{load_mtl, load_obj, MaterialData, MaterialMaps, Model};
pub use summary::{EnvironmentSummary, MaterialSummary, MeshSummary, ModelSummary, TextureSummary};
pub use texture::{
    generate_mips, generate_mips_f32, linear_to_srgb_u8, load_texture, load_texture_with_limits,
    srgb_to_linear, ColorSpace, TexelFormat, TextureCache, TextureData, TextureId,
};

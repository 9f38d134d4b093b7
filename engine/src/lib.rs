//! The renderer: backends, shaders and (growing) the deferred pipeline.
//!
//! - [`backend`]: the [`Backend`](backend::Backend) trait and its implementations (`gl`,
//!   `wgpu-vulkan`, `wgpu-gl`), chosen at run time by name.
//! - [`shaders`]: the WGSL sources, validated and translated to GLSL with naga.
//! - [`image`]: read-back images.
//! - [`ibl`]: image-based lighting maps (prefiltered specular, irradiance, DFG), precomputed on
//!   the CPU and cached.
//! - [`lit_cube`]: the first end-to-end scene, rendered identically on every backend.

pub mod assets;
pub mod backend;
pub mod files;
pub mod ibl;
pub mod image;
pub mod lit_cube;
pub mod mesh;
pub mod plan;
pub mod renderer;
pub mod scene;
pub mod scene_file;
pub mod shaders;
pub mod stats;

pub use backend::{Backend, BackendKind};
pub use image::{Image, ImageData};

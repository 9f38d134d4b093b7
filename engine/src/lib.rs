//! A deferred renderer behind a backend trait, built to be checked: a [`Scene`](scene::Scene)
//! becomes a [`RenderPlan`](plan::RenderPlan), the [`renderer`] records the plan's passes on any
//! [`Backend`], and every pass output can be read back by its typed identity
//! ([`TargetId`](plan::TargetId)).
//!
//! - [`scene`] and [`scene_file`]: the scene model and the TOML files that describe it.
//! - [`assets`] and [`mesh`]: OBJ/MTL and texture loading, vertex data and tangents.
//! - [`plan`]: the passes and targets a scene needs, and the lighting variants it uses.
//! - [`renderer`]: records the plan, one file per pass, and reads back the outputs.
//! - [`backend`]: the [`Backend`](backend::Backend) trait and its implementations (`gl`,
//!   `wgpu-vulkan`, `wgpu-gl`), chosen at run time by name.
//! - [`shaders`]: the WGSL sources, validated and translated to GLSL with naga;
//!   [`shader_bindings`]: a module's bindings, from naga's reflection of it.
//! - [`ibl`]: image-based lighting maps (prefiltered specular, irradiance, DFG), precomputed on
//!   the CPU and cached.
//! - [`image`]: read-back images; [`stats`]: percentiles; [`files`]: atomic file writes.
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
pub mod shader_bindings;
pub mod shaders;
pub mod stats;

pub use backend::{Backend, BackendKind};
pub use image::{Image, ImageData};

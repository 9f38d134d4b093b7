//! Typed handles and descriptor structs: the vocabulary every backend speaks.
//!
//! Descriptors are plain data. A backend turns them into driver objects (see each backend's
//! `conv.rs`) and hands back a [`Handle`], which is only meaningful to the backend that made it.
//! Handles and their marker types live here; the descriptors are grouped by resource kind and
//! re-exported:
//!
//! - `textures`: [`TextureFormat`], [`TextureKind`], [`TextureDesc`], [`Subresource`].
//! - `buffers`: [`BufferUsage`], [`BufferDesc`].
//! - `samplers`: [`FilterMode`], [`AddressMode`], [`CompareFunction`], [`SamplerDesc`].
//! - `pipelines`: [`ShaderDesc`], vertex and binding layouts, blend and depth state,
//!   [`PipelineDesc`], [`GeometryStage`], [`Features`].
//! - `passes`: attachments, [`Viewport`], bindings, [`Draw`], [`RenderPass`], [`PassTiming`].

use std::fmt;
use std::marker::PhantomData;

mod buffers;
mod passes;
mod pipelines;
mod samplers;
mod textures;

pub use buffers::*;
pub use passes::*;
pub use pipelines::*;
pub use samplers::*;
pub use textures::*;

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

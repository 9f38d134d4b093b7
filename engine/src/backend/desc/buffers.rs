//! Buffer descriptors: what a buffer is bound as ([`BufferUsage`]) and its [`BufferDesc`].

/// How a buffer is used.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum BufferUsage {
    /// Vertex attributes.
    Vertex,
    /// 16- or 32-bit indices.
    Index,
    /// Uniform data (std140 / WGSL uniform layout).
    Uniform,
    /// Read-only storage data (`var<storage, read>`), for parameters a driver must not
    /// specialise shaders on (see
    /// [`BindingKind::StorageBuffer`](super::BindingKind::StorageBuffer)).
    Storage,
}

/// Describes a buffer.
#[derive(Clone, Debug)]
pub struct BufferDesc {
    /// Debug label.
    pub label: String,
    /// Size in bytes (a multiple of 4).
    pub size: u64,
    /// What it is bound as.
    pub usage: BufferUsage,
}

//! Small builders the passes share: binding layouts and bindings, full-screen pipelines and
//! draws (one triangle covering the target), color attachments, and shader modules.

use crate::backend::*;
use crate::shaders;

use super::RenderError;

/// A binding of `resource` at `binding`.
pub(super) fn binding(binding: u32, resource: BindingResource) -> Binding {
    Binding { binding, resource }
}

/// An unfilterable 2D texture at `binding` (the G-buffer, masks, depth as float).
pub(super) fn texture_layout(binding: u32) -> BindingLayout {
    BindingLayout {
        binding,
        kind: BindingKind::Texture {
            sample_type: TextureSampleType::UnfilterableFloat,
            view: TextureViewKind::D2,
        },
    }
}

/// A filterable 2D texture at `binding`.
pub(super) fn filterable_texture_layout(binding: u32) -> BindingLayout {
    BindingLayout {
        binding,
        kind: BindingKind::Texture {
            sample_type: TextureSampleType::Float,
            view: TextureViewKind::D2,
        },
    }
}

/// The uniform buffer at binding 0.
pub(super) fn uniform_layout() -> BindingLayout {
    BindingLayout {
        binding: 0,
        kind: BindingKind::UniformBuffer,
    }
}

/// A pipeline drawing one full-screen triangle (`vs_fullscreen`) with `fragment_entry` into one
/// color target.
pub(super) fn fullscreen_pipeline(
    label: &str,
    shader: Handle<Shader>,
    fragment_entry: &str,
    bindings: Vec<BindingLayout>,
    format: TextureFormat,
    blend: Option<BlendState>,
) -> PipelineDesc {
    PipelineDesc {
        label: label.to_owned(),
        shader,
        vertex_entry: "vs_fullscreen".to_owned(),
        fragment_entry: Some(fragment_entry.to_owned()),
        vertex_buffers: vec![],
        bindings,
        color_targets: vec![ColorTarget { format, blend }],
        depth: None,
        topology: Topology::TriangleList,
        cull: CullMode::None,
        geometry: None,
        constants: vec![],
    }
}

/// The full-screen triangle with `pipeline` and `bindings`.
pub(super) fn fullscreen_draw(pipeline: Handle<Pipeline>, bindings: Vec<Binding>) -> Draw {
    Draw {
        pipeline,
        bindings,
        vertex_buffers: vec![],
        index_buffer: None,
        count: 3,
    }
}

/// Color attachment of mip 0, layer 0 of `texture`.
pub(super) fn attachment(texture: Handle<Texture>, load: LoadOp<[f32; 4]>) -> ColorAttachment {
    ColorAttachment {
        texture,
        subresource: Subresource::default(),
        load,
    }
}

/// The shader module of `source`, owned by `scope`.
pub(super) fn shader(
    scope: &mut ResourceScope,
    backend: &mut dyn Backend,
    source: shaders::ShaderSource,
) -> Result<Handle<Shader>, RenderError> {
    Ok(scope.shader(
        backend,
        &ShaderDesc {
            name: source.name.to_owned(),
            wgsl: source.wgsl.to_owned(),
        },
    )?)
}

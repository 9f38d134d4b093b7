//! The first end-to-end scene: a textured cube lit by a directional light, drawn in one pass into
//! an HDR RGBA16F target and a tone-mapped sRGB RGBA8 target with a D32F depth buffer.
//!
//! It exercises what every later pass relies on (vertex and index buffers, a uniform buffer, a
//! sampled sRGB texture, several color attachments, depth testing, back-face culling, readback)
//! and is the scene the backends are compared on.

use glam::{Mat4, Vec3};

use crate::backend::*;
use crate::image::Image;
use crate::{mesh, shaders};

/// What one render of the lit cube produces.
pub struct LitCubeImages {
    /// Linear radiance, RGBA16F.
    pub hdr: Image,
    /// Reinhard-tone-mapped, sRGB-encoded RGBA8.
    pub ldr: Image,
    /// Depth, D32F (1.0 where nothing was drawn).
    pub depth: Image,
    /// GPU time of the pass.
    pub timings: Vec<PassTiming>,
}

/// Interleaved vertex: position, normal, uv.
const VERTEX_FLOATS: usize = 8;

/// A unit cube (-1..1) with outward normals, counter-clockwise faces and per-face UVs:
/// [`mesh::cube`] in this scene's interleaved layout, with `v` flipped to grow downwards as WGSL
/// samples (texel row 0 at `v = 0`).
pub fn cube_mesh() -> (Vec<f32>, Vec<u16>) {
    let cube = mesh::cube();
    let mut vertices = Vec::with_capacity(cube.vertices.len() * VERTEX_FLOATS);
    for v in &cube.vertices {
        let ([px, py, pz], [nx, ny, nz], [tu, tv]) = (v.position, v.normal, v.uv);
        vertices.extend_from_slice(&[px, py, pz, nx, ny, nz, tu, 1.0 - tv]);
    }
    let indices = cube.indices.iter().map(|&i| i as u16).collect();
    (vertices, indices)
}

/// A 64x64 sRGB checkerboard (8x8 squares, warm and cool) with a white 8x8 marker in the top-left
/// texel corner, so that orientation errors show up in the picture.
pub fn checker_texture() -> (u32, Vec<u8>) {
    let size = 64u32;
    let mut texels = Vec::with_capacity((size * size * 4) as usize);
    for y in 0..size {
        for x in 0..size {
            let texel: [u8; 4] = if x < 8 && y < 8 {
                [255, 255, 255, 255]
            } else if (x / 8 + y / 8) % 2 == 0 {
                [200, 90, 40, 255]
            } else {
                [40, 110, 190, 255]
            };
            texels.extend_from_slice(&texel);
        }
    }
    (size, texels)
}

/// Uniform block matching `Globals` in `lit_cube.wgsl`.
fn globals() -> Vec<f32> {
    let eye = Vec3::new(2.6, 2.1, 3.4);
    let view = Mat4::look_at_rh(eye, Vec3::ZERO, Vec3::Y);
    let projection = Mat4::perspective_rh(45f32.to_radians(), 1.0, 0.1, 20.0);
    let model = Mat4::from_rotation_y(25f32.to_radians()) * Mat4::from_scale(Vec3::splat(0.9));
    let light = Vec3::new(0.6, 1.0, 0.35).normalize();
    let mut data = Vec::with_capacity(48);
    data.extend_from_slice(&(projection * view).to_cols_array());
    data.extend_from_slice(&model.to_cols_array());
    data.extend_from_slice(&[light.x, light.y, light.z, 0.0]);
    // An HDR light: lit faces exceed 1.0 in the RGBA16F target.
    data.extend_from_slice(&[3.0, 2.9, 2.7, 0.0]);
    data.extend_from_slice(&[0.06, 0.07, 0.09, 0.0]);
    data.extend_from_slice(&[eye.x, eye.y, eye.z, 0.0]);
    data
}

/// Renders the lit cube at `size` x `size` pixels and reads back all three targets. Every
/// resource it creates is destroyed before it returns, also on error.
pub fn render(backend: &mut dyn Backend, size: u32) -> Result<LitCubeImages> {
    let mut scope = ResourceScope::default();
    let result = render_with(backend, size, &mut scope);
    scope.destroy(backend);
    result
}

/// The render targets of the pass.
struct Targets {
    /// Linear radiance, RGBA16F.
    hdr: Handle<Texture>,
    /// Tone-mapped sRGB, RGBA8.
    ldr: Handle<Texture>,
    /// D32F depth.
    depth: Handle<Texture>,
}

fn render_with(
    backend: &mut dyn Backend,
    size: u32,
    scope: &mut ResourceScope,
) -> Result<LitCubeImages> {
    let (vertices, indices) = cube_mesh();
    let vertex_buffer = scope.buffer(
        backend,
        "cube vertices",
        BufferUsage::Vertex,
        bytemuck::cast_slice(&vertices),
    )?;
    let index_buffer = scope.buffer(
        backend,
        "cube indices",
        BufferUsage::Index,
        bytemuck::cast_slice(&indices),
    )?;
    let uniforms = scope.buffer(
        backend,
        "globals",
        BufferUsage::Uniform,
        bytemuck::cast_slice(&globals()),
    )?;
    let (albedo, sampler) = create_checker(backend, scope)?;
    let targets = create_targets(backend, size, scope)?;
    let pipeline = create_pipeline(backend, scope)?;

    let draw = Draw {
        pipeline,
        bindings: vec![
            Binding {
                binding: 0,
                resource: BindingResource::Buffer(uniforms),
            },
            Binding {
                binding: 1,
                resource: BindingResource::Texture(albedo),
            },
            Binding {
                binding: 2,
                resource: BindingResource::Sampler(sampler),
            },
        ],
        vertex_buffers: vec![vertex_buffer],
        index_buffer: Some((index_buffer, IndexFormat::U16)),
        count: indices.len() as u32,
    };
    let timings = backend.submit(&[render_pass(&targets, draw)])?;
    Ok(LitCubeImages {
        hdr: backend.read_texture(targets.hdr, Subresource::default())?,
        ldr: backend.read_texture(targets.ldr, Subresource::default())?,
        depth: backend.read_texture(targets.depth, Subresource::default())?,
        timings,
    })
}

/// Creates and uploads the checkerboard albedo texture and its repeating sampler.
fn create_checker(
    backend: &mut dyn Backend,
    scope: &mut ResourceScope,
) -> Result<(Handle<Texture>, Handle<Sampler>)> {
    let (tex_size, texels) = checker_texture();
    let albedo = scope.texture(
        backend,
        &TextureDesc::d2("checker", tex_size, tex_size, TextureFormat::Rgba8UnormSrgb),
    )?;
    backend.write_texture(albedo, Subresource::default(), &texels)?;
    let sampler = scope.sampler(
        backend,
        &SamplerDesc::linear("checker", AddressMode::Repeat),
    )?;
    Ok((albedo, sampler))
}

/// Creates the `size` x `size` HDR, LDR and depth targets.
fn create_targets(
    backend: &mut dyn Backend,
    size: u32,
    scope: &mut ResourceScope,
) -> Result<Targets> {
    let hdr = scope.texture(
        backend,
        &TextureDesc::d2("hdr", size, size, TextureFormat::Rgba16Float),
    )?;
    let ldr = scope.texture(
        backend,
        &TextureDesc::d2("ldr", size, size, TextureFormat::Rgba8UnormSrgb),
    )?;
    let depth = scope.texture(
        backend,
        &TextureDesc::d2("depth", size, size, TextureFormat::Depth32Float),
    )?;
    Ok(Targets { hdr, ldr, depth })
}

/// Creates the `lit_cube.wgsl` shader module and the pipeline drawing the cube with it.
fn create_pipeline(
    backend: &mut dyn Backend,
    scope: &mut ResourceScope,
) -> Result<Handle<Pipeline>> {
    let shader = scope.shader(
        backend,
        &ShaderDesc {
            name: shaders::LIT_CUBE.name.to_owned(),
            wgsl: shaders::LIT_CUBE.wgsl.to_owned(),
        },
    )?;
    scope.pipeline(backend, &pipeline_desc(shader))
}

/// The lit cube's pipeline: [`cube_mesh`]'s vertex layout, globals + albedo + sampler bindings,
/// HDR and LDR color outputs, depth test and back-face culling.
fn pipeline_desc(shader: Handle<Shader>) -> PipelineDesc {
    let float = |location, format, offset| VertexAttribute {
        location,
        format,
        offset,
    };
    PipelineDesc {
        label: "lit cube".to_owned(),
        shader,
        vertex_entry: "vs_main".to_owned(),
        fragment_entry: Some("fs_main".to_owned()),
        vertex_buffers: vec![VertexBufferLayout {
            stride: (VERTEX_FLOATS * 4) as u32,
            attributes: vec![
                float(0, VertexFormat::Float32x3, 0),
                float(1, VertexFormat::Float32x3, 12),
                float(2, VertexFormat::Float32x2, 24),
            ],
        }],
        bindings: vec![
            BindingLayout {
                binding: 0,
                kind: BindingKind::UniformBuffer,
            },
            BindingLayout {
                binding: 1,
                kind: BindingKind::Texture {
                    sample_type: TextureSampleType::Float,
                    view: TextureViewKind::D2,
                },
            },
            BindingLayout {
                binding: 2,
                kind: BindingKind::Sampler(SamplerBindingKind::Filtering),
            },
        ],
        color_targets: vec![
            ColorTarget {
                format: TextureFormat::Rgba16Float,
                blend: None,
            },
            ColorTarget {
                format: TextureFormat::Rgba8UnormSrgb,
                blend: None,
            },
        ],
        depth: Some(DepthState {
            format: TextureFormat::Depth32Float,
            write: true,
            compare: CompareFunction::Less,
        }),
        topology: Topology::TriangleList,
        cull: CullMode::Back,
        geometry: None,
        constants: vec![],
    }
}

/// The one pass: clears all three targets and runs `draw`.
fn render_pass(targets: &Targets, draw: Draw) -> RenderPass {
    let background = [0.02, 0.02, 0.03, 1.0];
    RenderPass {
        name: "lit_cube".to_owned(),
        color_attachments: vec![
            ColorAttachment {
                texture: targets.hdr,
                subresource: Subresource::default(),
                load: LoadOp::Clear(background),
            },
            ColorAttachment {
                texture: targets.ldr,
                subresource: Subresource::default(),
                load: LoadOp::Clear(background),
            },
        ],
        depth_attachment: Some(DepthAttachment {
            texture: targets.depth,
            subresource: Subresource::default(),
            load: LoadOp::Clear(1.0),
        }),
        viewports: vec![],
        draws: vec![draw],
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn cube_faces_wind_counter_clockwise_seen_from_outside() {
        let (vertices, indices) = cube_mesh();
        let position = |i: u16| {
            let v = &vertices[i as usize * VERTEX_FLOATS..];
            (Vec3::new(v[0], v[1], v[2]), Vec3::new(v[3], v[4], v[5]))
        };
        for tri in indices.chunks_exact(3) {
            let (a, n) = position(tri[0]);
            let (b, _) = position(tri[1]);
            let (c, _) = position(tri[2]);
            assert!(
                (b - a).cross(c - a).dot(n) > 0.0,
                "triangle {tri:?} winds clockwise"
            );
        }
    }
}

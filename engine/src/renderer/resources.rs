//! What every pass of a frame reads: the plan's render targets, the scene's meshes and material
//! textures on the GPU, and the camera. Created once per frame, in this order, before any pass
//! is recorded.

use std::collections::HashMap;
use std::sync::Arc;

use glam::Mat4;

use super::{CameraMatrices, RenderError};
use crate::backend::*;
use crate::mesh::MeshData;
use crate::plan::{RenderPlan, TargetContent, TargetId};
use crate::scene::{Object, Scene};

/// GPU copies of one mesh.
pub(super) struct GpuMesh {
    /// Vertex buffer.
    pub vertices: Handle<Buffer>,
    /// 32-bit index buffer.
    pub indices: Handle<Buffer>,
    /// Index count.
    pub count: u32,
}

/// The resources shared by a frame's passes.
pub(super) struct FrameResources {
    targets: HashMap<TargetId, Handle<Texture>>,
    meshes: HashMap<*const MeshData, GpuMesh>,
    /// The scene's material textures, by index.
    pub textures: Vec<Handle<Texture>>,
    /// A white texel, bound wherever a material has no map.
    pub white: Handle<Texture>,
    /// A transparent black texel: a mask that covers nothing.
    pub black: Handle<Texture>,
    /// Linear, repeating sampler of the material maps.
    pub material_sampler: Handle<Sampler>,
    /// The shader-mask targets, in plan order.
    pub mask_targets: Vec<Handle<Texture>>,
    /// The scene's camera, camera-relative.
    pub camera: CameraMatrices,
    /// `camera`'s view-projection in f32.
    pub view_projection: Mat4,
}

impl FrameResources {
    /// Creates the plan's targets, uploads each distinct mesh once and every material texture
    /// with its mips, and the placeholder texels and the material sampler.
    pub fn create(
        backend: &mut dyn Backend,
        scope: &mut ResourceScope,
        scene: &Scene,
        plan: &RenderPlan,
    ) -> Result<Self, RenderError> {
        let mut targets: HashMap<TargetId, Handle<Texture>> = HashMap::new();
        for spec in &plan.targets {
            let handle = scope.texture(
                backend,
                &TextureDesc::d2(&spec.id.to_string(), spec.width, spec.height, spec.format),
            )?;
            targets.insert(spec.id, handle);
        }
        let meshes = upload_meshes(backend, scope, scene)?;
        let textures = upload_textures(backend, scope, scene)?;
        let white = scope.texture(
            backend,
            &TextureDesc::d2("white", 1, 1, TextureFormat::Rgba8Unorm),
        )?;
        backend.write_texture(white, Subresource::default(), &[255; 4])?;
        let black = scope.texture(
            backend,
            &TextureDesc::d2("black", 1, 1, TextureFormat::Rgba8Unorm),
        )?;
        backend.write_texture(black, Subresource::default(), &[0, 0, 0, 0])?;
        let material_sampler = scope.sampler(
            backend,
            &SamplerDesc::linear("material", AddressMode::Repeat),
        )?;
        let camera = CameraMatrices::new(scene);
        let view_projection = camera.view_projection().as_mat4();
        let mask_targets: Vec<Handle<Texture>> = plan
            .targets
            .iter()
            .filter(|t| t.id.content() == TargetContent::Mask)
            .map(|t| targets[&t.id])
            .collect();
        Ok(Self {
            targets,
            meshes,
            textures,
            white,
            black,
            material_sampler,
            mask_targets,
            camera,
            view_projection,
        })
    }

    /// The plan's target `id` (the plan has every target a pass uses).
    pub fn target(&self, id: TargetId) -> Handle<Texture> {
        self.targets[&id]
    }

    /// The plan's target `id`, if the plan has it.
    pub fn optional_target(&self, id: TargetId) -> Option<Handle<Texture>> {
        self.targets.get(&id).copied()
    }

    /// The GPU copy of `object`'s mesh.
    pub fn mesh(&self, object: &Object) -> &GpuMesh {
        &self.meshes[&Arc::as_ptr(&object.mesh)]
    }
}

/// Each distinct mesh of the scene, uploaded once.
fn upload_meshes(
    backend: &mut dyn Backend,
    scope: &mut ResourceScope,
    scene: &Scene,
) -> Result<HashMap<*const MeshData, GpuMesh>, RenderError> {
    let mut meshes: HashMap<*const MeshData, GpuMesh> = HashMap::new();
    for object in &scene.objects {
        let key = Arc::as_ptr(&object.mesh);
        if meshes.contains_key(&key) {
            continue;
        }
        let mesh = &object.mesh;
        let vertices = scope.buffer(
            backend,
            &format!("{} vertices", mesh.name),
            BufferUsage::Vertex,
            bytemuck::cast_slice(&mesh.vertices),
        )?;
        let indices = scope.buffer(
            backend,
            &format!("{} indices", mesh.name),
            BufferUsage::Index,
            bytemuck::cast_slice(&mesh.indices),
        )?;
        meshes.insert(
            key,
            GpuMesh {
                vertices,
                indices,
                count: mesh.indices.len() as u32,
            },
        );
    }
    Ok(meshes)
}

/// The scene's material textures with all their mips.
fn upload_textures(
    backend: &mut dyn Backend,
    scope: &mut ResourceScope,
    scene: &Scene,
) -> Result<Vec<Handle<Texture>>, RenderError> {
    let mut textures = Vec::with_capacity(scene.textures.len());
    for image in &scene.textures {
        let format = match (image.format, image.srgb) {
            (crate::assets::TexelFormat::Rgba16Float, _) => TextureFormat::Rgba16Float,
            (crate::assets::TexelFormat::Rgba8, true) => TextureFormat::Rgba8UnormSrgb,
            (crate::assets::TexelFormat::Rgba8, false) => TextureFormat::Rgba8Unorm,
        };
        let handle = scope.texture(
            backend,
            &TextureDesc {
                mip_levels: image.mips.len().max(1) as u32,
                ..TextureDesc::d2(&image.label, image.width, image.height, format)
            },
        )?;
        for (mip, texels) in image.mips.iter().enumerate() {
            backend.write_texture(
                handle,
                Subresource {
                    mip: mip as u32,
                    layer: 0,
                },
                texels,
            )?;
        }
        textures.push(handle);
    }
    Ok(textures)
}

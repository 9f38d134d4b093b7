//! Uniform blocks of the renderer's shaders, laid out as the WGSL structs expect (std140-safe:
//! only vec4 and mat4 members). Everything positional is made camera-relative here, in f64.

use bytemuck::{Pod, Zeroable};
use glam::{DVec3, Mat4};

use super::{object_matrices, CameraMatrices, Variations};
use crate::plan::{MaskChannel, MAX_LIGHTS_PER_DRAW};
use crate::scene::{
    GbufferSettings, Light, NormalEncoding, Object, PositionStorage, Scene, Transform,
};

/// `LightData` in `lighting.wgsl`.
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, PartialEq, Pod, Zeroable)]
pub struct LightData {
    /// Directional: unit direction towards the light, w = 0. Point: camera-relative position,
    /// w = 1.
    pub position: [f32; 4],
    /// rgb = color * intensity * exposure; a = radius.
    pub color: [f32; 4],
    /// x = 1 / falloff (point lights); y, z = sine and cosine of the disc's angular radius
    /// (directional lights).
    pub params: [f32; 4],
}

/// The scene's lights as the lighting pass sees them (camera-relative, exposure applied).
pub fn light_uniforms(scene: &Scene) -> Vec<LightData> {
    let exposure = scene.quality.exposure;
    let origin = scene.camera.position;
    scene
        .lights
        .iter()
        .map(|light| match light {
            Light::Directional {
                direction,
                color,
                intensity,
                angular_radius,
                ..
            } => {
                let d = direction.normalize().as_vec3();
                LightData {
                    position: [d.x, d.y, d.z, 0.0],
                    color: scaled(color, intensity * exposure, 0.0),
                    params: if *angular_radius > 0.0 {
                        [0.0, angular_radius.sin(), angular_radius.cos(), 0.0]
                    } else {
                        [0.0; 4]
                    },
                }
            }
            Light::Point {
                position,
                color,
                intensity,
                radius,
                falloff,
                ..
            } => {
                let p = (*position - origin).as_vec3();
                LightData {
                    position: [p.x, p.y, p.z, 1.0],
                    color: scaled(color, intensity * exposure, *radius),
                    params: [1.0 / falloff, 0.0, 0.0, 0.0],
                }
            }
        })
        .collect()
}

fn scaled(color: &[f32; 3], factor: f32, w: f32) -> [f32; 4] {
    [color[0] * factor, color[1] * factor, color[2] * factor, w]
}

/// `ObjectUniforms` in `gbuffer.wgsl`, as floats.
pub(super) fn object_uniforms(
    object: &Object,
    transform: &Transform,
    camera_position: DVec3,
    view_projection: Mat4,
    channel: MaskChannel,
    variations: &Variations,
    gbuffer: &GbufferSettings,
) -> Vec<f32> {
    let (model, normal) = object_matrices(transform, camera_position);
    let m = &object.material;
    let flag = |present: Option<usize>| if present.is_some() { 1.0 } else { 0.0 };
    let mut one_hot = [[0.0f32; 4]; 2];
    one_hot[channel.target.min(1)][channel.channel] = 1.0;
    let mut data = Vec::with_capacity(16 * 3 + 4 * 7);
    data.extend_from_slice(&model.to_cols_array());
    data.extend_from_slice(&Mat4::from_mat3(normal).to_cols_array());
    data.extend_from_slice(&view_projection.to_cols_array());
    data.extend_from_slice(&[
        m.base_color[0],
        m.base_color[1],
        m.base_color[2],
        m.anisotropy,
    ]);
    data.extend_from_slice(&[m.roughness, m.metallic, m.specular, m.clearcoat]);
    let swap = if variations.swap_albedo_red_blue {
        1.0
    } else {
        0.0
    };
    let handedness = if transform.mirrors() { -1.0 } else { 1.0 };
    data.extend_from_slice(&[m.clearcoat_roughness, m.specular_exponent, swap, handedness]);
    data.extend_from_slice(&[
        flag(m.base_color_map),
        flag(m.normal_map),
        flag(m.roughness_map),
        flag(m.metallic_map),
    ]);
    let (position_mode, normal_mode) = gbuffer_modes(gbuffer);
    data.extend_from_slice(&[
        flag(m.clearcoat_map),
        flag(m.specular_map),
        position_mode,
        normal_mode,
    ]);
    data.extend_from_slice(&one_hot[0]);
    data.extend_from_slice(&one_hot[1]);
    let c = camera_position.as_vec3();
    data.extend_from_slice(&[c.x, c.y, c.z, 0.0]);
    data
}

/// The G-buffer settings as the shaders' flags: position (0 camera-relative, 1 world, 2 depth)
/// and normal (0 fp16, 1 octahedral).
pub(super) fn gbuffer_modes(gbuffer: &GbufferSettings) -> (f32, f32) {
    let position = match gbuffer.position {
        PositionStorage::CameraRelative => 0.0,
        PositionStorage::World => 1.0,
        PositionStorage::Depth => 2.0,
    };
    let normal = match gbuffer.normal {
        NormalEncoding::Fp16 => 0.0,
        NormalEncoding::Octahedral => 1.0,
    };
    (position, normal)
}

/// `LightingUniforms` in `lighting.wgsl`, as bytes.
pub(super) fn lighting_uniforms(
    scene: &Scene,
    camera: &CameraMatrices,
    channel: MaskChannel,
    batch: &[LightData],
    first_batch: bool,
    ibl_max_lod: f32,
) -> Vec<u8> {
    let mut select = [0.0f32; 4];
    select[channel.channel] = 1.0;
    let exposure = scene.quality.exposure;
    let ambient = if first_batch {
        let a = ambient_radiance(scene);
        [a[0] * exposure, a[1] * exposure, a[2] * exposure, 0.0]
    } else {
        [0.0; 4]
    };
    // The light count and the G-buffer modes are the draw's override constants.
    let counts = [0, u32::from(first_batch), 0, 0];
    // IBL: x = intensity * exposure (first batch only), y = highest specular lod,
    // z, w = cos and sin of the rotation about +Y.
    let ibl = match (&scene.environment, first_batch) {
        (Some(env), true) => {
            let r = env.rotation_degrees.to_radians();
            [env.intensity * exposure, ibl_max_lod, r.cos(), r.sin()]
        }
        _ => [0.0, 0.0, 1.0, 0.0],
    };
    let mut lights = [LightData::default(); MAX_LIGHTS_PER_DRAW];
    lights[..batch.len()].copy_from_slice(batch);
    let mut bytes = Vec::new();
    bytes.extend_from_slice(bytemuck::cast_slice(&select));
    bytes.extend_from_slice(bytemuck::cast_slice(&ambient));
    bytes.extend_from_slice(bytemuck::cast_slice(&counts));
    bytes.extend_from_slice(bytemuck::cast_slice(&ibl));
    let c = scene.camera.position.as_vec3();
    bytes.extend_from_slice(bytemuck::cast_slice(&[c.x, c.y, c.z, 0.0]));
    let inverse = camera.view_projection().inverse().as_mat4();
    bytes.extend_from_slice(bytemuck::cast_slice(&inverse.to_cols_array()));
    bytes.extend_from_slice(bytemuck::cast_slice(&lights));
    bytes
}

/// `SkyboxUniforms` in `skybox.wgsl`, as floats.
pub(super) fn skybox_uniforms(scene: &Scene, camera: &CameraMatrices) -> Vec<f32> {
    let inverse = camera.view_projection().inverse().as_mat4();
    let (rotation, intensity) = scene.environment.as_ref().map_or((0.0, 0.0), |e| {
        (e.rotation_degrees.to_radians(), e.intensity)
    });
    let mut data = inverse.to_cols_array().to_vec();
    data.extend_from_slice(&[
        scene.quality.width as f32,
        scene.quality.height as f32,
        rotation,
        intensity * scene.quality.exposure,
    ]);
    data
}

/// Uniform ambient radiance the lighting passes apply (diffuse only): the scene's `ambient`.
/// An environment lights the scene through the IBL maps instead.
pub fn ambient_radiance(scene: &Scene) -> [f32; 3] {
    scene.ambient
}

//! The scene model: an immutable snapshot of everything a frame depends on (camera, objects,
//! lights, environment, quality settings). Rendering a [`Scene`] is a pure function of it.
//!
//! World positions are `f64` ([`DVec3`]): the renderer subtracts the camera position in double
//! precision before anything reaches the GPU, so a scene 10 km from the origin renders like the
//! same scene at the origin.
//!
//! Surfaces are in `material`, lights and shadow settings in `light`, quality settings in
//! `quality`; everything is reachable from here.

use std::sync::Arc;

use glam::{DMat4, DQuat, DVec3};

use crate::mesh::MeshData;

mod ibl_settings;
mod light;
mod material;
mod quality;
mod validate;

pub use ibl_settings::{
    AnisotropicLookup, DominantDirection, Footprint, IblSettings, IrradianceMethod,
    MAX_EXTRACTED_LIGHTS,
};
pub use light::{Light, ShadowFilter, ShadowSettings};
pub use material::{LightingModel, Material, TextureIndex};
pub use quality::{
    GbufferSettings, NormalEncoding, PointShadowPass, PositionStorage, Quality, SsaoSettings,
    ToneMap,
};
pub use validate::InvalidScene;

/// A decoded RGBA8 texture with its full mip chain (top row first).
#[derive(Clone, Debug)]
pub struct TextureImage {
    /// Where it came from (file path or generator name), for messages.
    pub label: String,
    /// Whether the texels are sRGB-encoded color or linear data.
    pub srgb: bool,
    /// Width of mip 0.
    pub width: u32,
    /// Height of mip 0.
    pub height: u32,
    /// How the texels are stored: RGBA8 (sRGB-encoded where `srgb`), or linear RGBA16F from a
    /// 16-bit file.
    pub format: crate::assets::TexelFormat,
    /// Texels per mip level in `format`, level 0 first.
    pub mips: Vec<Vec<u8>>,
}

/// An equirectangular HDR environment: linear RGBA f32 texels, top row first.
#[derive(Clone, Debug)]
pub struct EnvironmentImage {
    /// Where it came from, for messages.
    pub label: String,
    /// Width in texels (longitude).
    pub width: u32,
    /// Height in texels (latitude, north at the top).
    pub height: u32,
    /// Texels.
    pub texels: Vec<[f32; 4]>,
}

/// A perspective camera.
#[derive(Clone, Debug, PartialEq)]
pub struct Camera {
    /// Eye position in world space.
    pub position: DVec3,
    /// Point looked at.
    pub target: DVec3,
    /// Up direction.
    pub up: DVec3,
    /// Vertical field of view in degrees.
    pub fov_y_degrees: f64,
    /// Near plane distance.
    pub near: f64,
    /// Far plane distance.
    pub far: f64,
}

impl Camera {
    /// World-to-view rotation with the camera at the origin (camera-relative view matrix).
    pub fn view_rotation(&self) -> DMat4 {
        DMat4::look_at_rh(DVec3::ZERO, self.target - self.position, self.up)
    }

    /// Projection with depth 0 at the near plane and 1 at the far plane.
    pub fn projection(&self, aspect: f64) -> DMat4 {
        DMat4::perspective_rh(self.fov_y_degrees.to_radians(), aspect, self.near, self.far)
    }
}

/// Translation, rotation and scale of an object.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Transform {
    /// World position.
    pub translation: DVec3,
    /// Orientation.
    pub rotation: DQuat,
    /// Scale per axis.
    pub scale: DVec3,
}

impl Default for Transform {
    fn default() -> Self {
        Self {
            translation: DVec3::ZERO,
            rotation: DQuat::IDENTITY,
            scale: DVec3::ONE,
        }
    }
}

impl Transform {
    /// Object-to-camera-relative matrix: the translation is taken relative to `origin` in f64.
    pub fn relative_to(&self, origin: DVec3) -> DMat4 {
        DMat4::from_scale_rotation_translation(self.scale, self.rotation, self.translation - origin)
    }

    /// Whether the transform mirrors the mesh (an odd number of negative scale factors): its
    /// triangles are then wound the other way round on screen, and its tangent frames change
    /// handedness. The renderer culls such an object's front-facing triangles instead of its
    /// back-facing ones, and flips the handedness it stores.
    pub fn mirrors(&self) -> bool {
        self.scale.x * self.scale.y * self.scale.z < 0.0
    }
}

/// One drawable: a mesh with a transform, a material and a lighting model.
#[derive(Clone, Debug)]
pub struct Object {
    /// Name for messages and plans.
    pub name: String,
    /// Geometry (shared between objects that use the same mesh).
    pub mesh: Arc<MeshData>,
    /// Placement.
    pub transform: Transform,
    /// Surface.
    pub material: Material,
    /// Which lighting pass shades it.
    pub lighting: LightingModel,
    /// Whether it is drawn into shadow maps.
    pub casts_shadows: bool,
}

/// An environment map around the scene.
#[derive(Clone, Debug)]
pub struct Environment {
    /// The equirectangular image.
    pub image: Arc<EnvironmentImage>,
    /// Rotation about +Y in degrees.
    pub rotation_degrees: f32,
    /// Radiance multiplier.
    pub intensity: f32,
}

/// Everything one frame depends on.
#[derive(Clone, Debug)]
pub struct Scene {
    /// Scene name (file stem for scene files).
    pub name: String,
    /// The camera.
    pub camera: Camera,
    /// Drawables.
    pub objects: Vec<Object>,
    /// Lights, any number.
    pub lights: Vec<Light>,
    /// Uniform ambient radiance from every direction (linear RGB); zero for none.
    pub ambient: [f32; 3],
    /// Environment map, if any.
    pub environment: Option<Environment>,
    /// Textures referenced by materials ([`TextureIndex`]).
    pub textures: Vec<Arc<TextureImage>>,
    /// Output size and quality knobs.
    pub quality: Quality,
}

impl Scene {
    /// The lighting models the scene's objects use, in mask-channel order, without duplicates.
    pub fn lighting_models(&self) -> Vec<LightingModel> {
        LightingModel::ALL
            .into_iter()
            .filter(|m| self.objects.iter().any(|o| o.lighting == *m))
            .collect()
    }

    /// The same scene moved by `offset` (objects, lights and camera).
    pub fn translated(&self, offset: DVec3) -> Scene {
        let mut moved = self.clone();
        moved.camera.position += offset;
        moved.camera.target += offset;
        for object in &mut moved.objects {
            object.transform.translation += offset;
        }
        for light in &mut moved.lights {
            if let Light::Point { position, .. } = light {
                *position += offset;
            }
        }
        moved
    }
}

//! Scenes built in code for tests that need exact control: the material grid the lighting pass
//! is checked on against the f64 reference, the white furnace, five lighting models in one frame
//! and 64 point lights. Procedural meshes only, so none of them touches the file system.

use std::f32::consts::TAU;
use std::sync::Arc;

use engine::mesh::{self, MeshData};
use engine::scene::*;
use glam::{DQuat, DVec3};

fn camera(position: DVec3, target: DVec3) -> Camera {
    Camera {
        position,
        target,
        up: DVec3::Y,
        fov_y_degrees: 40.0,
        near: 0.05,
        far: 100.0,
    }
}

fn sphere_at(
    name: String,
    mesh: &Arc<MeshData>,
    at: DVec3,
    radius: f64,
    material: Material,
    lighting: LightingModel,
) -> Object {
    Object {
        name,
        mesh: mesh.clone(),
        transform: Transform {
            translation: at,
            rotation: DQuat::from_rotation_x(0.3),
            scale: DVec3::splat(radius),
        },
        material,
        lighting,
        casts_shadows: true,
    }
}

fn empty_scene(name: &str, size: u32, camera: Camera) -> Scene {
    Scene {
        name: name.to_owned(),
        camera,
        objects: vec![],
        lights: vec![],
        ambient: [0.0; 3],
        environment: None,
        textures: vec![],
        quality: Quality {
            width: size,
            height: size,
            exposure: 1.0,
            tone_map: ToneMap::Aces,
            ..Quality::default()
        },
    }
}

/// Rows of spheres: roughness 0..1 across; down: dielectric, metal, clearcoat, anisotropy -1,
/// anisotropy +1, and a Blinn-Phong row with exponents 1..256. Lit by a directional light, two
/// point lights (one close to the grid, so attenuation varies) and a little ambient. The spheres'
/// silhouettes give grazing views.
pub fn material_grid(size: u32) -> Scene {
    let mesh = Arc::new(mesh::uv_sphere(48, 24));
    let columns = 6;
    let rows = 6;
    let mut scene = empty_scene(
        "material_grid",
        size,
        camera(DVec3::new(0.0, 0.4, 9.0), DVec3::new(0.0, 0.0, 0.0)),
    );
    for row in 0..rows {
        for column in 0..columns {
            let t = column as f32 / (columns - 1) as f32;
            let mut material = Material {
                base_color: [0.9, 0.55, 0.3],
                roughness: t,
                specular: 0.5,
                ..Material::default()
            };
            let mut lighting = LightingModel::Pbr;
            match row {
                0 => {}
                1 => {
                    material.metallic = 1.0;
                    material.base_color = [0.95, 0.64, 0.54];
                }
                2 => {
                    material.clearcoat = 1.0;
                    material.clearcoat_roughness = 0.05 + 0.3 * t;
                    material.base_color = [0.1, 0.2, 0.6];
                }
                3 => material.anisotropy = -1.0 + 0.4 * t,
                4 => {
                    material.anisotropy = 1.0 - 0.4 * t;
                    material.metallic = 1.0;
                    material.base_color = [0.9, 0.9, 0.9];
                }
                _ => {
                    lighting = LightingModel::BlinnPhong;
                    material.specular_exponent = 2f32.powf(8.0 * t);
                    material.specular = 0.6;
                }
            }
            let at = DVec3::new((column as f64 - 2.5) * 1.05, (2.5 - row as f64) * 1.05, 0.0);
            scene.objects.push(sphere_at(
                format!("sphere_{row}_{column}"),
                &mesh,
                at,
                0.48,
                material,
                lighting,
            ));
        }
    }
    scene.lights = vec![
        Light::Directional {
            direction: DVec3::new(-0.4, 0.6, 0.7),
            color: [1.0, 0.95, 0.9],
            intensity: 3.0,
            angular_radius: 0.0,
            shadow: None,
        },
        Light::Point {
            position: DVec3::new(2.0, 1.0, 2.0),
            color: [0.6, 0.7, 1.0],
            intensity: 4.0,
            radius: 6.0,
            falloff: 1.5,
            shadow: None,
        },
        Light::Point {
            position: DVec3::new(-1.0, -1.5, 0.9),
            color: [1.0, 0.5, 0.3],
            intensity: 2.0,
            radius: 2.5,
            falloff: 0.7,
            shadow: None,
        },
    ];
    scene.ambient = [0.03, 0.03, 0.035];
    scene
}

/// A unit sphere at the origin seen from 3 units away, alone, clamp tone mapping: the furnaces.
fn lone_sphere(
    name: &str,
    size: u32,
    mesh: MeshData,
    material: Material,
    lighting: LightingModel,
) -> Scene {
    let mut scene = empty_scene(name, size, camera(DVec3::new(0.0, 0.0, 3.0), DVec3::ZERO));
    scene.objects.push(sphere_at(
        "sphere".to_owned(),
        &Arc::new(mesh),
        DVec3::ZERO,
        1.0,
        material,
        lighting,
    ));
    scene.quality.tone_map = ToneMap::Clamp;
    scene
}

/// A white Lambert sphere under uniform unit ambient radiance and nothing else: every lit pixel
/// of the light buffer must equal the albedo (the white furnace).
pub fn white_furnace(size: u32, albedo: f32) -> Scene {
    let material = Material {
        base_color: [albedo; 3],
        specular: 0.0,
        ..Material::default()
    };
    let mut scene = lone_sphere(
        "white_furnace",
        size,
        mesh::uv_sphere(48, 24),
        material,
        LightingModel::Pbr,
    );
    scene.ambient = [1.0; 3];
    scene
}

/// Five spheres and a floor, one lighting model each (the floor is PBR), so the mask needs two
/// targets.
pub fn five_models(size: u32) -> Scene {
    let mesh = Arc::new(mesh::uv_sphere(32, 16));
    let mut scene = empty_scene(
        "five_models",
        size,
        camera(DVec3::new(0.0, 2.5, 8.5), DVec3::new(0.0, 0.3, 0.0)),
    );
    for (i, model) in LightingModel::ALL.into_iter().enumerate() {
        scene.objects.push(sphere_at(
            format!("sphere_{model}"),
            &mesh,
            DVec3::new(-2.4 + 1.2 * i as f64, 0.5, 0.0),
            0.5,
            Material {
                base_color: [0.8, 0.3 + 0.1 * i as f32, 0.2],
                roughness: 0.4,
                ..Material::default()
            },
            model,
        ));
    }
    scene.objects.push(Object {
        name: "floor".to_owned(),
        mesh: Arc::new(mesh::plane(8.0, 4.0)),
        transform: Transform::default(),
        material: Material::default(),
        lighting: LightingModel::Pbr,
        casts_shadows: false,
    });
    scene.lights.push(Light::Directional {
        direction: DVec3::new(0.3, 1.0, 0.5),
        color: [1.0; 3],
        intensity: 3.0,
        angular_radius: 0.0,
        shadow: None,
    });
    scene.ambient = [0.05; 3];
    scene
}

/// A floor lit by `count` coloured point lights on a grid just above it.
pub fn many_point_lights(size: u32, count: usize) -> Scene {
    let mut scene = empty_scene(
        "many_point_lights",
        size,
        camera(DVec3::new(0.0, 6.0, 6.0), DVec3::ZERO),
    );
    scene.objects.push(Object {
        name: "floor".to_owned(),
        mesh: Arc::new(mesh::plane(10.0, 1.0)),
        transform: Transform::default(),
        material: Material {
            base_color: [0.7; 3],
            roughness: 0.6,
            ..Material::default()
        },
        lighting: LightingModel::Pbr,
        casts_shadows: false,
    });
    let side = (count as f64).sqrt().ceil() as usize;
    for i in 0..count {
        let (x, z) = (i % side, i / side);
        let hue = i as f32 / count as f32;
        scene.lights.push(Light::Point {
            position: DVec3::new(
                (x as f64 + 0.5) / side as f64 * 8.0 - 4.0,
                0.3,
                (z as f64 + 0.5) / side as f64 * 8.0 - 4.0,
            ),
            color: [
                0.5 + 0.5 * (hue * TAU).cos(),
                0.5 + 0.5 * (hue * TAU + TAU / 3.0).cos(),
                0.5 + 0.5 * (hue * TAU + 2.0 * TAU / 3.0).cos(),
            ],
            intensity: 3.0,
            radius: 1.2,
            falloff: 1.0,
            shadow: None,
        });
    }
    scene
}

/// A sphere under a uniform environment of radiance 1 and nothing else (the IBL white
/// furnace), with the given material and lighting model.
pub fn ibl_furnace(size: u32, material: Material, lighting: LightingModel) -> Scene {
    let mut scene = lone_sphere(
        "ibl_furnace",
        size,
        mesh::uv_sphere(64, 32),
        material,
        lighting,
    );
    scene.environment = Some(Environment {
        image: Arc::new(EnvironmentImage {
            label: "uniform radiance 1".to_owned(),
            width: 64,
            height: 32,
            texels: vec![[1.0, 1.0, 1.0, 1.0]; 64 * 32],
        }),
        rotation_degrees: 0.0,
        intensity: 1.0,
    });
    scene
}

/// Where the wall of [`corner`] stands: the plane x = this, facing +x.
pub const CORNER_WALL_X: f64 = -1.0;

/// Two planes meeting at a right angle, a floor (y = 0, facing +y) and a wall
/// (x = [`CORNER_WALL_X`], facing +x), 8 m across, seen from the open side, with a uniform
/// ambient and screen-space ambient occlusion of `radius`: the occlusion of a floor point has
/// a closed form in its distance from the wall
/// ([`engine::renderer::ambient_occlusion::corner_occlusion`]).
pub fn corner(size: u32, radius: f32, samples: u32) -> Scene {
    let mut scene = empty_scene(
        "corner",
        size,
        camera(DVec3::new(2.0, 2.2, 3.2), DVec3::new(-0.6, 0.2, 0.0)),
    );
    let plane = Arc::new(mesh::plane(8.0, 4.0));
    let material = Material {
        base_color: [0.8; 3],
        roughness: 0.9,
        specular: 0.0,
        ..Material::default()
    };
    scene.objects.push(Object {
        name: "floor".to_owned(),
        mesh: plane.clone(),
        transform: Transform::default(),
        material: material.clone(),
        lighting: LightingModel::Pbr,
        casts_shadows: false,
    });
    scene.objects.push(Object {
        name: "wall".to_owned(),
        mesh: plane,
        transform: Transform {
            translation: DVec3::new(CORNER_WALL_X, 0.0, 0.0),
            // The plane's +y normal turned to +x, its extent now along y and z.
            rotation: DQuat::from_rotation_z(-std::f64::consts::FRAC_PI_2),
            scale: DVec3::ONE,
        },
        material,
        lighting: LightingModel::Pbr,
        casts_shadows: false,
    });
    scene.ambient = [1.0; 3];
    scene.quality.ssao = Some(SsaoSettings { radius, samples });
    scene
}

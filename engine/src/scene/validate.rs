//! Checking a scene before anything reaches the GPU: every value that would otherwise turn into
//! NaN pixels, an empty draw or a driver error is refused with a message naming the object or
//! light at fault.

use glam::DVec3;

use super::{Light, Object, Scene};

/// A scene that cannot be drawn as given, and why.
#[derive(Clone, Debug, PartialEq, Eq, thiserror::Error)]
#[error("scene `{scene}`: {problem}")]
pub struct InvalidScene {
    /// Scene name.
    pub scene: String,
    /// What is wrong (naming the object or light at fault).
    pub problem: String,
}

impl Scene {
    /// Checks what would otherwise turn into NaN pixels, an empty draw or a driver error.
    pub fn validate(&self) -> Result<(), InvalidScene> {
        validate(self)
    }
}

fn validate(scene: &Scene) -> Result<(), InvalidScene> {
    let checks = || -> Result<(), String> {
        check_name(&scene.name)?;
        check_output_and_camera(scene)?;
        for object in &scene.objects {
            check_object(object, scene.textures.len())?;
            check_reach(object, scene.camera.position)?;
        }
        for (i, light) in scene.lights.iter().enumerate() {
            check_light(i, light)?;
        }
        check_environment(scene)
    };
    checks().map_err(|problem| InvalidScene {
        scene: scene.name.clone(),
        problem,
    })
}

fn finite3(v: DVec3) -> bool {
    v.is_finite()
}

/// The scene's name names its folders (`golden/<name>/`, the failure images' `<out>/failures/
/// <name>/`), so it must be one folder name: a name that climbs out (`..`), is empty or holds a
/// separator would put goldens and failure images elsewhere, or clear another scene's.
fn check_name(name: &str) -> Result<(), String> {
    let bad = name.is_empty()
        || name == "."
        || name == ".."
        || name
            .chars()
            .any(|c| c == '/' || c == '\\' || c.is_control());
    if bad {
        return Err(format!(
            "name {name:?} cannot name a folder (golden/<name>/): it must not be empty, `.` or \
             `..`, nor hold `/`, `\\` or control characters"
        ));
    }
    Ok(())
}

/// The largest far / near ratio: beyond 2^24 a 32-bit float depth buffer cannot tell geometry
/// near the far plane (depth 1 - near/far) from the cleared background (depth 1), and it
/// vanishes.
const MAX_FAR_OVER_NEAR: f64 = 16_777_216.0;

/// Output size, exposure, camera and ambient.
fn check_output_and_camera(scene: &Scene) -> Result<(), String> {
    let q = &scene.quality;
    if q.width == 0 || q.height == 0 || q.width > 8192 || q.height > 8192 {
        return Err(format!(
            "output size {}x{} is outside 1..8192",
            q.width, q.height
        ));
    }
    if !(q.exposure.is_finite() && q.exposure > 0.0) {
        let beyond = if q.exposure.is_infinite() {
            BEYOND_F32
        } else {
            ""
        };
        return Err(format!(
            "exposure {} must be finite and positive{beyond}",
            q.exposure
        ));
    }
    if let Some(problem) = scene.quality.ssao.as_ref().and_then(|s| s.problem()) {
        return Err(problem);
    }
    let c = &scene.camera;
    if !finite3(c.position) || !finite3(c.target) || !finite3(c.up) {
        return Err("camera position, target and up must be finite".into());
    }
    let forward = c.target - c.position;
    if forward.length() < 1e-9 || forward.normalize().cross(c.up).length() < 1e-6 {
        return Err("camera target must differ from its position and not lie along `up`".into());
    }
    if !(c.fov_y_degrees > 0.0 && c.fov_y_degrees < 180.0) {
        return Err(format!(
            "camera fov {} must be between 0 and 180 degrees",
            c.fov_y_degrees
        ));
    }
    if !(c.near > 0.0 && c.far > c.near && c.far.is_finite()) {
        return Err(format!(
            "camera near {} and far {} must satisfy 0 < near < far",
            c.near, c.far
        ));
    }
    if c.far / c.near > MAX_FAR_OVER_NEAR {
        return Err(format!(
            "camera far / near is {:.3e}, over 2^24 (near {}, far {}): the 32-bit depth buffer \
             cannot tell what lies towards the far plane from the empty background; raise near \
             or lower far",
            c.far / c.near,
            c.near,
            c.far
        ));
    }
    if !scene.ambient.iter().all(|a| a.is_finite() && *a >= 0.0) {
        return Err("ambient must be finite and non-negative".into());
    }
    Ok(())
}

/// One object: its transform, material, texture indices and mesh.
fn check_object(object: &Object, texture_count: usize) -> Result<(), String> {
    let t = &object.transform;
    if !finite3(t.translation) || !t.rotation.is_finite() || !finite3(t.scale) {
        return Err(format!("object `{}`: transform is not finite", object.name));
    }
    if t.scale.abs().min_element() < 1e-12 {
        return Err(format!(
            "object `{}`: scale [{}, {}, {}] has a zero component",
            object.name, t.scale.x, t.scale.y, t.scale.z
        ));
    }
    let m = &object.material;
    let [r, g, b] = m.base_color;
    let named = [
        ("base color r", r),
        ("base color g", g),
        ("base color b", b),
        ("roughness", m.roughness),
        ("metallic", m.metallic),
        ("specular", m.specular),
        ("anisotropy", m.anisotropy),
        ("clearcoat", m.clearcoat),
        ("clearcoat roughness", m.clearcoat_roughness),
        ("specular exponent", m.specular_exponent),
    ];
    if let Some((name, value)) = named.iter().find(|(_, v)| !v.is_finite()) {
        return Err(format!(
            "object `{}`: material {name} is {value}, not a finite number",
            object.name
        ));
    }
    for index in [
        m.base_color_map,
        m.normal_map,
        m.roughness_map,
        m.metallic_map,
        m.clearcoat_map,
        m.specular_map,
    ]
    .into_iter()
    .flatten()
    {
        if index >= texture_count {
            return Err(format!(
                "object `{}`: texture index {index} out of range ({texture_count} textures)",
                object.name
            ));
        }
    }
    if object.mesh.indices.is_empty() {
        return Err(format!("object `{}`: mesh has no triangles", object.name));
    }
    let vertex_count = object.mesh.vertices.len();
    if object
        .mesh
        .indices
        .iter()
        .any(|&i| i as usize >= vertex_count)
    {
        return Err(format!(
            "object `{}`: mesh index out of range ({vertex_count} vertices)",
            object.name
        ));
    }
    Ok(())
}

/// The farthest an object may reach from the camera: the lighting squares camera-relative
/// coordinates in 32-bit floats (lengths, dot products), which overflow past about 1.8e19
/// (the square root of f32's largest value); beyond it an object vanishes or turns black
/// without a word. 1e18 leaves a margin of 18 for the sums.
pub const MAX_REACH: f64 = 1e18;

/// An object's mesh bounds, placed by its transform as the renderer places it (relative to the
/// camera), lie within [`MAX_REACH`] of the camera: the eight corners bound every vertex.
fn check_reach(object: &Object, camera: DVec3) -> Result<(), String> {
    let model = object.transform.relative_to(camera);
    let (min, max) = (object.mesh.bounds.min, object.mesh.bounds.max);
    let corner = |i: usize| {
        let pick = |axis: usize| {
            f64::from(if i >> axis & 1 == 0 {
                min[axis]
            } else {
                max[axis]
            })
        };
        model.transform_point3(DVec3::new(pick(0), pick(1), pick(2)))
    };
    let far = (0..8)
        .map(|i| corner(i).abs().max_element())
        .fold(0.0f64, f64::max);
    if far > MAX_REACH {
        return Err(format!(
            "object `{}` reaches {far:.3e} from the camera (its transform or its mesh's \
             coordinates), beyond {MAX_REACH:e}: the lighting's 32-bit arithmetic overflows there",
            object.name
        ));
    }
    Ok(())
}

/// Light `i`: finite parameters, and shadow settings its type supports.
fn check_light(i: usize, light: &Light) -> Result<(), String> {
    if let Some(problem) = light_value_problem(light) {
        return Err(format!("light {i}: {problem}"));
    }
    if let Some(problem) = light.shadow_problem() {
        return Err(format!("light {i}: {problem}"));
    }
    Ok(())
}

/// Why a scene value read as an f32 is infinite: a number written beyond its range reads so.
const BEYOND_F32: &str = " (a number beyond f32's range, about 3.4e38, reads as inf)";

/// The first of a light's values that is out of range, named as in the scene file with the
/// value read.
fn light_value_problem(light: &Light) -> Option<String> {
    // Colors and scalars are f32: a number written beyond its range reads as infinite.
    let f32_value = |name: &str, value: f32| {
        (!value.is_finite()).then(|| {
            let beyond = if value.is_nan() { "" } else { BEYOND_F32 };
            format!("{name} must be a finite number, not {value}{beyond}")
        })
    };
    let color = |c: &[f32; 3]| {
        c.iter()
            .find_map(|&v| f32_value("color", v))
            .map(|problem| format!("{problem} in {c:?}"))
    };
    let vector = |name: &str, v: &DVec3| {
        (!v.is_finite()).then(|| format!("{name} must be finite numbers, not {:?}", v.to_array()))
    };
    let positive = |name: &str, value: f32| {
        f32_value(name, value)
            .or_else(|| (value <= 0.0).then(|| format!("{name} must be positive, not {value}")))
    };
    match light {
        Light::Directional {
            direction,
            color: c,
            intensity,
            angular_radius,
            ..
        } => vector("direction", direction)
            .or_else(|| {
                (direction.length() <= 1e-12)
                    .then(|| format!("direction must not be zero, not {:?}", direction.to_array()))
            })
            .or_else(|| color(c))
            .or_else(|| f32_value("intensity", *intensity))
            .or_else(|| {
                (!(0.0..1.5).contains(angular_radius)).then(|| {
                    format!(
                        "angular_radius must be at least 0 and under 1.5 (radians), not \
                         {angular_radius}"
                    )
                })
            }),
        Light::Point {
            position,
            color: c,
            intensity,
            radius,
            falloff,
            ..
        } => vector("position", position)
            .or_else(|| color(c))
            .or_else(|| f32_value("intensity", *intensity))
            .or_else(|| positive("radius", *radius))
            .or_else(|| positive("falloff", *falloff)),
    }
}

/// The IBL settings, and the environment's intensity, rotation and image.
fn check_environment(scene: &Scene) -> Result<(), String> {
    let Some(env) = &scene.environment else {
        return Ok(());
    };
    if let Some(problem) = scene.quality.ibl.problem() {
        return Err(problem);
    }
    if !(env.intensity.is_finite() && env.intensity >= 0.0) {
        return Err(format!(
            "environment intensity {} must be finite and at least 0 (an environment cannot take \
             light away)",
            env.intensity
        ));
    }
    if !env.rotation_degrees.is_finite() {
        return Err(format!(
            "environment rotation {} must be finite",
            env.rotation_degrees
        ));
    }
    let image = &env.image;
    if image.width == 0
        || image.height == 0
        || image.texels.len() != (image.width * image.height) as usize
    {
        return Err(format!("environment `{}`: bad size", image.label));
    }
    Ok(())
}

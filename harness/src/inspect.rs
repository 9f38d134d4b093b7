//! `harness inspect PATH`: loads an OBJ, MTL, scene file, EXR or PNG exactly as a render would
//! and reports what was loaded (or the error), as text or JSON.

use std::path::Path;

use engine::assets::{self, ColorSpace, TextureCache};
use engine::renderer::PreparedFrame;
use engine::scene::{Light, Object};
use engine::scene_file;
use serde_json::{json, Value};

/// Why inspection failed: the loader's error, already naming the file.
#[derive(Debug, thiserror::Error)]
pub enum InspectError {
    /// An asset failed to load.
    #[error(transparent)]
    Asset(#[from] assets::AssetError),
    /// A scene file failed to load.
    #[error(transparent)]
    Scene(#[from] scene_file::SceneFileError),
    /// A scene's `[tolerances]` do not fit its golden passes (as `check` would refuse them).
    #[error(transparent)]
    Tolerances(#[from] Box<crate::golden::suite::SuiteError>),
    /// The extension is not one `inspect` knows.
    #[error("{0}: don't know how to inspect this (expected .obj, .mtl, .toml, an environment (.exr, .hdr) or a texture (.png, .jpg, .tga, .bmp))")]
    UnknownKind(String),
}

/// Loads `path` and returns a JSON description of what was loaded.
pub fn inspect(path: &Path) -> Result<Value, InspectError> {
    let extension = path
        .extension()
        .and_then(|e| e.to_str())
        .unwrap_or("")
        .to_ascii_lowercase();
    match extension.as_str() {
        "obj" => inspect_obj(path),
        "mtl" => inspect_mtl(path),
        "png" | "jpg" | "jpeg" | "tga" | "bmp" => inspect_texture(path),
        "exr" | "hdr" => inspect_environment(path),
        "toml" => inspect_scene(path),
        _ => Err(InspectError::UnknownKind(path.display().to_string())),
    }
}

/// An OBJ model: its meshes, materials and textures.
fn inspect_obj(path: &Path) -> Result<Value, InspectError> {
    let mut textures = TextureCache::new();
    let model = assets::load_obj(path, &mut textures)?;
    let summary = serde_json::to_value(model.summary(&textures)).unwrap_or(Value::Null);
    Ok(json!({ "kind": "obj", "model": summary }))
}

/// An MTL library: its materials and the textures they use.
fn inspect_mtl(path: &Path) -> Result<Value, InspectError> {
    let mut textures = TextureCache::new();
    let (materials, warnings) = assets::load_mtl(path, &mut textures)?;
    let texture_path = |id| {
        textures
            .get(id)
            .map(|t| t.path.display().to_string())
            .unwrap_or_default()
    };
    let materials: Vec<Value> = materials
        .iter()
        .map(|m| {
            json!({
                "name": m.name,
                "diffuse": m.diffuse,
                "specular": m.specular,
                "shininess": m.shininess,
                "maps": m.maps.iter().map(|(slot, id)| json!({"slot": slot, "path": texture_path(id)})).collect::<Vec<_>>(),
            })
        })
        .collect();
    let textures: Vec<Value> = textures
        .iter()
        .map(|(_, t)| {
            texture_json(
                &t.path.display().to_string(),
                t.width,
                t.height,
                t.mips.len(),
                t.color_space,
            )
        })
        .collect();
    Ok(
        json!({ "kind": "mtl", "path": path.display().to_string(), "materials": materials, "textures": textures, "warnings": warnings }),
    )
}

/// A texture, decoded as sRGB.
fn inspect_texture(path: &Path) -> Result<Value, InspectError> {
    let texture = assets::load_texture(path, ColorSpace::Srgb)?;
    let mut described = texture_json(
        &path.display().to_string(),
        texture.width,
        texture.height,
        texture.mips.len(),
        ColorSpace::Srgb,
    );
    described["bits"] = json!(texture.bits());
    Ok(json!({ "kind": "texture", "texture": described }))
}

/// An environment map.
fn inspect_environment(path: &Path) -> Result<Value, InspectError> {
    let environment = assets::load_environment(path)?;
    let summary = serde_json::to_value(environment.summary()).unwrap_or(Value::Null);
    Ok(json!({ "kind": "environment", "environment": summary }))
}

/// A scene file: its objects, lights, environment, textures and render plan.
fn inspect_scene(path: &Path) -> Result<Value, InspectError> {
    let loaded = scene_file::load(path)?;
    // Its tolerances read against its golden passes, as `check` reads them (only when it has
    // any; the rules, not the noise model's limits).
    if !loaded.tolerances.is_empty() {
        let model = crate::golden::noise::NoiseModel::default();
        crate::golden::suite::Case::from_loaded(loaded.clone(), &model).map_err(Box::new)?;
    }
    let scene = &loaded.scene;
    let objects: Vec<Value> = scene.objects.iter().map(object_json).collect();
    let lights: Vec<Value> = scene.lights.iter().map(light_json).collect();
    let textures: Vec<Value> = scene
        .textures
        .iter()
        .map(|t| {
            let space = if t.srgb {
                ColorSpace::Srgb
            } else {
                ColorSpace::Linear
            };
            texture_json(&t.label, t.width, t.height, t.mips.len(), space)
        })
        .collect();
    let environment = scene.environment.as_ref().map(|e| {
        json!({
            "path": e.image.label, "width": e.image.width, "height": e.image.height,
            "rotation_degrees": e.rotation_degrees, "intensity": e.intensity,
        })
    });
    Ok(json!({
        "kind": "scene",
        "path": path.display().to_string(),
        "name": scene.name,
        "description": loaded.description,
        "size": [scene.quality.width, scene.quality.height],
        "objects": objects,
        "lights": lights,
        "environment": environment,
        "textures": textures,
        "textures_decoded": loaded.textures_decoded,
        "warnings": loaded.warnings,
        "plan": match PreparedFrame::new(scene) {
            Ok(frame) => frame.plan().to_string(),
            Err(e) => format!("cannot be drawn: {e}"),
        },
    }))
}

/// One object of a scene: its mesh, lighting model and material.
fn object_json(o: &Object) -> Value {
    let m = &o.material;
    let maps: Vec<&str> = [
        ("base_color", m.base_color_map),
        ("normal", m.normal_map),
        ("roughness", m.roughness_map),
        ("metallic", m.metallic_map),
        ("clearcoat", m.clearcoat_map),
        ("specular", m.specular_map),
    ]
    .into_iter()
    .filter_map(|(name, map)| map.map(|_| name))
    .collect();
    // A map replaces its value (the Quarantamaula engine's rule, gbuffer.wgsl; the MTL
    // specification multiplies `Kd` by `map_Kd`): these values are not what is drawn. The
    // normal map has no value to replace.
    let replaced: Vec<&str> = maps.iter().copied().filter(|&m| m != "normal").collect();
    json!({
        "name": o.name,
        "mesh": o.mesh.name,
        "vertices": o.mesh.vertices.len(),
        "triangles": o.mesh.triangle_count(),
        "bounds": o.mesh.bounds,
        "lighting": o.lighting.name(),
        "base_color": m.base_color,
        "roughness": m.roughness,
        "metallic": m.metallic,
        "clearcoat": m.clearcoat,
        "anisotropy": m.anisotropy,
        "maps": maps,
        "replaced_by_maps": replaced,
    })
}

/// `x` as the decimal it was written as: an f32 widened to f64 as it is prints its binary
/// rounding (0.93 as 0.9300000071525574); its shortest decimal is what the scene file said.
fn decimal(x: f32) -> f64 {
    x.to_string().parse().unwrap_or(f64::from(x))
}

/// One light of a scene.
fn light_json(l: &Light) -> Value {
    match l {
        Light::Directional {
            direction,
            color,
            intensity,
            angular_radius,
            shadow,
        } => json!({
            "type": "directional", "direction": direction.to_array(), "color": color.map(decimal),
            "intensity": decimal(*intensity), "angular_radius": decimal(*angular_radius),
            "shadow_map": shadow.map(|s| s.map_size),
        }),
        Light::Point {
            position,
            color,
            intensity,
            radius,
            falloff,
            shadow,
        } => json!({
            "type": "point", "position": position.to_array(), "color": color.map(decimal),
            "intensity": decimal(*intensity), "radius": decimal(*radius), "falloff": decimal(*falloff),
            "shadow_map": shadow.map(|s| s.map_size),
        }),
    }
}

fn texture_json(path: &str, width: u32, height: u32, mips: usize, space: ColorSpace) -> Value {
    json!({
        "path": path,
        "width": width,
        "height": height,
        "mips": mips,
        "color_space": if space == ColorSpace::Srgb { "srgb" } else { "linear" },
    })
}

/// A short human-readable rendering of [`inspect`]'s JSON.
pub fn to_text(value: &Value) -> String {
    let mut out = String::new();
    let line = |out: &mut String, s: String| {
        out.push_str(&s);
        out.push('\n');
    };
    match value["kind"].as_str() {
        Some("obj") => {
            let m = &value["model"];
            line(
                &mut out,
                format!("OBJ {}", m["path"].as_str().unwrap_or("")),
            );
            for mesh in m["meshes"].as_array().into_iter().flatten() {
                line(
                    &mut out,
                    format!(
                        "  mesh {:<20} {:>7} vertices {:>7} triangles  material {}  bounds {} .. {}",
                        mesh["name"].as_str().unwrap_or(""),
                        mesh["vertices"],
                        mesh["triangles"],
                        mesh["material"].as_str().unwrap_or("-"),
                        mesh["bounds"]["min"],
                        mesh["bounds"]["max"]
                    ),
                );
            }
            for material in m["materials"].as_array().into_iter().flatten() {
                line(
                    &mut out,
                    format!(
                        "  material {} maps {}",
                        material["name"].as_str().unwrap_or(""),
                        material["maps"]
                    ),
                );
            }
            text_textures_and_warnings(&mut out, m);
        }
        Some("scene") => {
            line(
                &mut out,
                format!(
                    "scene {} ({})",
                    value["name"].as_str().unwrap_or(""),
                    value["path"].as_str().unwrap_or("")
                ),
            );
            if let Some(d) = value["description"].as_str() {
                line(&mut out, format!("  {d}"));
            }
            for o in value["objects"].as_array().into_iter().flatten() {
                let from_map = o["replaced_by_maps"]
                    .as_array()
                    .is_some_and(|r| r.iter().any(|v| v == "base_color"));
                let base_color = if from_map {
                    "its map".to_owned()
                } else {
                    short(&o["base_color"])
                };
                line(
                    &mut out,
                    format!(
                        "  object {:<28} {:>6} triangles  {:<11} base color {base_color}  maps {}",
                        o["name"].as_str().unwrap_or(""),
                        o["triangles"],
                        o["lighting"].as_str().unwrap_or(""),
                        o["maps"]
                    ),
                );
            }
            for l in value["lights"].as_array().into_iter().flatten() {
                line(&mut out, format!("  light {l}"));
            }
            if !value["environment"].is_null() {
                line(&mut out, format!("  environment {}", value["environment"]));
            }
            line(
                &mut out,
                format!(
                    "  {} textures, {} decoded",
                    value["textures"].as_array().map_or(0, Vec::len),
                    value["textures_decoded"]
                ),
            );
            for w in value["warnings"].as_array().into_iter().flatten() {
                line(&mut out, format!("  warning: {}", w.as_str().unwrap_or("")));
            }
            out.push_str(value["plan"].as_str().unwrap_or(""));
        }
        Some("mtl") => mtl_text(&mut out, value),
        Some("texture") => {
            let t = &value["texture"];
            line(
                &mut out,
                format!(
                    "texture {} {}x{} {}-bit {} mips (loaded as {})",
                    t["path"].as_str().unwrap_or(""),
                    t["width"],
                    t["height"],
                    t["bits"],
                    t["mips"],
                    t["color_space"].as_str().unwrap_or("")
                ),
            );
        }
        Some("environment") => {
            let e = &value["environment"];
            line(
                &mut out,
                format!(
                    "environment {} {}x{}, radiance ({}) {} .. {}, mean {}",
                    e["path"].as_str().unwrap_or(""),
                    e["width"],
                    e["height"],
                    e["radiance_measure"].as_str().unwrap_or(""),
                    e["min_radiance"],
                    e["max_radiance"],
                    e["mean_radiance"]
                ),
            );
        }
        _ => {
            out = serde_json::to_string_pretty(value).unwrap_or_default();
            out.push('\n');
        }
    }
    out
}

/// The texture lines (with their bit depth where known) and the warning lines of an OBJ's or
/// an MTL's [`to_text`], from the part of its JSON that lists them.
fn text_textures_and_warnings(out: &mut String, value: &Value) {
    for t in value["textures"].as_array().into_iter().flatten() {
        let bits = t["bits"]
            .as_u64()
            .map_or(String::new(), |b| format!("{b}-bit "));
        out.push_str(&format!(
            "  texture {} {}x{} {bits}{} mips {}\n",
            t["path"].as_str().unwrap_or(""),
            t["width"],
            t["height"],
            t["mips"],
            t["color_space"].as_str().unwrap_or("")
        ));
    }
    for w in value["warnings"].as_array().into_iter().flatten() {
        out.push_str(&format!("  warning: {}\n", w.as_str().unwrap_or("")));
    }
}

/// A JSON number, or list of numbers, read from f32 values, as their shortest decimals
/// (`[0.8, 0.7, 0.6]`, not `[0.800000011920929, ...]`); `-` for null.
fn short(value: &Value) -> String {
    let number = |v: &Value| {
        v.as_f64()
            .map_or_else(|| v.to_string(), |x| (x as f32).to_string())
    };
    match value {
        Value::Null => "-".to_owned(),
        Value::Array(items) => {
            let items: Vec<String> = items.iter().map(number).collect();
            format!("[{}]", items.join(", "))
        }
        other => number(other),
    }
}

/// [`to_text`] of an MTL: its materials (an unused `Kd` marked so), textures and warnings.
fn mtl_text(out: &mut String, value: &Value) {
    let line = |out: &mut String, s: String| {
        out.push_str(&s);
        out.push('\n');
    };
    line(out, format!("MTL {}", value["path"].as_str().unwrap_or("")));
    for m in value["materials"].as_array().into_iter().flatten() {
        let maps: Vec<&str> = m["maps"]
            .as_array()
            .into_iter()
            .flatten()
            .filter_map(|map| map["slot"].as_str())
            .collect();
        let kd = match &m["diffuse"] {
            Value::Null => "-".to_owned(),
            kd if maps.contains(&"base_color") => {
                format!("{} (unused: map_Kd replaces it)", short(kd))
            }
            kd => short(kd),
        };
        line(
            out,
            format!(
                "  material {}  Kd {kd}  Ns {}  maps {}",
                m["name"].as_str().unwrap_or(""),
                short(&m["shininess"]),
                if maps.is_empty() {
                    "none".to_owned()
                } else {
                    maps.join(", ")
                }
            ),
        );
    }
    text_textures_and_warnings(out, value);
}

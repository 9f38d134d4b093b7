//! Resolving a parsed [`SceneFile`] into a [`Scene`]: the camera and quality settings with their
//! defaults, and the environment, objects (meshes, MTL materials, textures, overrides) and
//! lights it names, each asset loaded once, with the problems found on the way as errors or
//! warnings that name the scene file.

use std::collections::HashMap;
use std::path::{Path, PathBuf};
use std::sync::Arc;

use glam::{DQuat, DVec3, EulerRot};

use crate::assets::{self, AssetError, ColorSpace, TextureCache, TextureId};
use crate::mesh::{self, MeshData};
use crate::scene::{
    Camera, Environment, EnvironmentImage, Light, LightingModel, Material, Object, Quality, Scene,
    ShadowSettings, TextureImage, Transform,
};

use super::schema::{
    CameraSpec, EnvironmentSpec, LightSpec, MaterialSpec, ObjectSpec, QualitySpec, ScaleSpec,
    SceneFile, ShadowSpec,
};
use super::{LoadedScene, SceneFileError};

/// Turns a [`SceneFile`] into a [`LoadedScene`], loading each mesh and texture once and
/// collecting the loaders' warnings.
pub(super) struct Resolver {
    path: PathBuf,
    dir: PathBuf,
    cache: TextureCache,
    texture_index: HashMap<TextureId, usize>,
    textures: Vec<Arc<TextureImage>>,
    models: HashMap<PathBuf, Arc<MeshParts>>,
    /// Each loaded asset's warnings, once per asset.
    warnings: Vec<String>,
    /// The scene file, environment, meshes and material libraries read so far (the textures
    /// are the cache's).
    files: Vec<PathBuf>,
}

/// The meshes of one OBJ file, each with its MTL material.
type MeshParts = Vec<(Arc<MeshData>, Option<assets::MaterialData>)>;

/// Whether every value is finite.
fn finite(values: &[f64]) -> bool {
    values.iter().all(|v| v.is_finite())
}

impl Resolver {
    pub(super) fn new(path: &Path, limits: assets::Limits) -> Self {
        Self {
            path: path.to_owned(),
            dir: path.parent().map(Path::to_owned).unwrap_or_default(),
            cache: TextureCache::with_limits(limits),
            texture_index: HashMap::new(),
            textures: Vec::new(),
            models: HashMap::new(),
            warnings: Vec::new(),
            files: vec![path.to_owned()],
        }
    }

    fn invalid(&self, message: String) -> SceneFileError {
        SceneFileError::Invalid {
            path: self.path.clone(),
            message,
        }
    }

    /// Checks an environment's size from its header (EXR or Radiance `.hdr`) and reserves its
    /// RGBA32F texels.
    fn reserve_environment(&mut self, path: &Path) -> Result<(), AssetError> {
        for (w, h) in crate::assets::environment_sizes(path)? {
            let (w, h) = (
                u32::try_from(w).unwrap_or(u32::MAX),
                u32::try_from(h).unwrap_or(u32::MAX),
            );
            self.cache.budget().check_image(path, w, h)?;
            self.cache
                .budget()
                .reserve(path, u64::from(w) * u64::from(h) * 16)?;
        }
        Ok(())
    }

    fn asset(&self, source: AssetError) -> SceneFileError {
        SceneFileError::Asset {
            path: self.path.clone(),
            source,
        }
    }

    fn texture(&mut self, id: Option<TextureId>) -> Option<usize> {
        let id = id?;
        if let Some(&index) = self.texture_index.get(&id) {
            return Some(index);
        }
        let data = self.cache.get(id)?;
        let index = self.textures.len();
        self.textures.push(Arc::new(TextureImage {
            label: data.path.display().to_string(),
            srgb: data.color_space == ColorSpace::Srgb,
            width: data.width,
            height: data.height,
            format: data.format,
            mips: data.mips.clone(),
        }));
        self.texture_index.insert(id, index);
        Some(index)
    }

    /// Warns that `path` (the scene's `what`) is absolute: a golden made with it would not load
    /// on another machine or checkout. Relative paths are resolved against the scene file.
    fn warn_if_absolute(&mut self, what: &str, path: &str) {
        if Path::new(path).is_absolute() {
            self.warnings.push(format!(
                "{}: {what} `{path}` is an absolute path; it will not resolve on another machine \
                 (give it relative to the scene file)",
                self.path.display()
            ));
        }
    }

    /// The meshes (with their MTL materials) of an OBJ file or built-in mesh, loaded once.
    fn model(&mut self, mesh_ref: &str) -> Result<Arc<MeshParts>, SceneFileError> {
        let key = if mesh_ref.starts_with("builtin:") {
            PathBuf::from(mesh_ref)
        } else {
            self.dir.join(mesh_ref)
        };
        if let Some(parts) = self.models.get(&key) {
            return Ok(parts.clone());
        }
        let parts: MeshParts = match mesh_ref.strip_prefix("builtin:") {
            Some("sphere") => vec![(Arc::new(mesh::uv_sphere(64, 32)), None)],
            Some("plane") => vec![(Arc::new(mesh::plane(1.0, 1.0)), None)],
            Some(other) => {
                return Err(self.invalid(format!(
                    "unknown built-in mesh `builtin:{other}` (expected builtin:sphere or \
                     builtin:plane)"
                )))
            }
            None => {
                let model = assets::load_obj(&key, &mut self.cache).map_err(|e| self.asset(e))?;
                self.warnings.extend(model.warnings);
                self.files.push(key.clone());
                self.files.extend(model.material_libraries);
                let materials = model.materials;
                model
                    .meshes
                    .into_iter()
                    .map(|m| {
                        let material = m.material.and_then(|i| materials.get(i).cloned());
                        (Arc::new(m), material)
                    })
                    .collect()
            }
        };
        let parts = Arc::new(parts);
        self.models.insert(key, parts.clone());
        Ok(parts)
    }

    /// The scene the file describes, with the harness's part of the file beside it.
    pub(super) fn resolve(mut self, file: SceneFile) -> Result<LoadedScene, SceneFileError> {
        let camera = self.camera(&file.camera)?;
        let quality = quality(&file.quality);
        let environment = match &file.environment {
            Some(spec) => Some(self.environment(spec)?),
            None => None,
        };

        let mut objects = Vec::new();
        for (index, spec) in file.objects.iter().enumerate() {
            objects.extend(self.object_parts(index, spec)?);
        }

        let mut lights = Vec::new();
        for (index, spec) in file.lights.iter().enumerate() {
            lights.push(self.light(index, spec)?);
        }

        let name = file.name.clone().unwrap_or_else(|| {
            self.path
                .file_stem()
                .and_then(|s| s.to_str())
                .unwrap_or("scene")
                .to_owned()
        });
        let scene = Scene {
            name,
            camera,
            objects,
            lights,
            ambient: file.ambient,
            environment,
            textures: self.textures.clone(),
            quality,
        };
        scene.validate().map_err(|e| self.invalid(e.to_string()))?;
        let mut files = self.files;
        files.extend(self.cache.iter().map(|(_, texture)| texture.path.clone()));
        let mut seen = std::collections::HashSet::new();
        files.retain(|file| seen.insert(file.clone()));
        Ok(LoadedScene {
            scene,
            path: self.path.clone(),
            description: file.description,
            tolerances: file.tolerances,
            textures_decoded: self.cache.decode_count(),
            files,
            warnings: self.warnings,
        })
    }

    /// `[camera]`, whose values must be finite (the first that is not is named).
    fn camera(&self, c: &CameraSpec) -> Result<Camera, SceneFileError> {
        let values: [(&str, &[f64]); 6] = [
            ("position", &c.position),
            ("target", &c.target),
            ("up", &c.up),
            ("fov_y", &[c.fov_y]),
            ("near", &[c.near]),
            ("far", &[c.far]),
        ];
        if let Some((key, value)) = values.iter().find(|(_, v)| !finite(v)) {
            let value = match value {
                [one] => one.to_string(),
                many => format!("{many:?}"),
            };
            return Err(self.invalid(format!("[camera] {key} = {value}: values must be finite")));
        }
        Ok(Camera {
            position: DVec3::from(c.position),
            target: DVec3::from(c.target),
            up: DVec3::from(c.up),
            fov_y_degrees: c.fov_y,
            near: c.near,
            far: c.far,
        })
    }

    /// `[environment]`: its EXR checked against the limits, then loaded.
    fn environment(&mut self, spec: &EnvironmentSpec) -> Result<Environment, SceneFileError> {
        self.warn_if_absolute("[environment] path", &spec.path.to_string_lossy());
        let env_path = self.dir.join(&spec.path);
        self.reserve_environment(&env_path)
            .map_err(|e| self.asset(e))?;
        let loaded = assets::load_environment(&env_path).map_err(|e| self.asset(e))?;
        self.files.push(env_path.clone());
        if loaded.width != 2 * loaded.height {
            self.warnings.push(format!(
                "{}: environment {} is {}x{}, not twice as wide as tall: an equirectangular \
                 image spans 360 degrees across and 180 down, so it will be stretched",
                self.path.display(),
                env_path.display(),
                loaded.width,
                loaded.height
            ));
        }
        Ok(Environment {
            image: Arc::new(EnvironmentImage {
                label: env_path.display().to_string(),
                width: loaded.width,
                height: loaded.height,
                texels: loaded.texels,
            }),
            rotation_degrees: spec.rotation,
            intensity: spec.intensity,
        })
    }

    /// The objects of `[[objects]]` entry `index`: one per mesh of its OBJ file, named
    /// `name/mesh` when there are several.
    fn object_parts(
        &mut self,
        index: usize,
        spec: &ObjectSpec,
    ) -> Result<Vec<Object>, SceneFileError> {
        let parts = self.model(&spec.mesh)?;
        let base_name = spec.name.clone().unwrap_or_else(|| {
            let stem = Path::new(&spec.mesh)
                .file_stem()
                .and_then(|s| s.to_str())
                .unwrap_or("object");
            format!("{stem}_{index}")
        });
        self.warn_if_absolute(&format!("object `{base_name}`: mesh"), &spec.mesh);
        if !finite(&spec.position) || !finite(&spec.rotation) {
            return Err(self.invalid(format!(
                "object `{base_name}`: position and rotation must be finite"
            )));
        }
        let scale = match spec.scale {
            None => DVec3::ONE,
            Some(ScaleSpec::Uniform(s)) => DVec3::splat(s),
            Some(ScaleSpec::PerAxis(s)) => DVec3::from(s),
        };
        let [rx, ry, rz] = spec.rotation.map(f64::to_radians);
        let transform = Transform {
            translation: DVec3::from(spec.position),
            rotation: DQuat::from_euler(EulerRot::ZYX, rz, ry, rx),
            scale,
        };
        self.check_material_names(&base_name, spec, &parts)?;
        let single = parts.len() == 1;
        let mut objects = Vec::new();
        for (mesh, mtl) in parts.iter() {
            let material = self.material(spec, mtl.as_ref());
            let name = if single {
                base_name.clone()
            } else {
                format!("{base_name}/{}", mesh.name)
            };
            objects.push(Object {
                name,
                mesh: mesh.clone(),
                transform,
                material,
                lighting: spec.lighting.unwrap_or(LightingModel::Pbr),
                casts_shadows: spec.casts_shadows,
            });
        }
        Ok(objects)
    }

    /// Every `materials.<name>` of an object must name an MTL material one of its meshes uses:
    /// a misspelt name would otherwise change nothing, silently.
    fn check_material_names(
        &self,
        object: &str,
        spec: &ObjectSpec,
        parts: &MeshParts,
    ) -> Result<(), SceneFileError> {
        let used: std::collections::BTreeSet<&str> = parts
            .iter()
            .filter_map(|(_, mtl)| mtl.as_ref().map(|m| m.name.as_str()))
            .collect();
        let Some(unknown) = spec.materials.keys().find(|k| !used.contains(k.as_str())) else {
            return Ok(());
        };
        let known = if used.is_empty() {
            "it uses none".to_owned()
        } else {
            let names: Vec<&str> = used.into_iter().collect();
            format!("it uses {}", names.join(", "))
        };
        Err(self.invalid(format!(
            "object `{object}`: `materials.{unknown}` names no MTL material of {} ({known})",
            spec.mesh
        )))
    }

    /// A mesh's material: the defaults, then its MTL material's values and (unless an override
    /// sets `use_maps = false`) maps, then the object's `material` and its `materials` entry for
    /// the MTL material's name.
    fn material(&mut self, spec: &ObjectSpec, mtl: Option<&assets::MaterialData>) -> Material {
        let mut material = Material::default();
        let mut use_maps = true;
        let mtl_name = mtl.map(|m| m.name.clone());
        let overrides = std::iter::once(&spec.material)
            .chain(mtl_name.as_ref().and_then(|name| spec.materials.get(name)));
        if let Some(mtl) = mtl {
            if let Some(kd) = mtl.diffuse {
                material.base_color = kd;
            }
            if let Some(ns) = mtl.shininess {
                material.specular_exponent = ns;
            }
        }
        for o in overrides.clone() {
            if let Some(v) = o.use_maps {
                use_maps = v;
            }
        }
        if let (Some(mtl), true) = (mtl, use_maps) {
            let maps = mtl.maps;
            material.base_color_map = self.texture(maps.base_color);
            material.normal_map = self.texture(maps.normal);
            material.roughness_map = self.texture(maps.roughness);
            material.metallic_map = self.texture(maps.metallic);
            material.clearcoat_map = self.texture(maps.clearcoat);
            material.specular_map = self.texture(maps.specular);
        }
        for o in overrides {
            apply_overrides(&mut material, o);
        }
        let object = spec.name.as_deref().unwrap_or(&spec.mesh);
        let of = mtl_name.map_or(String::new(), |m| format!(", material `{m}`"));
        for problem in out_of_range(&material) {
            self.warnings.push(format!(
                "{}: object `{object}`{of}: {problem}",
                self.path.display()
            ));
        }
        material
    }

    /// `[[lights]]` entry `index`: its settings checked, and a warning for a negative intensity.
    fn light(&mut self, index: usize, spec: &LightSpec) -> Result<Light, SceneFileError> {
        let light = match spec {
            LightSpec::Directional(l) => Light::Directional {
                direction: DVec3::from(l.direction),
                color: l.color.unwrap_or([1.0; 3]),
                intensity: l.intensity.unwrap_or(1.0),
                angular_radius: 0.0,
                shadow: shadow_settings(l.shadow),
            },
            LightSpec::Point(l) => Light::Point {
                position: DVec3::from(l.position),
                color: l.color.unwrap_or([1.0; 3]),
                intensity: l.intensity.unwrap_or(1.0),
                radius: l.radius,
                falloff: l.falloff.unwrap_or(1.0),
                shadow: shadow_settings(l.shadow),
            },
        };
        if let Some(problem) = light.shadow_problem() {
            return Err(self.invalid(format!("light {index}: {problem}")));
        }
        let intensity = match &light {
            Light::Directional { intensity, .. } | Light::Point { intensity, .. } => *intensity,
        };
        if intensity < 0.0 {
            self.warnings.push(format!(
                "{}: light {index}: negative intensity {intensity} (the light takes energy \
                 away; no physical light does)",
                self.path.display()
            ));
        }
        Ok(light)
    }
}

/// `[quality]`, each setting it leaves out at its default.
fn quality(q: &QualitySpec) -> Quality {
    let defaults = Quality::default();
    Quality {
        width: q.width.unwrap_or(defaults.width),
        height: q.height.unwrap_or(defaults.height),
        exposure: q.exposure.unwrap_or(defaults.exposure),
        tone_map: q.tone_map.unwrap_or(defaults.tone_map),
        gizmos: q.gizmos.unwrap_or(defaults.gizmos),
        debug_shadow_terms: q.debug_shadow_terms.unwrap_or(defaults.debug_shadow_terms),
        point_shadows: q.point_shadows.unwrap_or(defaults.point_shadows),
        ibl: q.ibl.clone().unwrap_or(defaults.ibl),
        gbuffer: q.gbuffer.unwrap_or(defaults.gbuffer),
        ssao: q.ssao.or(defaults.ssao),
    }
}

/// A light's `[lights.shadow]`, each setting it leaves out at its default; None without one.
fn shadow_settings(spec: Option<ShadowSpec>) -> Option<ShadowSettings> {
    spec.map(|s| {
        let d = ShadowSettings::default();
        ShadowSettings {
            map_size: s.map_size.unwrap_or(d.map_size),
            bias: s.bias.unwrap_or(d.bias),
            slope_bias: s.slope_bias.unwrap_or(d.slope_bias),
            normal_offset: s.normal_offset.unwrap_or(d.normal_offset),
            filter: s.filter.unwrap_or(d.filter),
            soft_radius: s.soft_radius.unwrap_or(d.soft_radius),
            soft_samples: s.soft_samples.unwrap_or(d.soft_samples),
            vsm_blur_radius: s.vsm_blur_radius.unwrap_or(d.vsm_blur_radius),
            vsm_min_variance: s.vsm_min_variance.unwrap_or(d.vsm_min_variance),
            vsm_bleeding_reduction: s.vsm_bleeding_reduction.unwrap_or(d.vsm_bleeding_reduction),
        }
    })
}

/// Applies the values an override sets; a scalar it sets replaces the map for that parameter.
fn apply_overrides(material: &mut Material, o: &MaterialSpec) {
    if let Some(v) = o.base_color {
        material.base_color = v;
        material.base_color_map = None;
    }
    let set = |value: Option<f32>, target: &mut f32| {
        if let Some(v) = value {
            *target = v;
        }
    };
    set(o.roughness, &mut material.roughness);
    set(o.metallic, &mut material.metallic);
    set(o.specular, &mut material.specular);
    set(o.anisotropy, &mut material.anisotropy);
    set(o.clearcoat, &mut material.clearcoat);
    set(o.clearcoat_roughness, &mut material.clearcoat_roughness);
    set(o.specular_exponent, &mut material.specular_exponent);
    if o.roughness.is_some() {
        material.roughness_map = None;
    }
    if o.metallic.is_some() {
        material.metallic_map = None;
    }
    if o.clearcoat.is_some() {
        material.clearcoat_map = None;
    }
    if o.specular.is_some() {
        material.specular_map = None;
    }
}

/// A material's values outside the ranges its fields document (finite ones: NaN and infinity
/// are refused by the scene's validation), each as a phrase for a load warning.
fn out_of_range(m: &Material) -> Vec<String> {
    let mut problems = Vec::new();
    let unit = [
        ("roughness", m.roughness),
        ("metallic", m.metallic),
        ("specular", m.specular),
        ("clearcoat", m.clearcoat),
        ("clearcoat_roughness", m.clearcoat_roughness),
    ];
    for (name, value) in unit {
        if value.is_finite() && !(0.0..=1.0).contains(&value) {
            problems.push(format!("{name} {value} is outside 0..1"));
        }
    }
    if m.anisotropy.is_finite() && !(-1.0..=1.0).contains(&m.anisotropy) {
        problems.push(format!("anisotropy {} is outside -1..1", m.anisotropy));
    }
    if m.base_color.iter().any(|c| *c < 0.0) {
        problems.push(format!(
            "base colour {:?} is negative (no surface reflects less than nothing)",
            m.base_color
        ));
    }
    if m.specular_exponent.is_finite() && m.specular_exponent <= 0.0 {
        problems.push(format!(
            "specular exponent {} is not positive",
            m.specular_exponent
        ));
    }
    problems
}

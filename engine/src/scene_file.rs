//! Scene files: TOML, parsed with serde into [`SceneFile`], then resolved into a [`Scene`] by
//! loading the meshes, textures and environment they name. Paths are relative to the scene
//! file. Unknown keys are errors that name the key, the file and the line.
//!
//! The `[tolerances]` table belongs to the golden harness; the engine keeps it as raw TOML
//! ([`SceneFile::tolerances`]) for the harness to parse.
//!
//! The format is documented with a full example in the README ("Scene files").

use std::collections::{BTreeMap, HashMap};
use std::path::{Path, PathBuf};
use std::sync::Arc;

use glam::{DQuat, DVec3, EulerRot};
use serde::Deserialize;

use crate::assets::{self, AssetError, ColorSpace, TextureCache, TextureId};
use crate::ibl::IblSettings;
use crate::mesh::{self, MeshData};
use crate::scene::*;

/// Why a scene file could not be loaded.
#[derive(Debug, thiserror::Error)]
pub enum SceneFileError {
    /// The file could not be read.
    #[error("{path}: cannot read scene file: {source}")]
    Io {
        /// Scene file.
        path: PathBuf,
        /// OS error.
        source: std::io::Error,
    },
    /// TOML syntax error, wrong type or unknown key.
    #[error("{path}:{line}:{column}: {message}")]
    Parse {
        /// Scene file.
        path: PathBuf,
        /// 1-based line.
        line: usize,
        /// 1-based column.
        column: usize,
        /// What is wrong (names the key for unknown keys).
        message: String,
    },
    /// Parsed, but the values make no sense (NaN, negative radius, ...).
    #[error("{path}: {message}")]
    Invalid {
        /// Scene file.
        path: PathBuf,
        /// What is wrong and where.
        message: String,
    },
    /// A mesh, texture or environment it names failed to load.
    #[error("{path}: {source}")]
    Asset {
        /// Scene file.
        path: PathBuf,
        /// The asset error (names the asset file).
        source: AssetError,
    },
    /// `--scene NAME` named no canonical scene.
    #[error("no scene `{name}`: not a file, and not one of the scenes in {dir} ({known})")]
    UnknownScene {
        /// What was asked for.
        name: String,
        /// Where canonical scenes were looked for.
        dir: String,
        /// Scenes found there.
        known: String,
    },
}

fn default_up() -> [f64; 3] {
    [0.0, 1.0, 0.0]
}
fn default_fov() -> f64 {
    45.0
}
fn default_near() -> f64 {
    0.05
}
fn default_far() -> f64 {
    100.0
}
fn default_one() -> f32 {
    1.0
}
fn default_true() -> bool {
    true
}

/// `[camera]`.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct CameraSpec {
    /// Eye position.
    pub position: [f64; 3],
    /// Point looked at.
    pub target: [f64; 3],
    /// Up vector (default +Y).
    #[serde(default = "default_up")]
    pub up: [f64; 3],
    /// Vertical field of view, degrees (default 45).
    #[serde(default = "default_fov")]
    pub fov_y: f64,
    /// Near plane (default 0.05).
    #[serde(default = "default_near")]
    pub near: f64,
    /// Far plane (default 100).
    #[serde(default = "default_far")]
    pub far: f64,
}

/// `[quality]`.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct QualitySpec {
    /// Output width (default 512).
    pub width: Option<u32>,
    /// Output height (default 512).
    pub height: Option<u32>,
    /// Linear exposure (default 1).
    pub exposure: Option<f32>,
    /// `aces` (default), `reinhard` or `clamp`.
    pub tone_map: Option<ToneMap>,
    /// Draw gizmos (default false).
    pub gizmos: Option<bool>,
    /// Write `shadow_term_<light>` debug outputs (default false).
    pub debug_shadow_terms: Option<bool>,
    /// `six-passes` (default) or `geometry-shader` (gl only).
    pub point_shadows: Option<PointShadowPass>,
    /// `[quality.ibl]`: image-based lighting precompute (defaults in [`IblSettings`]).
    pub ibl: Option<IblSettings>,
    /// `[quality.gbuffer]`: position storage and normal encoding (defaults: camera-relative,
    /// fp16).
    pub gbuffer: Option<GbufferSettings>,
}

/// `[environment]`.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct EnvironmentSpec {
    /// Equirectangular EXR, relative to the scene file.
    pub path: PathBuf,
    /// Rotation about +Y in degrees.
    #[serde(default)]
    pub rotation: f32,
    /// Radiance multiplier (default 1).
    #[serde(default = "default_one")]
    pub intensity: f32,
}

/// Material overrides; every field is optional and replaces the MTL's value or the default.
#[derive(Clone, Debug, Default, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct MaterialSpec {
    /// Linear base color.
    pub base_color: Option<[f32; 3]>,
    /// Perceptual roughness.
    pub roughness: Option<f32>,
    /// Metallic.
    pub metallic: Option<f32>,
    /// Specular.
    pub specular: Option<f32>,
    /// Anisotropy -1..1.
    pub anisotropy: Option<f32>,
    /// Clearcoat strength.
    pub clearcoat: Option<f32>,
    /// Clearcoat roughness.
    pub clearcoat_roughness: Option<f32>,
    /// Blinn-Phong exponent.
    pub specular_exponent: Option<f32>,
    /// Set false to ignore the MTL's maps (scalars only).
    pub use_maps: Option<bool>,
}

/// A scale: one number or three.
#[derive(Clone, Copy, Debug, Deserialize)]
#[serde(untagged)]
pub enum ScaleSpec {
    /// Uniform.
    Uniform(f64),
    /// Per axis.
    PerAxis([f64; 3]),
}

/// `[[objects]]`.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ObjectSpec {
    /// Name (default: the mesh file stem and index).
    pub name: Option<String>,
    /// OBJ path relative to the scene file, or `builtin:sphere` / `builtin:plane`.
    pub mesh: String,
    /// World position.
    #[serde(default)]
    pub position: [f64; 3],
    /// Euler angles in degrees, applied X, then Y, then Z.
    #[serde(default)]
    pub rotation: [f64; 3],
    /// Scale (default 1).
    pub scale: Option<ScaleSpec>,
    /// Lighting model (default `pbr`).
    pub lighting: Option<LightingModel>,
    /// Drawn into shadow maps (default true).
    #[serde(default = "default_true")]
    pub casts_shadows: bool,
    /// Overrides for every mesh of the object.
    #[serde(default)]
    pub material: MaterialSpec,
    /// Overrides per MTL material name (applied after `material`).
    #[serde(default)]
    pub materials: BTreeMap<String, MaterialSpec>,
}

/// `[lights.shadow]`.
#[derive(Clone, Copy, Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ShadowSpec {
    /// Map size in texels (default 1024).
    pub map_size: Option<u32>,
    /// Constant bias.
    pub bias: Option<f32>,
    /// Slope-scaled bias (texels, scaled by tan(angle)).
    pub slope_bias: Option<f32>,
    /// Normal offset in shadow-map texels.
    pub normal_offset: Option<f32>,
    /// `hard`, `pcf3` (default), `bilinear`, `pcf3-bilinear`, `soft`, `soft-full`,
    /// `soft-reference`, `vogel` or `vsm`.
    pub filter: Option<ShadowFilter>,
    /// Sample-disk radius of the soft filters, in texels (default 2.5).
    pub soft_radius: Option<f32>,
    /// Samples of the `vogel` filter (default 64).
    pub soft_samples: Option<u32>,
    /// VSM blur radius in texels (default 2).
    pub vsm_blur_radius: Option<u32>,
    /// VSM minimum variance (default 1e-6).
    pub vsm_min_variance: Option<f32>,
    /// VSM light-bleeding reduction, 0..1 (default 0.2).
    pub vsm_bleeding_reduction: Option<f32>,
}

/// `[[lights]]`, by its `type`.
#[derive(Debug, Deserialize)]
#[serde(tag = "type", rename_all = "kebab-case")]
pub enum LightSpec {
    /// A directional light.
    Directional(DirectionalLightSpec),
    /// A point light with r2 attenuation.
    Point(PointLightSpec),
}

/// `[[lights]]` with `type = "directional"`.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct DirectionalLightSpec {
    /// Direction from the scene towards the light.
    pub direction: [f64; 3],
    /// Linear color (default white).
    pub color: Option<[f32; 3]>,
    /// Intensity (default 1).
    pub intensity: Option<f32>,
    /// Shadow settings; absent means no shadows.
    pub shadow: Option<ShadowSpec>,
}

/// `[[lights]]` with `type = "point"`.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct PointLightSpec {
    /// Position.
    pub position: [f64; 3],
    /// Linear color (default white).
    pub color: Option<[f32; 3]>,
    /// Intensity (default 1).
    pub intensity: Option<f32>,
    /// Radius where the light reaches zero.
    pub radius: f32,
    /// Falloff exponent shape (default 1, linear).
    pub falloff: Option<f32>,
    /// Shadow settings; absent means no shadows.
    pub shadow: Option<ShadowSpec>,
}

/// A parsed scene file, before any asset is loaded.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct SceneFile {
    /// Scene name (default: file stem).
    pub name: Option<String>,
    /// One-line description shown by `harness inspect` and the report.
    pub description: Option<String>,
    /// Uniform ambient radiance (default black).
    #[serde(default)]
    pub ambient: [f32; 3],
    /// Camera.
    pub camera: CameraSpec,
    /// Quality.
    #[serde(default = "QualitySpec::empty")]
    pub quality: QualitySpec,
    /// Environment.
    pub environment: Option<EnvironmentSpec>,
    /// Objects.
    #[serde(default)]
    pub objects: Vec<ObjectSpec>,
    /// Lights.
    #[serde(default)]
    pub lights: Vec<LightSpec>,
    /// Per-pass tolerances, parsed by the harness.
    #[serde(default)]
    pub tolerances: toml::Table,
}

impl QualitySpec {
    fn empty() -> Self {
        Self {
            width: None,
            height: None,
            exposure: None,
            tone_map: None,
            gizmos: None,
            debug_shadow_terms: None,
            point_shadows: None,
            ibl: None,
            gbuffer: None,
        }
    }
}

/// A loaded scene with what the harness needs from its file.
pub struct LoadedScene {
    /// The scene.
    pub scene: Scene,
    /// Where it was loaded from.
    pub path: PathBuf,
    /// The description line.
    pub description: Option<String>,
    /// Raw `[tolerances]` table.
    pub tolerances: toml::Table,
    /// Texture files decoded while loading (each at most once).
    pub textures_decoded: usize,
    /// What the loaders noted about untidy but usable assets (text that is not UTF-8, a
    /// missing material library, unknown material names, generated normals, ...), each
    /// asset's once, each naming its file and line.
    pub warnings: Vec<String>,
}

fn line_column(text: &str, offset: usize) -> (usize, usize) {
    let before = &text[..offset.min(text.len())];
    let line = before.matches('\n').count() + 1;
    let column = before.len() - before.rfind('\n').map_or(0, |i| i + 1) + 1;
    (line, column)
}

/// Parses scene-file text (no assets are loaded).
pub fn parse(path: &Path, text: &str) -> Result<SceneFile, SceneFileError> {
    toml::from_str(text).map_err(|e| {
        let start = e.span().map_or(0, |span| span.start);
        let (start, message) =
            light_error(text, start).unwrap_or_else(|| (start, e.message().trim().to_owned()));
        let (line, column) = line_column(text, start);
        SceneFileError::Parse {
            path: path.to_owned(),
            line,
            column,
            message,
        }
    })
}

/// serde reads a `[[lights]]` table whole before it knows the light's `type`, so an error in one
/// of its keys is reported at the table's header. When `start` is such a header, this reads the
/// table again on its own, as the struct of its type, and returns where the key at fault is and
/// the error.
fn light_error(text: &str, start: usize) -> Option<(usize, String)> {
    let rest = &text[start..];
    if !rest.starts_with("[[lights]]") {
        return None;
    }
    // The table's body: from the line after the header to the next header.
    let body_start = start + rest.find('\n')? + 1;
    let body_len = text[body_start..]
        .match_indices('\n')
        .map(|(i, _)| i + 1)
        .find(|&i| text[body_start + i..].trim_start().starts_with('['))
        .unwrap_or(text.len() - body_start);
    let body = &text[body_start..body_start + body_len];
    let kind = toml::from_str::<toml::Table>(body)
        .ok()?
        .get("type")?
        .as_str()?
        .to_owned();
    // The same text without its `type` line (kept as an empty line, so offsets still match).
    let untyped: String = body
        .split_inclusive('\n')
        .map(|line| {
            let key = line.trim_start();
            let is_type = key
                .strip_prefix("type")
                .is_some_and(|after| after.trim_start().starts_with('='));
            if is_type {
                " ".repeat(line.trim_end_matches('\n').len())
                    + if line.ends_with('\n') { "\n" } else { "" }
            } else {
                line.to_owned()
            }
        })
        .collect();
    let error = match kind.as_str() {
        "directional" => toml::from_str::<DirectionalLightSpec>(&untyped).err()?,
        "point" => toml::from_str::<PointLightSpec>(&untyped).err()?,
        _ => return None,
    };
    Some((
        body_start + error.span()?.start,
        error.message().trim().to_owned(),
    ))
}

/// Finds a scene by canonical name (`chess`) or path (`scenes/chess.toml`). Names are looked
/// up in `scenes_dir`.
pub fn resolve(name_or_path: &str, scenes_dir: &Path) -> Result<PathBuf, SceneFileError> {
    let as_path = Path::new(name_or_path);
    if as_path.is_file() {
        return Ok(as_path.to_owned());
    }
    let candidate = scenes_dir.join(format!("{name_or_path}.toml"));
    if candidate.is_file() {
        return Ok(candidate);
    }
    Err(SceneFileError::UnknownScene {
        name: name_or_path.to_owned(),
        dir: scenes_dir.display().to_string(),
        known: canonical_scenes(scenes_dir).join(", "),
    })
}

/// Names of the scene files directly in `scenes_dir`, sorted.
pub fn canonical_scenes(scenes_dir: &Path) -> Vec<String> {
    let mut names: Vec<String> = std::fs::read_dir(scenes_dir)
        .into_iter()
        .flatten()
        .flatten()
        .filter_map(|e| {
            let path = e.path();
            (path.extension().is_some_and(|x| x == "toml"))
                .then(|| path.file_stem()?.to_str().map(str::to_owned))
                .flatten()
        })
        .collect();
    names.sort();
    names
}

/// Reads, parses and resolves a scene file, loading every asset it names within the default
/// [`assets::Limits`].
pub fn load(path: &Path) -> Result<LoadedScene, SceneFileError> {
    load_with_limits(path, assets::Limits::DEFAULT)
}

/// [`load`] with other limits ([`assets::Limits::NONE`] for none): an asset above them is
/// refused, naming its file, before it is decoded.
pub fn load_with_limits(
    path: &Path,
    limits: assets::Limits,
) -> Result<LoadedScene, SceneFileError> {
    let text = std::fs::read_to_string(path).map_err(|source| SceneFileError::Io {
        path: path.to_owned(),
        source,
    })?;
    let file = parse(path, &text)?;
    Resolver::new(path, limits).resolve(file)
}

struct Resolver {
    path: PathBuf,
    dir: PathBuf,
    cache: TextureCache,
    texture_index: HashMap<TextureId, usize>,
    textures: Vec<Arc<TextureImage>>,
    models: HashMap<PathBuf, Arc<MeshParts>>,
    /// Each loaded asset's warnings, once per asset.
    warnings: Vec<String>,
}

/// The meshes of one OBJ file, each with its MTL material.
type MeshParts = Vec<(Arc<MeshData>, Option<assets::MaterialData>)>;

fn finite(values: &[f64]) -> bool {
    values.iter().all(|v| v.is_finite())
}

impl Resolver {
    fn new(path: &Path, limits: assets::Limits) -> Self {
        Self {
            path: path.to_owned(),
            dir: path.parent().map(Path::to_owned).unwrap_or_default(),
            cache: TextureCache::with_limits(limits),
            texture_index: HashMap::new(),
            textures: Vec::new(),
            models: HashMap::new(),
            warnings: Vec::new(),
        }
    }

    fn invalid(&self, message: String) -> SceneFileError {
        SceneFileError::Invalid {
            path: self.path.clone(),
            message,
        }
    }

    /// Checks an environment's size from its EXR header and reserves its RGBA32F texels.
    fn reserve_environment(&mut self, path: &Path) -> Result<(), AssetError> {
        let meta =
            exr::meta::MetaData::read_from_file(path, false).map_err(|source| AssetError::Exr {
                path: path.to_owned(),
                source,
            })?;
        for header in &meta.headers {
            let (w, h) = (header.layer_size.width(), header.layer_size.height());
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

    fn resolve(mut self, file: SceneFile) -> Result<LoadedScene, SceneFileError> {
        let c = &file.camera;
        if !finite(&[c.fov_y, c.near, c.far]) || !finite(&c.position) || !finite(&c.target) {
            return Err(self.invalid("[camera]: values must be finite".into()));
        }
        let camera = Camera {
            position: DVec3::from(c.position),
            target: DVec3::from(c.target),
            up: DVec3::from(c.up),
            fov_y_degrees: c.fov_y,
            near: c.near,
            far: c.far,
        };
        let defaults = Quality::default();
        let q = &file.quality;
        let quality = Quality {
            width: q.width.unwrap_or(defaults.width),
            height: q.height.unwrap_or(defaults.height),
            exposure: q.exposure.unwrap_or(defaults.exposure),
            tone_map: q.tone_map.unwrap_or(defaults.tone_map),
            gizmos: q.gizmos.unwrap_or(defaults.gizmos),
            debug_shadow_terms: q.debug_shadow_terms.unwrap_or(defaults.debug_shadow_terms),
            point_shadows: q.point_shadows.unwrap_or(defaults.point_shadows),
            ibl: q.ibl.clone().unwrap_or(defaults.ibl),
            gbuffer: q.gbuffer.unwrap_or(defaults.gbuffer),
        };
        let environment = match &file.environment {
            Some(spec) => {
                self.warn_if_absolute("[environment] path", &spec.path.to_string_lossy());
                let env_path = self.dir.join(&spec.path);
                self.reserve_environment(&env_path)
                    .map_err(|e| self.asset(e))?;
                let loaded = assets::load_environment(&env_path).map_err(|e| self.asset(e))?;
                Some(Environment {
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
            None => None,
        };

        let mut objects = Vec::new();
        for (index, spec) in file.objects.iter().enumerate() {
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
            let single = parts.len() == 1;
            for (mesh, mtl) in parts.iter() {
                let mut material = Material::default();
                let mut use_maps = true;
                let mtl_name = mtl.as_ref().map(|m| m.name.clone());
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
                    apply(&mut material, o);
                }
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
        }

        let mut lights = Vec::new();
        for (index, spec) in file.lights.iter().enumerate() {
            let shadow = |s: &Option<ShadowSpec>| {
                s.map(|s| {
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
                        vsm_bleeding_reduction: s
                            .vsm_bleeding_reduction
                            .unwrap_or(d.vsm_bleeding_reduction),
                    }
                })
            };
            let light = match spec {
                LightSpec::Directional(l) => Light::Directional {
                    direction: DVec3::from(l.direction),
                    color: l.color.unwrap_or([1.0; 3]),
                    intensity: l.intensity.unwrap_or(1.0),
                    angular_radius: 0.0,
                    shadow: shadow(&l.shadow),
                },
                LightSpec::Point(l) => Light::Point {
                    position: DVec3::from(l.position),
                    color: l.color.unwrap_or([1.0; 3]),
                    intensity: l.intensity.unwrap_or(1.0),
                    radius: l.radius,
                    falloff: l.falloff.unwrap_or(1.0),
                    shadow: shadow(&l.shadow),
                },
            };
            if let Some(problem) = crate::renderer::shadows::settings_problem(&light) {
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
            lights.push(light);
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
        crate::renderer::validate(&scene).map_err(|e| self.invalid(e.to_string()))?;
        Ok(LoadedScene {
            scene,
            path: self.path.clone(),
            description: file.description,
            tolerances: file.tolerances,
            textures_decoded: self.cache.decode_count(),
            warnings: self.warnings,
        })
    }
}

fn apply(material: &mut Material, o: &MaterialSpec) {
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

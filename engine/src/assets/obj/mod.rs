//! Wavefront OBJ loading.
//!
//! The file is read once as bytes and pre-scanned line by line (`prescan.rs`: `tobj` errors
//! carry no line numbers and `tobj` can overflow/panic on absurd indices), so
//! every syntax or range problem is reported as `file:line: problem` before
//! anything is allocated from an index value. The pre-scan also produces a
//! normalized copy of the file for `tobj` (vertex colours dropped, `l`/`p`
//! elements removed, keywords re-spaced), which `tobj::load_obj_buf` then
//! loads with `triangulate` + `single_index`.
//!
//! Mesh split: `tobj` starts a new mesh at every `o` **and** `g` statement
//! (groups are not merged into their object) and at every `usemtl` change, so
//! one [`MeshData`] is one (object-or-group, material) run. Polygons with more
//! than three vertices are fan-triangulated. Points and lines are skipped with
//! a warning. Smoothing groups (`s`) are ignored: generated normals are smooth.

use std::cell::RefCell;
use std::io::Cursor;
use std::path::{Path, PathBuf};

use super::error::AssetError;
use super::mtl::{parse_mtl_file, MapSlot, ParsedMtl};
use super::texture::{TextureCache, TextureId};
use crate::mesh::MeshData;

mod prescan;

use prescan::{prescan, Scan, NO_MATERIAL};

/// A loaded OBJ file: meshes, their materials and any load warnings.
#[derive(Clone, Debug)]
pub struct Model {
    /// The OBJ file.
    pub path: PathBuf,
    /// Triangle meshes, one per (object/group, material) run.
    pub meshes: Vec<MeshData>,
    /// Materials from all `mtllib` files, in file order.
    pub materials: Vec<MaterialData>,
    /// The material libraries read (the textures their maps name are in the texture cache).
    pub material_libraries: Vec<PathBuf>,
    /// Non-fatal problems and notes (skipped elements, unknown keys,
    /// generated normals/UVs, repaired tangents, ...).
    pub warnings: Vec<String>,
}

/// A material from an MTL file.
#[derive(Clone, Debug, Default)]
pub struct MaterialData {
    /// `newmtl` name.
    pub name: String,
    /// `Kd`.
    pub diffuse: Option<[f32; 3]>,
    /// `Ks`.
    pub specular: Option<[f32; 3]>,
    /// `Ns`.
    pub shininess: Option<f32>,
    /// Texture maps, as ids into the [`TextureCache`] passed to [`load_obj`].
    pub maps: MaterialMaps,
}

/// Texture slots of a material.
#[derive(Copy, Clone, Debug, Default, PartialEq, Eq)]
pub struct MaterialMaps {
    /// `map_Kd` (sRGB).
    pub base_color: Option<TextureId>,
    /// `norm`, `map_Bump`/`map_bump` or `bump` (linear); `norm` wins.
    pub normal: Option<TextureId>,
    /// `map_Ks` (linear).
    pub specular: Option<TextureId>,
    /// `map_roughness` or `map_Pr` (linear).
    pub roughness: Option<TextureId>,
    /// `map_metallic` or `map_Pm` (linear).
    pub metallic: Option<TextureId>,
    /// `map_clearcoat` (linear).
    pub clearcoat: Option<TextureId>,
}

impl MaterialMaps {
    /// Every set slot as (slot name, id).
    pub fn iter(&self) -> impl Iterator<Item = (&'static str, TextureId)> {
        [
            ("base_color", self.base_color),
            ("normal", self.normal),
            ("specular", self.specular),
            ("roughness", self.roughness),
            ("metallic", self.metallic),
            ("clearcoat", self.clearcoat),
        ]
        .into_iter()
        .filter_map(|(n, id)| id.map(|id| (n, id)))
    }

    fn slot_mut(&mut self, slot: MapSlot) -> &mut Option<TextureId> {
        match slot {
            MapSlot::BaseColor => &mut self.base_color,
            MapSlot::Normal => &mut self.normal,
            MapSlot::Specular => &mut self.specular,
            MapSlot::Roughness => &mut self.roughness,
            MapSlot::Metallic => &mut self.metallic,
            MapSlot::Clearcoat => &mut self.clearcoat,
        }
    }
}

/// Loads an OBJ file, its MTL libraries and their textures (into `textures`),
/// and builds render-ready meshes with normals and MikkTSpace tangents.
pub fn load_obj(path: &Path, textures: &mut TextureCache) -> Result<Model, AssetError> {
    let bytes = std::fs::read(path).map_err(|e| AssetError::io(path, e))?;
    let (bytes, encoding) = super::text::utf8_bytes(path, &bytes);
    let scan = prescan(path, &bytes)?;
    // Limits from the pre-scan's counts, before tobj parses anything: positions, and the
    // vertices (48 bytes) and indices one triangle per face would take after single-indexing.
    textures.budget().check_vertices(path, scan.positions)?;
    let vertex_bytes = std::mem::size_of::<super::Vertex>() as u64 + 4;
    textures
        .budget()
        .reserve(path, (scan.faces as u64).saturating_mul(3 * vertex_bytes))?;
    let mut warnings: Vec<String> = encoding.into_iter().collect();
    warnings.extend(scan.warnings.iter().cloned());
    if scan.faces == 0 {
        return Err(AssetError::NoGeometry {
            path: path.to_path_buf(),
            detail: format!(
                "no faces ({} vertices, {} points and {} lines skipped)",
                scan.positions, scan.points, scan.lines
            ),
        });
    }

    let obj_dir = path.parent().unwrap_or(Path::new(""));
    let state: RefCell<LoaderState> = RefCell::default();
    // `..Default::default()` keeps this compiling if another crate enables
    // tobj's `merging`/`reordering` features (which add fields).
    #[allow(clippy::needless_update)]
    let options = tobj::LoadOptions {
        triangulate: true,
        single_index: true,
        ignore_points: true,
        ignore_lines: true,
        ..Default::default()
    };
    let result = tobj::load_obj_buf(
        &mut Cursor::new(scan.normalized.as_bytes()),
        &options,
        |name: &Path| load_mtllib(&state, &scan, path, obj_dir, name),
    );
    let state = state.into_inner();
    if let Some(err) = state.error {
        return Err(err);
    }
    let (models, _) = result.map_err(|source| AssetError::Obj {
        path: path.to_path_buf(),
        source,
    })?;

    for missing in &state.missing_mtls {
        warn(&mut warnings, missing.clone());
    }
    let mut materials = Vec::new();
    for lib in &state.libs {
        warnings.extend(lib.warnings.iter().cloned());
        materials.extend(resolve_materials(lib, textures)?);
    }
    // One warning per unknown name, at its first use.
    let mut unknown: Vec<(&str, usize, usize)> = Vec::new();
    for (name, line) in &scan.usemtls {
        if materials.iter().any(|m| &m.name == name) {
            continue;
        }
        match unknown.iter_mut().find(|(n, _, _)| n == name) {
            Some((_, _, uses)) => *uses += 1,
            None => unknown.push((name, *line, 1)),
        }
    }
    for (name, line, uses) in unknown {
        let more = if uses > 1 {
            format!(" ({uses} uses)")
        } else {
            String::new()
        };
        warn(
            &mut warnings,
            format!(
                "{}:{line}: usemtl `{name}` names no material in the loaded MTL files{more}; \
                 its faces use the default material",
                path.display()
            ),
        );
    }

    let mut meshes = Vec::new();
    for (i, m) in models.iter().enumerate() {
        let mesh = &m.mesh;
        let positions = triples(&mesh.positions);
        let normals = triples(&mesh.normals);
        let uvs: Vec<[f32; 2]> = mesh
            .texcoords
            .chunks_exact(2)
            .map(|c| [c.first(), c.get(1)].map(|v| v.copied().unwrap_or(0.0)))
            .collect();
        let name = if m.name.is_empty() {
            format!("unnamed{i}")
        } else {
            m.name.clone()
        };
        let before = warnings.len();
        let mut data = MeshData::from_triangles(
            &name,
            &positions,
            (!mesh.normals.is_empty()).then_some(normals.as_slice()),
            (!mesh.texcoords.is_empty()).then_some(uvs.as_slice()),
            &mesh.indices,
            &mut warnings,
        );
        // The mesh's notes name the OBJ file too (tobj calls a mesh without `o` or `g`
        // `unnamed_object`, which alone says nothing of where it is).
        for note in warnings.iter_mut().skip(before) {
            *note = format!("{}: {note}", path.display());
        }
        if data.indices.is_empty() {
            continue;
        }
        data.material = mesh.material_id.filter(|&id| id < materials.len());
        meshes.push(data);
    }
    if meshes.is_empty() {
        return Err(AssetError::NoGeometry {
            path: path.to_path_buf(),
            detail: "no triangles after loading".to_string(),
        });
    }
    log::info!(
        "loaded {}: {} meshes, {} materials, {} warnings",
        path.display(),
        meshes.len(),
        materials.len(),
        warnings.len()
    );
    Ok(Model {
        path: path.to_path_buf(),
        meshes,
        materials,
        material_libraries: state.libs.iter().map(|lib| lib.path.clone()).collect(),
        warnings,
    })
}

/// `tobj`'s flat `x, y, z, x, y, z, ...` array as triples (a trailing partial triple is dropped).
fn triples(flat: &[f32]) -> Vec<[f32; 3]> {
    flat.chunks_exact(3)
        .map(|c| [c.first(), c.get(1), c.get(2)].map(|v| v.copied().unwrap_or(0.0)))
        .collect()
}

/// Records a warning. It is logged at debug level only: callers report the list they get back
/// ([`Model::warnings`]), once per asset.
fn warn(warnings: &mut Vec<String>, msg: String) {
    log::debug!("{msg}");
    warnings.push(msg);
}

#[derive(Default)]
struct LoaderState {
    calls: usize,
    libs: Vec<ParsedMtl>,
    /// Warnings for `mtllib` files that could not be read.
    missing_mtls: Vec<String>,
    error: Option<AssetError>,
}

/// `tobj` material-loader callback: parses the MTL file(s) named by the
/// `mtllib` statement and hands `tobj` name-only materials in the same order,
/// so `tobj`'s `material_id`s index our material list.
fn load_mtllib(
    state: &RefCell<LoaderState>,
    scan: &Scan,
    obj: &Path,
    obj_dir: &Path,
    name: &Path,
) -> tobj::MTLLoadResult {
    let mut st = state.borrow_mut();
    let line = scan.mtllibs.get(st.calls).copied();
    st.calls += 1;
    if st.error.is_some() {
        return Err(tobj::LoadError::OpenFileFailed);
    }
    let whole = obj_dir.join(name);
    let text = name.to_string_lossy();
    // `mtllib a.mtl b.mtl` names several files unless one file has that name.
    let files: Vec<PathBuf> = if whole.exists() || !text.contains(char::is_whitespace) {
        vec![whole]
    } else {
        text.split_whitespace().map(|n| obj_dir.join(n)).collect()
    };
    let mut tobj_materials = Vec::new();
    let mut map = std::collections::HashMap::new();
    for file in files {
        match parse_mtl_file(&file, obj, line) {
            Ok(lib) => {
                for m in &lib.materials {
                    if m.name != NO_MATERIAL {
                        map.insert(m.name.clone(), tobj_materials.len());
                    }
                    tobj_materials.push(tobj::Material {
                        name: m.name.clone(),
                        ..Default::default()
                    });
                }
                st.libs.push(lib);
            }
            // A library that is not there: its materials are missing, not the model. The
            // `usemtl`s naming them are reported once the load is done.
            Err(AssetError::MissingMtl { path, source, .. }) => {
                let at = line.map_or(String::new(), |l| format!(":{l}"));
                st.missing_mtls.push(format!(
                    "{}{at}: material library `{}` cannot be read ({source}); its materials are \
                     missing and their faces use the default material",
                    obj.display(),
                    path.display()
                ));
            }
            Err(e) => {
                st.error = Some(e);
                return Err(tobj::LoadError::OpenFileFailed);
            }
        }
    }
    Ok((tobj_materials, map))
}

/// Loads the textures a parsed MTL library references and returns its materials.
fn resolve_materials(
    lib: &ParsedMtl,
    textures: &mut TextureCache,
) -> Result<Vec<MaterialData>, AssetError> {
    let mut materials = Vec::new();
    for m in &lib.materials {
        let mut data = MaterialData {
            name: m.name.clone(),
            diffuse: m.diffuse,
            specular: m.specular,
            shininess: m.shininess,
            maps: MaterialMaps::default(),
        };
        for map in &m.maps {
            let id = textures
                .load(&map.path, map.slot.color_space())
                .map_err(|e| AssetError::Texture {
                    path: map.path.clone(),
                    mtl: lib.path.clone(),
                    line: Some(map.line),
                    key: map.key.clone(),
                    source: Box::new(e),
                })?;
            *data.maps.slot_mut(map.slot) = Some(id);
        }
        materials.push(data);
    }
    Ok(materials)
}

/// Loads an MTL file on its own (for `harness inspect`): its materials, with every texture they
/// reference decoded into `textures`, and its warnings (unknown keys and the like).
pub fn load_mtl(
    path: &Path,
    textures: &mut TextureCache,
) -> Result<(Vec<MaterialData>, Vec<String>), AssetError> {
    let lib = parse_mtl_file(path, path, None)?;
    let materials = resolve_materials(&lib, textures)?;
    Ok((materials, lib.warnings))
}

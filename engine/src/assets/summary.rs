//! Serializable summaries of loaded assets, for the `inspect` command.

use serde::Serialize;

use super::environment::Environment;
use super::mesh::Aabb;
use super::obj::Model;
use super::texture::{ColorSpace, TextureCache, TextureId};

/// Summary of a [`Model`] and the textures it references.
#[derive(Clone, Debug, Serialize)]
pub struct ModelSummary {
    /// The OBJ file.
    pub path: String,
    /// One entry per mesh.
    pub meshes: Vec<MeshSummary>,
    /// One entry per material.
    pub materials: Vec<MaterialSummary>,
    /// Textures referenced by the materials, by id.
    pub textures: Vec<TextureSummary>,
    /// Load warnings.
    pub warnings: Vec<String>,
}

/// Summary of one mesh.
#[derive(Clone, Debug, Serialize)]
pub struct MeshSummary {
    /// Mesh name.
    pub name: String,
    /// Vertex count.
    pub vertices: usize,
    /// Triangle count.
    pub triangles: usize,
    /// Position bounds.
    pub bounds: Aabb,
    /// Material name, if any.
    pub material: Option<String>,
}

/// Summary of one material; maps are given as texture paths.
#[derive(Clone, Debug, Serialize)]
pub struct MaterialSummary {
    /// Material name.
    pub name: String,
    /// `Kd`.
    pub diffuse: Option<[f32; 3]>,
    /// `Ks`.
    pub specular: Option<[f32; 3]>,
    /// `Ns`.
    pub shininess: Option<f32>,
    /// (slot, texture path) for every set map.
    pub maps: Vec<(String, String)>,
}

/// Summary of one texture.
#[derive(Clone, Debug, Serialize)]
pub struct TextureSummary {
    /// Cache id.
    pub id: TextureId,
    /// Source path.
    pub path: String,
    /// Level-0 width.
    pub width: u32,
    /// Level-0 height.
    pub height: u32,
    /// Number of mip levels.
    pub mips: usize,
    /// Colour space.
    pub color_space: ColorSpace,
    /// Bits per channel of the file (8, or 16 for a map kept as RGBA16F).
    pub bits: u8,
}

/// Summary of an [`Environment`].
#[derive(Clone, Debug, Serialize)]
pub struct EnvironmentSummary {
    /// The environment file.
    pub path: String,
    /// Width in texels.
    pub width: u32,
    /// Height in texels.
    pub height: u32,
    /// What "radiance" means here.
    pub radiance_measure: &'static str,
    /// Smallest texel radiance.
    pub min_radiance: f32,
    /// Largest texel radiance.
    pub max_radiance: f32,
    /// Mean texel radiance.
    pub mean_radiance: f32,
}

impl Model {
    /// Summary for `inspect`; `textures` is the cache passed to `load_obj`.
    pub fn summary(&self, textures: &TextureCache) -> ModelSummary {
        let path_of = |id: TextureId| {
            textures.get(id).map_or_else(
                || format!("<missing {}>", id.0),
                |t| t.path.display().to_string(),
            )
        };
        let mut ids: Vec<TextureId> = self
            .materials
            .iter()
            .flat_map(|m| m.maps.iter().map(|(_, id)| id))
            .collect();
        ids.sort_by_key(|id| id.0);
        ids.dedup();
        ModelSummary {
            path: self.path.display().to_string(),
            meshes: self
                .meshes
                .iter()
                .map(|m| MeshSummary {
                    name: m.name.clone(),
                    vertices: m.vertices.len(),
                    triangles: m.triangle_count(),
                    bounds: m.bounds,
                    material: m
                        .material
                        .and_then(|i| self.materials.get(i))
                        .map(|mat| mat.name.clone()),
                })
                .collect(),
            materials: self
                .materials
                .iter()
                .map(|m| MaterialSummary {
                    name: m.name.clone(),
                    diffuse: m.diffuse,
                    specular: m.specular,
                    shininess: m.shininess,
                    maps: m
                        .maps
                        .iter()
                        .map(|(slot, id)| (slot.to_string(), path_of(id)))
                        .collect(),
                })
                .collect(),
            textures: ids
                .into_iter()
                .filter_map(|id| {
                    textures.get(id).map(|t| TextureSummary {
                        id,
                        path: t.path.display().to_string(),
                        width: t.width,
                        height: t.height,
                        mips: t.mips.len(),
                        color_space: t.color_space,
                        bits: t.bits(),
                    })
                })
                .collect(),
            warnings: self.warnings.clone(),
        }
    }
}

impl Environment {
    /// Summary for `inspect`.
    pub fn summary(&self) -> EnvironmentSummary {
        EnvironmentSummary {
            path: self.path.display().to_string(),
            width: self.width,
            height: self.height,
            radiance_measure: "max(R, G, B)",
            min_radiance: self.min_radiance,
            max_radiance: self.max_radiance,
            mean_radiance: self.mean_radiance(),
        }
    }
}

//! The lighting pass's image-based-lighting inputs: the precomputed maps ([`crate::ibl`])
//! uploaded as RGBA16F textures, or 1x1 black placeholders when the scene has no environment
//! (the pass then adds nothing: its IBL intensity is zero).

use crate::backend::*;
use crate::ibl::{CubeLevel, IblMaps};

/// Textures and sampler bound at `lighting.wgsl` bindings 13..16 and 19.
pub(super) struct IblTextures {
    /// Irradiance / pi cube.
    pub irradiance: Handle<Texture>,
    /// Prefiltered specular cube with its roughness mips.
    pub specular: Handle<Texture>,
    /// DFG table.
    pub dfg: Handle<Texture>,
    /// The environment with its box-filtered mips, for filtered importance samples (a black
    /// placeholder where the scene does not sample).
    pub radiance: Handle<Texture>,
    /// Trilinear, clamp to edge.
    pub sampler: Handle<Sampler>,
    /// Highest specular mip (roughness 1).
    pub max_lod: f32,
}

fn half_texels(texels: impl Iterator<Item = [f32; 4]>) -> Vec<u16> {
    crate::image::fp16_bits(texels.flatten())
}

fn cube(
    backend: &mut dyn Backend,
    scope: &mut ResourceScope,
    label: &str,
    levels: &[CubeLevel],
) -> Result<Handle<Texture>> {
    let texture = scope.texture(
        backend,
        &TextureDesc {
            kind: TextureKind::Cube,
            mip_levels: levels.len() as u32,
            ..TextureDesc::d2(
                label,
                levels[0].size,
                levels[0].size,
                TextureFormat::Rgba16Float,
            )
        },
    )?;
    for (mip, level) in levels.iter().enumerate() {
        let face_len = (level.size * level.size) as usize;
        for (layer, face) in level.texels.chunks(face_len).enumerate() {
            let data = half_texels(face.iter().map(|t| [t[0], t[1], t[2], 1.0]));
            backend.write_texture(
                texture,
                Subresource {
                    mip: mip as u32,
                    layer: layer as u32,
                },
                bytemuck::cast_slice(&data),
            )?;
        }
    }
    Ok(texture)
}

/// Uploads `maps`, or placeholders when there are none; the radiance chain only when `sampled`
/// (a draw of the plan takes filtered importance samples), else a placeholder.
pub(super) fn upload(
    backend: &mut dyn Backend,
    scope: &mut ResourceScope,
    maps: Option<&IblMaps>,
    sampled: bool,
) -> Result<IblTextures> {
    let black = [CubeLevel {
        size: 1,
        texels: vec![[0.0; 3]; 6],
    }];
    let (irradiance, specular, dfg, dfg_size) = match maps {
        Some(maps) => (
            std::slice::from_ref(&maps.irradiance),
            &maps.specular.levels[..],
            &maps.dfg[..],
            crate::ibl::dfg::SIZE,
        ),
        None => (&black[..], &black[..], &[[0.0f32; 2]][..], 1),
    };
    let irradiance = cube(backend, scope, "ibl irradiance", irradiance)?;
    let max_lod = (specular.len() - 1) as f32;
    let specular = cube(backend, scope, "ibl specular", specular)?;
    let radiance = match maps {
        Some(maps) if sampled => &maps.radiance.levels[..],
        _ => &black[..],
    };
    let radiance = cube(backend, scope, "ibl radiance", radiance)?;
    let dfg_texture = scope.texture(
        backend,
        &TextureDesc::d2("ibl dfg", dfg_size, dfg_size, TextureFormat::Rgba16Float),
    )?;
    let data = half_texels(dfg.iter().map(|t| [t[0], t[1], 0.0, 1.0]));
    backend.write_texture(
        dfg_texture,
        Subresource::default(),
        bytemuck::cast_slice(&data),
    )?;
    let sampler = scope.sampler(
        backend,
        &SamplerDesc::linear("ibl", AddressMode::ClampToEdge),
    )?;
    Ok(IblTextures {
        irradiance,
        specular,
        dfg: dfg_texture,
        radiance,
        sampler,
        max_lod,
    })
}

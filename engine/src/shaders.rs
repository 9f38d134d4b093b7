//! The single source of every shader: WGSL files under `engine/shaders/`, embedded at build time.
//!
//! wgpu consumes WGSL directly. The GL backend gets GLSL 4.50 core from naga, with explicit
//! `layout(binding = n)`: WGSL `@group(0) @binding(n)` becomes UBO binding `n` for uniform
//! buffers and texture unit `n` for textures; a sampler is bound (with `glBindSampler`) to the
//! unit of the texture it is used with, found from naga's reflection info. Pipeline-overridable
//! constants (WGSL `override`) are resolved by naga before the GLSL writer, as wgpu does for its
//! backends, so the GL driver compiles the specialised code only.

use naga::back::glsl;
use naga::valid::{Capabilities, ModuleInfo, ValidationFlags, Validator};

/// A WGSL shader file compiled into the crate.
#[derive(Clone, Copy, Debug)]
pub struct ShaderSource {
    /// File name under `engine/shaders/`.
    pub name: &'static str,
    /// WGSL text.
    pub wgsl: &'static str,
}

macro_rules! shader {
    ($file:literal) => {
        ShaderSource {
            name: $file,
            wgsl: include_str!(concat!("../shaders/", $file)),
        }
    };
}

/// The first end-to-end scene: a lit, textured cube.
pub const LIT_CUBE: ShaderSource = shader!("lit_cube.wgsl");
/// Orientation probe: a marker texture and a corner triangle.
pub const ORIENTATION: ShaderSource = shader!("orientation.wgsl");
/// Packs a depth texture's f32 bits into an RGBA8 target (exact depth readback on wgpu).
pub const DEPTH_COPY: ShaderSource = shader!("depth_copy.wgsl");

/// Deferred renderer: geometry pass into the G-buffer and shader-mask pass.
pub const GBUFFER: ShaderSource = shader!("gbuffer.wgsl");
/// The parts of the lighting shader under `engine/shaders/lighting/`, in the order they are
/// concatenated (WGSL declarations may come in any order; the split is for the reader).
pub const LIGHTING_PARTS: &[&str] = &[
    "inputs.wgsl",
    "shadows.wgsl",
    "surface.wgsl",
    "brdf.wgsl",
    "ibl.wgsl",
    "shade.wgsl",
];

/// Deferred renderer: one full-screen lighting pass per lighting model, one module made of
/// [`LIGHTING_PARTS`] (naga's line numbers count through them in that order).
pub const LIGHTING: ShaderSource = ShaderSource {
    name: "lighting.wgsl",
    wgsl: concat!(
        include_str!("../shaders/lighting/inputs.wgsl"),
        include_str!("../shaders/lighting/shadows.wgsl"),
        include_str!("../shaders/lighting/surface.wgsl"),
        include_str!("../shaders/lighting/brdf.wgsl"),
        include_str!("../shaders/lighting/ibl.wgsl"),
        include_str!("../shaders/lighting/shade.wgsl"),
    ),
};
/// Deferred renderer: screen-space ambient occlusion (the io7m r2 renderer's filter).
pub const SSAO: ShaderSource = shader!("ssao.wgsl");
/// Deferred renderer: environment behind the objects.
pub const SKYBOX: ShaderSource = shader!("skybox.wgsl");
/// Deferred renderer: HDR light buffer to the sRGB final image.
pub const TONEMAP: ShaderSource = shader!("tonemap.wgsl");
/// Deferred renderer: depth-only shadow-map pass.
pub const SHADOW: ShaderSource = shader!("shadow.wgsl");
/// Deferred renderer: axes and light markers over the final image.
pub const GIZMO: ShaderSource = shader!("gizmo.wgsl");

/// Benchmarks: floor passes (constants written to a pass's attachments, 1 to 5 color targets).
pub const FLOOR: ShaderSource = shader!("floor.wgsl");

/// GL-only geometry stage of the single-pass point-light shadow (GLSL: WGSL has no geometry
/// shaders); pairs with `vs_shadow_object` in `shadow.wgsl`.
pub const POINT_SHADOW_FACES_GEOMETRY: &str = include_str!("../shaders/gl/point_shadow_faces.geom");

/// Every shader in `engine/shaders/` (a test checks the folder and this list agree).
pub const ALL: &[ShaderSource] = &[
    LIT_CUBE,
    ORIENTATION,
    DEPTH_COPY,
    GBUFFER,
    LIGHTING,
    SSAO,
    SKYBOX,
    TONEMAP,
    GIZMO,
    SHADOW,
    FLOOR,
];

/// A shader that failed to parse, validate or translate.
#[derive(Debug, thiserror::Error)]
pub enum ShaderError {
    /// WGSL syntax or type error.
    #[error("{name}: WGSL parse error:\n{message}")]
    Parse {
        /// File name.
        name: String,
        /// naga's diagnostic.
        message: String,
    },
    /// naga validation failed.
    #[error("{name}: validation error:\n{message}")]
    Validate {
        /// File name.
        name: String,
        /// naga's diagnostic.
        message: String,
    },
    /// GLSL generation failed for an entry point.
    #[error("{name}: GLSL translation of `{entry}` failed: {message}")]
    Translate {
        /// File name.
        name: String,
        /// Entry point.
        entry: String,
        /// naga's message.
        message: String,
    },
}

/// A parsed and validated module.
pub struct ValidatedModule {
    /// File name, for messages.
    pub name: String,
    /// naga IR.
    pub module: naga::Module,
    /// Validation results (needed by naga's backends).
    pub info: ModuleInfo,
}

/// Parses and validates WGSL.
pub fn validate(name: &str, wgsl: &str) -> Result<ValidatedModule, ShaderError> {
    let module = naga::front::wgsl::parse_str(wgsl).map_err(|e| ShaderError::Parse {
        name: name.to_owned(),
        message: e.emit_to_string_with_path(wgsl, name),
    })?;
    let info = Validator::new(ValidationFlags::all(), Capabilities::default())
        .validate(&module)
        .map_err(|e| ShaderError::Validate {
            name: name.to_owned(),
            message: e.emit_to_string_with_path(wgsl, name),
        })?;
    Ok(ValidatedModule {
        name: name.to_owned(),
        module,
        info,
    })
}

/// GLSL for one entry point, with what the GL backend needs to bind resources.
pub struct GlslStage {
    /// `#version 450 core` source.
    pub source: String,
    /// For each combined texture-sampler uniform: the texture's binding (its unit) and the
    /// binding of the sampler used with it.
    pub sampler_units: Vec<(u32, Option<u32>)>,
}

/// Translates one entry point to GLSL 4.50 core with explicit bindings, with the module's
/// `override` constants set from `constants` (by name; the rest keep their defaults).
pub fn to_glsl(
    module: &ValidatedModule,
    stage: naga::ShaderStage,
    entry: &str,
    constants: &[(String, f64)],
) -> Result<GlslStage, ShaderError> {
    let err = |message: String| ShaderError::Translate {
        name: module.name.clone(),
        entry: entry.to_owned(),
        message,
    };
    let mut values = naga::back::PipelineConstants::default();
    values.extend(constants.iter().cloned());
    let (ir, info) = naga::back::pipeline_constants::process_overrides(
        &module.module,
        &module.info,
        Some((stage, entry)),
        &values,
    )
    .map_err(|e| err(format!("override constants: {e}")))?;
    let options = glsl::Options {
        version: glsl::Version::Desktop(450),
        // No y-flip or depth remap here: the GL backend sets glClipControl(UPPER_LEFT,
        // ZERO_TO_ONE), which gives wgpu's conventions in fixed function.
        writer_flags: glsl::WriterFlags::empty(),
        binding_map: identity_binding_map(&ir),
        zero_initialize_workgroup_memory: true,
    };
    let pipeline_options = glsl::PipelineOptions {
        shader_stage: stage,
        entry_point: entry.to_owned(),
        multiview: None,
    };
    let mut source = String::new();
    let mut writer = glsl::Writer::new(
        &mut source,
        &ir,
        &info,
        &options,
        &pipeline_options,
        naga::proc::BoundsCheckPolicies::default(),
    )
    .map_err(|e| err(e.to_string()))?;
    let reflection = writer.write().map_err(|e| err(e.to_string()))?;
    let binding_of = |var: naga::Handle<naga::GlobalVariable>| {
        ir.global_variables[var].binding.as_ref().map(|b| b.binding)
    };
    let mut sampler_units = Vec::new();
    for mapping in reflection.texture_mapping.values() {
        let unit = binding_of(mapping.texture)
            .ok_or_else(|| err("texture without @binding".to_owned()))?;
        sampler_units.push((unit, mapping.sampler.and_then(binding_of)));
    }
    sampler_units.sort();
    Ok(GlslStage {
        source,
        sampler_units,
    })
}

/// Maps every `@group(0) @binding(n)` resource to GL binding point `n`.
fn identity_binding_map(module: &naga::Module) -> glsl::BindingMap {
    module
        .global_variables
        .iter()
        .filter_map(|(_, var)| var.binding)
        .filter_map(|rb| u8::try_from(rb.binding).ok().map(|slot| (rb, slot)))
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Every shader parses, validates, and every entry point translates to GLSL 4.50 core.
    #[test]
    fn every_shader_validates_and_translates_to_glsl() {
        for source in ALL {
            let module = validate(source.name, source.wgsl).unwrap_or_else(|e| panic!("{e}"));
            assert!(
                !module.module.entry_points.is_empty(),
                "{} has no entry points",
                source.name
            );
            for ep in &module.module.entry_points {
                let glsl =
                    to_glsl(&module, ep.stage, &ep.name, &[]).unwrap_or_else(|e| panic!("{e}"));
                assert!(
                    glsl.source.starts_with("#version 450 core"),
                    "{}::{} did not produce GLSL 450 core",
                    source.name,
                    ep.name
                );
                assert!(glsl.source.contains("void main()"));
            }
        }
    }

    /// The embedded list and the shader folder agree, so no file is left unvalidated.
    #[test]
    fn shader_folder_matches_embedded_list() {
        let dir = concat!(env!("CARGO_MANIFEST_DIR"), "/shaders");
        let mut on_disk: Vec<String> = std::fs::read_dir(dir)
            .unwrap()
            .map(|e| e.unwrap().file_name().into_string().unwrap())
            .filter(|n| n.ends_with(".wgsl"))
            .collect();
        // A shader made of parts is a folder of them: `lighting/` is `lighting.wgsl`.
        on_disk.push("lighting.wgsl".to_owned());
        on_disk.sort();
        let mut listed: Vec<String> = ALL.iter().map(|s| s.name.to_owned()).collect();
        listed.sort();
        assert_eq!(on_disk, listed, "engine/shaders/ and shaders::ALL differ");
        let mut parts: Vec<String> = std::fs::read_dir(format!("{dir}/lighting"))
            .unwrap()
            .map(|e| e.unwrap().file_name().into_string().unwrap())
            .collect();
        parts.sort();
        let mut listed_parts: Vec<&str> = LIGHTING_PARTS.to_vec();
        listed_parts.sort();
        assert_eq!(
            parts, listed_parts,
            "engine/shaders/lighting/ and LIGHTING_PARTS differ"
        );
        // The concatenation in LIGHTING is the parts in LIGHTING_PARTS's order.
        let joined: String = LIGHTING_PARTS
            .iter()
            .map(|p| std::fs::read_to_string(format!("{dir}/lighting/{p}")).unwrap())
            .collect();
        assert_eq!(joined, LIGHTING.wgsl);
    }

    #[test]
    fn broken_wgsl_is_reported_with_the_file_name() {
        let err = validate("broken.wgsl", "fn main( {")
            .err()
            .expect("must fail");
        assert!(err.to_string().contains("broken.wgsl"), "{err}");
    }
}

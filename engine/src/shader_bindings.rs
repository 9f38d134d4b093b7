//! A shader module's bind group, read from naga's reflection of its WGSL: the one source of its
//! binding numbers and kinds. Pipelines take their layouts from here, and bind groups look their
//! slots up by the WGSL variable's name, so a binding is written once, in the shader.

use std::collections::HashMap;
use std::sync::{Arc, Mutex, OnceLock};

use naga::{AddressSpace, ImageClass, ImageDimension, ScalarKind, TypeInner};

use crate::backend::{
    BindingKind, BindingLayout, SamplerBindingKind, TextureSampleType, TextureViewKind,
};
use crate::shaders::{self, ShaderError, ShaderSource};

/// The bindings a module declares, by the name of the variable that declares each.
#[derive(Clone, Debug, PartialEq)]
pub struct ModuleBindings {
    module: &'static str,
    by_name: Vec<(String, BindingLayout)>,
}

impl ModuleBindings {
    /// The bindings of `source` (parsed and validated once per process, then shared).
    pub fn of(source: ShaderSource) -> Result<Arc<ModuleBindings>, ShaderError> {
        static CACHE: OnceLock<Mutex<HashMap<&'static str, Arc<ModuleBindings>>>> = OnceLock::new();
        let cache = CACHE.get_or_init(Mutex::default);
        if let Some(known) = cache
            .lock()
            .unwrap_or_else(|e| e.into_inner())
            .get(source.name)
        {
            return Ok(known.clone());
        }
        let reflected = Arc::new(reflect(source)?);
        cache
            .lock()
            .unwrap_or_else(|e| e.into_inner())
            .insert(source.name, reflected.clone());
        Ok(reflected)
    }

    /// Every binding, by binding number: the pipeline layout of any of the module's entry
    /// points (each uses some of them).
    pub fn layouts(&self) -> Vec<BindingLayout> {
        let mut layouts: Vec<BindingLayout> = self.by_name.iter().map(|(_, l)| *l).collect();
        layouts.sort_by_key(|l| l.binding);
        layouts
    }

    /// The layouts of the variables named, in that order.
    pub fn layouts_of(&self, names: &[&str]) -> Result<Vec<BindingLayout>, ShaderError> {
        names.iter().map(|name| self.layout(name)).collect()
    }

    /// The binding number of the variable `name`.
    pub fn slot(&self, name: &str) -> Result<u32, ShaderError> {
        Ok(self.layout(name)?.binding)
    }

    fn layout(&self, name: &str) -> Result<BindingLayout, ShaderError> {
        self.by_name
            .iter()
            .find(|(n, _)| n == name)
            .map(|(_, layout)| *layout)
            .ok_or_else(|| ShaderError::Validate {
                name: self.module.to_owned(),
                message: format!("no binding named `{name}`"),
            })
    }
}

/// Reads the bindings from the module: a uniform or storage buffer by its address space, a
/// sampler (comparison or filtering) and a texture (view and sample type) by its type. A float
/// texture is filterable where some entry point samples it with a filtering sampler, and
/// unfilterable where it is only loaded.
fn reflect(source: ShaderSource) -> Result<ModuleBindings, ShaderError> {
    let validated = shaders::validate(source.name, source.wgsl)?;
    let (module, info) = (&validated.module, &validated.info);
    let sampled_by_filter = |image| {
        (0..module.entry_points.len()).any(|index| {
            info.get_entry_point(index).sampling_set.iter().any(|key| {
                key.image == image
                    && matches!(
                        module.types[module.global_variables[key.sampler].ty].inner,
                        TypeInner::Sampler { comparison: false }
                    )
            })
        })
    };
    let unsupported = |name: &str, what: &str| ShaderError::Validate {
        name: source.name.to_owned(),
        message: format!("binding `{name}`: {what} is not a binding kind the backends know"),
    };
    let mut by_name = Vec::new();
    for (handle, var) in module.global_variables.iter() {
        let Some(binding) = &var.binding else {
            continue;
        };
        let name = var.name.clone().unwrap_or_default();
        let kind = match (var.space, &module.types[var.ty].inner) {
            (AddressSpace::Uniform, _) => BindingKind::UniformBuffer,
            (AddressSpace::Storage { .. }, _) => BindingKind::StorageBuffer,
            (_, TypeInner::Sampler { comparison }) => BindingKind::Sampler(if *comparison {
                SamplerBindingKind::Comparison
            } else {
                SamplerBindingKind::Filtering
            }),
            (
                _,
                TypeInner::Image {
                    dim,
                    arrayed,
                    class,
                },
            ) => {
                let view = match (dim, arrayed) {
                    (ImageDimension::D2, false) => TextureViewKind::D2,
                    (ImageDimension::D2, true) => TextureViewKind::D2Array,
                    (ImageDimension::Cube, false) => TextureViewKind::Cube,
                    _ => return Err(unsupported(&name, "this texture dimension")),
                };
                let sample_type = match class {
                    ImageClass::Depth { multi: false } => TextureSampleType::Depth,
                    ImageClass::Sampled {
                        kind: ScalarKind::Float,
                        multi: false,
                    } if sampled_by_filter(handle) => TextureSampleType::Float,
                    ImageClass::Sampled {
                        kind: ScalarKind::Float,
                        multi: false,
                    } => TextureSampleType::UnfilterableFloat,
                    _ => return Err(unsupported(&name, "this texture class")),
                };
                BindingKind::Texture { sample_type, view }
            }
            _ => return Err(unsupported(&name, "this type")),
        };
        by_name.push((
            name,
            BindingLayout {
                binding: binding.binding,
                kind,
            },
        ));
    }
    Ok(ModuleBindings {
        module: source.name,
        by_name,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    fn kind(bindings: &ModuleBindings, name: &str) -> BindingKind {
        bindings.layouts_of(&[name]).unwrap()[0].kind
    }

    #[test]
    fn the_lighting_shader_declares_its_bindings_once() {
        let bindings = ModuleBindings::of(shaders::LIGHTING).unwrap();
        let layouts = bindings.layouts();
        let numbers: Vec<u32> = layouts.iter().map(|l| l.binding).collect();
        assert_eq!(numbers, (0..=19).collect::<Vec<_>>());
        assert_eq!(kind(&bindings, "u"), BindingKind::UniformBuffer);
        let texture = |sample_type, view| BindingKind::Texture { sample_type, view };
        // Loaded only: unfilterable. Sampled through a filtering sampler: filterable.
        assert_eq!(
            kind(&bindings, "gbuffer_position"),
            texture(TextureSampleType::UnfilterableFloat, TextureViewKind::D2)
        );
        assert_eq!(
            kind(&bindings, "shadow_jitter"),
            texture(
                TextureSampleType::UnfilterableFloat,
                TextureViewKind::D2Array
            )
        );
        assert_eq!(
            kind(&bindings, "ibl_specular"),
            texture(TextureSampleType::Float, TextureViewKind::Cube)
        );
        assert_eq!(
            kind(&bindings, "shadow_map"),
            texture(TextureSampleType::Depth, TextureViewKind::D2)
        );
        assert_eq!(
            kind(&bindings, "shadow_sampler"),
            BindingKind::Sampler(SamplerBindingKind::Comparison)
        );
        assert_eq!(
            kind(&bindings, "ibl_sampler"),
            BindingKind::Sampler(SamplerBindingKind::Filtering)
        );
    }

    #[test]
    fn an_unknown_name_is_an_error_naming_the_module() {
        let bindings = ModuleBindings::of(shaders::LIGHTING).unwrap();
        let error = bindings.slot("gbuffer_colour").unwrap_err().to_string();
        assert!(
            error.contains("lighting.wgsl") && error.contains("gbuffer_colour"),
            "{error}"
        );
    }
}

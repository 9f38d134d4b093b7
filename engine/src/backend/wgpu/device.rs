//! Opening the wgpu device and making what lives on it: error scopes, driver info, and the
//! creation and upload of textures, buffers, samplers, shaders, pipelines (with their cache)
//! and bind groups. Destroying a resource takes a line and stays in `mod.rs`.

use ::wgpu;
use std::borrow::Cow;
use std::collections::HashMap;
use std::sync::Arc;

use super::{conv, BufferResource, PipelineResource, ShaderResource, TextureResource, WgpuBackend};
use crate::backend::pool::Pool;
use crate::backend::*;
use crate::shaders;

use super::quirks::{instance_flags, keep_gl_display, too_old_for_the_shaders, MIN_DESKTOP_GL};

impl WgpuBackend {
    /// Opens the first adapter of the pinned API (`WgpuVulkan` or `WgpuGl`).
    pub fn new(kind: BackendKind) -> Result<Self> {
        let (backends, api, fix) = match kind {
            BackendKind::WgpuVulkan => (
                wgpu::Backends::VULKAN,
                "Vulkan",
                "install a Vulkan driver; for lavapipe (CPU): apt-get install -y mesa-vulkan-drivers",
            ),
            BackendKind::WgpuGl => (
                wgpu::Backends::GL,
                "OpenGL",
                "install EGL and Mesa: apt-get install -y libegl1 libegl-mesa0 libgl1-mesa-dri",
            ),
            BackendKind::Gl => unreachable!("the gl backend is GlBackend"),
        };
        let unavailable = |reason: String| BackendError::Unavailable {
            backend: kind.name(),
            reason,
            fix: crate::backend::unavailable_fix(kind, fix),
        };
        let instance = wgpu::Instance::new(wgpu::InstanceDescriptor {
            backends,
            flags: instance_flags(),
            memory_budget_thresholds: Default::default(),
            backend_options: Default::default(),
            display: None,
        });
        let adapter = pollster::block_on(instance.request_adapter(&wgpu::RequestAdapterOptions {
            power_preference: wgpu::PowerPreference::HighPerformance,
            force_fallback_adapter: false,
            compatible_surface: None,
            apply_limit_buckets: false,
        }))
        .map_err(|e| {
            keep_gl_display(kind, &instance, None);
            unavailable(format!("no {api} adapter found ({e})"))
        })?;
        let adapter_info = adapter.get_info();
        if kind == BackendKind::WgpuGl {
            if let Some(version) = too_old_for_the_shaders(&adapter_info.driver_info) {
                keep_gl_display(kind, &instance, Some(&adapter));
                return Err(BackendError::Unavailable {
                    backend: kind.name(),
                    reason: format!(
                        "OpenGL adapter `{}` gave wgpu a {version} context; the shaders need \
                         GLSL {}.{} (bitfieldReverse, textureQueryLevels)",
                        adapter_info.name, MIN_DESKTOP_GL.0, MIN_DESKTOP_GL.1
                    ),
                    fix: "the gl backend asks this driver for a 4.6 or 4.5 core context and \
                          runs here; for wgpu-gl, a driver that answers wgpu's 3.3 request \
                          with 4.3 or later, such as Mesa: apt-get install -y libegl1 \
                          libegl-mesa0 libgl1-mesa-dri"
                        .to_owned(),
                });
            }
        }
        // Adapter-specific format features lift wgpu's downlevel limits where the driver can do
        // more (R32F render targets on wgpu-gl, which GL 4.5 supports).
        let wanted = wgpu::Features::TIMESTAMP_QUERY
            | wgpu::Features::FLOAT32_FILTERABLE
            | wgpu::Features::TEXTURE_ADAPTER_SPECIFIC_FORMAT_FEATURES;
        let features = adapter.features() & wanted;
        let (device, queue) = pollster::block_on(adapter.request_device(&wgpu::DeviceDescriptor {
            label: Some(kind.name()),
            required_features: features,
            required_limits: adapter.limits(),
            experimental_features: wgpu::ExperimentalFeatures::disabled(),
            memory_hints: wgpu::MemoryHints::Performance,
            trace: wgpu::Trace::Off,
        }))
        .map_err(|e| {
            keep_gl_display(kind, &instance, Some(&adapter));
            unavailable(format!(
                "{api} adapter `{}` refused a device: {e}",
                adapter_info.name
            ))
        })?;
        let backend_name = kind.name();
        device.on_uncaptured_error(Arc::new(move |e: wgpu::Error| {
            log::error!("{backend_name}: uncaptured wgpu error: {e}");
        }));
        if kind == BackendKind::WgpuGl
            && !crate::backend::gl::wgpu_interop::enable_seamless_cube_maps(&device)
        {
            log::debug!("wgpu-gl: seamless cube maps not enabled (GLES contexts always are)");
        }
        let timestamps = features.contains(wgpu::Features::TIMESTAMP_QUERY);
        let info = DriverInfo {
            // wgpu's GL backend takes a desktop core context where the driver offers one.
            api: if kind == BackendKind::WgpuGl && !adapter_info.driver_info.contains("OpenGL ES") {
                "OpenGL".to_owned()
            } else {
                api.to_owned()
            },
            api_version: adapter_info.driver_info.clone(),
            renderer: adapter_info.name.clone(),
            vendor: format!("0x{:04x}", adapter_info.vendor),
            driver: format!("{} {}", adapter_info.driver, adapter_info.driver_info)
                .trim()
                .to_owned(),
            timestamps,
            ..DriverInfo::new(kind)
        }
        .complete();
        Ok(Self {
            kind,
            info,
            device,
            queue,
            timestamps,
            textures: Pool::new("texture"),
            buffers: Pool::new("buffer"),
            samplers: Pool::new("sampler"),
            shaders: Pool::new("shader"),
            pipelines: Pool::new("pipeline"),
            module_cache: HashMap::new(),
            pipeline_cache: HashMap::new(),
            pipelines_compiled: 0,
            depth_copy: None,
        })
    }

    /// Runs `f` inside a validation/out-of-memory error scope and turns a captured error into
    /// a [`BackendError::Driver`] naming `context`.
    pub(super) fn scoped<T>(&self, context: &str, f: impl FnOnce() -> T) -> Result<T> {
        let oom = self.device.push_error_scope(wgpu::ErrorFilter::OutOfMemory);
        let validation = self.device.push_error_scope(wgpu::ErrorFilter::Validation);
        let value = f();
        let errors = [
            pollster::block_on(validation.pop()),
            pollster::block_on(oom.pop()),
        ];
        match errors.into_iter().flatten().next() {
            Some(e) => Err(self.driver_error(context, e.to_string())),
            None => Ok(value),
        }
    }

    /// A [`BackendError::Driver`] from this backend naming `context`.
    pub(super) fn driver_error(&self, context: &str, message: String) -> BackendError {
        BackendError::Driver {
            backend: self.kind.name(),
            context: context.to_owned(),
            message,
        }
    }

    /// Waits until the GPU has finished all submitted work.
    pub(super) fn wait(&self, context: &str) -> Result<()> {
        self.device
            .poll(wgpu::PollType::wait_indefinitely())
            .map(|_| ())
            .map_err(|e| self.driver_error(context, e.to_string()))
    }

    /// A view of one mip/layer of a texture, for rendering or copying.
    pub(super) fn target_view(
        &self,
        texture: Handle<Texture>,
        at: Subresource,
    ) -> Result<wgpu::TextureView> {
        let res = self.textures.get(texture)?;
        check_subresource(&res.desc, at)?;
        Ok(res.texture.create_view(&wgpu::TextureViewDescriptor {
            label: Some(&res.desc.label),
            dimension: Some(wgpu::TextureViewDimension::D2),
            base_mip_level: at.mip,
            mip_level_count: Some(1),
            base_array_layer: at.layer,
            array_layer_count: Some(1),
            ..Default::default()
        }))
    }

    /// Bind group 0 of `draw` for `pipeline`, with texture views of the dimension each slot
    /// declares.
    pub(super) fn bind_group(
        &self,
        pipeline: &PipelineResource,
        draw: &Draw,
    ) -> Result<wgpu::BindGroup> {
        let mut views = Vec::new();
        for layout in &pipeline.bindings {
            let bound = draw
                .bindings
                .iter()
                .find(|b| b.binding == layout.binding)
                .ok_or_else(|| {
                    BackendError::InvalidData(format!(
                        "pipeline `{}`: nothing bound to binding {}",
                        pipeline.label, layout.binding
                    ))
                })?;
            if let (BindingKind::Texture { view, .. }, BindingResource::Texture(t)) =
                (layout.kind, bound.resource)
            {
                let res = self.textures.get(t)?;
                views.push((
                    layout.binding,
                    res.texture.create_view(&wgpu::TextureViewDescriptor {
                        label: Some(&res.desc.label),
                        dimension: Some(conv::view_dimension(view)),
                        ..Default::default()
                    }),
                ));
            }
        }
        let mut entries = Vec::new();
        for binding in &draw.bindings {
            let resource = match binding.resource {
                BindingResource::Buffer(b) => self.buffers.get(b)?.buffer.as_entire_binding(),
                BindingResource::Sampler(s) => {
                    wgpu::BindingResource::Sampler(self.samplers.get(s)?)
                }
                BindingResource::Texture(_) => {
                    let (_, view) = views
                        .iter()
                        .find(|(b, _)| *b == binding.binding)
                        .ok_or_else(|| {
                            BackendError::InvalidData(format!(
                                "pipeline `{}`: binding {} is not a texture slot",
                                pipeline.label, binding.binding
                            ))
                        })?;
                    wgpu::BindingResource::TextureView(view)
                }
            };
            entries.push(wgpu::BindGroupEntry {
                binding: binding.binding,
                resource,
            });
        }
        Ok(self.device.create_bind_group(&wgpu::BindGroupDescriptor {
            label: Some(&pipeline.label),
            layout: &pipeline.bind_group_layout,
            entries: &entries,
        }))
    }
}

/// Creates a texture (with every usage this backend needs) inside an error scope.
pub(super) fn create_texture(
    backend: &mut WgpuBackend,
    desc: &TextureDesc,
) -> Result<Handle<Texture>> {
    check_texture_desc(desc)?;
    let texture = backend.scoped(&format!("texture `{}`", desc.label), || {
        backend.device.create_texture(&wgpu::TextureDescriptor {
            label: Some(&desc.label),
            size: wgpu::Extent3d {
                width: desc.width,
                height: desc.height,
                depth_or_array_layers: desc.kind.layers(),
            },
            mip_level_count: desc.mip_levels,
            sample_count: 1,
            dimension: wgpu::TextureDimension::D2,
            format: conv::format(desc.format),
            usage: wgpu::TextureUsages::TEXTURE_BINDING
                | wgpu::TextureUsages::RENDER_ATTACHMENT
                | wgpu::TextureUsages::COPY_SRC
                | wgpu::TextureUsages::COPY_DST,
            view_formats: &[],
        })
    })?;
    Ok(backend.textures.insert(TextureResource {
        texture,
        desc: desc.clone(),
    }))
}

/// Uploads the texels of one mip/layer of a color texture.
pub(super) fn write_texture(
    backend: &WgpuBackend,
    texture: Handle<Texture>,
    at: Subresource,
    data: &[u8],
) -> Result<()> {
    let res = backend.textures.get(texture)?;
    let (w, h) = check_upload(&res.desc, at, data)?;
    if res.desc.format.is_depth() {
        return Err(BackendError::Unsupported {
            backend: backend.kind.name(),
            what: format!("an upload to depth texture `{}`", res.desc.label),
            message: "wgpu cannot copy into depth formats; render depth instead".to_owned(),
        });
    }
    backend.scoped(&format!("upload to `{}`", res.desc.label), || {
        backend.queue.write_texture(
            wgpu::TexelCopyTextureInfo {
                texture: &res.texture,
                mip_level: at.mip,
                origin: wgpu::Origin3d {
                    x: 0,
                    y: 0,
                    z: at.layer,
                },
                aspect: wgpu::TextureAspect::All,
            },
            data,
            wgpu::TexelCopyBufferLayout {
                offset: 0,
                bytes_per_row: Some(w * res.desc.format.texel_size() as u32),
                rows_per_image: Some(h),
            },
            wgpu::Extent3d {
                width: w,
                height: h,
                depth_or_array_layers: 1,
            },
        )
    })
}

/// Creates a buffer inside an error scope.
pub(super) fn create_buffer(
    backend: &mut WgpuBackend,
    desc: &BufferDesc,
) -> Result<Handle<Buffer>> {
    check_buffer_desc(desc)?;
    let buffer = backend.scoped(&format!("buffer `{}`", desc.label), || {
        backend.device.create_buffer(&wgpu::BufferDescriptor {
            label: Some(&desc.label),
            size: desc.size,
            usage: conv::buffer_usage(desc.usage),
            mapped_at_creation: false,
        })
    })?;
    Ok(backend.buffers.insert(BufferResource {
        buffer,
        usage: desc.usage,
        size: desc.size,
    }))
}

/// Writes `data` into a buffer at `offset`, after checking it fits.
pub(super) fn write_buffer(
    backend: &WgpuBackend,
    buffer: Handle<Buffer>,
    offset: u64,
    data: &[u8],
) -> Result<()> {
    let res = backend.buffers.get(buffer)?;
    check_buffer_write(res.usage, res.size, offset, data.len())?;
    backend.queue.write_buffer(&res.buffer, offset, data);
    Ok(())
}

/// Creates a sampler.
pub(super) fn create_sampler(
    backend: &mut WgpuBackend,
    desc: &SamplerDesc,
) -> Result<Handle<Sampler>> {
    let address = conv::address(desc.address_mode);
    let sampler = backend.device.create_sampler(&wgpu::SamplerDescriptor {
        label: Some(&desc.label),
        address_mode_u: address,
        address_mode_v: address,
        address_mode_w: address,
        mag_filter: conv::filter(desc.mag_filter),
        min_filter: conv::filter(desc.min_filter),
        mipmap_filter: conv::mipmap_filter(desc.mipmap_filter),
        lod_min_clamp: 0.0,
        lod_max_clamp: 32.0,
        compare: desc.compare.map(conv::compare),
        anisotropy_clamp: 1,
        border_color: None,
    });
    Ok(backend.samplers.insert(sampler))
}

/// Creates a shader module, or reuses the cached one compiled from the same name and source.
pub(super) fn create_shader(
    backend: &mut WgpuBackend,
    desc: &ShaderDesc,
) -> Result<Handle<Shader>> {
    let key = desc.cache_key();
    if let Some(module) = backend.module_cache.get(&key) {
        let module = module.clone();
        return Ok(backend.shaders.insert(ShaderResource { module, key }));
    }
    // Validate with naga first for a diagnostic that names the file and line.
    shaders::validate(&desc.name, &desc.wgsl).map_err(|e| BackendError::Shader {
        backend: backend.kind.name(),
        name: desc.name.clone(),
        message: e.to_string(),
    })?;
    let module = backend.scoped(&format!("shader `{}`", desc.name), || {
        backend
            .device
            .create_shader_module(wgpu::ShaderModuleDescriptor {
                label: Some(&desc.name),
                source: wgpu::ShaderSource::Wgsl(Cow::Borrowed(&desc.wgsl)),
            })
    })?;
    backend.module_cache.insert(key, module.clone());
    Ok(backend.shaders.insert(ShaderResource { module, key }))
}

/// Creates a pipeline, or reuses the cached one made from the same shader and description.
pub(super) fn create_pipeline(
    backend: &mut WgpuBackend,
    desc: &PipelineDesc,
) -> Result<Handle<Pipeline>> {
    if let Some(geometry) = &desc.geometry {
        return Err(BackendError::Unsupported {
            backend: backend.kind.name(),
            what: format!("pipeline `{}`", desc.label),
            message: format!(
                "geometry stage `{}`: wgpu has no geometry shaders (use the gl backend)",
                geometry.name
            ),
        });
    }
    let shader = backend.shaders.get(desc.shader)?;
    let cache_key = pipeline_cache_key(shader.key, desc);
    if let Some(cached) = backend.pipeline_cache.get(&cache_key) {
        let cached = cached.clone();
        return Ok(backend.pipelines.insert(cached));
    }
    let resource = compile_pipeline(backend, &shader.module, desc)?;
    backend.pipeline_cache.insert(cache_key, resource.clone());
    backend.pipelines_compiled += 1;
    Ok(backend.pipelines.insert(resource))
}

/// The pipeline cache's key: the shader's key and every field of `desc` that shapes the
/// pipeline.
fn pipeline_cache_key(shader_key: u64, desc: &PipelineDesc) -> String {
    format!(
        "{:x}|{}|{}|{:?}|{:?}|{:?}|{:?}|{:?}|{:?}|{:?}|{:?}",
        shader_key,
        desc.label,
        desc.vertex_entry,
        desc.fragment_entry,
        desc.vertex_buffers,
        desc.bindings,
        desc.color_targets,
        desc.depth,
        desc.topology,
        desc.cull,
        desc.constants
    )
}

/// Compiles `desc` with `module` (a pipeline cache miss): its bind group layout, pipeline
/// layout and render pipeline, inside one error scope.
fn compile_pipeline(
    backend: &WgpuBackend,
    module: &wgpu::ShaderModule,
    desc: &PipelineDesc,
) -> Result<PipelineResource> {
    let context = format!("pipeline `{}`", desc.label);
    let constants: Vec<(&str, f64)> = desc
        .constants
        .iter()
        .map(|(name, value)| (name.as_str(), *value))
        .collect();
    let compilation_options = wgpu::PipelineCompilationOptions {
        constants: &constants,
        ..Default::default()
    };
    let entries: Vec<wgpu::BindGroupLayoutEntry> = desc
        .bindings
        .iter()
        .map(conv::bind_group_layout_entry)
        .collect();
    let attributes: Vec<Vec<wgpu::VertexAttribute>> = desc
        .vertex_buffers
        .iter()
        .map(conv::vertex_attributes)
        .collect();
    let vertex_buffers: Vec<Option<wgpu::VertexBufferLayout>> = desc
        .vertex_buffers
        .iter()
        .zip(&attributes)
        .map(|(layout, attributes)| {
            Some(wgpu::VertexBufferLayout {
                array_stride: layout.stride as u64,
                step_mode: wgpu::VertexStepMode::Vertex,
                attributes,
            })
        })
        .collect();
    let targets: Vec<Option<wgpu::ColorTargetState>> = desc
        .color_targets
        .iter()
        .map(|t| Some(conv::color_target(t)))
        .collect();
    let (bind_group_layout, pipeline) = backend.scoped(&context, || {
        let bind_group_layout =
            backend
                .device
                .create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
                    label: Some(&desc.label),
                    entries: &entries,
                });
        let layout = backend
            .device
            .create_pipeline_layout(&wgpu::PipelineLayoutDescriptor {
                label: Some(&desc.label),
                bind_group_layouts: &[Some(&bind_group_layout)],
                immediate_size: 0,
            });
        let pipeline = backend
            .device
            .create_render_pipeline(&wgpu::RenderPipelineDescriptor {
                label: Some(&desc.label),
                layout: Some(&layout),
                vertex: wgpu::VertexState {
                    module,
                    entry_point: Some(&desc.vertex_entry),
                    compilation_options: compilation_options.clone(),
                    buffers: &vertex_buffers,
                },
                primitive: conv::primitive(desc.topology, desc.cull),
                depth_stencil: desc.depth.map(conv::depth_stencil),
                multisample: wgpu::MultisampleState::default(),
                fragment: desc
                    .fragment_entry
                    .as_ref()
                    .map(|entry| wgpu::FragmentState {
                        module,
                        entry_point: Some(entry),
                        compilation_options: compilation_options.clone(),
                        targets: &targets,
                    }),
                multiview_mask: None,
                cache: None,
            });
        (bind_group_layout, pipeline)
    })?;
    Ok(PipelineResource {
        pipeline,
        bind_group_layout,
        bindings: desc.bindings.clone(),
        label: desc.label.clone(),
    })
}

//! The wgpu backend, pinned to one wgpu backend: Vulkan (`wgpu-vulkan`) or GL (`wgpu-gl`).
//!
//! wgpu is never allowed to fall back to another API: if the pinned one has no adapter, the
//! backend reports itself unavailable. Validation errors are caught with error scopes and
//! returned as [`BackendError`]s instead of panicking.

mod conv;

use ::wgpu;
use std::borrow::Cow;
use std::collections::HashMap;
use std::sync::Arc;

use super::pool::Pool;
use super::*;
use crate::image::Image;
use crate::shaders;

struct TextureResource {
    texture: wgpu::Texture,
    desc: TextureDesc,
}

struct BufferResource {
    buffer: wgpu::Buffer,
    usage: BufferUsage,
    size: u64,
}

#[derive(Clone)]
struct PipelineResource {
    pipeline: wgpu::RenderPipeline,
    bind_group_layout: wgpu::BindGroupLayout,
    bindings: Vec<BindingLayout>,
    label: String,
}

/// A shader module and the hash of its name and source (the caches' key).
struct ShaderResource {
    module: wgpu::ShaderModule,
    key: u64,
}

/// Depth readback through a copy pass packing f32 bits into RGBA8 (created on first use).
struct DepthCopy {
    pipeline: wgpu::RenderPipeline,
    bind_group_layout: wgpu::BindGroupLayout,
}

/// A wgpu device on one pinned API.
pub struct WgpuBackend {
    kind: BackendKind,
    info: DriverInfo,
    device: wgpu::Device,
    queue: wgpu::Queue,
    timestamps: bool,
    textures: Pool<TextureResource>,
    buffers: Pool<BufferResource>,
    samplers: Pool<wgpu::Sampler>,
    shaders: Pool<ShaderResource>,
    pipelines: Pool<PipelineResource>,
    /// Compiled modules and pipelines by source and description, kept for the backend's life
    /// and shared by every handle made from the same inputs, as a driver's pipeline cache
    /// would. Renders create the same pipelines every frame, and on wgpu's Vulkan path (with
    /// lavapipe) each pipeline created and destroyed kept ~450 KiB (measured: 200 cycles of one
    /// pipeline, +88 MiB; wgpu-gl +1 MiB), so the cache bounds memory by the number of
    /// distinct pipelines instead of the number of frames.
    module_cache: HashMap<u64, wgpu::ShaderModule>,
    pipeline_cache: HashMap<String, PipelineResource>,
    /// Pipelines compiled (cache misses), for [`Backend::pipelines_compiled`].
    pipelines_compiled: u64,
    depth_copy: Option<DepthCopy>,
}

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
            fix: fix.to_owned(),
        };
        let instance = wgpu::Instance::new(wgpu::InstanceDescriptor {
            backends,
            flags: wgpu::InstanceFlags::default(),
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
        .map_err(|e| unavailable(format!("no {api} adapter found ({e})")))?;
        let adapter_info = adapter.get_info();
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
            && !super::gl::wgpu_interop::enable_seamless_cube_maps(&device)
        {
            log::debug!("wgpu-gl: seamless cube maps not enabled (GLES contexts always are)");
        }
        let timestamps = features.contains(wgpu::Features::TIMESTAMP_QUERY);
        let info = DriverInfo {
            backend: kind.name().to_owned(),
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
            ..Default::default()
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
    fn scoped<T>(&self, context: &str, f: impl FnOnce() -> T) -> Result<T> {
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

    fn driver_error(&self, context: &str, message: String) -> BackendError {
        BackendError::Driver {
            backend: self.kind.name(),
            context: context.to_owned(),
            message,
        }
    }

    fn wait(&self, context: &str) -> Result<()> {
        self.device
            .poll(wgpu::PollType::wait_indefinitely())
            .map(|_| ())
            .map_err(|e| self.driver_error(context, e.to_string()))
    }

    /// A view of one mip/layer of a texture, for rendering or copying.
    fn target_view(&self, texture: Handle<Texture>, at: Subresource) -> Result<wgpu::TextureView> {
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

    fn bind_group(&self, pipeline: &PipelineResource, draw: &Draw) -> Result<wgpu::BindGroup> {
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

    /// Maps `buffer`, copies its bytes out, unmaps it.
    fn read_buffer(&self, buffer: &wgpu::Buffer, context: &str) -> Result<Vec<u8>> {
        let slice = buffer.slice(..);
        let (sender, receiver) = std::sync::mpsc::channel();
        slice.map_async(wgpu::MapMode::Read, move |r| {
            let _ = sender.send(r);
        });
        self.wait(context)?;
        receiver
            .recv()
            .map_err(|e| self.driver_error(context, e.to_string()))?
            .map_err(|e| self.driver_error(context, e.to_string()))?;
        let bytes = slice
            .get_mapped_range()
            .map_err(|e| self.driver_error(context, e.to_string()))?
            .to_vec();
        buffer.unmap();
        Ok(bytes)
    }

    fn depth_copy(&mut self) -> Result<&DepthCopy> {
        if self.depth_copy.is_none() {
            let module = self.scoped("depth copy shader", || {
                self.device
                    .create_shader_module(wgpu::ShaderModuleDescriptor {
                        label: Some(shaders::DEPTH_COPY.name),
                        source: wgpu::ShaderSource::Wgsl(Cow::Borrowed(shaders::DEPTH_COPY.wgsl)),
                    })
            })?;
            let bind_group_layout =
                self.device
                    .create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
                        label: Some("depth copy"),
                        entries: &[wgpu::BindGroupLayoutEntry {
                            binding: 0,
                            visibility: wgpu::ShaderStages::FRAGMENT,
                            ty: wgpu::BindingType::Texture {
                                sample_type: wgpu::TextureSampleType::Float { filterable: false },
                                view_dimension: wgpu::TextureViewDimension::D2,
                                multisampled: false,
                            },
                            count: None,
                        }],
                    });
            let layout = self
                .device
                .create_pipeline_layout(&wgpu::PipelineLayoutDescriptor {
                    label: Some("depth copy"),
                    bind_group_layouts: &[Some(&bind_group_layout)],
                    immediate_size: 0,
                });
            let pipeline = self.scoped("depth copy pipeline", || {
                self.device
                    .create_render_pipeline(&wgpu::RenderPipelineDescriptor {
                        label: Some("depth copy"),
                        layout: Some(&layout),
                        vertex: wgpu::VertexState {
                            module: &module,
                            entry_point: Some("vs_fullscreen"),
                            compilation_options: Default::default(),
                            buffers: &[],
                        },
                        primitive: wgpu::PrimitiveState::default(),
                        depth_stencil: None,
                        multisample: wgpu::MultisampleState::default(),
                        fragment: Some(wgpu::FragmentState {
                            module: &module,
                            entry_point: Some("fs_copy"),
                            compilation_options: Default::default(),
                            targets: &[Some(wgpu::ColorTargetState {
                                format: wgpu::TextureFormat::Rgba8Unorm,
                                blend: None,
                                write_mask: wgpu::ColorWrites::ALL,
                            })],
                        }),
                        multiview_mask: None,
                        cache: None,
                    })
            })?;
            self.depth_copy = Some(DepthCopy {
                pipeline,
                bind_group_layout,
            });
        }
        Ok(self.depth_copy.as_ref().expect("just created"))
    }

    /// Copies a color texture's subresource into a mappable buffer and returns its texels.
    fn read_color(
        &self,
        texture: &wgpu::Texture,
        desc: &TextureDesc,
        at: Subresource,
    ) -> Result<Vec<u8>> {
        let (w, h) = desc.mip_size(at.mip);
        let row = w as usize * desc.format.texel_size();
        let padded_row = row.next_multiple_of(wgpu::COPY_BYTES_PER_ROW_ALIGNMENT as usize);
        let context = format!("readback of `{}`", desc.label);
        let buffer = self.device.create_buffer(&wgpu::BufferDescriptor {
            label: Some("readback"),
            size: (padded_row * h as usize) as u64,
            usage: wgpu::BufferUsages::COPY_DST | wgpu::BufferUsages::MAP_READ,
            mapped_at_creation: false,
        });
        self.scoped(&context, || {
            let mut encoder = self
                .device
                .create_command_encoder(&wgpu::CommandEncoderDescriptor {
                    label: Some("readback"),
                });
            encoder.copy_texture_to_buffer(
                wgpu::TexelCopyTextureInfo {
                    texture,
                    mip_level: at.mip,
                    origin: wgpu::Origin3d {
                        x: 0,
                        y: 0,
                        z: at.layer,
                    },
                    aspect: wgpu::TextureAspect::All,
                },
                wgpu::TexelCopyBufferInfo {
                    buffer: &buffer,
                    layout: wgpu::TexelCopyBufferLayout {
                        offset: 0,
                        bytes_per_row: Some(padded_row as u32),
                        rows_per_image: Some(h),
                    },
                },
                wgpu::Extent3d {
                    width: w,
                    height: h,
                    depth_or_array_layers: 1,
                },
            );
            self.queue.submit([encoder.finish()]);
        })?;
        let padded = self.read_buffer(&buffer, &context)?;
        Ok(padded
            .chunks_exact(padded_row)
            .flat_map(|r| &r[..row])
            .copied()
            .collect())
    }
}

impl Backend for WgpuBackend {
    fn kind(&self) -> BackendKind {
        self.kind
    }

    fn info(&self) -> &DriverInfo {
        &self.info
    }

    fn features(&self) -> Features {
        Features::default()
    }

    fn create_texture(&mut self, desc: &TextureDesc) -> Result<Handle<Texture>> {
        check_texture_desc(desc)?;
        let texture = self.scoped(&format!("texture `{}`", desc.label), || {
            self.device.create_texture(&wgpu::TextureDescriptor {
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
        Ok(self.textures.insert(TextureResource {
            texture,
            desc: desc.clone(),
        }))
    }

    fn write_texture(
        &mut self,
        texture: Handle<Texture>,
        at: Subresource,
        data: &[u8],
    ) -> Result<()> {
        let res = self.textures.get(texture)?;
        let (w, h) = check_upload(&res.desc, at, data)?;
        if res.desc.format.is_depth() {
            return Err(BackendError::Unsupported {
                backend: self.kind.name(),
                what: format!("an upload to depth texture `{}`", res.desc.label),
                message: "wgpu cannot copy into depth formats; render depth instead".to_owned(),
            });
        }
        self.scoped(&format!("upload to `{}`", res.desc.label), || {
            self.queue.write_texture(
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

    fn destroy_texture(&mut self, texture: Handle<Texture>) -> Result<()> {
        self.textures.remove(texture)?.texture.destroy();
        Ok(())
    }

    fn create_buffer(&mut self, desc: &BufferDesc) -> Result<Handle<Buffer>> {
        check_buffer_desc(desc)?;
        let buffer = self.scoped(&format!("buffer `{}`", desc.label), || {
            self.device.create_buffer(&wgpu::BufferDescriptor {
                label: Some(&desc.label),
                size: desc.size,
                usage: conv::buffer_usage(desc.usage),
                mapped_at_creation: false,
            })
        })?;
        Ok(self.buffers.insert(BufferResource {
            buffer,
            usage: desc.usage,
            size: desc.size,
        }))
    }

    fn write_buffer(&mut self, buffer: Handle<Buffer>, offset: u64, data: &[u8]) -> Result<()> {
        let res = self.buffers.get(buffer)?;
        check_buffer_write(res.usage, res.size, offset, data.len())?;
        self.queue.write_buffer(&res.buffer, offset, data);
        Ok(())
    }

    fn destroy_buffer(&mut self, buffer: Handle<Buffer>) -> Result<()> {
        self.buffers.remove(buffer)?.buffer.destroy();
        Ok(())
    }

    fn create_sampler(&mut self, desc: &SamplerDesc) -> Result<Handle<Sampler>> {
        let address = conv::address(desc.address_mode);
        let sampler = self.device.create_sampler(&wgpu::SamplerDescriptor {
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
        Ok(self.samplers.insert(sampler))
    }

    fn destroy_sampler(&mut self, sampler: Handle<Sampler>) -> Result<()> {
        self.samplers.remove(sampler).map(drop)
    }

    fn create_shader(&mut self, desc: &ShaderDesc) -> Result<Handle<Shader>> {
        let key = desc.cache_key();
        if let Some(module) = self.module_cache.get(&key) {
            let module = module.clone();
            return Ok(self.shaders.insert(ShaderResource { module, key }));
        }
        // Validate with naga first for a diagnostic that names the file and line.
        shaders::validate(&desc.name, &desc.wgsl).map_err(|e| BackendError::Shader {
            backend: self.kind.name(),
            name: desc.name.clone(),
            message: e.to_string(),
        })?;
        let module = self.scoped(&format!("shader `{}`", desc.name), || {
            self.device
                .create_shader_module(wgpu::ShaderModuleDescriptor {
                    label: Some(&desc.name),
                    source: wgpu::ShaderSource::Wgsl(Cow::Borrowed(&desc.wgsl)),
                })
        })?;
        self.module_cache.insert(key, module.clone());
        Ok(self.shaders.insert(ShaderResource { module, key }))
    }

    fn destroy_shader(&mut self, shader: Handle<Shader>) -> Result<()> {
        self.shaders.remove(shader).map(drop)
    }

    fn create_pipeline(&mut self, desc: &PipelineDesc) -> Result<Handle<Pipeline>> {
        if let Some(geometry) = &desc.geometry {
            return Err(BackendError::Unsupported {
                backend: self.kind.name(),
                what: format!("pipeline `{}`", desc.label),
                message: format!(
                    "geometry stage `{}`: wgpu has no geometry shaders (use the gl backend)",
                    geometry.name
                ),
            });
        }
        let shader = self.shaders.get(desc.shader)?;
        let cache_key = format!(
            "{:x}|{}|{}|{:?}|{:?}|{:?}|{:?}|{:?}|{:?}|{:?}|{:?}",
            shader.key,
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
        );
        if let Some(cached) = self.pipeline_cache.get(&cache_key) {
            let cached = cached.clone();
            return Ok(self.pipelines.insert(cached));
        }
        let module = &shader.module;
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
            .map(|b| wgpu::BindGroupLayoutEntry {
                binding: b.binding,
                visibility: wgpu::ShaderStages::VERTEX_FRAGMENT,
                ty: conv::binding_type(b.kind),
                count: None,
            })
            .collect();
        let attributes: Vec<Vec<wgpu::VertexAttribute>> = desc
            .vertex_buffers
            .iter()
            .map(|layout| {
                layout
                    .attributes
                    .iter()
                    .map(|a| wgpu::VertexAttribute {
                        format: conv::vertex_format(a.format),
                        offset: a.offset as u64,
                        shader_location: a.location,
                    })
                    .collect()
            })
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
            .map(|t| {
                Some(wgpu::ColorTargetState {
                    format: conv::format(t.format),
                    blend: t.blend.map(conv::blend),
                    write_mask: wgpu::ColorWrites::ALL,
                })
            })
            .collect();
        let (bind_group_layout, pipeline) = self.scoped(&context, || {
            let bind_group_layout =
                self.device
                    .create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
                        label: Some(&desc.label),
                        entries: &entries,
                    });
            let layout = self
                .device
                .create_pipeline_layout(&wgpu::PipelineLayoutDescriptor {
                    label: Some(&desc.label),
                    bind_group_layouts: &[Some(&bind_group_layout)],
                    immediate_size: 0,
                });
            let pipeline = self
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
                    primitive: wgpu::PrimitiveState {
                        topology: conv::topology(desc.topology),
                        strip_index_format: None,
                        front_face: wgpu::FrontFace::Ccw,
                        cull_mode: conv::cull(desc.cull),
                        unclipped_depth: false,
                        polygon_mode: wgpu::PolygonMode::Fill,
                        conservative: false,
                    },
                    depth_stencil: desc.depth.map(|d| wgpu::DepthStencilState {
                        format: conv::format(d.format),
                        depth_write_enabled: Some(d.write),
                        depth_compare: Some(conv::compare(d.compare)),
                        stencil: Default::default(),
                        bias: Default::default(),
                    }),
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
        let resource = PipelineResource {
            pipeline,
            bind_group_layout,
            bindings: desc.bindings.clone(),
            label: desc.label.clone(),
        };
        self.pipeline_cache.insert(cache_key, resource.clone());
        self.pipelines_compiled += 1;
        Ok(self.pipelines.insert(resource))
    }

    fn destroy_pipeline(&mut self, pipeline: Handle<Pipeline>) -> Result<()> {
        self.pipelines.remove(pipeline).map(drop)
    }

    fn submit(&mut self, passes: &[RenderPass]) -> Result<Vec<PassTiming>> {
        // Views and bind groups must outlive the pass encoders that use them.
        struct Prepared {
            colors: Vec<wgpu::TextureView>,
            depth: Option<wgpu::TextureView>,
            bind_groups: Vec<wgpu::BindGroup>,
        }
        let mut prepared = Vec::with_capacity(passes.len());
        for pass in passes {
            if pass.viewports.len() > 1 {
                return Err(BackendError::Unsupported {
                    backend: self.kind.name(),
                    what: format!("pass `{}`", pass.name),
                    message: "viewport arrays need a geometry stage, which wgpu lacks".to_owned(),
                });
            }
            let colors = pass
                .color_attachments
                .iter()
                .map(|a| self.target_view(a.texture, a.subresource))
                .collect::<Result<Vec<_>>>()?;
            let depth = pass
                .depth_attachment
                .map(|d| self.target_view(d.texture, d.subresource))
                .transpose()?;
            let bind_groups = pass
                .draws
                .iter()
                .map(|d| self.bind_group(self.pipelines.get(d.pipeline)?, d))
                .collect::<Result<Vec<_>>>()?;
            prepared.push(Prepared {
                colors,
                depth,
                bind_groups,
            });
        }
        let query_count = 2 * passes.len() as u32;
        let timestamps = self.timestamps && query_count > 0;
        let queries = timestamps.then(|| {
            let set = self.device.create_query_set(&wgpu::QuerySetDescriptor {
                label: Some("pass timestamps"),
                ty: wgpu::QueryType::Timestamp,
                count: query_count,
            });
            let size = query_count as u64 * 8;
            let resolve = self.device.create_buffer(&wgpu::BufferDescriptor {
                label: Some("timestamp resolve"),
                size,
                usage: wgpu::BufferUsages::QUERY_RESOLVE | wgpu::BufferUsages::COPY_SRC,
                mapped_at_creation: false,
            });
            let read = self.device.create_buffer(&wgpu::BufferDescriptor {
                label: Some("timestamp read"),
                size,
                usage: wgpu::BufferUsages::COPY_DST | wgpu::BufferUsages::MAP_READ,
                mapped_at_creation: false,
            });
            (set, resolve, read)
        });
        let names: Vec<&str> = passes.iter().map(|p| p.name.as_str()).collect();
        let context = format!("passes [{}]", names.join(", "));
        self.scoped(&context, || -> Result<()> {
            let mut encoder = self
                .device
                .create_command_encoder(&wgpu::CommandEncoderDescriptor {
                    label: Some("frame"),
                });
            for (index, (pass, views)) in passes.iter().zip(&prepared).enumerate() {
                let color_attachments: Vec<_> = pass
                    .color_attachments
                    .iter()
                    .zip(&views.colors)
                    .map(|(a, view)| {
                        Some(wgpu::RenderPassColorAttachment {
                            view,
                            depth_slice: None,
                            resolve_target: None,
                            ops: wgpu::Operations {
                                load: match a.load {
                                    LoadOp::Clear([r, g, b, a]) => {
                                        wgpu::LoadOp::Clear(wgpu::Color {
                                            r: r as f64,
                                            g: g as f64,
                                            b: b as f64,
                                            a: a as f64,
                                        })
                                    }
                                    LoadOp::Load => wgpu::LoadOp::Load,
                                },
                                store: wgpu::StoreOp::Store,
                            },
                        })
                    })
                    .collect();
                let depth_stencil_attachment = pass
                    .depth_attachment
                    .as_ref()
                    .zip(views.depth.as_ref())
                    .map(|(d, view)| wgpu::RenderPassDepthStencilAttachment {
                        view,
                        depth_ops: Some(wgpu::Operations {
                            load: match d.load {
                                LoadOp::Clear(v) => wgpu::LoadOp::Clear(v),
                                LoadOp::Load => wgpu::LoadOp::Load,
                            },
                            store: wgpu::StoreOp::Store,
                        }),
                        stencil_ops: None,
                    });
                let mut render_pass = encoder.begin_render_pass(&wgpu::RenderPassDescriptor {
                    label: Some(&pass.name),
                    color_attachments: &color_attachments,
                    depth_stencil_attachment,
                    timestamp_writes: queries.as_ref().map(|(set, _, _)| {
                        wgpu::RenderPassTimestampWrites {
                            query_set: set,
                            beginning_of_pass_write_index: Some(2 * index as u32),
                            end_of_pass_write_index: Some(2 * index as u32 + 1),
                        }
                    }),
                    occlusion_query_set: None,
                    multiview_mask: None,
                });
                if let Some(v) = pass.viewports.first() {
                    render_pass.set_viewport(v.x, v.y, v.width, v.height, v.min_depth, v.max_depth);
                }
                for (draw, bind_group) in pass.draws.iter().zip(&views.bind_groups) {
                    render_pass.set_pipeline(&self.pipelines.get(draw.pipeline)?.pipeline);
                    render_pass.set_bind_group(0, bind_group, &[]);
                    for (slot, buffer) in draw.vertex_buffers.iter().enumerate() {
                        render_pass.set_vertex_buffer(
                            slot as u32,
                            self.buffers.get(*buffer)?.buffer.slice(..),
                        );
                    }
                    match draw.index_buffer {
                        Some((buffer, format)) => {
                            render_pass.set_index_buffer(
                                self.buffers.get(buffer)?.buffer.slice(..),
                                conv::index_format(format),
                            );
                            render_pass.draw_indexed(0..draw.count, 0, 0..1);
                        }
                        None => render_pass.draw(0..draw.count, 0..1),
                    }
                }
            }
            if let Some((set, resolve, read)) = &queries {
                encoder.resolve_query_set(set, 0..query_count, resolve, 0);
                encoder.copy_buffer_to_buffer(resolve, 0, read, 0, query_count as u64 * 8);
            }
            self.queue.submit([encoder.finish()]);
            Ok(())
        })??;
        let gpu_ns: Vec<Option<f64>> = match &queries {
            Some((_, _, read)) => {
                let bytes = self.read_buffer(read, &context)?;
                let ticks: Vec<u64> = bytes
                    .chunks_exact(8)
                    .map(|b| u64::from_le_bytes(b.try_into().expect("8 bytes")))
                    .collect();
                let period = self.queue.get_timestamp_period() as f64;
                ticks
                    .chunks_exact(2)
                    .map(|t| Some(t[1].saturating_sub(t[0]) as f64 * period))
                    .collect()
            }
            None => {
                self.wait(&context)?;
                vec![None; passes.len()]
            }
        };
        Ok(passes
            .iter()
            .zip(gpu_ns)
            .map(|(p, gpu_ns)| PassTiming {
                name: p.name.clone(),
                gpu_ns,
            })
            .collect())
    }

    fn read_texture(&mut self, texture: Handle<Texture>, at: Subresource) -> Result<Image> {
        let desc = self.textures.get(texture)?.desc.clone();
        let (w, h) = desc.mip_size(at.mip);
        check_subresource(&desc, at)?;
        if !desc.format.is_depth() {
            let bytes = self.read_color(&self.textures.get(texture)?.texture, &desc, at)?;
            return Ok(Image::from_texel_bytes(w, h, desc.format, &bytes));
        }
        // Depth: pack it into an RGBA8 texture (see depth_copy.wgsl), then read that.
        let source = self.target_view(texture, at)?;
        let context = format!("depth readback of `{}`", desc.label);
        let scratch = self.scoped(&context, || {
            self.device.create_texture(&wgpu::TextureDescriptor {
                label: Some("depth readback"),
                size: wgpu::Extent3d {
                    width: w,
                    height: h,
                    depth_or_array_layers: 1,
                },
                mip_level_count: 1,
                sample_count: 1,
                dimension: wgpu::TextureDimension::D2,
                format: wgpu::TextureFormat::Rgba8Unorm,
                usage: wgpu::TextureUsages::RENDER_ATTACHMENT | wgpu::TextureUsages::COPY_SRC,
                view_formats: &[],
            })
        })?;
        let scratch_view = scratch.create_view(&Default::default());
        let copy = self.depth_copy()?;
        let copy_pipeline = copy.pipeline.clone();
        let copy_layout = copy.bind_group_layout.clone();
        let bind_group = self.scoped(&context, || {
            self.device.create_bind_group(&wgpu::BindGroupDescriptor {
                label: Some("depth copy"),
                layout: &copy_layout,
                entries: &[wgpu::BindGroupEntry {
                    binding: 0,
                    resource: wgpu::BindingResource::TextureView(&source),
                }],
            })
        })?;
        self.scoped(&context, || {
            let mut encoder = self
                .device
                .create_command_encoder(&wgpu::CommandEncoderDescriptor {
                    label: Some("depth copy"),
                });
            {
                let mut pass = encoder.begin_render_pass(&wgpu::RenderPassDescriptor {
                    label: Some("depth copy"),
                    color_attachments: &[Some(wgpu::RenderPassColorAttachment {
                        view: &scratch_view,
                        depth_slice: None,
                        resolve_target: None,
                        ops: wgpu::Operations {
                            load: wgpu::LoadOp::Clear(wgpu::Color::BLACK),
                            store: wgpu::StoreOp::Store,
                        },
                    })],
                    depth_stencil_attachment: None,
                    timestamp_writes: None,
                    occlusion_query_set: None,
                    multiview_mask: None,
                });
                pass.set_pipeline(&copy_pipeline);
                pass.set_bind_group(0, &bind_group, &[]);
                pass.draw(0..3, 0..1);
            }
            self.queue.submit([encoder.finish()]);
        })?;
        // Each RGBA8 texel holds the little-endian bytes of one f32 depth.
        let scratch_desc = TextureDesc::d2("depth readback", w, h, TextureFormat::Rgba8Unorm);
        let bytes = self.read_color(&scratch, &scratch_desc, Subresource::default())?;
        scratch.destroy();
        Ok(Image::from_texel_bytes(
            w,
            h,
            TextureFormat::Depth32Float,
            &bytes,
        ))
    }

    fn live_resources(&self) -> usize {
        self.textures.len()
            + self.buffers.len()
            + self.samplers.len()
            + self.shaders.len()
            + self.pipelines.len()
    }

    fn pipelines_compiled(&self) -> u64 {
        self.pipelines_compiled
    }
}

//! The floor passes: per plan pass, the cheapest pass writing the same targets over every
//! pixel (a full-screen triangle writing constants), created once and submitted on demand.

use std::collections::BTreeMap;

use engine::backend::{
    self, Backend, ColorAttachment, ColorTarget, CompareFunction, CullMode, DepthAttachment,
    DepthState, Draw, Handle, LoadOp, Pipeline, PipelineDesc, RenderPass, ResourceScope,
    ShaderDesc, Subresource, Texture, TextureDesc, Topology,
};
use engine::plan::{PassId, RenderPlan};
use engine::shaders;

/// Floor passes for every pass of a plan, created once on a backend and submitted on demand.
pub struct Floors {
    scope: ResourceScope,
    passes: BTreeMap<PassId, RenderPass>,
}

impl Floors {
    /// Creates the targets and pipelines of every pass's floor.
    pub fn new(backend: &mut dyn Backend, plan: &RenderPlan) -> backend::Result<Self> {
        let mut scope = ResourceScope::default();
        let result = Self::record(backend, plan, &mut scope);
        match result {
            Ok(passes) => Ok(Self { scope, passes }),
            Err(e) => {
                scope.destroy(backend);
                Err(e)
            }
        }
    }

    fn record(
        backend: &mut dyn Backend,
        plan: &RenderPlan,
        scope: &mut ResourceScope,
    ) -> backend::Result<BTreeMap<PassId, RenderPass>> {
        let shader = scope.shader(
            backend,
            &ShaderDesc {
                name: shaders::FLOOR.name.to_owned(),
                wgsl: shaders::FLOOR.wgsl.to_owned(),
            },
        )?;
        let mut pipelines: BTreeMap<String, Handle<Pipeline>> = BTreeMap::new();
        let mut passes = BTreeMap::new();
        for spec in &plan.passes {
            let targets: Vec<_> = spec.writes.iter().filter_map(|w| plan.target(*w)).collect();
            let colors: Vec<_> = targets.iter().filter(|t| !t.format.is_depth()).collect();
            let depth = targets.iter().find(|t| t.format.is_depth());
            if colors.len() > 5 || (colors.is_empty() && depth.is_none()) {
                continue;
            }
            let key = format!(
                "{:?} {:?}",
                colors.iter().map(|t| t.format).collect::<Vec<_>>(),
                depth.map(|t| t.format)
            );
            let pipeline = match pipelines.get(&key) {
                Some(p) => *p,
                None => {
                    let p = scope.pipeline(
                        backend,
                        &PipelineDesc {
                            label: format!("floor {key}"),
                            shader,
                            vertex_entry: "vs_fullscreen".to_owned(),
                            fragment_entry: (!colors.is_empty())
                                .then(|| format!("fs_floor_{}", colors.len())),
                            vertex_buffers: vec![],
                            bindings: vec![],
                            color_targets: colors
                                .iter()
                                .map(|t| ColorTarget {
                                    format: t.format,
                                    blend: None,
                                })
                                .collect(),
                            depth: depth.map(|t| DepthState {
                                format: t.format,
                                write: true,
                                compare: CompareFunction::Always,
                            }),
                            topology: Topology::TriangleList,
                            cull: CullMode::None,
                            geometry: None,
                            constants: vec![],
                        },
                    )?;
                    pipelines.insert(key, p);
                    p
                }
            };
            let mut texture =
                |spec: &engine::plan::TargetSpec| -> backend::Result<Handle<Texture>> {
                    scope.texture(
                        backend,
                        &TextureDesc::d2(
                            &format!("floor {}", spec.id),
                            spec.width,
                            spec.height,
                            spec.format,
                        ),
                    )
                };
            let mut color_attachments = Vec::new();
            for t in &colors {
                color_attachments.push(ColorAttachment {
                    texture: texture(t)?,
                    subresource: Subresource::default(),
                    load: LoadOp::Clear([0.0; 4]),
                });
            }
            let depth_attachment = match depth {
                Some(t) => Some(DepthAttachment {
                    texture: texture(t)?,
                    subresource: Subresource::default(),
                    load: LoadOp::Clear(1.0),
                }),
                None => None,
            };
            passes.insert(
                spec.id,
                RenderPass {
                    name: format!("{} floor", spec.id),
                    color_attachments,
                    depth_attachment,
                    viewports: vec![],
                    draws: vec![Draw {
                        pipeline,
                        bindings: vec![],
                        vertex_buffers: vec![],
                        index_buffer: None,
                        count: 3,
                    }],
                },
            );
        }
        Ok(passes)
    }

    /// Submits the floor of plan pass `pass` once; its GPU ns (None without timestamps or when
    /// the pass has no floor).
    pub fn time(&self, backend: &mut dyn Backend, pass: PassId) -> backend::Result<Option<f64>> {
        self.time_repeated(backend, pass, 1)
    }

    /// Submits the floor of plan pass `pass` `copies` times in one submission: the GPU ns of
    /// one, on average (None without timestamps or when the pass has no floor). A floor far
    /// shorter than its pass is repeated so that its time is not all timer and start-up.
    pub fn time_repeated(
        &self,
        backend: &mut dyn Backend,
        pass: PassId,
        copies: usize,
    ) -> backend::Result<Option<f64>> {
        let Some(floor) = self.passes.get(&pass) else {
            return Ok(None);
        };
        let copies = copies.max(1);
        let timings = backend.submit(&vec![floor.clone(); copies])?;
        let total: Option<f64> = timings.iter().map(|t| t.gpu_ns).sum();
        Ok(total.map(|ns| ns / copies as f64))
    }

    /// Destroys the floors' resources.
    pub fn destroy(self, backend: &mut dyn Backend) {
        self.scope.destroy(backend);
    }
}

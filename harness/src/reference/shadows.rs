//! CPU reference for shadows: exact hard-shadow visibility by ray casting from each G-buffer
//! position to the light against the shadow casters' triangles (f64, camera-relative, through a
//! small bounding-volume hierarchy), compared with the GPU's shadow term read back from the
//! `shadow_term_<light>` debug output of the renderer.

use engine::plan::{self, GBufferTarget, TargetId};
use engine::renderer::Frame;
use engine::scene::{Light, Scene};
use engine::Image;
use glam::DVec3;

use super::ReferenceError;
use crate::golden::metrics::bitwise_equal;

/// A triangle in camera-relative world space.
#[derive(Clone, Copy, Debug)]
pub struct Triangle {
    /// The first corner.
    pub a: DVec3,
    /// The second corner.
    pub b: DVec3,
    /// The third corner.
    pub c: DVec3,
}

#[derive(Clone, Copy, Debug)]
struct Bounds {
    min: DVec3,
    max: DVec3,
}

impl Bounds {
    fn empty() -> Self {
        Self {
            min: DVec3::splat(f64::INFINITY),
            max: DVec3::splat(f64::NEG_INFINITY),
        }
    }

    fn grow(&mut self, p: DVec3) {
        self.min = self.min.min(p);
        self.max = self.max.max(p);
    }

    /// Slab test: does the ray hit the box before `t_max`?
    fn hit(&self, origin: DVec3, inverse_direction: DVec3, t_max: f64) -> bool {
        let t0 = (self.min - origin) * inverse_direction;
        let t1 = (self.max - origin) * inverse_direction;
        let near = t0.min(t1).max_element().max(0.0);
        let far = t0.max(t1).min_element().min(t_max);
        near <= far
    }
}

enum Node {
    Leaf {
        bounds: Bounds,
        first: usize,
        count: usize,
    },
    Inner {
        bounds: Bounds,
        left: usize,
        right: usize,
    },
}

/// A bounding-volume hierarchy over the shadow casters of a scene (median splits).
pub struct Occluders {
    triangles: Vec<Triangle>,
    nodes: Vec<Node>,
}

const LEAF_SIZE: usize = 4;

impl Occluders {
    /// The shadow casters of `scene`, camera-relative.
    pub fn new(scene: &Scene) -> Self {
        let mut triangles = Vec::new();
        for object in scene.objects.iter().filter(|o| o.casts_shadows) {
            let m = object.transform.relative_to(scene.camera.position);
            let p = |i: u32| {
                let v = object.mesh.vertices[i as usize].position;
                m.transform_point3(DVec3::new(v[0] as f64, v[1] as f64, v[2] as f64))
            };
            for t in object.mesh.indices.chunks_exact(3) {
                triangles.push(Triangle {
                    a: p(t[0]),
                    b: p(t[1]),
                    c: p(t[2]),
                });
            }
        }
        let mut occluders = Self {
            triangles,
            nodes: Vec::new(),
        };
        if !occluders.triangles.is_empty() {
            let count = occluders.triangles.len();
            occluders.build(0, count);
        }
        occluders
    }

    fn build(&mut self, first: usize, count: usize) -> usize {
        let mut bounds = Bounds::empty();
        let mut centers = Bounds::empty();
        for t in &self.triangles[first..first + count] {
            for p in [t.a, t.b, t.c] {
                bounds.grow(p);
            }
            centers.grow((t.a + t.b + t.c) / 3.0);
        }
        let index = self.nodes.len();
        if count <= LEAF_SIZE {
            self.nodes.push(Node::Leaf {
                bounds,
                first,
                count,
            });
            return index;
        }
        let extent = centers.max - centers.min;
        let axis = if extent.x >= extent.y && extent.x >= extent.z {
            0
        } else if extent.y >= extent.z {
            1
        } else {
            2
        };
        let key = |t: &Triangle| (t.a + t.b + t.c)[axis];
        self.triangles[first..first + count].sort_by(|x, y| key(x).total_cmp(&key(y)));
        self.nodes.push(Node::Leaf {
            bounds,
            first,
            count,
        });
        let half = count / 2;
        let left = self.build(first, half);
        let right = self.build(first + half, count - half);
        self.nodes[index] = Node::Inner {
            bounds,
            left,
            right,
        };
        index
    }

    /// Whether anything blocks the segment from `origin` along `direction` (unit) up to `t_max`.
    pub fn occluded(&self, origin: DVec3, direction: DVec3, t_max: f64) -> bool {
        if self.nodes.is_empty() {
            return false;
        }
        let inverse = DVec3::ONE / direction;
        // The nodes still to visit: a median split halves the triangles per level, so the
        // depth (and this stack, one entry per level plus one) stays far below 64.
        let mut stack = [0usize; 64];
        let mut depth = 1;
        while depth > 0 {
            depth -= 1;
            let index = stack[depth];
            match &self.nodes[index] {
                Node::Leaf {
                    bounds,
                    first,
                    count,
                } => {
                    if !bounds.hit(origin, inverse, t_max) {
                        continue;
                    }
                    for t in &self.triangles[*first..first + count] {
                        if intersect(t, origin, direction, t_max) {
                            return true;
                        }
                    }
                }
                Node::Inner {
                    bounds,
                    left,
                    right,
                } => {
                    if bounds.hit(origin, inverse, t_max) {
                        stack[depth] = *left;
                        stack[depth + 1] = *right;
                        depth += 2;
                    }
                }
            }
        }
        false
    }
}

/// Möller-Trumbore, two-sided.
pub fn intersect(t: &Triangle, origin: DVec3, direction: DVec3, t_max: f64) -> bool {
    let e1 = t.b - t.a;
    let e2 = t.c - t.a;
    let p = direction.cross(e2);
    let det = e1.dot(p);
    if det.abs() < 1e-18 {
        return false;
    }
    let inv = 1.0 / det;
    let s = origin - t.a;
    let u = s.dot(p) * inv;
    if !(0.0..=1.0).contains(&u) {
        return false;
    }
    let q = s.cross(e1);
    let v = direction.dot(q) * inv;
    if v < 0.0 || u + v > 1.0 {
        return false;
    }
    let distance = e2.dot(q) * inv;
    distance > 0.0 && distance < t_max
}

/// GPU shadow term against ray-cast visibility, for one light.
#[derive(Clone, Debug, serde::Serialize)]
pub struct VisibilityError {
    /// The light.
    pub light: usize,
    /// Covered pixels facing the light (N.L > 0): the ones a shadow can change.
    pub lit_surface_pixels: usize,
    /// Of those, pixels whose GPU term (> 0.5 = lit) disagrees with the ray cast.
    pub misclassified: usize,
    /// `misclassified / lit_surface_pixels`.
    pub fraction: f64,
    /// Pixels the ray cast finds in shadow.
    pub shadowed_by_reference: usize,
    /// Misclassified pixels the GPU lights but the ray cast finds shadowed (light leaks,
    /// peter-panning).
    pub false_lit: usize,
}

/// The G-buffer targets the ray cast reads (`mask_1` only where the plan has it).
const CAST_INPUTS: [TargetId; 4] = [
    TargetId::GBuffer(GBufferTarget::Position),
    TargetId::GBuffer(GBufferTarget::Normal),
    TargetId::Mask(0),
    TargetId::Mask(1),
];

/// The targets [`visibility_error`] reads for `light`, of those `plan` has: what a render
/// for it needs to read back (with [`engine::renderer::Readback::Needed`], nothing else runs).
pub fn visibility_targets(plan: &plan::RenderPlan, light: usize) -> Vec<TargetId> {
    std::iter::once(TargetId::ShadowTerm { light })
        .chain(CAST_INPUTS)
        .filter(|id| plan.target(*id).is_some())
        .collect()
}

/// Compares the frame's `shadow_term_<light>` with ray-cast visibility. `epsilon` (meters) moves
/// each ray's origin off its surface along the normal.
pub fn visibility_error(
    scene: &Scene,
    frame: &Frame,
    light: usize,
    epsilon: f64,
) -> Result<VisibilityError, ReferenceError> {
    RayCastVisibility::cast(scene, frame, light, epsilon)?.error(frame)
}

/// The frame's G-buffer inputs of the ray cast: position, normal, mask and the second mask.
struct GbufferInputs<'a> {
    position: &'a [f32],
    normal: &'a [f32],
    mask: &'a [u8],
    mask_1: Option<&'a [u8]>,
}

impl<'a> GbufferInputs<'a> {
    fn of(frame: &'a Frame) -> Result<Self, ReferenceError> {
        let float = |target: TargetId| {
            frame
                .output(target)
                .and_then(|i| i.as_f32())
                .ok_or(ReferenceError::no_float(target))
        };
        let [position, normal, mask, mask_1] = CAST_INPUTS;
        Ok(Self {
            position: float(position)?,
            normal: float(normal)?,
            mask: frame.output(mask).and_then(|i| i.as_u8()).ok_or(
                ReferenceError::MissingOutput {
                    target: mask,
                    storage: "8-bit",
                },
            )?,
            mask_1: frame.output(mask_1).and_then(|i| i.as_u8()),
        })
    }
}

/// Exact visibility of one light from every covered, light-facing pixel of a frame's G-buffer,
/// by ray casting: what [`visibility_error`] compares a shadow term with. Frames whose
/// G-buffer is the same (a sweep over shadow settings changes no geometry) share one cast.
pub struct RayCastVisibility {
    light: usize,
    /// The G-buffer cast from: [`CAST_INPUTS`], each where the frame had it.
    gbuffer: Vec<Option<Image>>,
    /// Per pixel: `None` off the lit surface (uncovered, or facing away from the light), else
    /// whether the light is visible.
    visible: Vec<Option<bool>>,
}

impl RayCastVisibility {
    /// Casts a ray to `light` from each covered pixel of `frame`'s G-buffer that faces it,
    /// `epsilon` (meters) off its surface along the normal.
    pub fn cast(
        scene: &Scene,
        frame: &Frame,
        light: usize,
        epsilon: f64,
    ) -> Result<Self, ReferenceError> {
        let inputs = GbufferInputs::of(frame)?;
        let occluders = Occluders::new(scene);
        let camera = scene.camera.position;
        let light_data = scene
            .lights
            .get(light)
            .ok_or_else(|| ReferenceError::SceneLacks {
                scene: scene.name.clone(),
                what: format!("light {light}"),
            })?;
        let (position, normal, mask) = (inputs.position, inputs.normal, inputs.mask);
        let visible = (0..position.len() / 4)
            .map(|i| {
                let covered = mask[i * 4..i * 4 + 4].iter().any(|&m| m > 127)
                    || inputs
                        .mask_1
                        .is_some_and(|m| m[i * 4..i * 4 + 4].iter().any(|&v| v > 127));
                if !covered {
                    return None;
                }
                let p = DVec3::new(
                    position[i * 4] as f64,
                    position[i * 4 + 1] as f64,
                    position[i * 4 + 2] as f64,
                );
                let n = DVec3::new(
                    normal[i * 4] as f64,
                    normal[i * 4 + 1] as f64,
                    normal[i * 4 + 2] as f64,
                )
                .normalize_or_zero();
                let (direction, distance) = match light_data {
                    Light::Directional { direction, .. } => (direction.normalize(), f64::INFINITY),
                    Light::Point { position, .. } => {
                        let to_light = *position - camera - p;
                        (to_light.normalize_or_zero(), to_light.length())
                    }
                };
                if n.dot(direction) <= 0.0 {
                    return None;
                }
                Some(!occluders.occluded(p + n * epsilon, direction, distance))
            })
            .collect();
        Ok(Self {
            light,
            gbuffer: CAST_INPUTS.map(|id| frame.output(id).cloned()).into(),
            visible,
        })
    }

    /// Whether `frame`'s G-buffer is the one this cast came from, so that it holds for `frame`.
    pub fn holds_for(&self, frame: &Frame) -> bool {
        CAST_INPUTS
            .iter()
            .zip(&self.gbuffer)
            .all(|(id, own)| match (own, frame.output(*id)) {
                (Some(own), Some(theirs)) => bitwise_equal(own, theirs),
                (own, theirs) => own.is_none() && theirs.is_none(),
            })
    }

    /// `frame`'s shadow term of this light against the cast (the frame must have the same
    /// G-buffer: see [`RayCastVisibility::holds_for`]).
    pub fn error(&self, frame: &Frame) -> Result<VisibilityError, ReferenceError> {
        let name = TargetId::ShadowTerm { light: self.light };
        let term = frame
            .output(name)
            .and_then(|i| i.as_f32())
            .ok_or(ReferenceError::no_float(name))?;
        if term.len() != self.visible.len() * 4 {
            return Err(ReferenceError::SizeMismatch {
                target: name,
                output: term.len() / 4,
                reference: self.visible.len(),
            });
        }
        let (mut lit_surface, mut wrong, mut shadowed, mut false_lit) = (0, 0, 0, 0);
        for (i, visible) in self.visible.iter().enumerate() {
            let Some(visible) = *visible else {
                continue;
            };
            lit_surface += 1;
            if !visible {
                shadowed += 1;
            }
            if (term[i * 4] > 0.5) != visible {
                wrong += 1;
                if !visible {
                    false_lit += 1;
                }
            }
        }
        Ok(VisibilityError {
            light: self.light,
            lit_surface_pixels: lit_surface,
            misclassified: wrong,
            fraction: wrong as f64 / lit_surface.max(1) as f64,
            shadowed_by_reference: shadowed,
            false_lit,
        })
    }
}

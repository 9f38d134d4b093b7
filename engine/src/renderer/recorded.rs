//! A frame recorded once and submitted many times, whole or one plan pass at a time: what the
//! harness's speed checks time. A pass submitted alone, right before its floor, sees the same
//! machine state as the floor, and each sample costs that pass only, not a frame's setup and
//! uploads.

use crate::backend::*;
use crate::plan::{PassId, RenderPlan};

use super::{record, PassTimes, PreparedFrame, Recorded, RenderError, SlowPass};

/// A frame's resources and render passes, kept alive between submissions. Destroy it with
/// [`RecordedFrame::destroy`]; its resources are the backend's until then.
pub struct RecordedFrame {
    scene: String,
    scope: ResourceScope,
    passes: Vec<RenderPass>,
    owners: Vec<PassId>,
    /// A [`SlowPass`]'s pass and its render passes without the injected copies.
    unslowed: Option<(PassId, Vec<RenderPass>)>,
}

impl RecordedFrame {
    /// Uploads the frame's resources and records its passes (with its variations: a
    /// [`SlowPass`] is in the passes recorded). Nothing is submitted yet.
    pub fn record(
        backend: &mut dyn Backend,
        prepared: &PreparedFrame,
    ) -> Result<Self, RenderError> {
        let scene = prepared.scene().name.clone();
        let mut scope = ResourceScope::default();
        match record(backend, prepared, &mut scope) {
            Ok(Recorded {
                passes,
                owners,
                unslowed,
                ..
            }) => Ok(Self {
                unslowed,
                scene,
                scope,
                passes,
                owners,
            }),
            Err(e) => {
                scope.destroy(backend);
                Err(named(&scene, e))
            }
        }
    }

    /// Submits every pass in plan order, as a render does: their times.
    pub fn submit(&self, backend: &mut dyn Backend) -> Result<PassTimes, RenderError> {
        let timings = backend
            .submit(&self.passes)
            .map_err(|e| named(&self.scene, e.into()))?;
        Ok(PassTimes {
            passes: timings,
            owners: self.owners.clone(),
        })
    }

    /// Submits plan pass `pass`'s render passes alone: its GPU ns (their sum; None when the
    /// frame has no such pass or the backend no timestamps). Its inputs hold what the last
    /// whole submission left in them; submit the frame once first.
    pub fn submit_pass(
        &self,
        backend: &mut dyn Backend,
        pass: PassId,
    ) -> Result<Option<f64>, RenderError> {
        // A plan pass records its render passes in a row (a slowed pass's copies right after
        // each of them), so they are one slice: nothing to clone between a pass and its floor.
        let Some(start) = self.owners.iter().position(|owner| *owner == pass) else {
            return Ok(None);
        };
        let count = self.owners[start..]
            .iter()
            .take_while(|owner| **owner == pass)
            .count();
        self.submit_timed(backend, &self.passes[start..start + count])
    }

    /// Submits `passes` (this frame's): their GPU ns summed (None without timestamps).
    fn submit_timed(
        &self,
        backend: &mut dyn Backend,
        passes: &[RenderPass],
    ) -> Result<Option<f64>, RenderError> {
        let timings = backend
            .submit(passes)
            .map_err(|e| named(&self.scene, e.into()))?;
        Ok(timings.iter().map(|t| t.gpu_ns).sum())
    }

    /// The pass a [`SlowPass`] slowed down in this frame, if any.
    pub fn slowed_pass(&self) -> Option<PassId> {
        self.unslowed.as_ref().map(|(pass, _)| *pass)
    }

    /// Submits a [`SlowPass`]'s pass ([`Self::slowed_pass`]) without its injected copies: its
    /// GPU ns (None without a slowed pass or timestamps). Timed in the same rounds as the slowed pass, it
    /// says what slowdown the copies delivered in this process: a copy that finds its inputs
    /// still in the caches costs less than the pass did.
    pub fn submit_unslowed(&self, backend: &mut dyn Backend) -> Result<Option<f64>, RenderError> {
        let Some((_, originals)) = &self.unslowed else {
            return Ok(None);
        };
        self.submit_timed(backend, originals)
    }

    /// Destroys the frame's resources.
    pub fn destroy(self, backend: &mut dyn Backend) {
        self.scope.destroy(backend);
    }
}

/// `e` with the scene's name filled in.
pub(super) fn named(scene: &str, e: RenderError) -> RenderError {
    match e {
        RenderError::Backend { source, .. } => RenderError::Backend {
            scene: scene.to_owned(),
            source,
        },
        RenderError::Shader { source, .. } => RenderError::Shader {
            scene: scene.to_owned(),
            source,
        },
        other => other,
    }
}

/// `passes` with `slow`'s extra copies of its pass's render passes right after each of them
/// (see [`SlowPass`]): a fractional copy's viewports are centred boxes of that fraction of
/// their area (a pass with none gets one in the target it writes first). Also the slowed
/// pass's render passes as they were, which the speed self-test times without the copies.
pub(super) fn slowed(
    plan: &RenderPlan,
    passes: Vec<RenderPass>,
    owners: Vec<PassId>,
    slow: SlowPass,
) -> (Vec<RenderPass>, Vec<PassId>, Vec<RenderPass>) {
    let copies = slow.extra_copies();
    let target_size = plan
        .passes
        .iter()
        .find(|p| p.id == slow.pass)
        .and_then(|p| p.writes.iter().find_map(|w| plan.target(*w)))
        .map(|t| (t.width as f32, t.height as f32));
    let mut out = Vec::with_capacity(passes.len() + copies.len());
    let mut out_owners = Vec::with_capacity(out.capacity());
    let mut originals = Vec::new();
    for (pass, owner) in passes.into_iter().zip(owners) {
        let extra: Vec<RenderPass> = if owner == slow.pass {
            originals.push(pass.clone());
            copies
                .iter()
                .map(|&fraction| partial_copy(&pass, fraction, target_size))
                .collect()
        } else {
            Vec::new()
        };
        out.push(pass);
        out_owners.push(owner);
        for copy in extra {
            out.push(copy);
            out_owners.push(owner);
        }
    }
    (out, out_owners, originals)
}

/// `pass` again, each viewport cut to a centred box of `fraction` of its area (the whole pass
/// at 1).
fn partial_copy(pass: &RenderPass, fraction: f32, target_size: Option<(f32, f32)>) -> RenderPass {
    let mut copy = pass.clone();
    if fraction >= 1.0 {
        return copy;
    }
    if copy.viewports.is_empty() {
        if let Some((width, height)) = target_size {
            copy.viewports.push(Viewport {
                x: 0.0,
                y: 0.0,
                width,
                height,
                min_depth: 0.0,
                max_depth: 1.0,
            });
        }
    }
    // A centred box of that fraction of the area: a full-screen pass reads its inputs where
    // its fragments are, and a scene's subject is framed in the middle (a top band might be
    // all sky, and cost nothing).
    let side = fraction.sqrt();
    for viewport in &mut copy.viewports {
        let (width, height) = (viewport.width * side, viewport.height * side);
        viewport.x += (viewport.width - width) / 2.0;
        viewport.y += (viewport.height - height) / 2.0;
        viewport.width = width.max(1.0);
        viewport.height = height.max(1.0);
    }
    copy
}

#[cfg(test)]
mod tests {
    use super::*;

    fn pass(name: &str, viewports: Vec<Viewport>) -> RenderPass {
        RenderPass {
            name: name.to_owned(),
            color_attachments: vec![],
            depth_attachment: None,
            viewports,
            draws: vec![],
        }
    }

    #[test]
    fn a_fractional_copy_cuts_each_viewport_to_a_centred_box_of_that_area() {
        let viewport = Viewport {
            x: 8.0,
            y: 16.0,
            width: 64.0,
            height: 32.0,
            min_depth: 0.0,
            max_depth: 1.0,
        };
        let quarter = partial_copy(&pass("face", vec![viewport; 2]), 0.25, None);
        assert!(quarter
            .viewports
            .iter()
            .all(|v| (v.x, v.y, v.width, v.height) == (24.0, 24.0, 32.0, 16.0)));
        let whole = partial_copy(&pass("face", vec![viewport]), 1.0, None);
        assert_eq!(whole.viewports, vec![viewport]);
        let full_target = partial_copy(&pass("tonemap", vec![]), 0.25, Some((100.0, 40.0)));
        assert_eq!(full_target.viewports.len(), 1);
        let v = full_target.viewports[0];
        assert_eq!((v.x, v.y, v.width, v.height), (25.0, 10.0, 50.0, 20.0));
    }

    /// A pass of several render passes (a point light's faces) slowed down: its copies follow
    /// each face, and the faces as they were come back beside them, for whole and fractional
    /// factors, without the other passes.
    #[test]
    fn the_originals_of_a_slowed_pass_are_its_render_passes_before_the_copies() {
        let plan = RenderPlan {
            scene: "s".to_owned(),
            width: 4,
            height: 4,
            targets: vec![],
            passes: vec![],
            mask_channels: vec![],
            lighting: vec![],
        };
        let passes = vec![
            pass("face 0", vec![]),
            pass("face 1", vec![]),
            pass("geometry", vec![]),
        ];
        let owners = vec![
            PassId::Shadow { light: 0 },
            PassId::Shadow { light: 0 },
            PassId::Geometry,
        ];
        for factor in [1.0, 1.5, 2.0, 3.25] {
            let slow = SlowPass {
                pass: PassId::Shadow { light: 0 },
                factor,
            };
            let (slowed_passes, _, originals) = slowed(&plan, passes.clone(), owners.clone(), slow);
            let names: Vec<String> = originals.into_iter().map(|p| p.name).collect();
            assert_eq!(names, ["face 0", "face 1"], "x{factor}");
            let copies = slow.extra_copies().len();
            assert_eq!(slowed_passes.len(), 3 + 2 * copies, "x{factor}");
        }
    }
}

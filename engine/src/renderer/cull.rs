//! The check of pass culling for [`Readback::Needed`](super::Readback::Needed): the renderer
//! culls by the plan's declared reads and writes
//! ([`RenderPlan::passes_needed_for`](crate::plan::RenderPlan::passes_needed_for)), and, where
//! debug assertions are on, checks that it keeps no pass the recorded passes themselves do not
//! need (an upper bound: a loaded depth attachment counts as written here).
//!
//! Here the dependencies come from the recorded passes: a pass writes its attachments, and
//! reads every texture its draws bind and every attachment it loads rather than clears (the
//! shader mask tests against the geometry pass's depth, the lighting passes add into the light
//! buffer). Walking back from the wanted targets, a pass is kept when it writes a target still
//! needed, and then what it reads is needed too. Every earlier writer of a needed target is
//! kept (also where a later one clears it), so the kept passes leave the wanted targets exactly
//! as the whole frame would.

use crate::backend::{BindingResource, Handle, LoadOp, RenderPass, Texture};

/// Which of `passes` (in their order) the `wanted` targets depend on.
pub(super) fn needed(passes: &[RenderPass], wanted: &[Handle<Texture>]) -> Vec<bool> {
    let mut needed: Vec<Handle<Texture>> = wanted.to_vec();
    let mut keep = vec![false; passes.len()];
    for (index, pass) in passes.iter().enumerate().rev() {
        if !writes(pass).any(|t| needed.contains(&t)) {
            continue;
        }
        keep[index] = true;
        for texture in reads(pass) {
            if !needed.contains(&texture) {
                needed.push(texture);
            }
        }
    }
    keep
}

/// The textures a pass renders to.
fn writes(pass: &RenderPass) -> impl Iterator<Item = Handle<Texture>> + '_ {
    let colors = pass.color_attachments.iter().map(|a| a.texture);
    colors.chain(pass.depth_attachment.map(|d| d.texture))
}

/// The textures a pass's draws sample, and the attachments it loads.
fn reads(pass: &RenderPass) -> impl Iterator<Item = Handle<Texture>> + '_ {
    let sampled = pass
        .draws
        .iter()
        .flat_map(|draw| &draw.bindings)
        .filter_map(|binding| match binding.resource {
            BindingResource::Texture(texture) => Some(texture),
            _ => None,
        });
    let loaded_colors = pass
        .color_attachments
        .iter()
        .filter(|a| a.load == LoadOp::Load)
        .map(|a| a.texture);
    let loaded_depth = pass
        .depth_attachment
        .filter(|d| d.load == LoadOp::Load)
        .map(|d| d.texture);
    sampled.chain(loaded_colors).chain(loaded_depth)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::backend::{
        Binding, ColorAttachment, DepthAttachment, Draw, Handle, LoadOp, Pipeline, Subresource,
    };

    fn texture(index: u32) -> Handle<Texture> {
        Handle::new(index, 0)
    }

    /// A pass named `name` writing `color` (loaded) and `depth` (`(texture, cleared)`), whose one
    /// draw samples `samples`.
    fn pass(name: &str, color: &[u32], depth: Option<(u32, bool)>, samples: &[u32]) -> RenderPass {
        RenderPass {
            name: name.to_owned(),
            color_attachments: color
                .iter()
                .map(|&t| ColorAttachment {
                    texture: texture(t),
                    subresource: Subresource::default(),
                    load: LoadOp::Load,
                })
                .collect(),
            depth_attachment: depth.map(|(t, cleared)| DepthAttachment {
                texture: texture(t),
                subresource: Subresource::default(),
                load: if cleared {
                    LoadOp::Clear(1.0)
                } else {
                    LoadOp::Load
                },
            }),
            viewports: vec![],
            draws: vec![Draw {
                pipeline: Handle::<Pipeline>::new(0, 0),
                bindings: samples
                    .iter()
                    .enumerate()
                    .map(|(slot, &t)| Binding {
                        binding: slot as u32,
                        resource: BindingResource::Texture(texture(t)),
                    })
                    .collect(),
                vertex_buffers: vec![],
                index_buffer: None,
                count: 3,
            }],
        }
    }

    /// shadow map 1; G-buffer 2 with depth 3; mask 4 (depth-tested against 3, loaded); skybox
    /// and lighting into light 5 (lighting reads 1, 2, 4; routed through depth 6, cleared);
    /// shadow term 7 (reads 1, 2, 4); tone mapping into final 8 (reads 5).
    fn frame() -> Vec<RenderPass> {
        vec![
            pass("shadow", &[], Some((1, true)), &[]),
            pass("geometry", &[2], Some((3, true)), &[]),
            pass("mask", &[4], Some((3, false)), &[]),
            pass("skybox", &[5], None, &[4]),
            pass("lighting", &[5], Some((6, true)), &[1, 2, 4]),
            pass("shadow_term", &[7], None, &[1, 2, 4]),
            pass("tonemap", &[8], None, &[5]),
        ]
    }

    fn kept(wanted: &[u32]) -> Vec<String> {
        let wanted: Vec<_> = wanted.iter().map(|&t| texture(t)).collect();
        let passes = frame();
        let keep = needed(&passes, &wanted);
        passes
            .into_iter()
            .zip(keep)
            .filter_map(|(p, keep)| keep.then_some(p.name))
            .collect()
    }

    #[test]
    fn the_final_image_needs_every_pass_but_the_debug_output() {
        assert_eq!(
            kept(&[8]),
            ["shadow", "geometry", "mask", "skybox", "lighting", "tonemap"]
        );
    }

    #[test]
    fn a_gbuffer_target_needs_only_the_geometry_pass() {
        assert_eq!(kept(&[2]), ["geometry"]);
        assert_eq!(kept(&[3, 4]), ["geometry", "mask"]);
    }

    #[test]
    fn a_loaded_attachment_needs_its_writers() {
        // The mask alone: its pass loads the geometry pass's depth.
        assert_eq!(kept(&[4]), ["geometry", "mask"]);
    }

    #[test]
    fn a_shadow_term_skips_the_lighting_passes() {
        assert_eq!(
            kept(&[7, 2, 4]),
            ["shadow", "geometry", "mask", "shadow_term"]
        );
    }

    #[test]
    fn every_writer_of_a_needed_target_is_kept() {
        assert_eq!(
            kept(&[5]),
            ["shadow", "geometry", "mask", "skybox", "lighting"]
        );
        assert!(kept(&[]).is_empty());
    }
}

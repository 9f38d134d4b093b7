//! CPU reference of the screen-space ambient occlusion on two planes meeting at a right angle
//! ([`crate::test_scenes::corner`]): for each floor pixel of a frame, in f64,
//!
//! - the kernel's own answer against the exact geometry: the fraction of the pass's kernel
//!   points, placed as the shader places them, that lie inside the wall. It isolates what the
//!   screen-space test adds (depth read at a pixel's center, the margin, halo removal, points
//!   off screen);
//! - the closed form the kernel converges to: a kernel uniform in the hemisphere's volume sees
//!   the wall take [`corner_occlusion`] of it, which bounds what the finite kernel adds.

use engine::plan::{GBufferTarget, TargetId};
use engine::renderer::ambient_occlusion::{corner_occlusion, kernel, tangent_frame};
use engine::renderer::Frame;
use engine::scene::Scene;
use glam::DVec3;

use super::ReferenceError;

/// How far a frame's occlusion is from the references, over the floor pixels.
#[derive(Clone, Debug, PartialEq)]
pub struct OcclusionError {
    /// Floor pixels compared.
    pub pixels: usize,
    /// Mean |GPU - kernel on the exact geometry|.
    pub mean_vs_kernel: f64,
    /// 99th percentile of |GPU - kernel on the exact geometry|.
    pub p99_vs_kernel: f64,
    /// Largest |GPU - kernel on the exact geometry|, and the distance from the wall (m) of the
    /// floor point where it is.
    pub max_vs_kernel: (f64, f64),
    /// Largest |kernel on the exact geometry - closed form|: the finite kernel's error.
    pub max_kernel_vs_exact: f64,
    /// Largest |GPU - closed form|.
    pub max_vs_exact: f64,
}

/// Compares `frame`'s occlusion of `scene` (a [`crate::test_scenes::corner`]) with the
/// references, over the floor pixels more than an eighth of the image from its edges (kernel
/// points that project off screen count as unoccluded on the GPU and are counted here: the
/// margin keeps most of them out).
pub fn corner_error(
    scene: &Scene,
    frame: &Frame,
    wall_x: f64,
) -> Result<OcclusionError, ReferenceError> {
    let settings = scene
        .quality
        .ssao
        .ok_or_else(|| ReferenceError::SceneLacks {
            scene: scene.name.clone(),
            what: "[quality.ssao]".to_owned(),
        })?;
    let radius = f64::from(settings.radius);
    let read = |target: TargetId| {
        frame
            .output(target)
            .and_then(|image| image.as_f32())
            .ok_or(ReferenceError::no_float(target))
    };
    let occlusion = read(TargetId::AmbientOcclusion)?;
    let position = read(TargetId::GBuffer(GBufferTarget::Position))?;
    let normal = read(TargetId::GBuffer(GBufferTarget::Normal))?;
    let points = kernel(settings.samples);
    let frame_axes = tangent_frame(DVec3::Y);
    let (width, height) = (frame.plan.width as usize, frame.plan.height as usize);
    let margin = width / 8;
    let mut differences = Vec::new();
    let mut error = OcclusionError {
        pixels: 0,
        mean_vs_kernel: 0.0,
        p99_vs_kernel: 0.0,
        max_vs_kernel: (0.0, 0.0),
        max_kernel_vs_exact: 0.0,
        max_vs_exact: 0.0,
    };
    for y in margin..height - margin {
        for x in margin..width - margin {
            let i = (y * width + x) * 4;
            let world = DVec3::new(
                f64::from(position[i]),
                f64::from(position[i + 1]),
                f64::from(position[i + 2]),
            ) + scene.camera.position;
            let floor = f64::from(normal[i + 1]) > 0.99 && world.y.abs() < 0.01;
            if !floor {
                continue;
            }
            let inside = points
                .iter()
                .filter(|k| {
                    let [t, b, n] = frame_axes;
                    let q = world + (t * k.x + b * k.y + n * k.z) * radius;
                    q.x < wall_x
                })
                .count();
            let by_kernel = 1.0 - inside as f64 / points.len() as f64;
            let exact = 1.0 - corner_occlusion(world.x - wall_x, radius);
            let gpu = f64::from(occlusion[i]);
            let difference = (gpu - by_kernel).abs();
            error.pixels += 1;
            error.mean_vs_kernel += difference;
            differences.push(difference);
            if difference > error.max_vs_kernel.0 {
                error.max_vs_kernel = (difference, world.x - wall_x);
            }
            error.max_kernel_vs_exact = error.max_kernel_vs_exact.max((by_kernel - exact).abs());
            error.max_vs_exact = error.max_vs_exact.max((gpu - exact).abs());
        }
    }
    if error.pixels == 0 {
        return Err(ReferenceError::NoPixels("floor pixels"));
    }
    error.mean_vs_kernel /= error.pixels as f64;
    error.p99_vs_kernel = engine::stats::percentile(differences, 0.99).unwrap_or(0.0);
    Ok(error)
}

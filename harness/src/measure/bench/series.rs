//! The scaling series: how a frame's or a pass's cost grows with resolution, point lights,
//! triangles and shadow-map size.

use engine::backend::BackendKind;
use engine::plan::PassId;
use engine::scene::{LightingModel, Scene};

use super::timing::{median_frame_ms, median_pass_ms, prepare, time_frames};
use super::BenchError;

/// The PBR lighting pass, which the resolution and light series time.
const PBR: PassId = PassId::Lighting(LightingModel::Pbr);

/// A scaling series of `harness bench --series`.
#[derive(
    Clone, Copy, Debug, PartialEq, Eq, serde::Serialize, serde::Deserialize, clap::ValueEnum,
)]
#[serde(rename_all = "kebab-case")]
pub enum Series {
    /// Chess at 256..2048 pixels a side (the PBR lighting pass).
    Resolution,
    /// 1..256 point lights on a floor (the PBR lighting pass).
    Lights,
    /// Chess's meshes subdivided 1x..64x (the geometry pass).
    Triangles,
    /// Chess's sun with 512..4096 shadow maps (its shadow pass).
    ShadowMap,
}

impl Series {
    /// Every series.
    pub const ALL: [Series; 4] = [
        Series::Resolution,
        Series::Lights,
        Series::Triangles,
        Series::ShadowMap,
    ];

    /// Its name on the command line and in the JSON.
    pub fn name(self) -> &'static str {
        match self {
            Series::Resolution => "resolution",
            Series::Lights => "lights",
            Series::Triangles => "triangles",
            Series::ShadowMap => "shadow-map",
        }
    }
}

/// One point of a scaling series.
#[derive(Clone, Debug, serde::Serialize, serde::Deserialize)]
pub struct SeriesPoint {
    /// The series.
    pub series: Series,
    /// The value varied: pixels per side, point lights, triangles, or shadow-map texels per side.
    pub value: u64,
    /// The pass the series is about.
    pub pass: PassId,
    /// Its median GPU time, ms.
    pub pass_ms: Option<f64>,
    /// Median GPU time of the whole frame, ms.
    pub frame_ms: Option<f64>,
}

/// How a frame's cost grows: chess at 256..2048 pixels (frame, lighting), 1..256 point lights on
/// a floor (lighting), chess's meshes subdivided 1x..64x (geometry), chess's sun with 512..4096
/// shadow maps (shadow pass).
pub fn series(
    name: Series,
    kind: BackendKind,
    frames: usize,
    mut progress: impl FnMut(&str),
) -> Result<Vec<SeriesPoint>, BenchError> {
    let chess = || {
        crate::load_scene("chess")
            .map(|l| l.scene)
            .map_err(|e| BenchError::Render {
                scene: "chess".to_owned(),
                backend: kind,
                message: e.to_string(),
            })
    };
    let settings: Vec<(u64, Scene, PassId)> = match name {
        Series::Resolution => [256u32, 512, 1024, 2048]
            .into_iter()
            .map(|size| {
                let mut scene = chess()?;
                scene.quality.width = size;
                scene.quality.height = size;
                Ok((u64::from(size), scene, PBR))
            })
            .collect::<Result<_, BenchError>>()?,
        Series::Lights => [1usize, 8, 64, 256]
            .into_iter()
            .map(|n| (n as u64, crate::test_scenes::many_point_lights(512, n), PBR))
            .collect(),
        Series::Triangles => {
            let mut scene = chess()?;
            let mut points = Vec::new();
            for level in 0..4 {
                if level > 0 {
                    let mut subdivided = std::collections::HashMap::new();
                    for object in &mut scene.objects {
                        let key = std::sync::Arc::as_ptr(&object.mesh);
                        let mesh = subdivided
                            .entry(key)
                            .or_insert_with(|| std::sync::Arc::new(object.mesh.subdivided()))
                            .clone();
                        object.mesh = mesh;
                    }
                }
                let triangles: usize = scene.objects.iter().map(|o| o.mesh.triangle_count()).sum();
                points.push((triangles as u64, scene.clone(), PassId::Geometry));
            }
            points
        }
        Series::ShadowMap => [512u32, 1024, 2048, 4096]
            .into_iter()
            .map(|size| {
                let mut scene = chess()?;
                for light in &mut scene.lights {
                    if let engine::scene::Light::Directional {
                        shadow: Some(s), ..
                    } = light
                    {
                        s.map_size = size;
                    }
                }
                Ok((u64::from(size), scene, PassId::Shadow { light: 0 }))
            })
            .collect::<Result<_, BenchError>>()?,
    };
    let mut backend = crate::faults::create_backend(kind).map_err(|e| BenchError::Backend {
        backend: kind,
        message: e.to_string(),
    })?;
    let mut points = Vec::new();
    for (value, scene, pass) in settings {
        progress(&format!("{} {value}", name.name()));
        let prepared = prepare(&scene, kind)?;
        let (timings, _) = time_frames(backend.as_mut(), &prepared, frames.max(1))?;
        points.push(SeriesPoint {
            series: name,
            value,
            pass,
            pass_ms: median_pass_ms(&timings, pass),
            frame_ms: median_frame_ms(&timings),
        });
    }
    Ok(points)
}

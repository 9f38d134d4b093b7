//! The mutation self-test: proof that the tolerances are tight. Small known changes to a scene
//! (or to the renderer) must each fail at least one pass's tolerance against the goldens, while
//! unmodified renders on every backend pass.
//!
//! Mutations: light intensity x1.02, roughness +0.05 on one material (the first object whose
//! roughness is not a map), camera yaw 0.25 degrees, shadow bias x4, environment rotated 2
//! degrees, and one G-buffer channel swapped (albedo red and blue, injected into the geometry
//! pass through [`engine::renderer::Faults`]).

use engine::backend::{self, BackendKind};
use engine::renderer::{self, Faults, Readback};
use engine::scene::{Light, Scene};
use glam::DQuat;

use crate::golden::GoldenStore;
use crate::suite::{self, Case};

/// A known change.
#[derive(Clone, Copy, Debug, PartialEq, Eq, serde::Serialize)]
pub enum Mutation {
    /// Every light's intensity x1.02.
    LightIntensity,
    /// Roughness +0.05 on the first object whose roughness is a scalar.
    Roughness,
    /// Camera turned 0.25 degrees about its up axis.
    CameraYaw,
    /// Every shadow's constant and slope-scaled bias x4.
    ShadowBias,
    /// Environment rotated 2 degrees.
    EnvironmentRotation,
    /// Albedo red and blue swapped in the G-buffer.
    GbufferChannelSwap,
}

impl Mutation {
    /// Every mutation.
    pub const ALL: [Mutation; 6] = [
        Mutation::LightIntensity,
        Mutation::Roughness,
        Mutation::CameraYaw,
        Mutation::ShadowBias,
        Mutation::EnvironmentRotation,
        Mutation::GbufferChannelSwap,
    ];

    /// Short description.
    pub fn describe(self) -> &'static str {
        match self {
            Mutation::LightIntensity => "light intensity x1.02",
            Mutation::Roughness => "roughness +0.05 on one material",
            Mutation::CameraYaw => "camera yaw 0.25 deg",
            Mutation::ShadowBias => "shadow bias x4",
            Mutation::EnvironmentRotation => "environment rotated 2 deg",
            Mutation::GbufferChannelSwap => "G-buffer albedo R<->B swapped",
        }
    }

    /// Applies the mutation; `None` when the scene has nothing it could change (no lights, no
    /// environment, no shadow-casting light, ...).
    pub fn apply(self, scene: &Scene) -> Option<(Scene, Faults)> {
        let mut s = scene.clone();
        let mut faults = Faults::default();
        match self {
            Mutation::LightIntensity => {
                if s.lights.is_empty() {
                    return None;
                }
                for light in &mut s.lights {
                    match light {
                        Light::Directional { intensity, .. } | Light::Point { intensity, .. } => {
                            *intensity *= 1.02
                        }
                    }
                }
            }
            Mutation::Roughness => {
                let object = s
                    .objects
                    .iter_mut()
                    .find(|o| o.material.roughness_map.is_none())?;
                object.material.roughness = (object.material.roughness + 0.05).min(1.0);
            }
            Mutation::CameraYaw => {
                let c = &mut s.camera;
                let rotation = DQuat::from_axis_angle(c.up.normalize(), 0.25f64.to_radians());
                c.target = c.position + rotation * (c.target - c.position);
            }
            Mutation::ShadowBias => {
                let mut any = false;
                for light in &mut s.lights {
                    match light {
                        Light::Directional { shadow, .. } | Light::Point { shadow, .. } => {
                            if let Some(shadow) = shadow {
                                shadow.bias *= 4.0;
                                shadow.slope_bias *= 4.0;
                                any = true;
                            }
                        }
                    }
                }
                if !any {
                    return None;
                }
            }
            Mutation::EnvironmentRotation => {
                s.environment.as_mut()?.rotation_degrees += 2.0;
            }
            Mutation::GbufferChannelSwap => faults.swap_albedo_red_blue = true,
        }
        Some((s, faults))
    }
}

/// What one mutation did to one scene.
#[derive(Clone, Debug, serde::Serialize)]
pub struct Detection {
    /// Scene.
    pub scene: String,
    /// Mutation.
    pub mutation: Mutation,
    /// `None`: not applicable to this scene; otherwise the passes whose tolerance failed.
    pub failed_passes: Option<Vec<String>>,
}

/// The self-test's findings.
#[derive(Clone, Debug, serde::Serialize)]
pub struct SelfTest {
    /// Unmodified renders that failed: (scene, backend, pass or error).
    pub false_alarms: Vec<(String, String, String)>,
    /// Per scene and mutation.
    pub detections: Vec<Detection>,
}

impl SelfTest {
    /// Mutations that no scene detected (and that applied to some scene).
    pub fn undetected(&self) -> Vec<Mutation> {
        Mutation::ALL
            .into_iter()
            .filter(|m| {
                !self.detections.iter().any(|d| {
                    d.mutation == *m && d.failed_passes.as_ref().is_some_and(|p| !p.is_empty())
                })
            })
            .collect()
    }

    /// A table: one row per mutation, one column per scene.
    pub fn table(&self) -> String {
        let mut scenes: Vec<&str> = self.detections.iter().map(|d| d.scene.as_str()).collect();
        scenes.dedup();
        let mut out = format!("{:<32}", "mutation");
        for s in &scenes {
            out.push_str(&format!(" {s:<28}"));
        }
        out.push('\n');
        for m in Mutation::ALL {
            out.push_str(&format!("{:<32}", m.describe()));
            for s in &scenes {
                let cell = self
                    .detections
                    .iter()
                    .find(|d| d.mutation == m && d.scene == *s)
                    .map_or("-".to_owned(), |d| match &d.failed_passes {
                        None => "n/a".to_owned(),
                        Some(p) if p.is_empty() => "MISSED".to_owned(),
                        Some(p) => p.join(","),
                    });
                out.push_str(&format!(" {cell:<28}"));
            }
            out.push('\n');
        }
        out
    }
}

fn failed_passes(
    store: &GoldenStore,
    case: &Case,
    kind: BackendKind,
    scene: &Scene,
    faults: &Faults,
) -> Result<Vec<String>, String> {
    let mut backend = backend::create(kind).map_err(|e| e.to_string())?;
    let wanted: Vec<&str> = case.passes.iter().map(String::as_str).collect();
    let frame =
        renderer::render_with_faults(backend.as_mut(), scene, Readback::Only(&wanted), faults)
            .map_err(|e| e.to_string())?;
    Ok(case
        .passes
        .iter()
        .filter(|pass| {
            !suite::check_pass(store, case, pass, kind, &frame.outputs[pass.as_str()])
                .outcome
                .passed()
        })
        .cloned()
        .collect())
}

/// Runs the self-test: unmodified renders on `backends`, mutations on `mutation_backend`. Scenes
/// run in parallel, one thread each (each with its own backends).
pub fn run(
    cases: &[Case],
    store: &GoldenStore,
    backends: &[BackendKind],
    mutation_backend: BackendKind,
) -> SelfTest {
    let per_case: Vec<SelfTest> = std::thread::scope(|scope| {
        let handles: Vec<_> = cases
            .iter()
            .map(|case| scope.spawn(move || run_case(case, store, backends, mutation_backend)))
            .collect();
        handles
            .into_iter()
            .zip(cases)
            .map(|(handle, case)| {
                handle.join().unwrap_or_else(|_| SelfTest {
                    false_alarms: vec![(
                        case.name().to_owned(),
                        "-".to_owned(),
                        "self-test thread panicked".to_owned(),
                    )],
                    detections: vec![],
                })
            })
            .collect()
    });
    let mut result = SelfTest {
        false_alarms: vec![],
        detections: vec![],
    };
    for part in per_case {
        result.false_alarms.extend(part.false_alarms);
        result.detections.extend(part.detections);
    }
    result
}

fn run_case(
    case: &Case,
    store: &GoldenStore,
    backends: &[BackendKind],
    mutation_backend: BackendKind,
) -> SelfTest {
    let mut false_alarms = Vec::new();
    let mut detections = Vec::new();
    let scene = &case.loaded.scene;
    for &kind in backends {
        match failed_passes(store, case, kind, scene, &Faults::default()) {
            Ok(failed) => false_alarms.extend(
                failed
                    .into_iter()
                    .map(|p| (case.name().to_owned(), kind.name().to_owned(), p)),
            ),
            Err(e) => false_alarms.push((case.name().to_owned(), kind.name().to_owned(), e)),
        }
    }
    for mutation in Mutation::ALL {
        let failed = match mutation.apply(scene) {
            None => None,
            Some((mutated, faults)) => {
                match failed_passes(store, case, mutation_backend, &mutated, &faults) {
                    Ok(failed) => Some(failed),
                    Err(e) => {
                        false_alarms.push((
                            case.name().to_owned(),
                            mutation_backend.name().to_owned(),
                            format!("render of mutation `{}` failed: {e}", mutation.describe()),
                        ));
                        Some(Vec::new())
                    }
                }
            }
        };
        detections.push(Detection {
            scene: case.name().to_owned(),
            mutation,
            failed_passes: failed,
        });
    }
    SelfTest {
        false_alarms,
        detections,
    }
}

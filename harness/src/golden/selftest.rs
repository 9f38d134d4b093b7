//! The mutation self-test: proof of the golden tolerances from both sides.
//!
//! - Tight enough: each small known change ([`Mutation`]: a light 2% brighter, a material
//!   parameter moved by 0.05, the camera turned a quarter degree, an injected fault in one pass,
//!   ...) must fail in the pass where it originates ([`Mutation::origin`]: light changes in the
//!   light buffer, material changes in the G-buffer target holding them, shadow bias in the
//!   shadow term, geometry in depth, tone mapping in the final image) by at least
//!   [`MIN_MUTATION_RATIO`] times its limit, on every backend and in every scene it applies to.
//!   A suite whose only working rule were on the final image would tell the user *that*
//!   something changed, not *where*.
//! - Loose enough: an unchanged render under every noise source must stay at or below
//!   [`MAX_NOISE_RATIO`] of every limit: each backend and synthetic rounding, rendered by this
//!   run, and the sources `harness noise` recorded in golden/noise.toml (llvmpipe's CPU code
//!   paths, another Mesa, renders from other hosts).
//!
//! Faults that no scene parameter can express are injected through
//! [`engine::renderer::Faults`].

use std::collections::BTreeMap;

use engine::backend::{self, BackendKind};
use engine::plan;
use engine::renderer::{self, Faults, Readback};
use engine::scene::{Light, LightingModel, Material, Scene};
use engine::Image;
use glam::DQuat;

use crate::golden::noise::{NoiseModel, MAX_NOISE_RATIO, MIN_MUTATION_RATIO};
use crate::golden::portability;
use crate::golden::suite::{self, Case};
use crate::golden::{self, GoldenStore, Outcome};

/// A known change.
#[derive(Clone, Copy, Debug, PartialEq, Eq, PartialOrd, Ord, serde::Serialize)]
pub enum Mutation {
    /// Every light's intensity x1.02.
    LightIntensity,
    /// Exposure x1.03.
    Exposure,
    /// The first point light moved 1 cm along +X.
    PointLightMoved,
    /// Environment intensity x1.02.
    EnvironmentIntensity,
    /// Environment rotated 2 degrees.
    EnvironmentRotation,
    /// Every shadow's constant and slope-scaled bias x4.
    ShadowBias,
    /// Roughness ±0.05 (down where up would pass 1) on the first PBR object whose roughness is a
    /// scalar.
    Roughness,
    /// Metallic ±0.05 on the first PBR object whose metallic is a scalar.
    Metallic,
    /// Clearcoat ±0.05 on the first PBR object whose clearcoat is a scalar.
    Clearcoat,
    /// Specular ±0.05 on the first PBR object whose specular is a scalar.
    Specular,
    /// Base color x0.97 on the first PBR object whose base color is a scalar.
    BaseColor,
    /// Albedo red and blue swapped in the G-buffer (an injected fault).
    GbufferChannelSwap,
    /// Camera turned 0.25 degrees about its up axis.
    CameraYaw,
    /// The last object drawn with another lighting model (PBR <-> Lambert).
    LightingModel,
    /// The tone-mapping pass scales its input by 1.03 (an injected fault: the light buffer is
    /// untouched).
    ToneCurve,
}

impl Mutation {
    /// Every mutation.
    pub const ALL: [Mutation; 15] = [
        Mutation::LightIntensity,
        Mutation::Exposure,
        Mutation::PointLightMoved,
        Mutation::EnvironmentIntensity,
        Mutation::EnvironmentRotation,
        Mutation::ShadowBias,
        Mutation::Roughness,
        Mutation::Metallic,
        Mutation::Clearcoat,
        Mutation::Specular,
        Mutation::BaseColor,
        Mutation::GbufferChannelSwap,
        Mutation::CameraYaw,
        Mutation::LightingModel,
        Mutation::ToneCurve,
    ];

    /// Short description.
    pub fn describe(self) -> &'static str {
        match self {
            Mutation::LightIntensity => "light intensity x1.02",
            Mutation::Exposure => "exposure x1.03",
            Mutation::PointLightMoved => "point light moved 1 cm",
            Mutation::EnvironmentIntensity => "environment intensity x1.02",
            Mutation::EnvironmentRotation => "environment rotated 2 deg",
            Mutation::ShadowBias => "shadow bias x4",
            Mutation::Roughness => "roughness ±0.05 on one material",
            Mutation::Metallic => "metallic ±0.05 on one material",
            Mutation::Clearcoat => "clearcoat ±0.05 on one material",
            Mutation::Specular => "specular ±0.05 on one material",
            Mutation::BaseColor => "base color x0.97 on one material",
            Mutation::GbufferChannelSwap => "G-buffer albedo R<->B swapped",
            Mutation::CameraYaw => "camera yaw 0.25 deg",
            Mutation::LightingModel => "one object's lighting model",
            Mutation::ToneCurve => "tone-map input x1.03",
        }
    }

    /// The golden pass where the change first shows, and so must be caught: lighting changes in
    /// the light buffer, material changes in the G-buffer target that holds them, geometry in
    /// depth, the lighting model in the mask, tone mapping in the final image.
    pub fn origin(self) -> &'static str {
        match self {
            Mutation::LightIntensity
            | Mutation::Exposure
            | Mutation::PointLightMoved
            | Mutation::EnvironmentIntensity
            | Mutation::EnvironmentRotation
            | Mutation::ShadowBias => plan::LIGHT,
            Mutation::Roughness => "gbuffer_position",
            Mutation::Metallic | Mutation::Clearcoat => "gbuffer_material",
            Mutation::Specular => "gbuffer_normal",
            Mutation::BaseColor | Mutation::GbufferChannelSwap => "gbuffer_albedo",
            Mutation::CameraYaw => plan::DEPTH,
            Mutation::LightingModel => "mask",
            Mutation::ToneCurve => plan::FINAL,
        }
    }

    /// Applies the mutation; `None` when the scene has nothing it could change (no lights, no
    /// environment, no shadow-casting light, no scalar material parameter, ...).
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
            Mutation::Exposure => s.quality.exposure *= 1.03,
            Mutation::PointLightMoved => {
                let position = s.lights.iter_mut().find_map(|l| match l {
                    Light::Point { position, .. } => Some(position),
                    Light::Directional { .. } => None,
                })?;
                position.x += 0.01;
            }
            Mutation::EnvironmentIntensity => s.environment.as_mut()?.intensity *= 1.02,
            Mutation::EnvironmentRotation => {
                s.environment.as_mut()?.rotation_degrees += 2.0;
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
            Mutation::Roughness => {
                let m = scalar_material(&mut s, |m| m.roughness_map.is_none())?;
                m.roughness = nudge(m.roughness);
            }
            Mutation::Metallic => {
                let m = scalar_material(&mut s, |m| m.metallic_map.is_none())?;
                m.metallic = nudge(m.metallic);
            }
            Mutation::Clearcoat => {
                let m = scalar_material(&mut s, |m| m.clearcoat_map.is_none())?;
                m.clearcoat = nudge(m.clearcoat);
            }
            Mutation::Specular => {
                let m = scalar_material(&mut s, |m| m.specular_map.is_none())?;
                m.specular = nudge(m.specular);
            }
            Mutation::BaseColor => {
                let m = scalar_material(&mut s, |m| m.base_color_map.is_none())?;
                m.base_color = m.base_color.map(|c| c * 0.97);
            }
            Mutation::GbufferChannelSwap => faults.swap_albedo_red_blue = true,
            Mutation::CameraYaw => {
                let c = &mut s.camera;
                let rotation = DQuat::from_axis_angle(c.up.normalize(), 0.25f64.to_radians());
                c.target = c.position + rotation * (c.target - c.position);
            }
            Mutation::LightingModel => {
                let object = s.objects.last_mut()?;
                object.lighting = if object.lighting == LightingModel::Pbr {
                    LightingModel::Lambert
                } else {
                    LightingModel::Pbr
                };
            }
            Mutation::ToneCurve => faults.tonemap_input_scale = Some(1.03),
        }
        Some((s, faults))
    }
}

/// A 0..1 material parameter moved by 0.05: up, or down where up would leave the range.
fn nudge(value: f32) -> f32 {
    if value <= 0.95 {
        value + 0.05
    } else {
        value - 0.05
    }
}

/// The material of the first PBR object for which `scalar` holds (the parameter is not a map).
fn scalar_material(scene: &mut Scene, scalar: impl Fn(&Material) -> bool) -> Option<&mut Material> {
    scene
        .objects
        .iter_mut()
        .find(|o| o.lighting == LightingModel::Pbr && scalar(&o.material))
        .map(|o| &mut o.material)
}

/// One mutation rendered on one scene and backend.
#[derive(Clone, Debug, serde::Serialize)]
pub struct MutationResult {
    /// Scene.
    pub scene: String,
    /// Mutation.
    pub mutation: Mutation,
    /// Backend.
    pub backend: String,
    /// Whether the mutation applies to the scene (if not, nothing was rendered).
    pub applies: bool,
    /// `value / limit` of every golden pass's rule (see [`crate::golden::tolerance::Verdict::ratio`]).
    pub ratios: BTreeMap<String, f64>,
    /// Why the render failed, if it did.
    pub error: Option<String>,
}

impl MutationResult {
    /// The ratio in the pass where the mutation originates (the largest, for the shadow bias
    /// over the scene's shadow terms); `None` when that pass is not among the scene's goldens.
    pub fn origin_ratio(&self) -> Option<f64> {
        self.ratios
            .iter()
            .filter(|(pass, _)| self.mutation.is_origin(pass))
            .map(|(_, &r)| r)
            .fold(None, |m: Option<f64>, r| Some(m.map_or(r, |m| m.max(r))))
    }

    /// Other passes that failed (ratio above 1).
    pub fn also_failing(&self) -> Vec<&str> {
        self.ratios
            .iter()
            .filter(|(pass, &r)| r > 1.0 && !self.mutation.is_origin(pass))
            .map(|(pass, _)| pass.as_str())
            .collect()
    }
}

impl Mutation {
    /// Whether `pass` is where this mutation originates (any shadow term, for the shadow bias).
    pub fn is_origin(self, pass: &str) -> bool {
        match self {
            Mutation::ShadowBias => pass.starts_with("shadow_term_"),
            _ => pass == self.origin(),
        }
    }
}

/// An unchanged render under one noise source, against the limits.
#[derive(Clone, Debug, serde::Serialize)]
pub struct NoiseResult {
    /// Source (`drivers`, `synthetic-rounding`, or one recorded in golden/noise.toml).
    pub source: String,
    /// Scene.
    pub scene: String,
    /// Backend (`-` where the source has none).
    pub backend: String,
    /// Pass.
    pub pass: String,
    /// `value / limit` of the pass's rule (for recorded figures, the worst check's).
    pub ratio: f64,
    /// Rendered by this run (rather than read from golden/noise.toml).
    pub live: bool,
}

/// The self-test's findings.
#[derive(Clone, Debug, serde::Serialize)]
pub struct SelfTest {
    /// Every mutation on every scene and backend.
    pub mutations: Vec<MutationResult>,
    /// Every unchanged render (live, and recorded in the noise model) against every limit.
    pub noise: Vec<NoiseResult>,
    /// Renders that failed.
    pub errors: Vec<String>,
}

impl SelfTest {
    /// Applicable mutations that do not fail in their originating pass by
    /// [`MIN_MUTATION_RATIO`] (or whose origin has no golden).
    pub fn weak_detections(&self) -> Vec<&MutationResult> {
        self.mutations
            .iter()
            .filter(|m| m.applies && m.origin_ratio().is_none_or(|r| r < MIN_MUTATION_RATIO))
            .collect()
    }

    /// Unchanged renders above [`MAX_NOISE_RATIO`] of a limit.
    pub fn noisy(&self) -> Vec<&NoiseResult> {
        self.noise
            .iter()
            .filter(|n| n.ratio > MAX_NOISE_RATIO)
            .collect()
    }

    /// Every mutation caught where it originates with its margin, every noise source within its
    /// bound, no failed render.
    pub fn passed(&self) -> bool {
        self.weak_detections().is_empty() && self.noisy().is_empty() && self.errors.is_empty()
    }

    fn backends(&self) -> Vec<String> {
        let mut backends: Vec<String> = Vec::new();
        for b in self
            .mutations
            .iter()
            .map(|m| &m.backend)
            .chain(self.noise.iter().map(|n| &n.backend))
        {
            if b != "-" && !backends.contains(b) {
                backends.push(b.clone());
            }
        }
        backends
    }

    /// The margin table: per mutation and scene, the originating pass's `value / limit` on
    /// every backend (at least [`MIN_MUTATION_RATIO`] to pass), and the other passes it failed.
    pub fn margin_table(&self) -> String {
        let backends = self.backends();
        let mut out = format!("{:<34} {:<7} {:<17}", "mutation", "scene", "origin pass");
        for b in &backends {
            out.push_str(&format!(" {b:>11}"));
        }
        out.push_str("  also failing\n");
        let mut keys: Vec<(Mutation, &str)> = self
            .mutations
            .iter()
            .map(|m| (m.mutation, m.scene.as_str()))
            .collect();
        keys.sort();
        keys.dedup();
        for (mutation, scene) in keys {
            let rows: Vec<&MutationResult> = self
                .mutations
                .iter()
                .filter(|m| m.mutation == mutation && m.scene == scene)
                .collect();
            out.push_str(&format!(
                "{:<34} {scene:<7} {:<17}",
                mutation.describe(),
                if mutation == Mutation::ShadowBias {
                    "shadow_term_*"
                } else {
                    mutation.origin()
                }
            ));
            if !rows.iter().any(|m| m.applies) {
                out.push_str(" n/a\n");
                continue;
            }
            let mut also: Vec<&str> = Vec::new();
            for b in &backends {
                let cell = match rows.iter().find(|m| &m.backend == b) {
                    None => "-".to_owned(),
                    Some(m) if m.error.is_some() => "ERROR".to_owned(),
                    Some(m) => {
                        for p in m.also_failing() {
                            if !also.contains(&p) {
                                also.push(p);
                            }
                        }
                        match m.origin_ratio() {
                            None => "no golden".to_owned(),
                            Some(r) if r < MIN_MUTATION_RATIO => format!("WEAK {}", ratio(r)),
                            Some(r) => ratio(r),
                        }
                    }
                };
                out.push_str(&format!(" {cell:>11}"));
            }
            out.push_str(&format!("  {}\n", also.join(",")));
        }
        out
    }

    /// The noise table: per source and scene, the worst `value / limit` over every pass on each
    /// backend (at most [`MAX_NOISE_RATIO`] to pass), with the pass it was in.
    pub fn noise_table(&self) -> String {
        let backends = self.backends();
        let mut out = format!("{:<28} {:<7}", "unchanged render, source", "scene");
        for b in backends.iter().chain(std::iter::once(&"-".to_owned())) {
            out.push_str(&format!(
                " {:>26}",
                if b == "-" { "(no backend)" } else { b }
            ));
        }
        out.push('\n');
        let mut keys: Vec<(&str, &str, bool)> = self
            .noise
            .iter()
            .map(|n| (n.source.as_str(), n.scene.as_str(), n.live))
            .collect();
        keys.sort_by_key(|k| (!k.2, k.0, k.1));
        keys.dedup();
        for (source, scene, live) in keys {
            let label = if live {
                format!("{source} (live)")
            } else {
                source.to_owned()
            };
            out.push_str(&format!("{label:<28} {scene:<7}"));
            for b in backends.iter().chain(std::iter::once(&"-".to_owned())) {
                let worst = self
                    .noise
                    .iter()
                    .filter(|n| n.source == source && n.scene == scene && &n.backend == b)
                    .max_by(|x, y| x.ratio.total_cmp(&y.ratio));
                let cell = worst.map_or("-".to_owned(), |n| {
                    if n.ratio == 0.0 {
                        return "0".to_owned();
                    }
                    format!(
                        "{}{} {}",
                        if n.ratio > MAX_NOISE_RATIO {
                            "HIGH "
                        } else {
                            ""
                        },
                        ratio(n.ratio),
                        n.pass
                    )
                });
                out.push_str(&format!(" {cell:>26}"));
            }
            out.push('\n');
        }
        out
    }
}

fn ratio(r: f64) -> String {
    if r >= 100.0 {
        format!("{r:.0}x")
    } else if r >= 10.0 {
        format!("{r:.1}x")
    } else {
        format!("{r:.2}x")
    }
}

/// Ratios of every golden pass of `outputs` against the goldens.
fn ratios(
    case: &Case,
    goldens: &BTreeMap<String, Option<Image>>,
    outputs: &BTreeMap<String, Image>,
) -> BTreeMap<String, f64> {
    let mut out = BTreeMap::new();
    for pass in &case.passes {
        let (Some(actual), Some(golden)) = (outputs.get(pass), goldens.get(pass)) else {
            continue;
        };
        let ratio = match golden::check(actual, golden.as_ref(), &case.rules[pass]) {
            Outcome::Passed(v) | Outcome::Failed(v) => v.ratio,
            Outcome::MissingGolden | Outcome::Incomparable(_) => f64::INFINITY,
        };
        out.insert(pass.clone(), ratio);
    }
    out
}

/// Runs the self-test on `backends`: every mutation and an unchanged render on each, synthetic
/// rounding of the reference backend's render, and the figures `model` recorded for the sources
/// this run does not produce (CPU code paths, another Mesa, recorded hosts). Scenes run in
/// parallel, one thread each, each with its own backends.
pub fn run(
    cases: &[Case],
    store: &GoldenStore,
    backends: &[BackendKind],
    model: &NoiseModel,
) -> SelfTest {
    let parts: Vec<SelfTest> = std::thread::scope(|scope| {
        let handles: Vec<_> = cases
            .iter()
            .map(|case| scope.spawn(move || run_case(case, store, backends, model)))
            .collect();
        handles
            .into_iter()
            .zip(cases)
            .map(|(handle, case)| {
                handle.join().unwrap_or_else(|_| SelfTest {
                    mutations: vec![],
                    noise: vec![],
                    errors: vec![format!("{}: self-test thread panicked", case.name())],
                })
            })
            .collect()
    });
    let mut result = SelfTest {
        mutations: vec![],
        noise: vec![],
        errors: vec![],
    };
    for part in parts {
        result.mutations.extend(part.mutations);
        result.noise.extend(part.noise);
        result.errors.extend(part.errors);
    }
    result
}

fn run_case(
    case: &Case,
    store: &GoldenStore,
    backends: &[BackendKind],
    model: &NoiseModel,
) -> SelfTest {
    let mut result = SelfTest {
        mutations: vec![],
        noise: vec![],
        errors: vec![],
    };
    let scene = &case.loaded.scene;
    let goldens: BTreeMap<String, Option<Image>> = case
        .passes
        .iter()
        .map(|pass| {
            let golden = store.load(case.name(), pass, case.is_eight_bit(pass));
            (pass.clone(), golden.ok().flatten())
        })
        .collect();
    let wanted: Vec<&str> = case.passes.iter().map(String::as_str).collect();
    let reference = backends
        .iter()
        .copied()
        .find(|&k| k == suite::REFERENCE_BACKEND)
        .or(backends.first().copied());
    for &kind in backends {
        let mut backend = match backend::create(kind) {
            Ok(backend) => backend,
            Err(e) => {
                result
                    .errors
                    .push(format!("{} on {kind}: {e}", case.name()));
                continue;
            }
        };
        let mut render = |scene: &Scene, faults: &Faults| {
            renderer::render_with_faults(backend.as_mut(), scene, Readback::Only(&wanted), faults)
                .map_err(|e| e.to_string())
        };
        match render(scene, &Faults::default()) {
            Ok(frame) => {
                for (pass, ratio) in ratios(case, &goldens, &frame.outputs) {
                    result.noise.push(NoiseResult {
                        source: "drivers".to_owned(),
                        scene: case.name().to_owned(),
                        backend: kind.name().to_owned(),
                        pass,
                        ratio,
                        live: true,
                    });
                }
                if Some(kind) == reference {
                    let synthetic = portability::synthetic_rounding(case, &frame.outputs);
                    for (pass, ratio) in ratios(case, &goldens, &synthetic) {
                        result.noise.push(NoiseResult {
                            source: "synthetic-rounding".to_owned(),
                            scene: case.name().to_owned(),
                            backend: "-".to_owned(),
                            pass,
                            ratio,
                            live: true,
                        });
                    }
                }
            }
            Err(e) => result
                .errors
                .push(format!("unchanged {} on {kind}: {e}", case.name())),
        }
        for mutation in Mutation::ALL {
            let mut entry = MutationResult {
                scene: case.name().to_owned(),
                mutation,
                backend: kind.name().to_owned(),
                applies: false,
                ratios: BTreeMap::new(),
                error: None,
            };
            if let Some((mutated, faults)) = mutation.apply(scene) {
                entry.applies = true;
                match render(&mutated, &faults) {
                    Ok(frame) => entry.ratios = ratios(case, &goldens, &frame.outputs),
                    Err(e) => {
                        result.errors.push(format!(
                            "{} on {kind} with `{}`: {e}",
                            case.name(),
                            mutation.describe()
                        ));
                        entry.error = Some(e);
                    }
                }
            }
            result.mutations.push(entry);
        }
    }
    // The sources this run does not produce, from the figures golden/noise.toml recorded.
    if let Some(passes) = model.scenes.get(case.name()) {
        for (pass, checks) in passes {
            let Some(rule) = case.rules.get(pass) else {
                continue;
            };
            for (metric, limit) in rule.checks() {
                let Some(figures) = checks.get(&metric.to_string()) else {
                    continue;
                };
                for (key, &value) in &figures.noise {
                    let (source, backend) = key.split_once('/').unwrap_or((key, "-"));
                    if source == "drivers" || source == "synthetic-rounding" {
                        continue;
                    }
                    result.noise.push(NoiseResult {
                        source: source.to_owned(),
                        scene: case.name().to_owned(),
                        backend: backend.to_owned(),
                        pass: pass.clone(),
                        ratio: crate::golden::tolerance::ratio(value, limit, false),
                        live: false,
                    });
                }
            }
        }
    }
    result
}

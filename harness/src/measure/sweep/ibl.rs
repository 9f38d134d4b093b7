//! The IBL sweep: the IBL precompute's settings one knob at a time, each timed (precompute
//! and lighting pass) and measured against the Monte Carlo reference per roughness.

use engine::backend::BackendKind;
use engine::renderer::{self, PreparedFrame, Readback};
use engine::scene::Scene;

use super::{lighting, pareto_front_n, pass_ms, stats, timing_rounds, SweepError};

/// One setting of the IBL sweep.
#[derive(Clone, Debug, serde::Serialize)]
pub struct IblSweepRow {
    /// What differs from the default settings.
    pub setting: String,
    /// The settings.
    pub settings: engine::ibl::IblSettings,
    /// CPU precompute of the maps without caches, seconds (the DFG table, shared by every
    /// setting, is computed once per process and not included); NaN with [`MapSource::Cached`].
    pub precompute_s: f64,
    /// Median GPU time of the lighting pass, ms.
    pub lighting_ms: Option<f64>,
    /// GPU memory of the prefiltered specular cube, every level (RGBA16F), MiB.
    pub specular_mib: f64,
    /// Error of the light buffer against the Monte Carlo reference, per roughness.
    pub by_roughness: Vec<crate::reference::ibl::RoughnessError>,
    /// Mean relative error over every reference pixel.
    pub mean_relative: f64,
    /// 99th percentile and maximum relative error over every reference pixel.
    pub p99_max_relative: (f64, f64),
    /// Mean and 95th-percentile relative error per material family (rows) and roughness
    /// (cells).
    pub by_family: Vec<crate::reference::ibl::FamilyRow>,
    /// Whether these are the default settings.
    pub is_default: bool,
    /// Whether no other setting has both a shorter precompute and a smaller mean error.
    pub pareto: bool,
}

/// The settings the IBL sweep visits: the default, then one knob changed at a time.
pub fn ibl_settings() -> Vec<(String, engine::ibl::IblSettings)> {
    use engine::ibl::{IblSettings, IrradianceMethod};
    let d = IblSettings::default();
    vec![
        ("default".to_owned(), d.clone()),
        (
            "64 samples".to_owned(),
            IblSettings {
                specular_samples: 64,
                ..d.clone()
            },
        ),
        (
            "1024 samples".to_owned(),
            IblSettings {
                specular_samples: 1024,
                ..d.clone()
            },
        ),
        (
            "specular 64".to_owned(),
            IblSettings {
                specular_size: 64,
                ..d.clone()
            },
        ),
        (
            "specular 256".to_owned(),
            IblSettings {
                specular_size: 256,
                ..d.clone()
            },
        ),
        (
            "sh9 irradiance".to_owned(),
            IblSettings {
                irradiance: IrradianceMethod::Sh9,
                ..d.clone()
            },
        ),
        (
            "fis 16".to_owned(),
            IblSettings {
                runtime_samples: 16,
                ..d.clone()
            },
        ),
        (
            "fis 64".to_owned(),
            IblSettings {
                runtime_samples: 64,
                ..d.clone()
            },
        ),
        (
            "fis 256".to_owned(),
            IblSettings {
                runtime_samples: 256,
                ..d.clone()
            },
        ),
        // The extracted sun without its shadow: the Monte Carlo reference, like the split sum,
        // sees the environment unoccluded, so a shadow one sphere casts on the next would count
        // as an error of the lighting (the shadow itself is tested in tests/integration/ibl.rs).
        (
            "sun".to_owned(),
            IblSettings {
                extract_sun: true,
                sun_shadow: false,
                ..d.clone()
            },
        ),
        (
            "sun + fis 64".to_owned(),
            IblSettings {
                extract_sun: true,
                sun_shadow: false,
                runtime_samples: 64,
                ..d.clone()
            },
        ),
        // Three suns extracted (interior.exr: its two lamps, of 11 and 16 texels, which carry a
        // third of its flux, and a bright patch of 105; sunset.exr has one sun, of 7 texels),
        // unshadowed like "sun", and the lobe sampled over a 256² specular cube: what the
        // samples alias is cut out of the maps and lit exactly. The most accurate setting: 5%
        // mean and 15% p95 in every cell under both shipped skies (docs/renderer.md).
        (
            BEST_SETTING.to_owned(),
            IblSettings {
                extract_sun: true,
                extracted_lights: 3,
                sun_shadow: false,
                runtime_samples: 256,
                specular_size: 256,
                ..d
            },
        ),
    ]
}

/// The name of the most accurate setting of [`ibl_settings`].
pub const BEST_SETTING: &str = "3 suns + fis 256 specular 256";

/// The cube sizes the timed sweep (`harness sweep --knob ibl`) adds to [`ibl_settings`]: what a
/// mirror's texel costs (a specular cube of 512² needs a source cube as large; "source 512"
/// separates the two). Not in the sweep tests' settings: each is a precompute of seconds.
pub fn ibl_size_settings() -> Vec<(String, engine::ibl::IblSettings)> {
    use engine::ibl::IblSettings;
    let d = IblSettings::default();
    vec![
        (
            "source 512".to_owned(),
            IblSettings {
                source_size: 512,
                ..d.clone()
            },
        ),
        (
            "specular 512".to_owned(),
            IblSettings {
                source_size: 512,
                specular_size: 512,
                ..d
            },
        ),
    ]
}

/// What the timed sweep adds for the specular IBL's candidates: other sample footprints (the
/// default reads once a sample's solid angle; Krivanek and Colbert read 4 times), Frostbite's
/// dominant direction for the split sum, the split sum's anisotropic taps (alone and with that
/// direction), samples on the anisotropic pixels only (alone and with that direction),
/// sampling over a 256² specular cube, whose level 0 the sharpest lobes still read, and three
/// suns extracted with Frostbite's direction and a few samples on the anisotropic pixels
/// (candidates for a cheaper default).
pub fn ibl_sampling_settings() -> Vec<(String, engine::ibl::IblSettings)> {
    let d = engine::ibl::IblSettings::default();
    let mut rows: Vec<_> = [64, 256]
        .into_iter()
        .flat_map(|samples| [(samples, -2), (samples, 2)])
        .filter_map(|(samples, log2)| {
            let footprint = engine::ibl::Footprint::from_log2(log2)?;
            Some((
                format!("fis {samples} footprint {footprint}"),
                engine::ibl::IblSettings {
                    runtime_samples: samples,
                    runtime_footprint: footprint,
                    ..d.clone()
                },
            ))
        })
        .collect();
    let frostbite = engine::ibl::DominantDirection::Frostbite;
    rows.push((
        "frostbite dominant".to_owned(),
        engine::ibl::IblSettings {
            dominant_direction: frostbite,
            ..d.clone()
        },
    ));
    rows.push((
        "frostbite + aniso fis 16".to_owned(),
        engine::ibl::IblSettings {
            dominant_direction: frostbite,
            anisotropic_samples: 16,
            ..d.clone()
        },
    ));
    let taps = engine::ibl::AnisotropicLookup::Taps;
    rows.push((
        "anisotropic taps".to_owned(),
        engine::ibl::IblSettings {
            anisotropic_lookup: taps,
            ..d.clone()
        },
    ));
    rows.push((
        "frostbite + anisotropic taps".to_owned(),
        engine::ibl::IblSettings {
            dominant_direction: frostbite,
            anisotropic_lookup: taps,
            ..d.clone()
        },
    ));
    for samples in [4, 8, 16] {
        rows.push((
            format!("aniso fis {samples}"),
            engine::ibl::IblSettings {
                anisotropic_samples: samples,
                ..d.clone()
            },
        ));
    }
    for samples in [256, 1024] {
        rows.push((
            format!("fis {samples} specular 256"),
            engine::ibl::IblSettings {
                runtime_samples: samples,
                specular_size: 256,
                ..d.clone()
            },
        ));
    }
    // Candidates for a cheaper default: the same suns with the split sum, Frostbite's lean and
    // a few samples on the anisotropic pixels only, at two footprints.
    for (samples, log2) in [(8, 0), (8, -2), (12, 0)] {
        let Some(footprint) = engine::ibl::Footprint::from_log2(log2) else {
            continue;
        };
        rows.push((
            format!("3 suns + frostbite + aniso fis {samples} footprint {footprint}"),
            engine::ibl::IblSettings {
                extract_sun: true,
                extracted_lights: 3,
                sun_shadow: false,
                dominant_direction: frostbite,
                anisotropic_samples: samples,
                runtime_footprint: footprint,
                ..d.clone()
            },
        ));
    }
    rows
}

/// GPU memory of the prefiltered specular cube of `settings`: six RGBA16F faces per level, from
/// `specular_size` down to 4 x 4, MiB.
pub fn specular_mib(settings: &engine::ibl::IblSettings) -> f64 {
    let mut size = u64::from(settings.specular_size);
    let mut bytes = 0u64;
    while size >= 4 {
        bytes += 6 * size * size * 8;
        size /= 2;
    }
    bytes as f64 / f64::from(1u32 << 20)
}

/// Reference pixels and directions per strategy of the IBL sweep's Monte Carlo reference.
pub const IBL_REFERENCE_PIXELS: usize = 576;
/// Directions per strategy and pixel (three or four strategies).
pub const IBL_REFERENCE_SAMPLES: usize = 4096;

/// Where the IBL sweep's maps come from.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum MapSource {
    /// Built for the sweep without caches and timed: the precompute column and the Pareto
    /// front (the `harness sweep` command).
    Timed,
    /// From the IBL caches (memory, then disk) like any render, built only where missing, and
    /// not timed: `precompute_s` is NaN and no row is on a front. For checking errors, where
    /// the cost of the precompute is not what is measured (the sweep tests).
    Cached,
}

/// Runs the IBL sweep on one backend: per setting, the precompute time, the lighting pass's GPU
/// time (median of `repeats` rounds over every setting in turn) and the error against the
/// Monte Carlo reference per roughness. The reference is computed once, from the default
/// render's G-buffer (the G-buffer does not depend on IBL settings).
///
/// `choice` narrows the settings visited and adds settings of the user's own; the default, the
/// baseline of every lighting time, is always visited.
pub fn ibl_sweep(
    scene: &Scene,
    kind: BackendKind,
    repeats: usize,
    choice: &IblSweepChoice,
    progress: impl FnMut(&str),
) -> Result<Vec<IblSweepRow>, SweepError> {
    sweep_settings(
        scene,
        kind,
        repeats,
        MapSource::Timed,
        choice.settings(),
        progress,
    )
}

/// Which settings `harness sweep --knob ibl` visits besides the default.
#[derive(Clone, Debug, Default)]
pub struct IblSweepChoice {
    /// Only the built-in settings whose names contain one of these (every one when both this
    /// and `tried` are empty; none when only `tried` is given).
    pub only: Vec<String>,
    /// Settings of the user's own, each named by its text.
    pub tried: Vec<(String, engine::ibl::IblSettings)>,
}

impl IblSweepChoice {
    /// The settings visited, in order: the default and the built-in settings chosen, then the
    /// tried ones.
    pub fn settings(&self) -> Vec<(String, engine::ibl::IblSettings)> {
        let mut settings = ibl_settings();
        settings.extend(ibl_size_settings());
        settings.extend(ibl_sampling_settings());
        if !self.only.is_empty() || !self.tried.is_empty() {
            let default = engine::ibl::IblSettings::default();
            settings.retain(|(name, s)| {
                *s == default || self.only.iter().any(|o| name.contains(o.as_str()))
            });
        }
        settings.extend(self.tried.iter().cloned());
        settings
    }
}

/// Parses a setting to try: the keys of a scene file's `[quality.ibl]` table, comma-separated
/// as in a TOML inline table (`extract_sun = true, extracted_lights = 2`), the rest default.
pub fn parse_tried_setting(text: &str) -> Result<engine::ibl::IblSettings, String> {
    #[derive(serde::Deserialize)]
    struct Wrapper {
        ibl: engine::ibl::IblSettings,
    }
    let wrapper: Wrapper = toml::from_str(&format!("ibl = {{ {text} }}"))
        .map_err(|e| format!("not a [quality.ibl] setting: {}", e.message()))?;
    match wrapper.ibl.problem() {
        Some(problem) => Err(problem),
        None => Ok(wrapper.ibl),
    }
}

/// [`ibl_sweep`] with its maps from `maps`. With [`MapSource::Cached`] each setting renders
/// once, and its lighting time is that render's (`repeats` is not used).
pub fn ibl_sweep_with(
    scene: &Scene,
    kind: BackendKind,
    repeats: usize,
    maps: MapSource,
    progress: impl FnMut(&str),
) -> Result<Vec<IblSweepRow>, SweepError> {
    let settings = match maps {
        MapSource::Timed => IblSweepChoice::default().settings(),
        MapSource::Cached => ibl_settings(),
    };
    sweep_settings(scene, kind, repeats, maps, settings, progress)
}

/// [`ibl_sweep_with`] over `settings_list`.
fn sweep_settings(
    scene: &Scene,
    kind: BackendKind,
    repeats: usize,
    maps: MapSource,
    settings_list: Vec<(String, engine::ibl::IblSettings)>,
    mut progress: impl FnMut(&str),
) -> Result<Vec<IblSweepRow>, SweepError> {
    let environment = scene
        .environment
        .as_ref()
        .ok_or_else(|| SweepError::NoEnvironment(scene.name.clone()))?;
    let mut backend =
        crate::faults::create_backend(kind).map_err(|e| SweepError::Render(e.to_string()))?;
    let mut rows = Vec::new();
    let mut references = None;
    let mut built: Vec<(engine::ibl::cache::Key, f64)> = Vec::new();
    let mut prepared = Vec::new();
    for (name, settings) in settings_list {
        // Cached: the render below prepares its maps through the caches, as any render does.
        let precompute_s = match maps {
            MapSource::Cached => f64::NAN,
            MapSource::Timed => {
                progress(&format!("precompute {name}"));
                engine::ibl::dfg_table();
                // Timed, and kept in memory for the render below. Settings that change only
                // the render (the runtime samples) share an earlier setting's maps and its time.
                let key = engine::ibl::cache::key_of_shared(&environment.image, &settings);
                match built.iter().find(|(k, _)| *k == key) {
                    Some(&(_, seconds)) => seconds,
                    None => {
                        let (_, seconds) = engine::ibl::build_timed(&environment.image, &settings);
                        built.push((key, seconds));
                        seconds
                    }
                }
            }
        };
        let mut variant = scene.clone();
        variant.quality.ibl = settings.clone();
        let frame = PreparedFrame::new(&variant)?;
        let rendered = renderer::render_prepared(backend.as_mut(), &frame, Readback::All)?;
        if maps == MapSource::Timed {
            prepared.push(frame);
        }
        if references.is_none() {
            progress("Monte Carlo reference");
            references = Some(crate::reference::ibl::reference_pixels(
                scene,
                &rendered,
                IBL_REFERENCE_PIXELS,
                IBL_REFERENCE_SAMPLES,
            )?);
        }
        let references = references.as_deref().unwrap_or_default();
        let by_roughness = crate::reference::ibl::error_by_roughness(&rendered, references);
        let by_family = crate::reference::ibl::error_by_family(&rendered, references);
        let (_, p99, max) = stats(crate::reference::ibl::pixel_errors(&rendered, references));
        let total: usize = by_roughness.iter().map(|r| r.pixels).sum();
        let mean_relative = by_roughness
            .iter()
            .map(|r| r.mean_relative * r.pixels as f64)
            .sum::<f64>()
            / total.max(1) as f64;
        let is_default = settings == engine::ibl::IblSettings::default();
        let specular_mib = specular_mib(&settings);
        rows.push(IblSweepRow {
            setting: name,
            settings,
            precompute_s,
            lighting_ms: pass_ms(std::slice::from_ref(&rendered), lighting),
            specular_mib,
            by_roughness,
            mean_relative,
            p99_max_relative: (p99, max),
            by_family,
            is_default,
            pareto: false,
        });
    }
    if maps == MapSource::Cached {
        return Ok(rows);
    }
    // The lighting times: `repeats` rounds over every setting in turn.
    let rounds = timing_rounds(backend.as_mut(), &prepared, repeats, &mut progress)?;
    for (row, frames) in rows.iter_mut().zip(&rounds) {
        row.lighting_ms = pass_ms(frames, lighting);
    }
    // Two costs: the precompute (once per environment and settings) and the lighting pass (every
    // frame; the filtered importance sampling settings spend it there).
    let points: Vec<Vec<f64>> = rows
        .iter()
        .map(|r| {
            vec![
                r.precompute_s,
                r.lighting_ms.unwrap_or(f64::INFINITY),
                r.mean_relative,
            ]
        })
        .collect();
    for (row, on_front) in rows.iter_mut().zip(pareto_front_n(&points)) {
        row.pareto = on_front;
    }
    Ok(rows)
}

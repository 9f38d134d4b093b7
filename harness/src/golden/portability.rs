//! Measuring the noise model's figures: the sources of variation a user's machine can bring
//! (the three backends, llvmpipe's other CPU code paths, a second Mesa release, synthetic host
//! rounding, renders recorded on other hosts), the metrics of unchanged renders under each, and
//! the model ([`crate::golden::noise`]) built from them: the portability check behind
//! `harness noise` and `scripts/portability.sh`.
//!
//! Sources that change the driver's environment run `harness check --json` as a child process
//! per scene and backend, so a driver that aborts takes down one measurement, not the run.

use std::collections::BTreeMap;
use std::path::{Path, PathBuf};
use std::process::Command;

use engine::assets::linear_to_srgb_u8;
use engine::backend::BackendKind;
use engine::ibl::splitmix64;
use engine::scene::ToneMap;
use engine::{Image, ImageData};

use crate::golden::check::CheckRun;
use crate::golden::noise::{
    resolution, round_up, CheckFigures, NoiseModel, SceneFigures, MAX_NOISE_RATIO, REGENERATE,
};
use crate::golden::suite::Case;
use crate::golden::{self, GoldenStore, Outcome};

/// How a source changes a render.
#[derive(Clone, Debug, PartialEq)]
pub enum SourceKind {
    /// Renders in a child process with these environment variables set (the drivers as they
    /// are, when empty).
    Environment(Vec<(String, String)>),
    /// 8-bit outputs re-quantized from an f64 evaluation of the same tone mapping of the light
    /// buffer; float outputs moved by ±1 ulp of their storage (seeded, per value).
    SyntheticRounding,
    /// Outputs rendered on another host, kept in `golden/evidence/<name>/` as
    /// `<scene>_<pass>_<backend>.png|exr`.
    Recorded(PathBuf),
}

/// A source of variation between machines.
#[derive(Clone, Debug, PartialEq)]
pub struct Source {
    /// Name (`drivers`, `cpu-sse4.1`, `mesa-25.0.7`, `synthetic-rounding`, ...).
    pub name: String,
    /// What it is.
    pub description: String,
    /// How it changes a render.
    pub kind: SourceKind,
    /// Cheap enough for CI (a short run with no download).
    pub cheap: bool,
}

/// Where `scripts/mesa-backports.sh` installs the second Mesa.
pub fn mesa_backports_prefix() -> PathBuf {
    std::env::var_os("HARNESS_MESA_BACKPORTS")
        .map(PathBuf::from)
        .unwrap_or_else(|| crate::workspace_root().join("target/mesa-backports"))
}

/// The second Mesa's environment (from `<prefix>/env.list`, `KEY=value` lines) and version, or
/// why it is not there.
pub fn mesa_backports() -> Result<(String, Vec<(String, String)>), String> {
    let prefix = mesa_backports_prefix();
    let list = prefix.join("env.list");
    let text = std::fs::read_to_string(&list).map_err(|_| {
        format!(
            "no second Mesa at {} (install it with scripts/mesa-backports.sh)",
            prefix.display()
        )
    })?;
    let version = std::fs::read_to_string(prefix.join("version"))
        .unwrap_or_default()
        .trim()
        .to_owned();
    let vars = text
        .lines()
        .filter_map(|l| l.split_once('='))
        .map(|(k, v)| (k.trim().to_owned(), v.trim().to_owned()))
        .collect();
    Ok((version, vars))
}

fn env_source(name: &str, description: &str, vars: &[(&str, &str)], cheap: bool) -> Source {
    Source {
        name: name.to_owned(),
        description: description.to_owned(),
        kind: SourceKind::Environment(
            vars.iter()
                .map(|(k, v)| ((*k).to_owned(), (*v).to_owned()))
                .collect(),
        ),
        cheap,
    }
}

/// Every source: the ones this machine can produce (the second Mesa only once installed: `Err`
/// says how), and the recorded hosts in `golden/evidence/`.
pub fn sources(store: &GoldenStore) -> (Vec<Source>, Vec<(String, String)>) {
    // llvmpipe's and lavapipe's other code paths: (name, what, variable, value, cheap).
    let code_paths = [
        (
            "cpu-sse4.1",
            "llvmpipe/lavapipe limited to SSE4.1 code",
            "GALLIUM_OVERRIDE_CPU_CAPS",
            "sse4.1",
            true,
        ),
        (
            "cpu-avx",
            "llvmpipe/lavapipe limited to AVX code",
            "GALLIUM_OVERRIDE_CPU_CAPS",
            "avx",
            true,
        ),
        (
            "vector-128",
            "llvmpipe/lavapipe with 128-bit vectors",
            "LP_NATIVE_VECTOR_WIDTH",
            "128",
            false,
        ),
        (
            "threads-1",
            "llvmpipe/lavapipe rasterizing on one thread",
            "LP_NUM_THREADS",
            "1",
            false,
        ),
    ];
    let mut sources = vec![env_source(
        "drivers",
        "this machine's drivers as they are (every backend)",
        &[],
        true,
    )];
    for (name, description, key, value, cheap) in code_paths {
        sources.push(env_source(name, description, &[(key, value)], cheap));
    }
    let mut missing = Vec::new();
    match mesa_backports() {
        Ok((version, vars)) => {
            // The second Mesa alone and with each code path: a user's machine brings both at
            // once (a newer Mesa on a CPU without AVX2, say), and they add up.
            let short = version.split('-').next().unwrap_or(&version).to_owned();
            let mesa = format!("mesa-{short}");
            let description = format!("Mesa {version} from bookworm-backports, private prefix");
            sources.push(Source {
                name: mesa.clone(),
                description: description.clone(),
                kind: SourceKind::Environment(vars.clone()),
                cheap: false,
            });
            for (name, what, key, value, _) in code_paths {
                let mut combined = vars.clone();
                combined.push((key.to_owned(), value.to_owned()));
                sources.push(Source {
                    name: format!("{mesa}+{name}"),
                    description: format!("{description}; {what}"),
                    kind: SourceKind::Environment(combined),
                    cheap: false,
                });
            }
        }
        Err(why) => missing.push(("mesa-backports".to_owned(), why)),
    }
    sources.push(Source {
        name: "synthetic-rounding".to_owned(),
        description: "8-bit outputs re-quantized from an f64 tone mapping of the light buffer; \
                      float outputs moved by ±1 ulp of their storage"
            .to_owned(),
        kind: SourceKind::SyntheticRounding,
        cheap: true,
    });
    let evidence = store.root().join("evidence");
    if let Ok(entries) = std::fs::read_dir(&evidence) {
        let mut hosts: Vec<PathBuf> = entries
            .filter_map(|e| e.ok().map(|e| e.path()))
            .filter(|p| p.is_dir())
            .collect();
        hosts.sort();
        for dir in hosts {
            let name = dir
                .file_name()
                .map(|n| n.to_string_lossy().into_owned())
                .unwrap_or_default();
            let readme = std::fs::read_to_string(dir.join("README.md")).unwrap_or_default();
            let description = readme
                .lines()
                .find(|l| !l.trim().is_empty() && !l.starts_with('#'))
                .unwrap_or("renders recorded on another host")
                .to_owned();
            sources.push(Source {
                name,
                description,
                kind: SourceKind::Recorded(dir),
                cheap: true,
            });
        }
    }
    (sources, missing)
}

/// The sources named (every one when `names` is empty; `cheap` picks the quick ones), in the
/// order of `all`, or why a name matches none (`missing` says why a source is not here).
pub fn select(
    all: &[Source],
    missing: &[(String, String)],
    names: &[String],
) -> Result<Vec<Source>, String> {
    for name in names {
        if !all.iter().any(|s| &s.name == name || name == "cheap") {
            if let Some((_, why)) = missing
                .iter()
                .find(|(m, _)| name.starts_with("mesa") && m == "mesa-backports")
            {
                return Err(format!("source `{name}`: {why}"));
            }
            return Err(format!(
                "unknown source `{name}` (sources: {}, or cheap)",
                all.iter()
                    .map(|s| s.name.as_str())
                    .collect::<Vec<_>>()
                    .join(", ")
            ));
        }
    }
    Ok(all
        .iter()
        .filter(|s| {
            names.is_empty()
                || names
                    .iter()
                    .any(|n| *n == s.name || (n == "cheap" && s.cheap))
        })
        .cloned()
        .collect())
}

/// One measurement: a render of one scene under one source, every golden pass's checks.
#[derive(Clone, Debug, serde::Serialize)]
pub struct Measurement {
    /// Source name.
    pub source: String,
    /// Backend (`-` for synthetic rounding, which derives from the reference backend).
    pub backend: String,
    /// Scene.
    pub scene: String,
    /// Pass.
    pub pass: String,
    /// Metric (as printed) and its value.
    pub values: Vec<(String, f64)>,
}

/// A measurement that could not be made.
#[derive(Clone, Debug, serde::Serialize)]
pub struct Missed {
    /// Source name.
    pub source: String,
    /// Backend.
    pub backend: String,
    /// Scene.
    pub scene: String,
    /// What happened.
    pub error: String,
    /// A known driver crash (see [`known_driver_crash`]): reported, not a failure.
    pub known: bool,
}

/// Driver crashes that are not the harness's to fix, with the evidence. Measured here: lavapipe
/// with `LP_NATIVE_VECTOR_WIDTH=128` corrupts its heap and aborts (`malloc(): invalid next size`)
/// on valid draws whose vertex count is 1-4 modulo 8, such as the board's 4-vertex quads (Mesa
/// 22.3.6 always at 9-12 vertices, 25.0.7 similarly; the 256-bit default, llvmpipe, and
/// valgrind runs are clean). A scene without such draws renders (ibl), so a render that does
/// is measured; one that aborts is reported as this known crash.
pub fn known_driver_crash(source: &Source, backend: BackendKind) -> Option<String> {
    let SourceKind::Environment(vars) = &source.kind else {
        return None;
    };
    let vector_128 = vars
        .iter()
        .any(|(k, v)| k == "LP_NATIVE_VECTOR_WIDTH" && v == "128");
    (vector_128 && backend == BackendKind::WgpuVulkan).then(|| {
        "lavapipe with LP_NATIVE_VECTOR_WIDTH=128 aborts with heap corruption on draws of 1-4 \
         vertices modulo 8 (Mesa 22.3.6 and 25.0.7): a driver bug"
            .to_owned()
    })
}

fn values_of(outcome: &Outcome) -> Option<Vec<(String, f64)>> {
    match outcome {
        Outcome::Passed(v) | Outcome::Failed(v) => Some(
            v.checks
                .iter()
                .map(|c| (c.metric.clone(), c.value))
                .collect(),
        ),
        Outcome::MissingGolden | Outcome::Incomparable(_) => None,
    }
}

/// What measuring one source gave.
#[derive(Clone, Debug, Default, serde::Serialize)]
pub struct SourceRun {
    /// The measurements.
    pub measurements: Vec<Measurement>,
    /// What could not be measured.
    pub missed: Vec<Missed>,
    /// Driver fingerprint per backend, as the source saw it.
    pub drivers: BTreeMap<String, String>,
}

/// Measures an environment source: `harness check --json` (the binary `exe`) in a child process
/// per scene and backend.
pub fn measure_environment(
    exe: &Path,
    source: &Source,
    cases: &[Case],
    backends: &[BackendKind],
    mut progress: impl FnMut(&str),
) -> SourceRun {
    let SourceKind::Environment(vars) = &source.kind else {
        return SourceRun::default();
    };
    let mut measurements = Vec::new();
    let mut missed = Vec::new();
    let mut drivers = BTreeMap::new();
    for case in cases {
        for &backend in backends {
            progress(&format!("{} {} on {backend}", source.name, case.name()));
            let out = std::env::temp_dir().join(format!(
                "harness-noise-{}-{}",
                std::process::id(),
                source.name
            ));
            let output = Command::new(exe)
                .args(["check", "--json", "--scene"])
                .arg(&case.loaded.path)
                .args(["--backend", backend.name(), "--out"])
                .arg(&out)
                .envs(vars.iter().map(|(k, v)| (k, v)))
                .output();
            let _ = std::fs::remove_dir_all(&out);
            let mut miss = |error: String| {
                let known = known_driver_crash(source, backend);
                missed.push(Missed {
                    source: source.name.clone(),
                    backend: backend.name().to_owned(),
                    scene: case.name().to_owned(),
                    error: known.clone().unwrap_or(error),
                    known: known.is_some(),
                });
            };
            let output = match output {
                Ok(output) => output,
                Err(e) => {
                    miss(format!("cannot run {}: {e}", exe.display()));
                    continue;
                }
            };
            let run: CheckRun = match serde_json::from_slice(&output.stdout) {
                Ok(run) => run,
                Err(_) => {
                    let stderr = String::from_utf8_lossy(&output.stderr);
                    let tail: Vec<&str> = stderr
                        .lines()
                        .filter(|l| !l.contains("XDG_RUNTIME_DIR"))
                        .collect();
                    let tail = tail[tail.len().saturating_sub(3)..].join(" / ");
                    miss(format!("the check died ({}): {tail}", output.status));
                    continue;
                }
            };
            for (scene, b, error) in &run.render_errors {
                miss(format!("{scene} on {b}: {error}"));
            }
            for b in &run.backends {
                if let Some(fingerprint) = &b.fingerprint {
                    drivers.insert(b.backend.clone(), fingerprint.clone());
                }
            }
            for result in &run.results {
                if let Some(values) = values_of(&result.outcome) {
                    measurements.push(Measurement {
                        source: source.name.clone(),
                        backend: result.backend.clone(),
                        scene: result.scene.clone(),
                        pass: result.pass.clone(),
                        values,
                    });
                }
            }
        }
    }
    SourceRun {
        measurements,
        missed,
        drivers,
    }
}

/// Measures the checks of every golden pass of `outputs` against the goldens.
fn measure_outputs(
    store: &GoldenStore,
    case: &Case,
    source: &str,
    backend: &str,
    outputs: &BTreeMap<String, Image>,
) -> Vec<Measurement> {
    let mut measurements = Vec::new();
    for (pass, image) in outputs {
        let Some(rule) = case.rules.get(pass) else {
            continue;
        };
        let Ok(Some(golden)) = store.load(case.name(), pass, golden::is_eight_bit(image)) else {
            continue;
        };
        if let Some(values) = values_of(&golden::check(image, Some(&golden), rule)) {
            measurements.push(Measurement {
                source: source.to_owned(),
                backend: backend.to_owned(),
                scene: case.name().to_owned(),
                pass: pass.clone(),
                values,
            });
        }
    }
    measurements
}

/// Synthetic host rounding of a frame's golden outputs (see [`SourceKind::SyntheticRounding`]):
/// 8-bit outputs that are a tone mapping of the light buffer are re-quantized from an f64
/// evaluation of it; float outputs move by ±1 ulp of their storage. The mask (exact one-hot
/// values, no arithmetic to round) and outputs drawn over by gizmos are left out.
pub fn synthetic_rounding(
    case: &Case,
    outputs: &BTreeMap<String, Image>,
) -> BTreeMap<String, Image> {
    let quality = &case.loaded.scene.quality;
    let mut out = BTreeMap::new();
    for (seed, (pass, image)) in outputs.iter().enumerate() {
        match &image.data {
            ImageData::F32(_) => {
                out.insert(pass.clone(), ulp_noise(image, seed as u64));
            }
            ImageData::U8(_) if pass == engine::plan::FINAL && !quality.gizmos => {
                if let Some(light) = outputs.get(engine::plan::LIGHT) {
                    out.insert(pass.clone(), requantize_final(light, quality.tone_map));
                }
            }
            ImageData::U8(_) => {}
        }
    }
    out
}

/// The tone-mapping pass's curve, in f64 (engine/shaders/tonemap.wgsl).
pub fn tone_map(x: f64, operator: ToneMap) -> f64 {
    let x = x.max(0.0);
    match operator {
        ToneMap::Aces => (x * (2.51 * x + 0.03)) / (x * (2.43 * x + 0.59) + 0.14),
        ToneMap::Reinhard => x / (1.0 + x),
        ToneMap::Clamp => x,
    }
    .clamp(0.0, 1.0)
}

/// The final image as an exact f64 evaluation of the tone mapping and sRGB encoding of `light`,
/// rounded to 8 bits: where the GPU's f32 arithmetic lands near a rounding boundary, this rounds
/// the other way, as another host's would.
pub fn requantize_final(light: &Image, operator: ToneMap) -> Image {
    let values = light.as_f32().unwrap_or(&[]);
    let channels = light.channels();
    let mut data = Vec::with_capacity(light.width as usize * light.height as usize * 4);
    for pixel in values.chunks_exact(channels) {
        for c in 0..3 {
            let v = f64::from(pixel[c.min(channels - 1)]);
            data.push(linear_to_srgb_u8(tone_map(v, operator)));
        }
        data.push(255);
    }
    Image {
        width: light.width,
        height: light.height,
        format: engine::backend::TextureFormat::Rgba8UnormSrgb,
        data: ImageData::U8(data),
    }
}

/// Moves `x` by `steps` representable values of its storage: fp16 for RGBA16F outputs, f32
/// otherwise. Infinities and NaN stay as they are; zero moves to the smallest subnormal.
pub fn step_ulps(x: f32, steps: i32, fp16: bool) -> f32 {
    if !x.is_finite() {
        return x;
    }
    // Map the bits to integers that order like the values (negative values below zero).
    if fp16 {
        let bits = i32::from(half::f16::from_f32(x).to_bits());
        let ordered = if bits & 0x8000 != 0 {
            -(bits & 0x7fff)
        } else {
            bits
        };
        let moved = (ordered + steps).clamp(-0x7bff, 0x7bff);
        let bits = if moved < 0 { (-moved) | 0x8000 } else { moved };
        half::f16::from_bits(bits as u16).to_f32()
    } else {
        let bits = i64::from(x.to_bits());
        let ordered = if bits & 0x8000_0000 != 0 {
            -(bits & 0x7fff_ffff)
        } else {
            bits
        };
        let moved = (ordered + i64::from(steps)).clamp(-0x7f7f_ffff, 0x7f7f_ffff);
        let bits = if moved < 0 {
            (-moved) | 0x8000_0000
        } else {
            moved
        };
        f32::from_bits(bits as u32)
    }
}

/// Every value moved by -1, 0 or +1 ulp of its storage, chosen by a hash of `seed` and its index.
pub fn ulp_noise(image: &Image, seed: u64) -> Image {
    let fp16 = image.format == engine::backend::TextureFormat::Rgba16Float;
    let mut out = image.clone();
    if let ImageData::F32(values) = &mut out.data {
        for (i, v) in values.iter_mut().enumerate() {
            let step = (splitmix64(seed.wrapping_mul(0x1_0000_0001) ^ i as u64) % 3) as i32 - 1;
            *v = step_ulps(*v, step, fp16);
        }
    }
    out
}

/// Measures synthetic rounding of the reference backend's frame of `case`.
pub fn measure_synthetic(
    store: &GoldenStore,
    case: &Case,
    outputs: &BTreeMap<String, Image>,
    source: &str,
) -> Vec<Measurement> {
    measure_outputs(store, case, source, "-", &synthetic_rounding(case, outputs))
}

/// Measures renders recorded on another host: `<dir>/<scene>_<pass>_<backend>.png|exr`.
pub fn measure_recorded(
    store: &GoldenStore,
    case: &Case,
    source: &str,
    dir: &Path,
) -> (Vec<Measurement>, Vec<Missed>) {
    let mut measurements = Vec::new();
    let mut missed = Vec::new();
    for pass in &case.passes {
        for backend in BackendKind::ALL {
            let stem = format!("{}_{pass}_{}", case.name(), backend.name());
            for (extension, eight_bit) in [("png", true), ("exr", false)] {
                let path = dir.join(format!("{stem}.{extension}"));
                if !path.exists() {
                    continue;
                }
                let read = if eight_bit {
                    crate::images::read_png(&path)
                } else {
                    crate::images::read_exr(&path)
                };
                match read {
                    Ok(image) => {
                        let outputs = BTreeMap::from([(pass.clone(), image)]);
                        measurements.extend(measure_outputs(
                            store,
                            case,
                            source,
                            backend.name(),
                            &outputs,
                        ));
                    }
                    Err(e) => missed.push(Missed {
                        source: source.to_owned(),
                        backend: backend.name().to_owned(),
                        scene: case.name().to_owned(),
                        error: e.to_string(),
                        known: false,
                    }),
                }
            }
        }
    }
    (measurements, missed)
}

/// Measures `sources` on `cases`: environment sources through `exe` (the `harness` binary) on
/// `backends`, synthetic rounding from an in-process render on `reference`, recorded hosts from
/// their files. Returns one run per source, in order.
pub fn measure(
    exe: &Path,
    store: &GoldenStore,
    cases: &[Case],
    sources: &[Source],
    backends: &[BackendKind],
    reference: BackendKind,
    mut progress: impl FnMut(&str),
) -> Vec<(Source, SourceRun)> {
    let mut runs = Vec::new();
    for source in sources {
        let run = match &source.kind {
            SourceKind::Environment(_) => {
                measure_environment(exe, source, cases, backends, &mut progress)
            }
            SourceKind::SyntheticRounding => {
                let mut run = SourceRun::default();
                for case in cases {
                    progress(&format!("{} {} on {reference}", source.name, case.name()));
                    match case.render(reference) {
                        Ok(frame) => run.measurements.extend(measure_synthetic(
                            store,
                            case,
                            &frame.outputs,
                            &source.name,
                        )),
                        Err(error) => run.missed.push(Missed {
                            source: source.name.clone(),
                            backend: reference.name().to_owned(),
                            scene: case.name().to_owned(),
                            error,
                            known: false,
                        }),
                    }
                }
                run
            }
            SourceKind::Recorded(dir) => {
                let mut run = SourceRun::default();
                for case in cases {
                    let (measurements, missed) = measure_recorded(store, case, &source.name, dir);
                    run.measurements.extend(measurements);
                    run.missed.extend(missed);
                }
                run
            }
        };
        runs.push((source.clone(), run));
    }
    runs
}

/// A table of `ratios`: a row per scene, pass and metric, a numbered column per source holding
/// the worst `value / limit` over backends (`!` above [`MAX_NOISE_RATIO`], `X` above 1), then
/// the limit.
pub fn table(ratios: &[Ratio], sources: &[String]) -> String {
    // (scene, pass, metric) -> (limit, ratio per source).
    type Row = (f64, BTreeMap<String, f64>);
    let mut rows: BTreeMap<(String, String, String), Row> = BTreeMap::new();
    for r in ratios {
        let row = rows
            .entry((r.scene.clone(), r.pass.clone(), r.metric.clone()))
            .or_insert((r.limit, BTreeMap::new()));
        row.1.insert(r.source.clone(), r.ratio);
    }
    // Columns are numbered, with a legend above: source names are too long for a column.
    let mut out = String::from("sources:");
    for (i, s) in sources.iter().enumerate() {
        out.push_str(&format!(" [{}] {s}", i + 1));
    }
    out.push('\n');
    out.push_str(&format!("{:<8} {:<17} {:<44}", "scene", "pass", "metric"));
    for i in 0..sources.len() {
        out.push_str(&format!(" {:>7}", format!("[{}]", i + 1)));
    }
    out.push_str("  limit\n");
    for ((scene, pass, metric), (limit, cells)) in rows {
        out.push_str(&format!("{scene:<8} {pass:<17} {metric:<44}"));
        for s in sources {
            let cell = match cells.get(s) {
                None => "-".to_owned(),
                Some(&r) if r > 1.0 => format!("X{r:.2}"),
                Some(&r) if r > MAX_NOISE_RATIO => format!("!{r:.2}"),
                Some(&r) => format!("{r:.2}"),
            };
            out.push_str(&format!(" {cell:>7}"));
        }
        out.push_str(&format!("  {limit:.3e}\n"));
    }
    out.push_str(&format!(
        "cells: worst value / limit over backends; ! above {MAX_NOISE_RATIO}, X above 1 (fails)\n"
    ));
    out
}

/// The model the measurements give: per scene, pass and metric the largest value per
/// `<source>/<backend>`, and the limit `margin x max(noise, resolution)`. Scenes of `previous`
/// that were not measured are kept as they were.
pub fn build_model(
    cases: &[Case],
    measurements: &[Measurement],
    margin: f64,
    sources: BTreeMap<String, String>,
    missed: &[Missed],
    previous: &NoiseModel,
) -> NoiseModel {
    let mut model = NoiseModel {
        margin,
        regenerate: REGENERATE.to_owned(),
        sources,
        known_crashes: missed
            .iter()
            .filter(|m| m.known)
            .map(|m| {
                (
                    format!("{}/{}/{}", m.source, m.backend, m.scene),
                    m.error.clone(),
                )
            })
            .collect(),
        scenes: previous.scenes.clone(),
    };
    for case in cases {
        let mut passes = SceneFigures::new();
        for pass in &case.passes {
            let pixels = case.pixels(pass);
            let mut checks = BTreeMap::new();
            for (metric, _) in case.rules[pass].checks() {
                let key = metric.to_string();
                let mut noise = BTreeMap::new();
                for m in measurements
                    .iter()
                    .filter(|m| m.scene == case.name() && &m.pass == pass)
                {
                    if let Some((_, v)) = m.values.iter().find(|(k, _)| *k == key) {
                        let slot = noise
                            .entry(format!("{}/{}", m.source, m.backend))
                            .or_insert(0.0f64);
                        *slot = slot.max(*v);
                    }
                }
                let resolution = resolution(metric, pixels);
                let worst = noise.values().fold(0.0f64, |m, &v| m.max(v));
                checks.insert(
                    key,
                    CheckFigures {
                        limit: round_up(margin * worst.max(resolution)),
                        resolution,
                        noise,
                    },
                );
            }
            passes.insert(pass.clone(), checks);
        }
        model.scenes.insert(case.name().to_owned(), passes);
    }
    model
}

/// The worst `value / limit` of each `(source, scene, pass)` over backends and metrics, with the
/// limits of `cases`' rules.
pub fn ratios(cases: &[Case], measurements: &[Measurement]) -> Vec<Ratio> {
    let mut out: BTreeMap<(String, String, String, String), Ratio> = BTreeMap::new();
    for m in measurements {
        let Some(case) = cases.iter().find(|c| c.name() == m.scene) else {
            continue;
        };
        let Some(rule) = case.rules.get(&m.pass) else {
            continue;
        };
        for (metric, limit) in rule.checks() {
            let key = metric.to_string();
            let Some((_, value)) = m.values.iter().find(|(k, _)| *k == key) else {
                continue;
            };
            let ratio = crate::golden::tolerance::ratio(*value, limit, false);
            let entry = out
                .entry((
                    m.source.clone(),
                    m.scene.clone(),
                    m.pass.clone(),
                    key.clone(),
                ))
                .or_insert(Ratio {
                    source: m.source.clone(),
                    scene: m.scene.clone(),
                    pass: m.pass.clone(),
                    metric: key.clone(),
                    backend: m.backend.clone(),
                    value: *value,
                    limit,
                    ratio,
                });
            if ratio > entry.ratio {
                entry.ratio = ratio;
                entry.value = *value;
                entry.backend = m.backend.clone();
            }
        }
    }
    out.into_values().collect()
}

/// One source's worst measurement of one check against its limit.
#[derive(Clone, Debug, serde::Serialize)]
pub struct Ratio {
    /// Source.
    pub source: String,
    /// Scene.
    pub scene: String,
    /// Pass.
    pub pass: String,
    /// Metric, as printed.
    pub metric: String,
    /// The backend with the worst value.
    pub backend: String,
    /// The worst value.
    pub value: f64,
    /// The limit.
    pub limit: f64,
    /// value / limit.
    pub ratio: f64,
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn ulp_steps_move_by_one_representable_value() {
        for fp16 in [true, false] {
            for x in [0.0f32, 1.0, -1.0, 0.1, 123.4, -7e-3] {
                let up = step_ulps(x, 1, fp16);
                let down = step_ulps(x, -1, fp16);
                assert!(up > x && down < x, "{x}: {down} {up} (fp16 {fp16})");
                if fp16 {
                    let h = half::f16::from_f32(x).to_f32();
                    assert_eq!(step_ulps(up, -1, true), h, "{x}");
                    assert!(((up - h) / h.abs().max(1e-4)).abs() < 2e-3, "{x}: {up}");
                } else {
                    assert_eq!(step_ulps(up, -1, false), x);
                    if x > 0.0 {
                        assert_eq!(up, f32::from_bits(x.to_bits() + 1));
                    }
                }
            }
        }
        assert_eq!(step_ulps(0.0, 1, false), f32::from_bits(1));
        assert_eq!(step_ulps(0.0, -1, false), -f32::from_bits(1));
        assert!(step_ulps(f32::NAN, 1, true).is_nan());
        assert_eq!(step_ulps(65504.0, 1, true), 65504.0);
    }

    #[test]
    fn ulp_noise_is_seeded_and_moves_about_two_thirds_of_the_values() {
        let image = Image {
            width: 64,
            height: 64,
            format: engine::backend::TextureFormat::Rgba16Float,
            data: ImageData::F32(vec![0.75; 64 * 64 * 4]),
        };
        let a = ulp_noise(&image, 7);
        assert_eq!(a, ulp_noise(&image, 7));
        assert_ne!(a, ulp_noise(&image, 8));
        let values = a.as_f32().unwrap();
        let moved = values.iter().filter(|&&v| v != 0.75).count() as f64 / values.len() as f64;
        assert!((moved - 2.0 / 3.0).abs() < 0.03, "{moved}");
        assert!(values
            .iter()
            .all(|&v| ((v - 0.75) / 0.75).abs() <= 2f32.powi(-11) * 1.34));
    }

    #[test]
    fn requantized_final_follows_the_exact_curve() {
        // A gradient through the whole ACES range: the f64 evaluation rounds exactly.
        let n = 4096;
        let light = Image {
            width: n as u32,
            height: 1,
            format: engine::backend::TextureFormat::Rgba16Float,
            data: ImageData::F32((0..n).flat_map(|i| [i as f32 / 256.0; 4]).collect()),
        };
        let f = requantize_final(&light, ToneMap::Aces);
        let values = f.as_u8().unwrap();
        assert_eq!(values[0], 0);
        assert_eq!(values[(n - 1) * 4], 255);
        // Mid-grey 0.18 -> ACES 0.26690 -> sRGB 0.55346 -> 141.13 -> 141.
        assert!((tone_map(0.18, ToneMap::Aces) - 0.266_899).abs() < 1e-6);
        // sRGB 0.553457 x 255 = 141.13.
        assert_eq!(linear_to_srgb_u8(0.266_899), 141);
        let grey = requantize_final(
            &Image {
                width: 1,
                height: 1,
                format: engine::backend::TextureFormat::Rgba16Float,
                data: ImageData::F32(vec![0.18, 0.18, 0.18, 1.0]),
            },
            ToneMap::Aces,
        );
        // 0.18 in fp16 storage is 0.17993, still 141.
        assert_eq!(grey.as_u8().unwrap(), [141, 141, 141, 255]);
    }

    #[test]
    fn sources_are_selected_by_name_or_as_the_cheap_ones() {
        let store = GoldenStore::new(std::env::temp_dir().join("no-such-golden-folder"));
        let (all, missing) = sources(&store);
        let names = |picked: Vec<Source>| picked.into_iter().map(|s| s.name).collect::<Vec<_>>();
        assert_eq!(names(select(&all, &missing, &[]).unwrap()).len(), all.len());
        let cheap = names(select(&all, &missing, &["cheap".to_owned()]).unwrap());
        assert_eq!(
            cheap,
            ["drivers", "cpu-sse4.1", "cpu-avx", "synthetic-rounding"]
        );
        let one = select(
            &all,
            &missing,
            &["threads-1".to_owned(), "drivers".to_owned()],
        );
        assert_eq!(names(one.unwrap()), ["drivers", "threads-1"]);
        let err = select(&all, &missing, &["nope".to_owned()]).unwrap_err();
        assert!(err.contains("unknown source `nope`"), "{err}");
    }
}

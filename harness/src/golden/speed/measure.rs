//! Measuring the timing-noise model: unchanged builds probed under every source a user's
//! machine can bring, each pass's ratio as a factor of its golden.
//!
//! This host's sources ([`Tier::SameHost`]): repeated runs, and runs beside a busy neighbour
//! (a process spinning on one core, started and stopped here). Another host's
//! ([`Tier::OtherHost`]): llvmpipe's other CPU code paths and the second Mesa, each as a
//! child's environment. Each backend is measured against its own goldens, so the backends
//! are sources of each other's figures only as far as they share the model's passes.

use std::collections::BTreeMap;
use std::path::Path;

use engine::backend::BackendKind;
use engine::plan::PassId;

use super::{PassNoise, Tier, TimingGoldens, TimingNoise, CHECK_ROUNDS};

/// A source of timing variation.
#[derive(Clone, Debug, PartialEq)]
pub struct TimingSource {
    /// Name (`runs`, `busy-neighbour`, `cpu-sse4.1`, `mesa-25.0.7`, ...).
    pub name: String,
    /// What it is.
    pub description: String,
    /// Whose noise it is.
    pub tier: Tier,
    /// Environment of the probes.
    pub env: Vec<(String, String)>,
    /// Whether a busy neighbour spins on one core during its probes.
    pub busy: bool,
    /// Probes taken.
    pub probes: usize,
}

/// Probes of the plain runs: enough to reach the tail of a pass's spread (with 4, check runs of
/// the same build later came out up to x1.16 where the runs had seen x1.05).
pub const PLAIN_PROBES: usize = 12;

/// Every timing source this machine can produce, and those it cannot with why.
pub fn timing_sources() -> (Vec<TimingSource>, Vec<(String, String)>) {
    let source =
        |name: &str, description: &str, tier, env: &[(&str, &str)], busy, probes| TimingSource {
            name: name.to_owned(),
            description: description.to_owned(),
            tier,
            env: env
                .iter()
                .map(|(k, v)| ((*k).to_owned(), (*v).to_owned()))
                .collect(),
            busy,
            probes,
        };
    let mut sources = vec![
        source(
            "runs",
            "repeated probes of an unchanged build",
            Tier::SameHost,
            &[],
            false,
            PLAIN_PROBES,
        ),
        source(
            "busy-neighbour",
            "probes beside a process spinning on one core",
            Tier::SameHost,
            &[],
            true,
            4,
        ),
        source(
            "cpu-sse4.1",
            "llvmpipe/lavapipe limited to SSE4.1 code",
            Tier::OtherHost,
            &[("GALLIUM_OVERRIDE_CPU_CAPS", "sse4.1")],
            false,
            1,
        ),
        source(
            "cpu-avx",
            "llvmpipe/lavapipe limited to AVX code",
            Tier::OtherHost,
            &[("GALLIUM_OVERRIDE_CPU_CAPS", "avx")],
            false,
            1,
        ),
    ];
    let mut missing = Vec::new();
    match crate::golden::portability::mesa_backports() {
        Ok((version, vars)) => {
            let short = version.split('-').next().unwrap_or(&version).to_owned();
            sources.push(TimingSource {
                name: format!("mesa-{short}"),
                description: format!("Mesa {version} from bookworm-backports, private prefix"),
                tier: Tier::OtherHost,
                env: vars,
                busy: false,
                probes: 2,
            });
        }
        Err(why) => missing.push(("mesa".to_owned(), why)),
    }
    (sources, missing)
}

/// One pass's ratio under a source, as a factor of its golden.
#[derive(Clone, Debug, PartialEq, serde::Serialize)]
pub struct TimingMeasurement {
    /// Source name.
    pub source: String,
    /// Its tier.
    pub tier: Tier,
    /// Scene.
    pub scene: String,
    /// Backend.
    pub backend: BackendKind,
    /// Pass.
    pub pass: PassId,
    /// Largest ratio / golden over the source's probes.
    pub factor: f64,
}

/// A process spinning on one core while it lives: the busy neighbour.
pub struct BusyNeighbour(Option<std::process::Child>);

impl BusyNeighbour {
    /// Starts it (a warning when it cannot start: the probes then run without it).
    pub fn start() -> Self {
        let child = std::process::Command::new("sh")
            .args(["-c", "while :; do :; done"])
            .stdin(std::process::Stdio::null())
            .spawn();
        if let Err(e) = &child {
            eprintln!("warning: could not start the busy neighbour (sh): {e}");
        }
        Self(child.ok())
    }
}

impl Drop for BusyNeighbour {
    fn drop(&mut self) {
        if let Some(child) = &mut self.0 {
            let _ = child.kill();
            let _ = child.wait();
        }
    }
}

/// The timing goldens of `scenes` (name, argument) under `root`, by scene name, and an error
/// for each scene whose goldens could not be read.
pub fn load_goldens(
    root: &Path,
    scenes: &[(String, String)],
) -> (BTreeMap<String, TimingGoldens>, Vec<String>) {
    let mut goldens = BTreeMap::new();
    let mut errors = Vec::new();
    for (scene, _) in scenes {
        match TimingGoldens::load(root, scene) {
            Ok(g) => {
                goldens.insert(scene.clone(), g);
            }
            Err(e) => errors.push(e.to_string()),
        }
    }
    (goldens, errors)
}

/// Probes `scenes` (name, argument) on `backends` under each source, and each pass's largest
/// factor over its golden under `root`; with the probes that failed.
pub fn measure_timing(
    exe: &Path,
    root: &Path,
    scenes: &[(String, String)],
    backends: &[BackendKind],
    sources: &[TimingSource],
    mut progress: impl FnMut(&str),
) -> (Vec<TimingMeasurement>, Vec<String>) {
    let arguments: Vec<String> = scenes.iter().map(|(_, a)| a.clone()).collect();
    let (goldens, mut errors) = load_goldens(root, scenes);
    let mut worst: BTreeMap<(String, String, BackendKind, PassId), (Tier, f64)> = BTreeMap::new();
    for source in sources {
        for &kind in backends {
            for probe_index in 1..=source.probes {
                progress(&format!(
                    "{} on {kind}, probe {probe_index} of {}",
                    source.name, source.probes
                ));
                let _neighbour = source.busy.then(BusyNeighbour::start);
                let (probes, failed) = crate::measure::speed::probe_in_child(
                    exe,
                    &arguments,
                    &[kind],
                    CHECK_ROUNDS,
                    Default::default(),
                    &source.env,
                );
                errors.extend(failed.into_iter().map(|e| format!("{}: {e}", source.name)));
                for probe in probes {
                    let Some(golden) = goldens
                        .get(&probe.scene)
                        .and_then(|g| g.backends.get(&kind))
                    else {
                        continue;
                    };
                    for pass in &probe.passes {
                        let (Some(ratio), Some(g)) = (pass.ratio(), golden.passes.get(&pass.pass))
                        else {
                            continue;
                        };
                        if let Some(why) = targets_changed(&probe.scene, kind, pass, g) {
                            if !errors.contains(&why) {
                                errors.push(why);
                            }
                            continue;
                        }
                        let factor = ratio / g.ratio;
                        let key = (source.name.clone(), probe.scene.clone(), kind, pass.pass);
                        let entry = worst.entry(key).or_insert((source.tier, factor));
                        entry.1 = entry.1.max(factor);
                    }
                }
            }
        }
    }
    let measurements = worst
        .into_iter()
        .map(
            |((source, scene, backend, pass), (tier, factor))| TimingMeasurement {
                source,
                tier,
                scene,
                backend,
                pass,
                factor,
            },
        )
        .collect();
    (measurements, errors)
}

/// The model from `measurements`: per pass, the largest factor of each tier and where.
pub fn model_from(
    measurements: &[TimingMeasurement],
    sources: &[TimingSource],
    margin: f64,
) -> TimingNoise {
    let mut model = TimingNoise {
        margin,
        sources: sources
            .iter()
            .map(|s| (s.name.clone(), s.description.clone()))
            .collect(),
        ..TimingNoise::default()
    };
    for m in measurements {
        let entry = model
            .scenes
            .entry(m.scene.clone())
            .or_default()
            .entry(m.backend)
            .or_default()
            .entry(m.pass)
            .or_insert_with(|| PassNoise {
                host: 0.0,
                host_at: "-".to_owned(),
                drivers: 0.0,
                drivers_at: "-".to_owned(),
            });
        let (value, at) = match m.tier {
            Tier::SameHost => (&mut entry.host, &mut entry.host_at),
            Tier::OtherHost | Tier::RecordedHost | Tier::MovedHere => {
                (&mut entry.drivers, &mut entry.drivers_at)
            }
        };
        if m.factor > *value {
            *value = ceil4(m.factor);
            *at = m.source.clone();
        }
    }
    model
}

/// `model` with `measured`'s figures merged in: each pass's figure of each tier raised (with
/// where) where `measured` has a larger one, every other figure kept, and `measured`'s sources
/// added. What `noise --timing --source S --write` writes: one source measured again or a host
/// recorded, without probing the others.
pub fn merged(mut model: TimingNoise, measured: TimingNoise) -> TimingNoise {
    // What a new pass borrows is the model as it was, not a scene added by this merge.
    let before = model.clone();
    model.sources.extend(measured.sources);
    for (scene, backends) in measured.measured_on {
        model.measured_on.entry(scene).or_default().extend(backends);
    }
    for (scene, backends) in measured.scenes {
        for (backend, passes) in backends {
            for (pass, new) in passes {
                let known = model
                    .scenes
                    .get(&scene)
                    .and_then(|b| b.get(&backend))
                    .is_some_and(|p| p.contains_key(&pass));
                if !known {
                    let borrowed = before.figures(&scene, backend, pass).map(|(f, _)| f);
                    if let Some(first) = first_figures(new, borrowed) {
                        model
                            .scenes
                            .entry(scene.clone())
                            .or_default()
                            .entry(backend)
                            .or_default()
                            .insert(pass, first);
                    }
                    continue;
                }
                let old = model
                    .scenes
                    .entry(scene.clone())
                    .or_default()
                    .entry(backend)
                    .or_default()
                    .entry(pass)
                    .or_insert_with(|| new.clone());
                if new.host > old.host {
                    old.host = new.host;
                    old.host_at = new.host_at;
                }
                if new.drivers > old.drivers {
                    old.drivers = new.drivers;
                    old.drivers_at = new.drivers_at;
                }
            }
        }
    }
    model
}

/// The figures a pass new to the model starts with, from `new` (what this run measured, a
/// tier no source measured being a placeholder, `-`) and `borrowed` (what its checks read
/// until now: every scene's largest, [`TimingNoise::figures`]). No other host has recorded the
/// pass, so its figure for any host is at least the borrowed one; a tier this run did not
/// measure keeps the borrowed figure. `None` (the pass left out, its checks borrowing as
/// before) where a tier has neither: a placeholder is no figure, and a figure of 0 no limit.
fn first_figures(new: PassNoise, borrowed: Option<PassNoise>) -> Option<PassNoise> {
    let label = |at: &str| format!("{}, borrowed", at.trim_end_matches(", borrowed"));
    let (host, host_at) = match (&borrowed, new.host_at != "-") {
        (_, true) => (new.host, new.host_at),
        (Some(b), false) => (b.host, label(&b.host_at)),
        (None, false) => return None,
    };
    let measured = (new.drivers_at != "-").then_some((new.drivers, new.drivers_at));
    let (drivers, drivers_at) = match (measured, &borrowed) {
        (Some((d, at)), Some(b)) if d >= b.drivers => (d, at),
        (_, Some(b)) => (b.drivers, label(&b.drivers_at)),
        (Some((d, at)), None) => (d, at),
        (None, None) => return None,
    };
    Some(PassNoise {
        host,
        host_at,
        drivers,
        drivers_at,
    })
}

/// A full measurement (`measured`, every source of this run) laid over `old`: its passes
/// replace old's, a pass new to the model starting from what it borrowed from `old`
/// ([`first_figures`]: no other host has recorded it), and every scene, backend and pass it
/// did not measure keeps its figures. What `noise --timing --write` writes without `--source`.
pub fn remeasured(measured: TimingNoise, old: TimingNoise) -> TimingNoise {
    let mut model = measured;
    for (scene, backends) in &mut model.scenes {
        for (backend, passes) in backends.iter_mut() {
            let new: Vec<PassId> = passes
                .keys()
                .copied()
                .filter(|pass| {
                    old.scenes
                        .get(scene)
                        .and_then(|b| b.get(backend))
                        .is_none_or(|p| !p.contains_key(pass))
                })
                .collect();
            for pass in new {
                let measured = passes.remove(&pass).expect("listed above");
                let borrowed = old.figures(scene, *backend, pass).map(|(f, _)| f);
                if let Some(first) = first_figures(measured, borrowed) {
                    passes.insert(pass, first);
                }
            }
        }
    }
    for (scene, backends) in old.scenes {
        for (backend, passes) in backends {
            let kept = model
                .scenes
                .entry(scene.clone())
                .or_default()
                .entry(backend)
                .or_default();
            for (pass, figures) in passes {
                kept.entry(pass).or_insert(figures);
            }
        }
    }
    model.measured_on = old.measured_on;
    model
}

/// As [`merged`], except that the same-host figures of `moved` (scenes and backends whose
/// figures in `model` were measured on another host: goldens moved here) are replaced by
/// `measured`'s instead of raised: the other host's noise is not this one's.
pub fn merged_replacing(
    mut model: TimingNoise,
    measured: TimingNoise,
    moved: &[(String, BackendKind)],
) -> TimingNoise {
    for (scene, kind) in moved {
        let (Some(new), Some(old)) = (
            measured.scenes.get(scene).and_then(|b| b.get(kind)),
            model.scenes.get_mut(scene).and_then(|b| b.get_mut(kind)),
        ) else {
            continue;
        };
        // A placeholder (`-`: no same-host source measured the pass in this run) replaces
        // nothing.
        for (pass, figures) in new.iter().filter(|(_, f)| f.host_at != "-") {
            if let Some(old) = old.get_mut(pass) {
                old.host = figures.host;
                old.host_at = figures.host_at.clone();
            }
        }
    }
    merged(model, measured)
}

/// `x` rounded up to 4 decimals (the file stays readable, and no measurement lies above its
/// recorded figure).
pub fn ceil4(x: f64) -> f64 {
    (x * 1e4).ceil() / 1e4
}

/// Each measurement against the limit of its tier: `ln factor / ln limit` (at most 0.5 for
/// every source under a margin of 2).
pub fn scores(
    model: &TimingNoise,
    measurements: &[TimingMeasurement],
) -> Vec<(TimingMeasurement, f64, f64)> {
    measurements
        .iter()
        .filter_map(|m| {
            let (figures, _) = model.figures(&m.scene, m.backend, m.pass)?;
            let limit = model.limit(figures.noise(m.tier).0);
            Some((m.clone(), limit, m.factor.max(1.0).ln() / limit.ln()))
        })
        .collect()
}

/// The load on the kernel's CPUs: tasks running besides the reader, the median of `samples`
/// readings of `/proc/stat`'s `procs_running` (which counts the reading thread itself) a tenth
/// of a second apart, and the CPUs that count covers (its `cpuN` lines: in a container, the
/// host's, as `procs_running` is the host's). None where it cannot be read (not Linux).
pub fn machine_load(samples: usize) -> Option<(usize, usize)> {
    let cpus = std::fs::read_to_string("/proc/stat")
        .ok()?
        .lines()
        .filter(|l| {
            l.strip_prefix("cpu")
                .is_some_and(|n| n.starts_with(|c: char| c.is_ascii_digit()))
        })
        .count();
    let mut readings = Vec::with_capacity(samples);
    for i in 0..samples.max(1) {
        if i > 0 {
            std::thread::sleep(std::time::Duration::from_millis(100));
        }
        let stat = std::fs::read_to_string("/proc/stat").ok()?;
        let running = stat
            .lines()
            .find_map(|l| l.strip_prefix("procs_running "))?
            .trim()
            .parse::<usize>()
            .ok()?;
        readings.push(running.saturating_sub(1));
    }
    readings.sort_unstable();
    Some((readings[readings.len() / 2], cpus.max(1)))
}

/// Why a machine with `others` tasks running besides the measurement, on `cpus` CPUs, is too
/// busy to measure timing noise on (None: quiet enough). From half the CPUs busy: the probes
/// run one rasterizer thread, and the busy-neighbour source adds a spinning process itself,
/// so another load on top measures a host that is not this one at rest, and a figure taken
/// then stays (a pass's noise is its largest spread; a recording only adds probes).
pub fn too_busy(others: usize, cpus: usize) -> Option<String> {
    (others >= (cpus / 2).max(1)).then(|| {
        format!(
            "this machine is busy: {others} other task(s) running on its {cpus} CPU(s) (the \
             median of ten readings of /proc/stat's procs_running). Timing figures measured now \
             measure that load, and a pass's noise is its largest spread, kept for good: one \
             busy probe can leave it too noisy to time. Measure on a quiet machine (stop builds, \
             tests and other checks), or pass --busy-ok to measure anyway"
        )
    })
}

/// Why `pass`'s ratio (a probe of `scene` on `kind`) says nothing of the noise against its
/// golden `golden`: it writes other targets than when the golden was blessed, so the two ratios
/// do not compare (None where they do, or where either does not say).
pub fn targets_changed(
    scene: &str,
    kind: BackendKind,
    pass: &crate::measure::speed::PassSpeed,
    golden: &super::PassTiming,
) -> Option<String> {
    let (Some(then), Some(now)) = (&golden.targets, &pass.targets) else {
        return None;
    };
    (then != now).then(|| {
        format!(
            "{scene} {} on {kind}: it writes {now}, where its timing golden's pass wrote {then}: \
             bless its timing before measuring its noise",
            pass.pass
        )
    })
}

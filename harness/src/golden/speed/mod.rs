//! Speed goldens: a slower pass fails the suite like a changed pixel.
//!
//! Each canonical scene's `golden/<scene>/timing.toml` records, per backend and pass, the
//! pass's **speed ratio** from the speed probe ([`crate::measure::speed`]: the pass alone, its
//! fastest time over its floor's fastest, interleaved round by round), blessed with the images.
//! The milliseconds and the host are kept for information only; the ratio is what travels.
//!
//! `golden/timing-noise.toml` is the timing-noise model ([`TimingNoise`]), measured like the
//! image one by `harness noise --timing --write`: per pass, the largest factor by which an
//! unchanged build's ratio came out above its golden, under the sources of one host (repeated
//! runs, a busy neighbour on one core; each backend against its own goldens) and under the
//! sources of another host (llvmpipe's other CPU code paths, the second Mesa). A pass's limit is
//!
//! `limit = noise ^ margin`, i.e. `ln limit = margin x ln noise`,
//!
//! on the log scale, where slowdowns multiply; `noise` is at least [`MIN_NOISE`] (at least
//! [`MIN_NOISE_SHORT`] for a pass under [`SHORT_PASS_MS`]). A check is
//! scored as `ln(ratio / golden) / ln(limit)`: 1 at the limit, and unchanged runs under every
//! measured source at 1/margin or less. On a host whose driver fingerprint or CPU differs from
//! the one that blessed (every host, for goldens that keep no CPU signature), or where the
//! model's same-host figures were measured on another host (goldens moved with `bless
//! --speed-only --every-pass`, until `noise --timing --write` runs there), the other-host
//! figures count too (the CPU code paths, the second Mesa, and the
//! hosts recorded in `golden/evidence/`, [`recorded`]), and a pass whose limit there would not
//! catch a doubling is reported as untimed on that host, with the reason. A host that is itself
//! recorded there (the same fingerprint and [`cpu_signature`]) is checked against its own
//! recording instead: each pass's median recorded ratio, with a limit from that host's own
//! spread, since a ratio lands x0.4 to x1.7 away from the blessing host's on another CPU.
//!
//! The probe runs with llvmpipe/lavapipe on one rasterizer thread ([`PROBE_THREADS`]): the
//! ratio then does not depend on the host's core count, and a busy neighbour on a two-core
//! machine leaves the rasterizer a core of its own.

pub mod accept;
pub mod bless;
pub mod goldens;
pub mod history;
pub mod measure;
pub mod model;
pub mod recorded;
pub mod selftest;
pub mod verdict;

use engine::backend::BackendKind;

pub use bless::{
    bless_scenes, kept_as_another_hosts, median_probe, record_scaled_check, Fate, SpeedBlessed,
    TimingBless,
};
pub use goldens::{BackendTimings, PassTiming, Stamp, TimingGoldens, TIMING_FILE};
pub use model::{MeasuredOn, PassNoise, Tier, TimingNoise, TIMING_NOISE_FILE};
pub use verdict::{
    check_speed, check_speed_with, coverage, SpeedCheck, SpeedCoverage, SpeedOutcome,
};

/// The environment the speed probe runs under: one rasterizer thread.
pub const PROBE_THREADS: (&str, &str) = ("LP_NUM_THREADS", "1");
/// `ln limit = margin x ln noise`.
pub const DEFAULT_TIMING_MARGIN: f64 = 2.0;
/// The smallest noise factor a limit is derived from (x1.44 at a margin of 2): no finite set
/// of probes taken within minutes rules out the drift of the next hours. In 38 `check` runs of
/// one build over two hours on the host that blessed (quiet, beside a busy neighbour, under
/// Mesa 25 and the AVX code path, 2026-11-25), passes of 2 ms or more came out up to x1.27
/// above their goldens where the model's probes had seen x1.05 to x1.19; one run failed at
/// x1.27 against the x1.25 of a floor of 1.12.
pub const MIN_NOISE: f64 = 1.2;
/// Passes shorter than this (ms) are short: a few samples' worth of work, and timer and
/// start-up weigh more.
pub const SHORT_PASS_MS: f64 = 2.0;
/// The smallest noise factor of a short pass's limit (x1.69 at a margin of 2: a doubling is
/// still caught). In those runs, short passes came out up to x1.35 above their goldens
/// (corner's 0.6 ms tone mapping and mask).
pub const MIN_NOISE_SHORT: f64 = 1.3;
/// The smallest noise factor of a recorded host's own limits (x1.69 at a margin of 2), as for a
/// short pass: a recording is fewer probes over less time than the blessing host's drift study.
/// On host-c, fresh checks came out up to x1.45 above the median of a recording of 57 ratios
/// whose largest was x1.21 above it (ibl's lighting on wgpu-vulkan, 2026-11-26).
pub const MIN_NOISE_RECORDED: f64 = MIN_NOISE_SHORT;
/// A limit that would not catch a pass taking this many times as long is no check of ordinary
/// slowdowns: such a pass is untimed, with the reason, and fails only beyond its limit.
pub const MUST_CATCH: f64 = 2.0;
/// Passes faster than this (their fastest sample, ms) are too short to time: timer resolution
/// and fixed costs dominate.
pub const MIN_PASS_MS: f64 = 0.15;

/// Why timing goldens or the timing-noise model could not be read or written.
#[derive(Debug, thiserror::Error)]
pub enum SpeedError {
    /// A file could not be read, parsed or written.
    #[error("{path}: {message}")]
    File {
        /// The file.
        path: std::path::PathBuf,
        /// What went wrong.
        message: String,
    },
    /// A speed probe failed.
    #[error("speed probe: {0}")]
    Probe(String),
}

/// A ratio or factor read from a file of the speed goldens: finite and positive, or an error at
/// its key (a NaN ratio would read "xNaN of golden ... ok", a negative one always "faster").
fn positive_finite<'de, D: serde::Deserializer<'de>>(deserializer: D) -> Result<f64, D::Error> {
    let value = <f64 as serde::Deserialize>::deserialize(deserializer)?;
    if is_positive_finite(value) {
        Ok(value)
    } else {
        Err(serde::de::Error::custom(format!(
            "{value} is not a finite positive number"
        )))
    }
}

/// Whether `value` is a ratio or factor the speed files can hold: finite and positive.
fn is_positive_finite(value: f64) -> bool {
    value.is_finite() && value > 0.0
}

/// Reads a TOML file of the speed goldens: its value, or `None` when there is no file yet.
fn read_toml<T: serde::de::DeserializeOwned>(
    path: &std::path::Path,
) -> Result<Option<T>, SpeedError> {
    let error = |message: String| SpeedError::File {
        path: path.to_owned(),
        message,
    };
    match std::fs::read_to_string(path) {
        Ok(text) => toml::from_str(&text)
            .map(Some)
            .map_err(|e| error(e.to_string())),
        Err(e) if e.kind() == std::io::ErrorKind::NotFound => Ok(None),
        Err(e) => Err(error(e.to_string())),
    }
}

/// Writes `value` as TOML under `header` atomically (a temporary file renamed over the old one).
fn write_toml<T: serde::Serialize>(
    path: &std::path::Path,
    header: &str,
    value: &T,
) -> Result<(), SpeedError> {
    let error = |message: String| SpeedError::File {
        path: path.to_owned(),
        message,
    };
    let body = toml::to_string(value).map_err(|e| error(e.to_string()))?;
    crate::images::write_atomically(path, format!("{header}\n{body}").as_bytes())
        .map_err(|e| error(e.to_string()))
}

/// The host as a speed check sees it: the backend's driver fingerprint, the CPU model, and the
/// variables that change llvmpipe's code paths. Two hosts with the same one time alike.
pub fn host_fingerprint(driver: &str) -> String {
    let cpu = cpuinfo_field("model name").unwrap_or_else(|| "unknown CPU".to_owned());
    format!("{driver} | CPU {cpu}")
}

/// The CPU as its family, model and stepping (`/proc/cpuinfo`), which virtual machines keep
/// where they make the model name generic ("Intel(R) Xeon(R) Processor" covers several
/// generations of Xeon): what a recorded host's own reference is tied to.
pub fn cpu_signature() -> String {
    let field = |name| cpuinfo_field(name).unwrap_or_else(|| "?".to_owned());
    format!(
        "family {} model {} stepping {}",
        field("cpu family"),
        field("model"),
        field("stepping")
    )
}

/// Whether a CPU signature names a CPU: not empty (goldens blessed before it was kept) and
/// with every field found (`/proc/cpuinfo` on some architectures has no family or model, and
/// two such hosts would otherwise match whatever their CPUs).
pub fn cpu_known(signature: &str) -> bool {
    !signature.is_empty() && !signature.contains('?')
}

/// Whether a host written down as `their_host` (its driver fingerprint for a backend) and
/// `their_cpu` is this one (`host`, `cpu`): the same fingerprint and a known, equal CPU
/// signature. The one rule for the blessing host, a recorded host and the host that measured
/// the model's same-host figures.
pub fn same_host(their_host: &str, their_cpu: &str, host: &str, cpu: &str) -> bool {
    their_host == host && cpu_known(their_cpu) && their_cpu == cpu
}

/// The first CPU's `name` field in `/proc/cpuinfo`, trimmed. The file is read once per process
/// (a check asks for the CPU per scene and backend, and the CPU does not change under it).
fn cpuinfo_field(name: &str) -> Option<String> {
    static CPUINFO: std::sync::OnceLock<Option<String>> = std::sync::OnceLock::new();
    let text = CPUINFO
        .get_or_init(|| std::fs::read_to_string("/proc/cpuinfo").ok())
        .as_deref()?;
    text.lines()
        .filter_map(|l| l.split_once(':'))
        .find(|(key, _)| key.trim() == name)
        .map(|(_, value)| value.trim().to_owned())
}

/// Rounds of one speed check (each pass alone, then its floor, per round).
pub const CHECK_ROUNDS: usize = crate::measure::speed::SPEED_ROUNDS;
/// Probes a bless takes per backend; each pass's golden is the one with the median ratio.
pub const BLESS_PROBES: usize = 3;

/// The speed checks of a run, and what kept some from running.
#[derive(Clone, Debug, Default, serde::Serialize, serde::Deserialize)]
pub struct SpeedRun {
    /// One per scene, backend and pass probed.
    pub checks: Vec<SpeedCheck>,
    /// Probes that failed (a backend or scene), each a failure of the run.
    pub errors: Vec<String>,
    /// Where a backend's checks read at another host's limits although a recording of this
    /// CPU exists: what in the driver fingerprint differs from it ([`near_recordings`]).
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub host_notes: Vec<String>,
    /// Per backend, the name of the recording in golden/evidence/ of this host (its driver
    /// fingerprint and CPU), where there is one: what the advice to record the host again
    /// names ([`verdict::record_advice`]).
    #[serde(default, skip_serializing_if = "std::collections::BTreeMap::is_empty")]
    pub recorded_as: std::collections::BTreeMap<BackendKind, String>,
    /// The probes ran the lighting unspecialised (`check --debug-unspecialised-lighting`): a
    /// slowdown reproduced on purpose, which nothing accepts as a timing golden.
    #[serde(default, skip_serializing_if = "std::ops::Not::not")]
    pub unspecialised_lighting: bool,
}

impl SpeedRun {
    /// Whether `check` is a pass slowed on purpose by `--debug-unspecialised-lighting`: the
    /// setting's own, which no bless or accept takes.
    pub fn is_debug_slowdown(&self, check: &SpeedCheck) -> bool {
        self.unspecialised_lighting && check.outcome == SpeedOutcome::Slower
    }
}

/// Why `kind`'s checks on this host (fingerprint `host`, CPU signature `cpu`) are not read
/// against a recording that has this CPU: per such recording, the parts of the fingerprint
/// (the ` | `-separated driver, Mesa, LLVM and driver variables) found only here and only there.
/// None where no recording has this CPU, or one matches whole.
pub fn near_recordings(
    recordings: &[(String, recorded::RecordedTimings)],
    kind: BackendKind,
    host: &str,
    cpu: &str,
) -> Option<String> {
    let same_cpu: Vec<(&String, &String)> = recordings
        .iter()
        .filter(|(_, r)| r.cpu == cpu)
        .filter_map(|(name, r)| Some((name, r.hosts.get(&kind)?)))
        .collect();
    if same_cpu.is_empty() || same_cpu.iter().any(|(_, there)| *there == host) {
        return None;
    }
    let parts = |fingerprint: &str| -> Vec<String> {
        fingerprint.split(" | ").map(str::to_owned).collect()
    };
    let differences: Vec<String> = same_cpu
        .iter()
        .map(|(name, there)| {
            let (here, there) = (parts(host), parts(there));
            let only = |a: &[String], b: &[String]| -> String {
                let only: Vec<String> = a
                    .iter()
                    .filter(|p| !b.contains(p))
                    .map(|p| format!("`{p}`"))
                    .collect();
                if only.is_empty() {
                    "nothing".to_owned()
                } else {
                    only.join(", ")
                }
            };
            format!(
                "{name}'s recording has this CPU, but here {} where it has {}",
                only(&here, &there),
                only(&there, &here)
            )
        })
        .collect();
    Some(format!(
        "{kind}: {} (a variable that selects a driver is part of the fingerprint: run as the \
         recording ran, or record this setup under a name of its own)",
        differences.join("; ")
    ))
}

impl SpeedRun {
    /// Whether nothing failed: no pass slower than its limit, none without a golden, no probe
    /// error.
    pub fn passed(&self) -> bool {
        self.errors.is_empty() && !self.checks.iter().any(SpeedCheck::failed)
    }
}

/// A speed check under way: its probe child ([`ProbeChild`](crate::measure::speed::ProbeChild)),
/// preparing while the caller does other work, and what a second probe of a scene needs.
pub struct StartedCheck {
    probe: crate::measure::speed::ProbeChild,
    exe: std::path::PathBuf,
    variations: engine::renderer::Variations,
    env: Vec<(String, String)>,
}

/// Starts the speed check of `scenes` (names and their command-line arguments, names or files)
/// on `kinds` (every available backend when empty) in a child process of `exe`: it prepares
/// its probes at once and takes the timed rounds in [`check_scenes`]. `variations` are the
/// slowdowns a self-test injects (none for a plain check); `env` is added to the children's.
pub fn start_check(
    exe: &std::path::Path,
    scenes: &[(String, String)],
    kinds: &[BackendKind],
    variations: engine::renderer::Variations,
    env: &[(String, String)],
) -> StartedCheck {
    let arguments: Vec<String> = scenes
        .iter()
        .map(|(_, argument)| argument.clone())
        .collect();
    // One child for every backend: a process start and the scenes' loading once.
    StartedCheck {
        probe: crate::measure::speed::ProbeChild::start(
            exe,
            &arguments,
            kinds,
            CHECK_ROUNDS,
            variations,
            env,
        ),
        exe: exe.to_owned(),
        variations,
        env: env.to_vec(),
    }
}

/// Finishes `started` (the timed rounds of its probes) and checks every pass of `scenes` on
/// each of `backends` (with its driver fingerprint) against the goldens under `root` and the
/// timing-noise model there. A scene with a slower pass is probed once more and judged on the
/// samples of both probes.
pub fn check_scenes(
    started: StartedCheck,
    root: &std::path::Path,
    scenes: &[(String, String)],
    backends: &[(BackendKind, String)],
    mut progress: impl FnMut(&str),
) -> SpeedRun {
    let mut run = SpeedRun::default();
    let noise = match TimingNoise::load(root) {
        Ok(noise) => noise,
        Err(e) => {
            run.errors.push(e.to_string());
            return run;
        }
    };
    let recordings = match recorded::load_all(root) {
        Ok(recordings) => recordings,
        Err(e) => {
            run.errors.push(e.to_string());
            return run;
        }
    };
    progress(&format!(
        "timing {} scene(s) on {}",
        scenes.len(),
        crate::names(&backends.iter().map(|(k, _)| *k).collect::<Vec<_>>())
    ));
    let StartedCheck {
        probe,
        exe,
        variations,
        env,
    } = started;
    let (probes, errors) = probe.finish();
    run.errors.extend(errors);
    for probe in probes {
        let kind = probe.backend;
        // A backend the caller found unavailable is not checked (the child skips it too).
        let Some(driver) = backends
            .iter()
            .find(|(k, _)| *k == kind)
            .map(|(_, d)| d.as_str())
        else {
            continue;
        };
        let host = host_fingerprint(driver);
        if let Some((name, _)) = recorded::of_host(&recordings, kind, &host, &cpu_signature()) {
            run.recorded_as.insert(kind, name.to_owned());
        }
        let goldens = match TimingGoldens::load(root, &probe.scene) {
            Ok(goldens) => goldens,
            Err(e) => {
                run.errors.push(e.to_string());
                continue;
            }
        };
        let mut checks = check_speed_with(&probe, &goldens, &noise, &host, &recordings);
        if checks.iter().any(|c| c.outcome == SpeedOutcome::Slower) {
            // Confirm: probe the scene again and judge the samples of both. A real slowdown
            // stays; a probe that met a noisy moment in every round of a pass does not.
            let argument = scenes
                .iter()
                .find(|(name, _)| *name == probe.scene)
                .map_or_else(|| probe.scene.clone(), |(_, a)| a.clone());
            progress(&format!("confirming {} on {kind}", probe.scene));
            let (again, errors) = crate::measure::speed::probe_in_child(
                &exe,
                &[argument],
                &[kind],
                CHECK_ROUNDS,
                variations,
                &env,
            );
            run.errors.extend(errors);
            if let Some(again) = again.into_iter().find(|a| a.scene == probe.scene) {
                checks =
                    check_speed_with(&probe.merged(&again), &goldens, &noise, &host, &recordings);
                // What an injection delivered is one process's figure: the first probe's.
                for check in &mut checks {
                    check.delivered = probe
                        .pass(check.pass)
                        .and_then(crate::measure::speed::PassSpeed::delivered);
                }
            }
        }
        // Read at the limits for any host: say what keeps a recording of this CPU from applying.
        if checks.iter().any(|c| c.tier == Tier::OtherHost) {
            if let Some(note) = near_recordings(&recordings, kind, &host, &cpu_signature()) {
                if !run.host_notes.contains(&note) {
                    run.host_notes.push(note);
                }
            }
        }
        run.checks.extend(checks);
    }
    run.host_notes.extend(moved_here_notes(&run.checks));
    run
}

/// Per scene with checks at [`Tier::MovedHere`] (timing goldens blessed on this host, the
/// model's same-host figures for them measured on another): a note saying they were read at
/// the limits for any host, on which backends, and the command that measures this host's noise.
pub fn moved_here_notes(checks: &[SpeedCheck]) -> Vec<String> {
    let mut scenes: Vec<(&str, Vec<BackendKind>, bool)> = Vec::new();
    for c in checks.iter().filter(|c| c.tier == Tier::MovedHere) {
        match scenes.iter_mut().find(|(scene, ..)| *scene == c.scene) {
            Some((_, kinds, borrowed)) => {
                *borrowed &= c.borrowed;
                if !kinds.contains(&c.backend) {
                    kinds.push(c.backend);
                }
            }
            None => scenes.push((&c.scene, vec![c.backend], c.borrowed)),
        }
    }
    scenes
        .into_iter()
        .map(|(scene, kinds, borrowed)| {
            let whose = if borrowed {
                "golden/timing-noise.toml has no figures of its own for it yet: it borrows every \
                 scene's, measured on other hosts"
            } else {
                "golden/timing-noise.toml's same-host figures for them were measured on another \
                 host (or by a model that did not yet record where)"
            };
            let measure = crate::golden::command_line::harness_command(&format!(
                "noise --timing --write {}",
                crate::golden::command_line::scene_flag(scene)
            ));
            format!(
                "{scene}'s timing goldens on {} were blessed on this host, but {whose}, so they \
                 were read at the limits for any host. Measure this host's: `{measure}` (without \
                 the second Mesa: `{measure} --source runs --source busy-neighbour`)",
                crate::names(&kinds)
            )
        })
        .collect()
}

/// Appends a check's ratios to the speed history in `out` ([`history`]).
pub fn append_history(
    out: &std::path::Path,
    run: &SpeedRun,
    backends: &[(BackendKind, String)],
    inputs: std::collections::BTreeMap<String, String>,
) {
    let hosts = backends
        .iter()
        .map(|(kind, driver)| (*kind, host_fingerprint(driver)))
        .collect();
    let ratios = run
        .checks
        .iter()
        .map(|c| history::HistoryRatio {
            scene: c.scene.clone(),
            backend: c.backend,
            pass: c.pass,
            ratio: c.ratio,
            ms: c.ms,
        })
        .collect();
    history::record(out, "check", hosts, ratios, inputs);
}

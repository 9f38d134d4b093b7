//! The speed probe: what a timing golden records and `harness check` compares, a pass's cost as
//! a number that travels between hosts.
//!
//! A frame is recorded once ([`RecordedFrame`]) and submitted whole once (every input filled,
//! every pipeline compiled). Then, round after round, each pass is submitted alone and its
//! floor (the cheapest pass writing the same targets, [`Floors`]) right after it, a short floor
//! repeated in one submission to last [`MIN_FLOOR_MS`] (a 0.1 ms floor is mostly timer). The pass's
//! **speed ratio** is the minimum of its times over the minimum of its floor's: a busy
//! neighbour or a frequency step only ever adds time, so the fastest of several samples is the
//! one closest to the work itself, and the floor, timed moments later in every round, cancels
//! what the host's speed does to both. Rounds interleave the passes, so slow drift reaches each
//! alike, and a pass stops sampling once it has settled (at least [`MIN_ROUNDS`] rounds, the
//! last two finding nothing faster): a quiet machine takes few rounds, a busy one more.
//!
//! The untimed part ([`PreparedProbe::new`]: the backend, the recording, the first submissions)
//! and the timed one ([`PreparedProbe::sample`]) are apart, so that a probe child
//! ([`ProbeChild`]) prepares while its parent is busy and times once the machine is quiet.

use engine::backend::{self, BackendKind};
use engine::plan::PassId;
use engine::renderer::{PreparedFrame, RecordedFrame, Variations};
use engine::scene::Scene;

use super::bench::{BenchError, Floors};

/// The most rounds the speed probe takes by default (each: every pass that has not settled
/// alone, then its floor); a quiet machine settles after [`MIN_ROUNDS`] or a few more.
pub const SPEED_ROUNDS: usize = 12;

/// One pass's samples from the speed probe.
#[derive(Clone, Debug, serde::Serialize, serde::Deserialize)]
pub struct PassSpeed {
    /// The plan pass.
    pub pass: PassId,
    /// Its GPU ms alone, one per round.
    pub pass_ms: Vec<f64>,
    /// Its floor's GPU ms, one per round, each timed right after the pass (the mean of its
    /// copies where a short floor is repeated to last [`MIN_FLOOR_MS`]).
    pub floor_ms: Vec<f64>,
    /// What the pass and its floor write ([`engine::plan::RenderPlan::written_targets`]): a
    /// ratio compares only with one of the same targets (None: not known, from an older
    /// probe).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub targets: Option<String>,
    /// Where the speed self-test slowed this pass down ([`SlowPass`](engine::renderer::SlowPass)):
    /// its GPU ms without the injected copies, timed in every other turn of the pass (each
    /// after a turn with them, in the same place in the round).
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub unslowed_ms: Vec<f64>,
}

impl PassSpeed {
    /// The slowdown an injected [`SlowPass`](engine::renderer::SlowPass) delivered in this
    /// probe's process: the pass's fastest time over its fastest without the copies (None where
    /// nothing was injected).
    pub fn delivered(&self) -> Option<f64> {
        let unslowed = self.unslowed_ms.iter().copied().reduce(f64::min)?;
        let slowed = self.min_ms()?;
        (unslowed > 0.0).then(|| slowed / unslowed)
    }

    /// The fastest of the pass's samples, ms.
    pub fn min_ms(&self) -> Option<f64> {
        self.pass_ms.iter().copied().reduce(f64::min)
    }

    /// The fastest of the floor's samples, ms.
    pub fn floor_min_ms(&self) -> Option<f64> {
        self.floor_ms.iter().copied().reduce(f64::min)
    }

    /// The speed ratio: the pass's fastest sample over its floor's fastest.
    pub fn ratio(&self) -> Option<f64> {
        let (pass, floor) = (self.min_ms()?, self.floor_min_ms()?);
        (floor > 0.0).then(|| pass / floor)
    }
}

/// The speed probe of one scene on one backend.
#[derive(Clone, Debug, serde::Serialize, serde::Deserialize)]
pub struct SceneSpeed {
    /// Scene name.
    pub scene: String,
    /// Backend.
    pub backend: BackendKind,
    /// The most rounds allowed (a pass that settles earlier has fewer samples).
    pub rounds: usize,
    /// Every plan pass that has a floor and a time, in plan order.
    pub passes: Vec<PassSpeed>,
}

impl SceneSpeed {
    /// This probe's samples and `other`'s together (the same scene and backend probed again):
    /// each pass's samples of both, in order.
    pub fn merged(&self, other: &SceneSpeed) -> SceneSpeed {
        let mut merged = self.clone();
        merged.rounds += other.rounds;
        for pass in &mut merged.passes {
            if let Some(more) = other.pass(pass.pass) {
                pass.pass_ms.extend(&more.pass_ms);
                pass.floor_ms.extend(&more.floor_ms);
                pass.unslowed_ms.extend(&more.unslowed_ms);
            }
        }
        merged
    }

    /// The samples of `pass`.
    pub fn pass(&self, pass: PassId) -> Option<&PassSpeed> {
        self.passes.iter().find(|p| p.pass == pass)
    }
}

/// Probes `scene` on `kind` for at most `rounds` rounds with `variations` applied to the frame (a
/// [`SlowPass`](engine::renderer::SlowPass) injected by the speed self-test, the unspecialised
/// lighting of `--debug-unspecialised-lighting`); the floors are never varied. A backend
/// without timestamps gives no passes. [`PreparedProbe::new`], then [`PreparedProbe::sample`].
pub fn probe(
    scene: &Scene,
    kind: BackendKind,
    rounds: usize,
    variations: Variations,
) -> Result<SceneSpeed, BenchError> {
    PreparedProbe::new(scene, kind, variations)?.sample(rounds)
}

/// The untimed part of a probe: `scene`'s frame and its floors on a backend of their own,
/// recorded and submitted once (every pipeline compiled, every target touched, each floor
/// once). It may run while the machine is busy (`harness check` prepares its probes while it
/// renders the images); [`PreparedProbe::sample`] takes the timed rounds, which may not.
pub struct PreparedProbe {
    scene: String,
    kind: BackendKind,
    backend: Box<dyn backend::Backend>,
    recorded: RecordedFrame,
    floors: Floors,
    passes: Vec<PassId>,
    /// What each pass writes, as its samples will carry it.
    targets: Vec<(PassId, String)>,
}

impl PreparedProbe {
    /// Starts a backend of `kind`, records `scene`'s frame with `variations` and the floors of
    /// its passes, and submits each once.
    pub fn new(
        scene: &Scene,
        kind: BackendKind,
        variations: Variations,
    ) -> Result<Self, BenchError> {
        let backend_error = |e: backend::BackendError| BenchError::Backend {
            backend: kind,
            message: e.to_string(),
        };
        let render_error = |e: engine::renderer::RenderError| BenchError::Render {
            scene: scene.name.clone(),
            backend: kind,
            message: e.to_string(),
        };
        let mut backend = crate::faults::create_backend(kind).map_err(backend_error)?;
        let prepared = PreparedFrame::new(scene)
            .map_err(render_error)?
            .with_variations(variations);
        let floors = Floors::new(backend.as_mut(), prepared.plan()).map_err(backend_error)?;
        let recorded = match RecordedFrame::record(backend.as_mut(), &prepared) {
            Ok(recorded) => recorded,
            Err(e) => {
                floors.destroy(backend.as_mut());
                return Err(render_error(e));
            }
        };
        let mut probe = Self {
            scene: scene.name.clone(),
            kind,
            backend,
            recorded,
            floors,
            passes: prepared.plan().passes.iter().map(|p| p.id).collect(),
            targets: prepared
                .plan()
                .passes
                .iter()
                .filter_map(|p| Some((p.id, prepared.plan().written_targets(p.id)?)))
                .collect(),
        };
        match probe.warm_up() {
            Ok(()) => Ok(probe),
            Err(e) => Err(probe.fail(e)),
        }
    }

    /// The scene's name.
    pub fn scene(&self) -> &str {
        &self.scene
    }

    /// The backend.
    pub fn backend(&self) -> BackendKind {
        self.kind
    }

    /// The whole frame once and every floor once: the first submissions compile their shaders
    /// and first touch their targets (3 to 5 ms for a 0.4 ms floor), so none of it is timed.
    fn warm_up(&mut self) -> Result<(), SampleError> {
        let backend = self.backend.as_mut();
        self.recorded.submit(backend).map_err(SampleError::Render)?;
        for &id in &self.passes {
            self.floors
                .time(backend, id)
                .map_err(SampleError::Backend)?;
        }
        Ok(())
    }

    /// The timed rounds ([`sample`]), at most `rounds` (at least one); frees the probe's
    /// resources.
    pub fn sample(mut self, rounds: usize) -> Result<SceneSpeed, BenchError> {
        let rounds = rounds.max(1);
        match sample(
            self.backend.as_mut(),
            &self.recorded,
            &self.floors,
            &self.passes,
            rounds,
        ) {
            Ok(mut passes) => {
                for pass in &mut passes {
                    pass.targets = self
                        .targets
                        .iter()
                        .find(|(id, _)| *id == pass.pass)
                        .map(|(_, t)| t.clone());
                }
                let (scene, kind) = (self.scene.clone(), self.kind);
                self.destroy();
                Ok(SceneSpeed {
                    scene,
                    backend: kind,
                    rounds,
                    passes,
                })
            }
            Err(e) => Err(self.fail(e)),
        }
    }

    /// Frees the probe's resources and names `error` by scene and backend.
    fn fail(self, error: SampleError) -> BenchError {
        let (scene, backend) = (self.scene.clone(), self.kind);
        self.destroy();
        match error {
            SampleError::Render(e) => BenchError::Render {
                scene,
                backend,
                message: e.to_string(),
            },
            SampleError::Backend(e) => BenchError::Backend {
                backend,
                message: e.to_string(),
            },
        }
    }

    fn destroy(self) {
        let Self {
            mut backend,
            recorded,
            floors,
            ..
        } = self;
        recorded.destroy(backend.as_mut());
        floors.destroy(backend.as_mut());
    }
}

/// The environment every speed probe runs under, on top of the caller's: one rasterizer
/// thread (see [`crate::golden::speed`]).
pub const PROBE_ENV: [(&str, &str); 1] = [crate::golden::speed::PROBE_THREADS];

/// Runs the probe of `scenes` (names or scene files) on `backends` (one after the other) in one
/// child process of `exe` ([`ProbeChild`]) and waits for it: the scenes that were probed, and an
/// error per scene or backend that failed.
pub fn probe_in_child(
    exe: &std::path::Path,
    scenes: &[String],
    backends: &[BackendKind],
    rounds: usize,
    variations: Variations,
    env: &[(String, String)],
) -> (Vec<SceneSpeed>, Vec<String>) {
    ProbeChild::start(exe, scenes, backends, rounds, variations, env).finish()
}

/// The probe of some scenes on some backends in a child process, `exe speed --in-process --json
/// --wait-for-go` (the harness binary), under [`PROBE_ENV`] and the caller's environment: one
/// rasterizer thread, which a process cannot choose for itself once its drivers have started.
/// The child prepares every probe ([`PreparedProbe::new`]) as soon as it starts, and takes the
/// timed rounds only once [`ProbeChild::finish`] tells it to: `harness check` starts it before
/// rendering the images, so the preparing runs on a core the renders leave idle, and finishes
/// it after them, on a quiet machine. Every probe goes this way, so goldens, the noise model and
/// checks are measured alike. Dropped unfinished, the child is killed.
pub struct ProbeChild {
    child: Result<std::process::Child, String>,
    /// The backends' names, for its errors.
    label: String,
}

impl ProbeChild {
    /// Starts the child for `scenes` on `backends` (every available one when empty), at most
    /// `rounds` rounds each. `variations` may hold a slowed pass and the unspecialised lighting
    /// (the ones `harness speed` takes); the others are not passed on.
    pub fn start(
        exe: &std::path::Path,
        scenes: &[String],
        backends: &[BackendKind],
        rounds: usize,
        variations: Variations,
        env: &[(String, String)],
    ) -> Self {
        let mut command = std::process::Command::new(exe);
        command
            .args(["speed", "--in-process", "--json", "--wait-for-go"])
            .args(["--rounds", &rounds.to_string()]);
        for backend in backends {
            command.args(["--backend", backend.name()]);
        }
        for scene in scenes {
            command.args(["--scene", scene]);
        }
        if let Some(slow) = variations.slow_pass {
            command
                .args(["--slow-pass", &slow.pass.to_string()])
                .args(["--slowdown", &slow.factor.to_string()]);
        }
        if variations.unspecialised_lighting {
            command.arg("--debug-unspecialised-lighting");
        }
        command.envs(PROBE_ENV.iter().map(|(k, v)| (*k, *v)));
        command.envs(env.iter().map(|(k, v)| (k, v)));
        command
            .stdin(std::process::Stdio::piped())
            .stdout(std::process::Stdio::piped())
            .stderr(std::process::Stdio::piped());
        let label = if backends.is_empty() {
            "every backend".to_owned()
        } else {
            crate::names(backends)
        };
        Self {
            child: command
                .spawn()
                .map_err(|e| format!("{label}: cannot run {}: {e}", exe.display())),
            label,
        }
    }

    /// Lets the child take its timed rounds and waits for them: the scenes that were probed,
    /// and an error per scene or backend that failed.
    pub fn finish(mut self) -> (Vec<SceneSpeed>, Vec<String>) {
        let placeholder = Err(String::new());
        let mut child = match std::mem::replace(&mut self.child, placeholder) {
            Ok(child) => child,
            Err(e) => return (Vec::new(), vec![e]),
        };
        if let Some(mut stdin) = child.stdin.take() {
            // A child that died already does not read it; its output says why.
            let _ = std::io::Write::write_all(&mut stdin, b"go\n");
        }
        let output = match child.wait_with_output() {
            Ok(output) => output,
            Err(e) => {
                return (
                    Vec::new(),
                    vec![format!("{}: the speed probe was lost: {e}", self.label)],
                )
            }
        };
        let stderr = String::from_utf8_lossy(&output.stderr);
        let mut errors: Vec<String> = stderr
            .lines()
            .filter_map(|l| l.strip_prefix("error: "))
            .map(|l| format!("{}: {l}", self.label))
            .collect();
        match serde_json::from_slice::<Vec<SceneSpeed>>(&output.stdout) {
            Ok(results) => (results, errors),
            Err(_) => {
                let tail: Vec<&str> = stderr
                    .lines()
                    .filter(|l| !l.contains("XDG_RUNTIME_DIR") && !l.contains("eglInitialize"))
                    .collect();
                errors.push(format!(
                    "{}: the speed probe died ({}): {}",
                    self.label,
                    output.status,
                    tail[tail.len().saturating_sub(3)..].join(" / ")
                ));
                (Vec::new(), errors)
            }
        }
    }
}

impl Drop for ProbeChild {
    fn drop(&mut self) {
        if let Ok(child) = &mut self.child {
            let _ = child.kill();
            let _ = child.wait();
        }
    }
}

/// A floor is timed at least this long (repeated in one submission), ms.
pub const MIN_FLOOR_MS: f64 = 1.0;
/// At most this many copies of a floor per sample.
pub const MAX_FLOOR_COPIES: usize = 16;

/// Copies of a floor whose one submission took `floor_ms` that last at least [`MIN_FLOOR_MS`].
pub fn floor_copies(floor_ms: f64) -> usize {
    if floor_ms <= 0.0 {
        return MAX_FLOOR_COPIES;
    }
    ((MIN_FLOOR_MS / floor_ms).ceil() as usize).clamp(1, MAX_FLOOR_COPIES)
}

enum SampleError {
    Render(engine::renderer::RenderError),
    Backend(backend::BackendError),
}

/// The timed part of a probe warmed up by [`PreparedProbe::new`]: every floor once more, sizing
/// its repeats, then round after round each pass that has not settled alone and its floor,
/// until every pass has settled ([`settled`]) or `rounds` rounds were taken.
fn sample(
    backend: &mut dyn backend::Backend,
    recorded: &RecordedFrame,
    floors: &Floors,
    ids: &[PassId],
    rounds: usize,
) -> Result<Vec<PassSpeed>, SampleError> {
    let mut passes: Vec<PassSpeed> = Vec::new();
    let mut copies = Vec::new();
    for &id in ids {
        // Sized from the floor's second submission: the first (the warm-up's) compiled its
        // shaders and first touched its targets, so sized from it no floor was ever repeated.
        if let Some(floor_ns) = floors.time(backend, id).map_err(SampleError::Backend)? {
            passes.push(PassSpeed {
                pass: id,
                pass_ms: Vec::with_capacity(rounds),
                floor_ms: Vec::with_capacity(rounds),
                targets: None,
                unslowed_ms: Vec::new(),
            });
            copies.push(floor_copies(floor_ns / 1e6));
        }
    }
    for _ in 0..rounds {
        let mut sampled = false;
        for (speed, &n) in passes.iter_mut().zip(&copies) {
            if settled(speed) {
                continue;
            }
            // A slowed pass gives every other turn to itself without its copies, in the same
            // place (after the previous pass's floor, before its own): what they delivered.
            if recorded.slowed_pass() == Some(speed.pass)
                && speed.unslowed_ms.len() < speed.pass_ms.len()
            {
                if let Some(ns) = recorded
                    .submit_unslowed(backend)
                    .map_err(SampleError::Render)?
                {
                    speed.unslowed_ms.push(ns / 1e6);
                }
                // The floor as after the pass, so that the next pass follows the same work.
                floors
                    .time_repeated(backend, speed.pass, n)
                    .map_err(SampleError::Backend)?;
                sampled = true;
                continue;
            }
            let pass_ns = recorded
                .submit_pass(backend, speed.pass)
                .map_err(SampleError::Render)?;
            let floor_ns = floors
                .time_repeated(backend, speed.pass, n)
                .map_err(SampleError::Backend)?;
            if let (Some(pass_ns), Some(floor_ns)) = (pass_ns, floor_ns) {
                speed.pass_ms.push(pass_ns / 1e6);
                speed.floor_ms.push(floor_ns / 1e6);
                sampled = true;
            }
        }
        if !sampled {
            break;
        }
    }
    passes.retain(|p| !p.pass_ms.is_empty());
    Ok(passes)
}

/// Rounds every pass is sampled at least.
pub const MIN_ROUNDS: usize = 4;
/// A pass has settled when its last this many rounds improved neither its fastest time nor its
/// floor's by more than [`SETTLE_TOLERANCE`].
const SETTLE_ROUNDS: usize = 2;
/// See [`SETTLE_ROUNDS`].
const SETTLE_TOLERANCE: f64 = 0.01;

/// Whether a pass needs no more rounds: [`MIN_ROUNDS`] taken, and the last [`SETTLE_ROUNDS`]
/// found nothing faster by more than [`SETTLE_TOLERANCE`] (a busy neighbour keeps a pass
/// sampling until it gets a quiet moment or the rounds run out).
pub fn settled(speed: &PassSpeed) -> bool {
    let n = speed.pass_ms.len();
    if n < MIN_ROUNDS {
        return false;
    }
    let still = |samples: &[f64]| {
        let (earlier, last) = samples.split_at(n - SETTLE_ROUNDS);
        let best_before = earlier.iter().copied().fold(f64::INFINITY, f64::min);
        let best_last = last.iter().copied().fold(f64::INFINITY, f64::min);
        best_last >= best_before * (1.0 - SETTLE_TOLERANCE)
    };
    still(&speed.pass_ms) && still(&speed.floor_ms)
}

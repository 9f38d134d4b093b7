//! The speed self-test: proof that the speed checks catch a slower pass, in that pass and in no
//! other. Each pass of each scene is slowed down in turn ([`SlowPass`]: its work submitted
//! ×1.5 and ×2), on every backend, and the check must flag it there and nowhere else (one
//! check per pass and slowdown, of every scene with the pass on every backend, probed in one
//! child as `harness check` probes: see [`run`]). The
//! unchanged side (every source at or below half its limit) is `harness noise --timing`'s.
//!
//! Each probe also times the slowed pass without its copies, in the same rounds
//! ([`PassSpeed::delivered`](crate::measure::speed::PassSpeed::delivered)), so the table shows
//! what slowdown the injection delivered in its own process beside what the check measured
//! against the golden: where a doubling is missed, whether the copies fell short or the
//! process ran the pass faster than the golden's.

use engine::backend::BackendKind;
use engine::plan::PassId;
use engine::renderer::{SlowPass, Variations};

use super::{check_scenes, start_check, SpeedCheck, SpeedOutcome};

/// The slowdowns injected.
pub const INJECTED: [f32; 2] = [1.5, 2.0];

/// One injection's result.
#[derive(Clone, Debug, serde::Serialize)]
pub struct Injection {
    /// Scene.
    pub scene: String,
    /// Backend.
    pub backend: BackendKind,
    /// The pass slowed down.
    pub pass: PassId,
    /// By how much its work was multiplied.
    pub factor: f32,
    /// The slowdown its copies delivered in the probe's own process: the pass's time over its
    /// time without them, timed in the same rounds (None without timestamps).
    pub delivered: Option<f64>,
    /// The slowdown measured in that pass (ratio / golden).
    pub measured: Option<f64>,
    /// Its score (`ln slowdown / ln limit`; above 1 is flagged).
    pub score: Option<f64>,
    /// Its limit; None when the pass is untimed (with the reason in `untimed`).
    pub limit: Option<f64>,
    /// Why the pass is not timed, if it is not.
    pub untimed: Option<String>,
    /// Whether the check flagged the pass.
    pub flagged: bool,
    /// Other passes of the scene the check flagged (must be none).
    pub flagged_elsewhere: Vec<PassId>,
    /// The largest score among the other passes.
    pub worst_elsewhere: Option<f64>,
}

impl Injection {
    /// Whether the injection behaved: flagged where it was injected (unless that pass is
    /// untimed, which the table shows) and nowhere else.
    pub fn correct(&self) -> bool {
        (self.flagged || self.untimed.is_some()) && self.flagged_elsewhere.is_empty()
    }
}

/// Injects each slowdown of `factors` into each pass of `scenes` (each scene with the passes it
/// slows) and checks it, at the limits the check would use here (run this on a recorded host,
/// or the one that blessed where the goldens name one).
///
/// One slowdown of one pass is one check of every scene that has the pass, on every backend,
/// in one probe child, as `harness check` probes: the pass is slowed wherever it runs, as a
/// change to its shader would slow it, and each scene and backend is judged on its own. A
/// child probing a single scene on a single backend reads some passes' ratios x0.6 to x0.7 of
/// what a child probing them all reads (host-d, 2026-11-27: wgpu-vulkan's floors up to twice
/// as long there), and the goldens and recordings are probed the latter way.
pub fn run(
    exe: &std::path::Path,
    root: &std::path::Path,
    scenes: &[(String, String, Vec<PassId>)],
    backends: &[(BackendKind, String)],
    factors: &[f32],
    mut progress: impl FnMut(&str),
) -> (Vec<Injection>, Vec<String>) {
    let mut injections = Vec::new();
    let mut errors = Vec::new();
    let mut passes: Vec<PassId> = Vec::new();
    for (_, _, slowed) in scenes {
        for pass in slowed {
            if !passes.contains(pass) {
                passes.push(*pass);
            }
        }
    }
    let kinds: Vec<BackendKind> = backends.iter().map(|(k, _)| *k).collect();
    for &pass in &passes {
        let with_pass: Vec<(String, String)> = scenes
            .iter()
            .filter(|(_, _, slowed)| slowed.contains(&pass))
            .map(|(name, argument, _)| (name.clone(), argument.clone()))
            .collect();
        for &factor in factors {
            progress(&format!(
                "{pass} x{factor} in {} on {}",
                with_pass
                    .iter()
                    .map(|(name, _)| name.as_str())
                    .collect::<Vec<_>>()
                    .join(", "),
                crate::names(&kinds)
            ));
            let variations = Variations {
                slow_pass: Some(SlowPass { pass, factor }),
                ..Default::default()
            };
            let started = start_check(exe, &with_pass, &kinds, variations, &[]);
            let run = check_scenes(started, root, &with_pass, backends, |_| {});
            errors.extend(run.errors.iter().cloned());
            for (scene, _) in &with_pass {
                for &kind in &kinds {
                    let checks: Vec<&SpeedCheck> = run
                        .checks
                        .iter()
                        .filter(|c| c.scene == *scene && c.backend == kind)
                        .collect();
                    injections.push(injection(scene, kind, pass, factor, &checks));
                }
            }
        }
    }
    // In the table's order: scene, backend, then the scene's passes as given.
    let order = |i: &Injection| {
        let scene = scenes.iter().position(|(name, _, _)| *name == i.scene);
        let pass = scene.and_then(|s| scenes[s].2.iter().position(|p| *p == i.pass));
        let backend = kinds.iter().position(|k| *k == i.backend);
        (scene, backend, pass)
    };
    injections.sort_by_key(|i| order(i));
    (injections, errors)
}

/// One injection's row from the checks of its scene on its backend (none where the probe
/// failed there: the errors say why).
fn injection(
    scene: &str,
    backend: BackendKind,
    pass: PassId,
    factor: f32,
    checks: &[&SpeedCheck],
) -> Injection {
    let own = checks.iter().copied().find(|c| c.pass == pass);
    let others: Vec<&SpeedCheck> = checks.iter().copied().filter(|c| c.pass != pass).collect();
    Injection {
        scene: scene.to_owned(),
        backend,
        pass,
        factor,
        delivered: own.and_then(|c| c.delivered),
        measured: own.and_then(SpeedCheck::slowdown),
        score: own.and_then(SpeedCheck::score),
        limit: own.and_then(|c| c.limit),
        untimed: own.and_then(|c| match &c.outcome {
            SpeedOutcome::Untimed(why) => Some(why.clone()),
            _ => None,
        }),
        flagged: own.is_some_and(|c| c.outcome == SpeedOutcome::Slower),
        flagged_elsewhere: others
            .iter()
            .filter(|c| c.outcome == SpeedOutcome::Slower)
            .map(|c| c.pass)
            .collect(),
        worst_elsewhere: others.iter().filter_map(|c| c.score()).reduce(f64::max),
    }
}

/// The margin table: a row per injection with the slowdown it delivered in its own process and
/// the one measured against the golden, the value against the limit in its pass, the smallest
/// slowdown the pass's limit detects, and the worst other pass.
pub fn table(injections: &[Injection]) -> String {
    let mut out = format!(
        "{:<8} {:<12} {:<22} {:>6} {:>9} {:>10} {:>12} {:>10} {:>14}  {}\n",
        "scene",
        "backend",
        "pass",
        "inject",
        "delivered",
        "measured",
        "value/limit",
        "detects",
        "others' worst",
        "verdict"
    );
    for i in injections {
        let verdict = match (&i.untimed, i.correct()) {
            (Some(why), _) => format!("untimed: {why}"),
            (None, true) => "flagged here only".to_owned(),
            (None, false) if !i.flagged => "MISSED".to_owned(),
            (None, false) => format!("ALSO FLAGGED {}", crate::names(&i.flagged_elsewhere)),
        };
        out += &format!(
            "{:<8} {:<12} {:<22} {:>6} {:>9} {:>10} {:>12} {:>10} {:>14}  {verdict}\n",
            i.scene,
            i.backend.name(),
            i.pass.to_string(),
            format!("x{}", i.factor),
            i.delivered.map_or("-".to_owned(), |d| format!("x{d:.2}")),
            i.measured.map_or("-".to_owned(), |m| format!("x{m:.3}")),
            i.score.map_or("-".to_owned(), |s| format!("{s:.2}")),
            i.limit.map_or("-".to_owned(), |l| format!("x{l:.2}")),
            i.worst_elsewhere
                .map_or("-".to_owned(), |s| format!("{s:.2}")),
        );
    }
    out
}

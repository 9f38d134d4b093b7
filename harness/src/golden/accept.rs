//! Accepting what `check` rendered, without rendering again (`harness bless --from-last-check`):
//! `check` keeps its results in `<out>/last-check.json` and the outputs of its failing passes
//! under `<out>/failures/` (written losslessly, as a bless writes them); accepting reads those and
//! blesses them through the same path as `harness bless` ([`super::bless::bless_pass`]), so
//! blessed.toml gets the same record: the check's backend and driver fingerprint and the
//! metrics against the golden it replaces. A golden rewritten after the check is not
//! overwritten: that pass is refused, with the reason.

use std::path::{Path, PathBuf};
use std::time::SystemTime;

use engine::backend::BackendKind;
use engine::plan::TargetId;

use super::bless::{bless_pass, BlessRequest, BlessedPass};
use super::check::CheckRun;
use super::suite::{Case, PassCheck};
use super::{GoldenStore, SceneLock};
pub use crate::golden::speed::accept::{accept_timings, KeptTiming, TimingAcceptance};

/// The file `check` keeps its results in, under its output folder.
pub const LAST_CHECK: &str = "last-check.json";

/// Why a pass of the last check cannot be accepted.
#[derive(Debug, thiserror::Error)]
pub enum AcceptError {
    /// No last check, or one that does not parse.
    #[error("cannot read the last check at {path}: {message} (run `harness check` first)")]
    LastCheck {
        /// The file.
        path: PathBuf,
        /// What went wrong.
        message: String,
    },
    /// A scene file outside scenes/ named like a canonical scene: its goldens are not written.
    #[error("{0}")]
    SharesACanonicalName(String),
    /// The last check ran the lighting unspecialised on purpose: its timings are the debug
    /// setting's, not the renderer's.
    #[error(
        "the last check ran with --debug-unspecialised-lighting: its speed failures are that \
         setting's own, not the renderer's, and no timing golden is taken from them (check \
         without it, then accept or bless a slowdown of your own)"
    )]
    DebugSlowdown,
    /// The request names what the last check did not check (a typo, or another check's).
    #[error("the last check did not check {what} (it checked {checked}); nothing accepted")]
    NotChecked {
        /// The scene, pass or backend named.
        what: String,
        /// What it did check, of that kind.
        checked: String,
    },
}

/// Refuses a request naming a backend, scene or pass the last check `run` did not check, so a
/// typo is an error rather than "nothing to accept". `backend` None: any (timing goldens);
/// a pass may be an output (`final`) or a plan pass (`lighting_pbr`, for the speed checks).
fn check_request(
    run: &CheckRun,
    backend: Option<BackendKind>,
    scenes: &[String],
    passes: &[String],
) -> Result<(), AcceptError> {
    fn listed<T: ToString>(items: impl Iterator<Item = T>) -> String {
        let mut names: Vec<String> = items.map(|i| i.to_string()).collect();
        names.sort();
        names.dedup();
        if names.is_empty() {
            "nothing".to_owned()
        } else {
            crate::names(&names)
        }
    }
    let not_checked = |what: String, checked: String| AcceptError::NotChecked { what, checked };
    if let Some(backend) = backend {
        if !run.results.iter().any(|r| r.backend == backend) {
            let checked = listed(run.results.iter().map(|r| r.backend.name()));
            return Err(not_checked(format!("backend {backend}"), checked));
        }
    }
    for scene in scenes {
        let known = run
            .results
            .iter()
            .any(|r| &r.scene == scene || &r.scene_argument == scene)
            || run.speed.checks.iter().any(|c| &c.scene == scene);
        if !known {
            let checked = listed(run.results.iter().map(|r| &r.scene));
            return Err(not_checked(format!("scene {scene}"), checked));
        }
    }
    for pass in passes {
        let known = run.results.iter().any(|r| &r.pass.to_string() == pass)
            || run.speed.checks.iter().any(|c| &c.pass.to_string() == pass);
        if !known {
            let outputs = run.results.iter().map(|r| r.pass.to_string());
            let plan = run.speed.checks.iter().map(|c| c.pass.to_string());
            let checked = listed(outputs.chain(plan));
            return Err(not_checked(format!("a pass named {pass}"), checked));
        }
    }
    Ok(())
}

/// One failing pass of the last check, to accept.
#[derive(Clone, Debug)]
pub struct Candidate {
    /// The check's result.
    pub check: PassCheck,
    /// The driver fingerprint the check rendered it with.
    pub driver: String,
    /// When the last check was written.
    pub checked_at: SystemTime,
    /// The check's verification of this output, if it verified it.
    pub verification: Option<crate::golden::verify::Verification>,
    /// The files the check loaded the scene from (None from a check that did not record them).
    pub inputs: Option<crate::golden::scene_inputs::SceneInputs>,
}

/// The last check under `out` and when it was written.
fn last_check(out: &Path) -> Result<(CheckRun, SystemTime), AcceptError> {
    let path = out.join(LAST_CHECK);
    let error = |message: String| AcceptError::LastCheck {
        path: path.clone(),
        message,
    };
    let bytes = std::fs::read(&path).map_err(|e| error(e.to_string()))?;
    let checked_at = std::fs::metadata(&path)
        .and_then(|m| m.modified())
        .map_err(|e| error(e.to_string()))?;
    let mut run: CheckRun = serde_json::from_slice(&bytes).map_err(|e| error(e.to_string()))?;
    // Paths as the check's machine wrote them: its kept outputs are read from this folder's
    // copies (a CI job's `out`, downloaded), and the goldens are this workspace's, which an
    // accept writes.
    let goldens = crate::golden::GoldenStore::workspace();
    for result in &mut run.results {
        crate::golden::merge::rebase(&mut result.artifacts, out);
        if let Some(file) = result.golden_path.file_name() {
            result.golden_path = goldens.root().join(&result.scene).join(file);
        }
    }
    Ok((run, checked_at))
}

/// The last check's failing passes on `backend` (by default the reference among the backends
/// it checked: gl, or the first), of `scenes` and `passes` (all when empty).
pub fn candidates(
    out: &Path,
    backend: Option<BackendKind>,
    scenes: &[String],
    passes: &[String],
) -> Result<Vec<Candidate>, AcceptError> {
    let (run, checked_at) = last_check(out)?;
    check_request(&run, backend, scenes, passes)?;
    let checked: Vec<BackendKind> = run.results.iter().map(|r| r.backend).collect();
    let Some(backend) = backend.or_else(|| crate::golden::suite::reference_among(&checked)) else {
        return Ok(Vec::new());
    };
    let driver = run
        .backends
        .iter()
        .find(|b| b.backend == backend)
        .and_then(|b| b.fingerprint.clone())
        .unwrap_or_default();
    let (verifications, inputs) = (run.verifications, run.inputs);
    Ok(run
        .results
        .into_iter()
        .filter(|r| r.backend == backend && !r.outcome.passed())
        .filter(|r| {
            scenes.is_empty() || scenes.contains(&r.scene) || scenes.contains(&r.scene_argument)
        })
        .filter(|r| passes.is_empty() || passes.contains(&r.pass.to_string()))
        .map(|check| Candidate {
            verification: verifications
                .iter()
                .find(|v| {
                    v.scene == check.scene && v.backend == backend && v.passes.contains(&check.pass)
                })
                .cloned(),
            inputs: inputs.iter().find(|i| i.scene == check.scene).cloned(),
            check,
            driver: driver.clone(),
            checked_at,
        })
        .collect())
}

/// Why the output a check kept of a pass is not accepted ([`kept_output`]).
#[derive(Clone, Debug, PartialEq, Eq)]
pub enum NotKept {
    /// The pass's golden was written after the check (accepted already, or overtaken): this
    /// pass is left out, the scene's others are accepted.
    Settled(String),
    /// The check kept none, or it cannot be read, or it is not the pass's size or kind: the
    /// check's outputs of the scene are not whole, so nothing of it is accepted.
    Unusable(String),
}

impl std::fmt::Display for NotKept {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            NotKept::Settled(why) | NotKept::Unusable(why) => f.write_str(why),
        }
    }
}

/// The output the check kept of `candidate`'s pass of `case`, or why not: the check kept none,
/// or it is unreadable or not the size and kind of the pass's target ([`NotKept::Unusable`]),
/// or the golden changed after the check, saying so when the golden is now that output
/// (accepted already; [`NotKept::Settled`]), else with the check to run again (writing to
/// `check_out`, the folder the accept reads).
pub fn kept_output(
    candidate: &Candidate,
    case: &Case,
    check_out: Option<&Path>,
) -> Result<engine::Image, NotKept> {
    let check = &candidate.check;
    let name = format!("{}/{} ({})", check.scene, check.pass, check.backend);
    let Some(actual) = &check.artifacts.actual else {
        return Err(NotKept::Unusable(format!(
            "{name}: the check kept no output to accept"
        )));
    };
    // By content where the check kept the golden's digest (a checkout newer than a downloaded
    // check has newer files, not other goldens); by time for a check from before it kept one.
    let golden_changed = match &check.golden_digest {
        Some(then) => {
            crate::golden::scene_inputs::file_digest(&check.golden_path).as_ref() != Some(then)
        }
        None => std::fs::metadata(&check.golden_path)
            .and_then(|m| m.modified())
            .is_ok_and(|modified| modified > candidate.checked_at),
    };
    if golden_changed {
        // Accepted already (by this review or another accept): the golden is the kept output.
        let accepted = read_output(actual)
            .ok()
            .zip(read_output(&check.golden_path).ok())
            .is_some_and(|(kept, golden)| kept == golden);
        return Err(NotKept::Settled(if accepted {
            format!(
                "{name}: already accepted: {} is the output the last check kept",
                check.golden_path.display()
            )
        } else {
            format!(
                "{name}: {} changed after the last check; check it again: `{}`",
                check.golden_path.display(),
                crate::golden::command_line::check_command(&check.scene_argument, check_out)
            )
        }));
    }
    let image = read_output(actual).map_err(|e| NotKept::Unusable(format!("{name}: {e}")))?;
    // Size and kind, as a message says them ("512x512 8-bit").
    let shape = |(width, height): (u32, u32), eight_bit: bool| {
        format!(
            "{width}x{height} {}",
            if eight_bit { "8-bit" } else { "float" }
        )
    };
    let kept = shape(
        (image.width, image.height),
        crate::golden::is_eight_bit(&image),
    );
    let rendered = case
        .target(check.pass)
        .map(|t| shape((t.width, t.height), case.is_eight_bit(check.pass)));
    if rendered.as_ref() != Some(&kept) {
        return Err(NotKept::Unusable(format!(
            "{name}: {} is {kept}, where the pass renders {}",
            actual.display(),
            rendered.as_deref().unwrap_or("nothing")
        )));
    }
    Ok(image)
}

/// Accepts `image`, the output the last check kept of `candidate`'s pass of `case`
/// ([`kept_output`]), holding the scene's `lock`: blessed as `harness bless` would bless a fresh
/// render.
pub fn accept(
    store: &GoldenStore,
    lock: &SceneLock,
    case: &Case,
    candidate: &Candidate,
    image: &engine::Image,
    options: AcceptOptions<'_>,
) -> Result<BlessedPass, String> {
    let check = &candidate.check;
    let named = [check.pass];
    bless_pass(
        store,
        lock,
        case,
        check.pass,
        image,
        (check.backend, &candidate.driver),
        BlessRequest {
            // Failed in the check: written even where it would now be within tolerance.
            named: &named,
            every_pass: false,
            dry_run: options.dry_run,
            unverified: options.unverified,
            reason: options.reason,
        },
    )
    .map_err(|e| format!("{}/{} ({}): {e}", check.scene, check.pass, check.backend))
}

/// How accepted outputs are blessed: what `harness bless --from-last-check` was told.
#[derive(Clone, Copy, Debug, Default)]
pub struct AcceptOptions<'a> {
    /// Decide and print; write nothing.
    pub dry_run: bool,
    /// Write without verifying that the outputs reproduce (recorded in blessed.toml).
    pub unverified: bool,
    /// Why the pictures changed, recorded in blessed.toml (`--reason`).
    pub reason: Option<&'a str>,
    /// The last check's folder: where a refused scene's check, run again, must write.
    pub check_out: Option<&'a Path>,
}

/// A kept output, as `check` wrote it (PNG for 8-bit passes, EXR for float ones).
fn read_output(path: &Path) -> Result<engine::Image, crate::images::ImageFileError> {
    if path.extension().is_some_and(|x| x == "png") {
        crate::images::read_png(path)
    } else {
        crate::images::read_exr(path)
    }
}

/// The last check's speed checks to accept: a pass slower or faster than its timing golden
/// beyond the limit, or timed without one, of `scenes` and `passes` (plan passes, by name; all
/// when empty); with what [`accept_timings`] needs to know of the check ([`CheckContext`]).
pub fn speed_candidates(
    out: &Path,
    scenes: &[String],
    passes: &[String],
) -> Result<(Vec<crate::golden::speed::SpeedCheck>, CheckContext), AcceptError> {
    let (run, _) = last_check(out)?;
    if run.speed.unspecialised_lighting {
        return Err(AcceptError::DebugSlowdown);
    }
    let hosts = run
        .backends
        .iter()
        .filter_map(|b| {
            let driver = b.fingerprint.as_deref()?;
            Some((b.backend, crate::golden::speed::host_fingerprint(driver)))
        })
        .collect();
    check_request(&run, None, scenes, passes)?;
    let checks: Vec<_> = run
        .speed
        .checks
        .into_iter()
        .filter(|c| c.outcome.moved())
        .filter(|c| {
            // A scene named as the check named it: by name, or by its file's path.
            scenes.is_empty()
                || scenes.contains(&c.scene)
                || run
                    .results
                    .iter()
                    .any(|r| r.scene == c.scene && scenes.contains(&r.scene_argument))
        })
        .filter(|c| passes.is_empty() || passes.contains(&c.pass.to_string()))
        .collect();
    // A scene file named like a canonical scene writes none of that scene's timing goldens.
    for c in &checks {
        let why = run
            .results
            .iter()
            .filter(|r| r.scene == c.scene)
            .find_map(|r| crate::golden::bless::refusal_for(&r.scene, &r.scene_argument));
        if let Some(why) = why {
            return Err(AcceptError::SharesACanonicalName(why));
        }
    }
    let arguments = checks
        .iter()
        .filter_map(|c| {
            let r = run.results.iter().find(|r| r.scene == c.scene)?;
            Some((c.scene.clone(), r.scene_argument.clone()))
        })
        .collect();
    let inputs = run.inputs;
    let out = out.to_owned();
    Ok((
        checks,
        CheckContext {
            hosts,
            arguments,
            inputs,
            out,
        },
    ))
}

/// What accepting the last check's speed checks needs to know of that check.
#[derive(Clone, Debug, Default)]
pub struct CheckContext {
    /// The host each backend ran on, by its fingerprint
    /// ([`crate::golden::speed::host_fingerprint`] of the check's driver, on this machine's CPU).
    pub hosts: std::collections::BTreeMap<BackendKind, String>,
    /// Each scene as the check was given it (a name in scenes/ or a scene file's path), by
    /// name: what a printed command names to find it again.
    pub arguments: std::collections::BTreeMap<String, String>,
    /// The files each scene was loaded from: a scene changed since has its timings refused.
    pub inputs: Vec<crate::golden::scene_inputs::SceneInputs>,
    /// The check's folder.
    pub out: std::path::PathBuf,
}

impl CheckContext {
    /// `scene` as the check was given it (the name itself when not recorded).
    pub fn scene_argument<'a>(&'a self, scene: &'a str) -> &'a str {
        self.arguments.get(scene).map_or(scene, String::as_str)
    }
}

/// What accepting one scene's candidates did ([`accept_scene`]).
#[derive(Debug, Default)]
pub struct SceneAcceptance {
    /// The passes blessed (with `dry_run`, that would be).
    pub accepted: Vec<BlessedPass>,
    /// Passes refused one by one (no kept output, golden changed since the check), with why.
    pub refused: Vec<(TargetId, String)>,
    /// Where verification disagreed: then nothing of the scene was written.
    pub disagreements: Vec<crate::golden::verify::Disagreement>,
    /// Whether the check's own verification was used (nothing was rendered), rather than a
    /// verification run by the accept.
    pub verified_by_check: bool,
}

/// Accepts `candidates`, failing passes of `case` from the last check, holding the scene's
/// `lock`: their kept outputs, verified together (unless `options` say unverified or dry run:
/// by the check's own verification when it covers them and the scene's inputs are unchanged,
/// which renders nothing; otherwise now, running `exe`, the harness binary, with `progress` told
/// each source), then blessed. The one flow of `bless --from-last-check` and `harness review`.
/// Refused whole, with the files, where a file the scene was loaded from changed since the
/// check ([`SceneInputs`](crate::golden::scene_inputs::SceneInputs)).
pub fn accept_scene(
    exe: &Path,
    store: &GoldenStore,
    lock: &SceneLock,
    case: &Case,
    candidates: &[&Candidate],
    options: AcceptOptions<'_>,
    progress: impl FnMut(&str),
) -> Result<SceneAcceptance, String> {
    if let Some(why) = crate::golden::bless::refusal(case) {
        return Err(why);
    }
    // Outputs of the scene as it was are not goldens of the scene as it is, verified or not.
    if let Some(why) = candidates.iter().find_map(|c| {
        let then = c.inputs.as_ref()?;
        let changed = then.changed(&case.inputs);
        then.refusal(&changed, &c.check.scene_argument, options.check_out)
    }) {
        return Err(why);
    }
    let mut done = SceneAcceptance::default();
    let mut kept = Vec::new();
    let mut unusable = Vec::new();
    for &candidate in candidates {
        match kept_output(candidate, case, options.check_out) {
            Ok(image) => kept.push((candidate, image)),
            Err(NotKept::Settled(why)) => done.refused.push((candidate.check.pass, why)),
            Err(NotKept::Unusable(why)) => unusable.push(why),
        }
    }
    // A scene's passes are accepted together or not at all: its light without its final
    // would leave goldens of two different pictures.
    if !unusable.is_empty() {
        return Err(format!(
            "{}: nothing of it accepted, as the check's outputs of it are not whole: {}",
            case.name(),
            unusable.join("; ")
        ));
    }
    crate::golden::bless::preflight(store, case).map_err(|e| e.to_string())?;
    if !options.dry_run && !options.unverified && !kept.is_empty() {
        if let Some(recorded) = recorded_verification(store, case, &kept) {
            done.verified_by_check = true;
            done.disagreements = recorded;
        } else {
            let images: Vec<_> = kept
                .iter()
                .map(|(c, i)| (c.check.pass, i.clone()))
                .collect();
            done.disagreements =
                crate::golden::verify::verify(exe, store, case, &images, progress)?;
        }
        if !done.disagreements.is_empty() {
            return Ok(done);
        }
    }
    for (candidate, image) in &kept {
        match accept(store, lock, case, candidate, image, options) {
            Ok(blessed) => done.accepted.push(blessed),
            Err(why) => done.refused.push((candidate.check.pass, why)),
        }
    }
    Ok(done)
}

/// What the check's own verification says of `kept` (see
/// [`Verification::verdict_on`](crate::golden::verify::Verification::verdict_on)): `None` when
/// the accept must verify again.
fn recorded_verification(
    store: &GoldenStore,
    case: &Case,
    kept: &[(&Candidate, engine::Image)],
) -> Option<Vec<crate::golden::verify::Disagreement>> {
    let record = kept.first()?.0.verification.as_ref()?;
    if !kept
        .iter()
        .all(|(c, _)| c.verification.as_ref() == Some(record))
    {
        return None;
    }
    let files: Vec<_> = kept
        .iter()
        .map(|(c, _)| {
            let digest = c.check.artifacts.actual.as_deref();
            (
                c.check.pass,
                digest.and_then(crate::golden::verify::file_digest),
            )
        })
        .collect();
    record.verdict_on(&crate::golden::verify::inputs_digest(store, case), &files)
}

/// Accepts `checks` (speed checks of the last check, [`speed_candidates`]) as the timing
/// goldens, scene by scene under each scene's lock (`on_wait` as for
/// [`GoldenStore::lock_scene`]), `reason` beside each: per scene, the lines
/// [`accept_timings`] says, or why not.
pub fn accept_all_timings(
    store: &GoldenStore,
    checks: &[crate::golden::speed::SpeedCheck],
    check: &CheckContext,
    dry_run: bool,
    reason: Option<&str>,
    on_wait: impl Fn(&Path),
) -> Vec<(String, Result<TimingAcceptance, String>)> {
    let mut scenes: Vec<&str> = checks.iter().map(|c| c.scene.as_str()).collect();
    scenes.sort_unstable();
    scenes.dedup();
    scenes
        .into_iter()
        .map(|scene| {
            let lock = if dry_run {
                Ok(store.dry_run_lock(scene))
            } else {
                store.lock_scene(scene, &on_wait)
            };
            let result = lock
                .map_err(|e| e.to_string())
                .and_then(|lock| accept_timings(store, &lock, checks, check, dry_run, reason));
            (scene.to_owned(), result)
        })
        .collect()
}

//! Blessing timing goldens: `harness bless` probes each backend [`BLESS_PROBES`] times and
//! records, per pass, the probe with the median ratio. Like the images, only the passes whose
//! ratio moved beyond their limit (or have no golden) are rewritten, unless every pass is asked
//! for.

use std::collections::BTreeMap;

use engine::backend::BackendKind;
use engine::plan::PassId;

use super::{
    check_speed_with, host_fingerprint, BackendTimings, PassTiming, SpeedCheck, SpeedError,
    SpeedOutcome, Tier, TimingGoldens, TimingNoise, BLESS_PROBES, CHECK_ROUNDS,
};
use crate::measure::speed::{PassSpeed, SceneSpeed};

/// Each pass's probe with the median ratio over `probes` of one scene and backend (the upper
/// one of an even count).
pub fn median_probe(probes: &[SceneSpeed]) -> Option<SceneSpeed> {
    let first = probes.first()?;
    let mut by_pass: BTreeMap<PassId, Vec<&PassSpeed>> = BTreeMap::new();
    for probe in probes {
        for pass in &probe.passes {
            by_pass.entry(pass.pass).or_default().push(pass);
        }
    }
    let passes = first
        .passes
        .iter()
        .filter_map(|p| {
            let mut samples = by_pass.remove(&p.pass)?;
            samples.sort_by(|a, b| {
                a.ratio()
                    .unwrap_or(f64::INFINITY)
                    .total_cmp(&b.ratio().unwrap_or(f64::INFINITY))
            });
            Some(samples[samples.len() / 2].clone())
        })
        .collect();
    Some(SceneSpeed {
        scene: first.scene.clone(),
        backend: first.backend,
        rounds: first.rounds,
        passes,
    })
}

/// One line of a timing bless: a pass (or every pass of a scene on a backend), its check
/// against the old golden or why its goldens are kept, and what became of it.
pub struct SpeedBlessed {
    /// Scene.
    pub scene: String,
    /// Backend.
    pub backend: BackendKind,
    /// The pass; None for a line about every pass of the scene on the backend.
    pub pass: Option<PassId>,
    /// The new ratio against the old golden, or why the goldens are kept.
    pub previous: String,
    /// What became of the golden.
    pub fate: Fate,
    /// Whether the line's goldens were another host's (or named none) and are moving to this
    /// host whole: the model's same-host figures for them are then that other host's noise.
    pub moved_here: bool,
    /// Whether a golden asked for (a pass named, or one that moved) was not written: a timing
    /// bless that writes nothing it was asked to is a refusal, not a bless.
    pub refused: bool,
}

/// The scenes (sorted, once each) among `lines` whose timing goldens moved to this host whole
/// and whose same-host figures in `model` were not measured here: their checks read them at the
/// limits for any host until this host measures its own. `hosts` holds each backend's
/// fingerprint here, `cpu` this host's signature ([`super::cpu_signature`]).
pub fn moved_without_figures_here<'a>(
    lines: &'a [SpeedBlessed],
    model: &super::TimingNoise,
    hosts: &[(BackendKind, String)],
    cpu: &str,
) -> Vec<&'a str> {
    let measured_here = |line: &SpeedBlessed| {
        hosts
            .iter()
            .find(|(kind, _)| *kind == line.backend)
            .is_some_and(|(_, host)| {
                model.figures_measured_on_host(&line.scene, line.backend, host, cpu)
            })
    };
    let mut scenes: Vec<&str> = lines
        .iter()
        .filter(|l| l.moved_here && l.fate.written() && !measured_here(l))
        .map(|l| l.scene.as_str())
        .collect();
    scenes.sort_unstable();
    scenes.dedup();
    scenes
}

/// What a timing bless did, or in a dry run would do, with a golden.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Fate {
    /// Written over the golden there was.
    Rewritten,
    /// Written where there was none.
    Written,
    /// Would be written over the golden there is (a dry run).
    WouldBeRewritten,
    /// Would be written where there is none (a dry run).
    WouldBeWritten,
    /// Left as it was.
    Kept,
    /// Left as it was, every pass of the scene on the backend: another host's timing goldens
    /// ([`kept_as_another_hosts`]).
    KeptAsAnotherHosts,
}

impl Fate {
    /// Whether the golden was written ([`Fate::Rewritten`] or [`Fate::Written`]).
    pub fn written(self) -> bool {
        matches!(self, Fate::Rewritten | Fate::Written)
    }
}

impl std::fmt::Display for Fate {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(match self {
            Fate::Rewritten => "rewritten",
            Fate::Written => "written (new)",
            Fate::WouldBeRewritten => "would be rewritten (dry run)",
            Fate::WouldBeWritten => "would be written (new; dry run)",
            Fate::Kept | Fate::KeptAsAnotherHosts => "kept",
        })
    }
}

impl std::fmt::Display for SpeedBlessed {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self.pass {
            Some(pass) => write!(
                f,
                "{}/{pass} on {} (speed): {}; {}",
                self.scene, self.backend, self.previous, self.fate
            ),
            // A line about a whole backend says what became of it first: the why is long.
            None => write!(
                f,
                "{} on {} (speed): {}: {}",
                self.scene, self.backend, self.fate, self.previous
            ),
        }
    }
}

/// Why a bless on this host (fingerprint `host`, CPU signature `cpu`) keeps the timing goldens
/// `existing` of a scene on one backend as they are, or None when it may rewrite them: where
/// there are none yet, where this host blessed them, or where they are asked to move here
/// (`move_here`: the backend's goldens then move to this host whole). A backend's goldens are
/// one host's ratios: another CPU puts a pass x0.4 to x1.75 away, so a few passes blessed here
/// among another host's would be judged against the wrong host's figures. What to do instead
/// is said once for every such line ([`another_hosts_lines`]).
pub fn kept_as_another_hosts(
    existing: Option<&BackendTimings>,
    host: &str,
    cpu: &str,
    move_here: bool,
) -> Option<String> {
    let existing = existing?;
    if move_here || existing.blessed_on(host, cpu) {
        return None;
    }
    Some(format!(
        "blessed on another host ({}, {}); a backend's timing goldens are one host's ratios, \
         so none is rewritten from here",
        existing.blessed_by(),
        existing.blessed
    ))
}

/// The lines of a bless's [`Fate::KeptAsAnotherHosts`] among `lines`, said once: one line per
/// backend and reason naming every scene it holds for (`arguments` maps a scene to its
/// command-line argument), then what to do instead, with one command for them all. Empty where
/// there are none.
pub fn another_hosts_lines(lines: &[SpeedBlessed], arguments: &[(String, String)]) -> Vec<String> {
    let kept: Vec<&SpeedBlessed> = lines
        .iter()
        .filter(|l| l.fate == Fate::KeptAsAnotherHosts)
        .collect();
    if kept.is_empty() {
        return Vec::new();
    }
    let mut groups: Vec<(BackendKind, &str, Vec<&str>)> = Vec::new();
    for line in &kept {
        match groups
            .iter_mut()
            .find(|(backend, why, _)| *backend == line.backend && *why == line.previous)
        {
            Some((_, _, scenes)) => scenes.push(&line.scene),
            None => groups.push((line.backend, &line.previous, vec![&line.scene])),
        }
    }
    let mut said: Vec<String> = groups
        .iter()
        .map(|(backend, why, scenes)| {
            format!("{} on {backend} (speed): kept: {why}", scenes.join(", "))
        })
        .collect();
    let mut scenes: Vec<&str> = Vec::new();
    for line in &kept {
        let argument = arguments
            .iter()
            .find(|(name, _)| *name == line.scene)
            .map_or(line.scene.as_str(), |(_, argument)| argument.as_str());
        if !scenes.contains(&argument) {
            scenes.push(argument);
        }
    }
    said.push(format!(
        "note: a recorded host blesses a slowdown into another host's timing goldens, scaled by \
         its own recording (`{}` records this one); to move them to this host instead, every \
         backend's and every pass: {}",
        crate::golden::command_line::harness_command("noise --timing --record-host NAME"),
        crate::golden::command_line::move_timings_command(&scenes)
    ));
    said
}

/// Writes the timing golden of `check`'s pass, a check on a recorded host
/// ([`Tier::RecordedHost`]), in the terms of the host that blessed the section: the golden now
/// times the slowdown the check measured against this host's own recording of that golden
/// ([`TimingGoldens::record_scaled`]), `reason` beside it, on `date`. Returns the new ratio,
/// or why the check cannot be carried over (another tier, no golden or recorded reference).
pub fn record_scaled_check(
    goldens: &mut TimingGoldens,
    check: &SpeedCheck,
    date: &str,
    reason: Option<&str>,
) -> Result<f64, String> {
    if check.outcome == SpeedOutcome::MissingGolden {
        return Err(
            "no timing golden to scale (a pass new to the plan): its first golden comes from \
             the host that blessed the backend's, or with the move here (`--speed-only \
             --every-pass`)"
                .to_owned(),
        );
    }
    if let SpeedOutcome::TargetsChanged(what) = &check.outcome {
        return Err(format!(
            "{what}: a ratio at other targets does not compare with the golden, so there is no \
             slowdown to carry into the blessing host's terms; move the backend's timing goldens \
             here whole (`--speed-only --every-pass`), or bless them on the host that blessed \
             them"
        ));
    }
    let (Tier::RecordedHost, Some(reference), Some(slowdown)) =
        (check.tier, check.golden, check.slowdown())
    else {
        return Err(
            "not read against a current recording of this host, so there is no slowdown to \
             carry into the blessing host's terms"
                .to_owned(),
        );
    };
    let before = goldens
        .backends
        .get(&check.backend)
        .and_then(|b| b.passes.get(&check.pass))
        .map(|p| p.ratio)
        .ok_or_else(|| "no timing golden to scale".to_owned())?;
    let recording = check
        .noise
        .as_ref()
        .map_or("this host's recording", |(_, at)| at.as_str());
    let measured = PassTiming {
        ratio: check.ratio,
        ms: check.ms,
        floor_ms: check.ms / check.ratio,
        targets: check.targets.clone(),
        reason: reason.map(str::to_owned),
        scaled: None,
    };
    let how = format!(
        "{date}: x{slowdown:.3} against {recording} (ratio {:.3} over its median {reference:.3}) \
         times the golden before, {before:.4}",
        check.ratio
    );
    goldens
        .record_scaled(check.backend, check.pass, slowdown, &measured, how)
        .ok_or_else(|| "no timing golden to scale".to_owned())
}

/// How a timing bless may write a scene's goldens on a backend.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Writing {
    /// This host's own ratios (the section is this host's, new, or moving here whole).
    Own {
        /// Moving another host's section here: every pass, the old section replaced.
        moving: bool,
    },
    /// Another host's section, this host recorded: slowdowns against the recording, scaled
    /// into that host's terms ([`record_scaled_check`]).
    Scaled,
}

/// Which timing goldens a bless rewrites, and what it records beside them.
#[derive(Clone, Copy, Debug, Default)]
pub struct TimingBless<'a> {
    /// Every pass, also those within their limit.
    pub every_pass: bool,
    /// Where another host blessed a backend's timing goldens, move them to this host whole
    /// (every pass probed and written); otherwise they are kept. `bless --speed-only
    /// --every-pass` sets it: an image bless's `--every-pass` (after a driver change) does not.
    pub move_here: bool,
    /// Decide and print; write nothing.
    pub dry_run: bool,
    /// Why the passes written changed (`--reason`), recorded beside each.
    pub reason: Option<&'a str>,
    /// Only these passes (every one when empty), each rewritten even within its limit, as
    /// `bless --speed-only --pass` names them.
    pub passes: &'a [PassId],
}

impl TimingBless<'_> {
    /// Whether `pass` is among those asked for.
    fn names(&self, pass: PassId) -> bool {
        self.passes.is_empty() || self.passes.contains(&pass)
    }
}

/// Probes `scenes` (name, command-line argument) on each of `backends` (with its driver
/// fingerprint) [`BLESS_PROBES`] times in child processes of `exe` and rewrites the timing
/// goldens under `root` that moved beyond their limit or are missing (every one with
/// `options.every_pass`; none with `options.dry_run`).
pub fn bless_scenes(
    exe: &std::path::Path,
    root: &std::path::Path,
    scenes: &[(String, String)],
    backends: &[(BackendKind, String)],
    options: TimingBless<'_>,
    mut progress: impl FnMut(&str),
) -> Result<Vec<SpeedBlessed>, SpeedError> {
    let noise = TimingNoise::load(root)?;
    let blessed = humantime::format_rfc3339_seconds(std::time::SystemTime::now()).to_string();
    let cpu = super::cpu_signature();
    let fate = if options.dry_run {
        Fate::WouldBeRewritten
    } else {
        Fate::Rewritten
    };
    let recordings = super::recorded::load_all(root)?;
    let mut lines = Vec::new();
    for (kind, driver) in backends {
        let host = host_fingerprint(driver);
        let recorded = super::recorded::of_host(&recordings, *kind, &host, &cpu);
        // Decided before probing: a backend whose goldens are all another host's is not probed,
        // unless this host is recorded (then its slowdowns are carried over, scaled).
        let mut writable = Vec::new();
        for (scene, argument) in scenes {
            let goldens = TimingGoldens::load(root, scene)?;
            let existing = goldens.backends.get(kind);
            match kept_as_another_hosts(existing, &host, &cpu, options.move_here) {
                Some(_) if recorded.is_some() => {
                    writable.push((scene.clone(), argument.clone(), Writing::Scaled));
                }
                Some(why) => lines.push(SpeedBlessed {
                    scene: scene.clone(),
                    backend: *kind,
                    pass: None,
                    previous: why,
                    fate: Fate::KeptAsAnotherHosts,
                    moved_here: false,
                    refused: true,
                }),
                None => {
                    let moving = existing.is_some_and(|e| !e.blessed_on(&host, &cpu));
                    writable.push((scene.clone(), argument.clone(), Writing::Own { moving }));
                }
            }
        }
        if writable.is_empty() {
            continue;
        }
        let arguments: Vec<String> = writable.iter().map(|(_, a, _)| a.clone()).collect();
        let mut probes: BTreeMap<String, Vec<SceneSpeed>> = BTreeMap::new();
        for round in 1..=BLESS_PROBES {
            progress(&format!(
                "timing on {kind}, probe {round} of {BLESS_PROBES}"
            ));
            let (results, errors) = crate::measure::speed::probe_in_child(
                exe,
                &arguments,
                &[*kind],
                CHECK_ROUNDS,
                Default::default(),
                &[],
            );
            if let Some(error) = errors.first() {
                return Err(SpeedError::Probe(error.clone()));
            }
            for result in results {
                probes.entry(result.scene.clone()).or_default().push(result);
            }
        }
        for (scene, _, writing) in &writable {
            let Some(probe) = probes.get(scene).and_then(|p| median_probe(p)) else {
                return Err(SpeedError::Probe(format!(
                    "{kind}: scene {scene} was not probed"
                )));
            };
            let mut goldens = TimingGoldens::load(root, scene)?;
            // Judged as a check on this host judges it (against its recording where current).
            let checks = check_speed_with(&probe, &goldens, &noise, &host, &recordings);
            let written = match writing {
                Writing::Scaled => bless_scaled(&mut goldens, &checks, options, &blessed, fate),
                Writing::Own { moving } => {
                    let stamp = super::Stamp {
                        host: &host,
                        cpu: &cpu,
                        blessed: &blessed,
                        reason: options.reason,
                    };
                    bless_own(
                        &mut goldens,
                        &probe,
                        &checks,
                        *moving,
                        options,
                        &stamp,
                        fate,
                    )
                }
            };
            if !options.dry_run && written.iter().any(|l| l.fate.written()) {
                goldens.save(root, scene)?;
            }
            lines.extend(written);
        }
    }
    Ok(lines)
}

/// The lines of a bless of this host's own section (`moving`: another host's, moving here
/// whole): the passes that moved, every pass (`options.every_pass`, or moving), or the ones
/// named, recorded from `probe` with `stamp`; nothing with `options.dry_run`. The section is
/// replaced whole only when every pass is written (not with named passes). A move asked of
/// named passes only is kept, with why: it takes every pass.
pub fn bless_own(
    goldens: &mut TimingGoldens,
    probe: &SceneSpeed,
    checks: &[SpeedCheck],
    moving: bool,
    options: TimingBless<'_>,
    stamp: &super::Stamp<'_>,
    fate: Fate,
) -> Vec<SpeedBlessed> {
    if moving && !options.passes.is_empty() {
        return vec![SpeedBlessed {
            scene: probe.scene.clone(),
            backend: probe.backend,
            pass: None,
            previous: "another host's timing goldens move to this host whole, every pass, so \
                       not with --pass: bless without it"
                .to_owned(),
            fate: Fate::Kept,
            moved_here: false,
            refused: true,
        }];
    }
    let every_pass = options.every_pass || moving || !options.passes.is_empty();
    let mut rewrite = Vec::new();
    let mut lines = Vec::new();
    for check in checks.iter().filter(|c| options.names(c.pass)) {
        let written = every_pass || check.outcome.moved();
        if written {
            rewrite.push(check.pass);
        }
        lines.push(SpeedBlessed {
            scene: check.scene.clone(),
            backend: check.backend,
            pass: Some(check.pass),
            previous: check.describe(),
            fate: match (written, &check.outcome) {
                (false, _) => Fate::Kept,
                (true, SpeedOutcome::MissingGolden) => match fate {
                    Fate::Rewritten => Fate::Written,
                    Fate::WouldBeRewritten => Fate::WouldBeWritten,
                    other => other,
                },
                (true, _) => fate,
            },
            moved_here: moving,
            refused: false,
        });
    }
    if !rewrite.is_empty() && !options.dry_run {
        if (moving || options.every_pass) && options.passes.is_empty() {
            // Every pass is this probe's: none of another host's (or of a pass gone from the
            // plan) stays beside them.
            goldens.backends.remove(&probe.backend);
        }
        goldens.record(probe, &rewrite, stamp);
    }
    lines
}

/// The lines of a bless of another host's section from a recorded host: each pass that moved
/// beyond its limit against this host's recording, or is named, is written scaled into the
/// blessing host's terms ([`record_scaled_check`]); nothing with `options.dry_run`. What cannot
/// be scaled is kept, with why, and refused. `options.every_pass` writes no more: a pass within
/// its limit has no slowdown to carry over, only this host's run-to-run noise (and each
/// scaled pass makes every recording of it stale).
pub fn bless_scaled(
    goldens: &mut TimingGoldens,
    checks: &[SpeedCheck],
    options: TimingBless<'_>,
    date: &str,
    fate: Fate,
) -> Vec<SpeedBlessed> {
    checks
        .iter()
        .filter(|c| options.names(c.pass))
        .map(|check| {
            let mut previous = check.describe();
            let mut this_fate = Fate::Kept;
            let asked = !options.passes.is_empty() || check.outcome.moved();
            let mut refused = false;
            if asked {
                let mut scaled = goldens.clone();
                match record_scaled_check(&mut scaled, check, date, options.reason) {
                    Ok(ratio) => {
                        previous += &format!(
                            "; carried into the blessing host's terms as ratio {ratio:.4} (this \
                             host's recording of it is then of the golden before: the pass is \
                             read at the limits for any host here until this host is recorded \
                             again)"
                        );
                        if !options.dry_run {
                            *goldens = scaled;
                        }
                        this_fate = fate;
                    }
                    Err(why) => {
                        previous += &format!("; not written: {why}");
                        refused = true;
                    }
                }
            }
            SpeedBlessed {
                scene: check.scene.clone(),
                backend: check.backend,
                pass: Some(check.pass),
                previous,
                fate: this_fate,
                moved_here: false,
                refused,
            }
        })
        .collect()
}

//! Blessing timing goldens: `harness bless` probes each backend [`BLESS_PROBES`] times and
//! records, per pass, the probe with the median ratio. Like the images, only the passes whose
//! ratio moved beyond their limit (or have no golden) are rewritten, unless every pass is asked
//! for.

use std::collections::BTreeMap;

use engine::backend::BackendKind;
use engine::plan::PassId;

use super::{
    check_speed, host_fingerprint, BackendTimings, SpeedError, SpeedOutcome, TimingGoldens,
    TimingNoise, BLESS_PROBES, CHECK_ROUNDS,
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
}

/// What a timing bless did, or in a dry run would do, with a golden.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Fate {
    /// Written.
    Rewritten,
    /// Would be written (a dry run).
    WouldBeRewritten,
    /// Left as it was.
    Kept,
}

impl std::fmt::Display for Fate {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(match self {
            Fate::Rewritten => "rewritten",
            Fate::WouldBeRewritten => "would be rewritten (dry run)",
            Fate::Kept => "kept",
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
/// `existing` of a scene (its command-line `argument`) on one backend as they are, or None when
/// it may rewrite them: where there are none yet, where this host blessed them, or where they
/// are asked to move here (`move_here`: the backend's goldens then move to this host whole). A
/// backend's goldens are one host's ratios: another CPU puts a pass x0.4 to x1.75 away, so a
/// few passes blessed here among another host's would be judged against the wrong host's
/// figures.
pub fn kept_as_another_hosts(
    existing: Option<&BackendTimings>,
    host: &str,
    cpu: &str,
    move_here: bool,
    argument: &str,
) -> Option<String> {
    let existing = existing?;
    if move_here || existing.blessed_on(host, cpu) {
        return None;
    }
    Some(format!(
        "blessed on another host ({}, {}); a backend's timing goldens are one host's ratios, \
         so none is rewritten from here. To move every backend's to this host: {}",
        existing.blessed_by(),
        existing.blessed,
        crate::golden::command_line::speed_bless_command(argument, false)
    ))
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
    let mut lines = Vec::new();
    for (kind, driver) in backends {
        let host = host_fingerprint(driver);
        // Decided before probing: a backend whose goldens are all another host's is not probed.
        let mut writable = Vec::new();
        for (scene, argument) in scenes {
            let goldens = TimingGoldens::load(root, scene)?;
            let existing = goldens.backends.get(kind);
            match kept_as_another_hosts(existing, &host, &cpu, options.move_here, argument) {
                Some(why) => lines.push(SpeedBlessed {
                    scene: scene.clone(),
                    backend: *kind,
                    pass: None,
                    previous: why,
                    fate: Fate::Kept,
                    moved_here: false,
                }),
                None => {
                    // Moving another host's goldens here: every pass, the old section replaced.
                    let moving = existing.is_some_and(|e| !e.blessed_on(&host, &cpu));
                    writable.push((scene.clone(), argument.clone(), moving));
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
        for (scene, _, moving) in &writable {
            let every_pass = options.every_pass || *moving;
            let Some(probe) = probes.get(scene).and_then(|p| median_probe(p)) else {
                return Err(SpeedError::Probe(format!(
                    "{kind}: scene {scene} was not probed"
                )));
            };
            let mut goldens = TimingGoldens::load(root, scene)?;
            let checks = check_speed(&probe, &goldens, &noise, &host);
            let mut rewrite = Vec::new();
            for check in &checks {
                let moved = matches!(
                    check.outcome,
                    SpeedOutcome::Slower
                        | SpeedOutcome::Faster
                        | SpeedOutcome::MissingGolden
                        | SpeedOutcome::TargetsChanged(_)
                );
                let written = every_pass || moved;
                if written {
                    rewrite.push(check.pass);
                }
                lines.push(SpeedBlessed {
                    scene: scene.clone(),
                    backend: *kind,
                    pass: Some(check.pass),
                    previous: check.describe(),
                    fate: if written { fate } else { Fate::Kept },
                    moved_here: *moving,
                });
            }
            if !rewrite.is_empty() && !options.dry_run {
                if every_pass {
                    // Every pass is this probe's: none of another host's (or of a pass gone
                    // from the plan) stays beside them.
                    goldens.backends.remove(kind);
                }
                let stamp = super::Stamp {
                    host: &host,
                    cpu: &cpu,
                    blessed: &blessed,
                    reason: options.reason,
                };
                goldens.record(&probe, &rewrite, &stamp);
                goldens.save(root, scene)?;
            }
        }
    }
    Ok(lines)
}

//! Blessing timing goldens: `harness bless` probes each backend [`BLESS_PROBES`] times and
//! records, per pass, the probe with the median ratio. Like the images, only the passes whose
//! ratio moved beyond their limit (or have no golden) are rewritten, unless every pass is asked
//! for.

use std::collections::BTreeMap;

use engine::backend::BackendKind;
use engine::plan::PassId;

use super::{
    check_speed, host_fingerprint, SpeedError, SpeedOutcome, TimingGoldens, TimingNoise,
    BLESS_PROBES, CHECK_ROUNDS,
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

/// One line of a timing bless: a pass, its check against the old golden, and whether it was
/// (or in a dry run would be) written.
pub struct SpeedBlessed {
    /// Scene.
    pub scene: String,
    /// Backend.
    pub backend: BackendKind,
    /// Pass.
    pub pass: PassId,
    /// The new ratio against the old golden.
    pub previous: String,
    /// Whether it is rewritten.
    pub written: bool,
}

impl std::fmt::Display for SpeedBlessed {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(
            f,
            "{}/{} on {} (speed): {}; {}",
            self.scene,
            self.pass,
            self.backend,
            self.previous,
            if self.written { "rewritten" } else { "kept" }
        )
    }
}

/// Which timing goldens a bless rewrites, and what it records beside them.
#[derive(Clone, Copy, Debug, Default)]
pub struct TimingBless<'a> {
    /// Every pass, also those within their limit.
    pub every_pass: bool,
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
    let arguments: Vec<String> = scenes.iter().map(|(_, a)| a.clone()).collect();
    let blessed = humantime::format_rfc3339_seconds(std::time::SystemTime::now()).to_string();
    let mut lines = Vec::new();
    for (kind, driver) in backends {
        let host = host_fingerprint(driver);
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
        for (scene, _) in scenes {
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
                    SpeedOutcome::Slower | SpeedOutcome::Faster | SpeedOutcome::MissingGolden
                );
                let written = options.every_pass || moved;
                if written {
                    rewrite.push(check.pass);
                }
                lines.push(SpeedBlessed {
                    scene: scene.clone(),
                    backend: *kind,
                    pass: check.pass,
                    previous: check.describe(),
                    written,
                });
            }
            if !rewrite.is_empty() && !options.dry_run {
                let cpu = super::cpu_signature();
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

//! Speed ratios recorded on other hosts, `golden/evidence/<host>/timing.toml`: a source of the
//! timing-noise model's other-host figures, as host-b's renders are a source of the image model,
//! and the reference a recorded host's own checks are read against.
//!
//! A host that did not bless probes every canonical scene on each of its backends under the
//! model's own sources (repeated runs, a busy neighbour, the CPU code paths, the second Mesa),
//! each probe a fresh process, and may add the ratios of its earlier checks
//! (`harness noise --timing --record-host <name> [--history OUT]`). The file keeps every ratio
//! with the golden it was measured against. For the model, the host's factor for a pass is the
//! largest of those ratios over that golden: how far that host reads from the one that blessed,
//! for the same engine, under everything a check there may meet. For that host's own checks
//! ([`RecordedPass::reference`]), the median of its plain ratios is the reference and its own
//! spread the noise. A pass whose golden is blessed again no longer matches its recording and
//! falls back to the other-host figures there until the host is recorded again.

use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

use engine::backend::BackendKind;
use engine::plan::PassId;

use super::measure::{TimingMeasurement, TimingSource};
use super::{SpeedError, Tier, CHECK_ROUNDS};

/// The file a recorded host's ratios are kept in, in its evidence folder.
pub const RECORDED_TIMING_FILE: &str = "timing.toml";

/// The sources whose median is a recorded host's own reference: its plain probes and checks.
pub const REFERENCE_SOURCES: [&str; 2] = ["runs", CHECKS_SOURCE];
/// The sources that are this host as it is (no other driver or code path): what its own checks
/// meet, and so its own noise.
pub const OWN_SOURCES: [&str; 3] = ["runs", "busy-neighbour", CHECKS_SOURCE];

/// The most probes a recording takes per source and backend (the plain runs; the other
/// sources take as many as the model's own measurement does).
pub const RECORD_PROBES: usize = 6;

const HEADER: &str = "\
# Speed ratios recorded on another host, written by `harness noise --timing --record-host`.
# Per scene, backend and pass: each probe's ratio (a fresh process each) and the timing golden
# it was measured against. `harness noise --timing` counts the largest ratio over that golden
# as this host's factor, among the other-host figures. See harness/src/golden/speed/recorded.rs.
";

/// One pass as a recorded host measured it.
#[derive(Clone, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct RecordedPass {
    /// Each probe's ratio, per source.
    pub ratios: BTreeMap<String, Vec<f64>>,
    /// The timing golden's ratio at the time.
    pub golden: f64,
}

impl RecordedPass {
    /// The largest ratio over the golden (0 when there is none), and the source it came from.
    pub fn factor(&self) -> (f64, &str) {
        let mut worst = (0.0, "-");
        for (source, ratios) in &self.ratios {
            for &ratio in ratios {
                if ratio / self.golden > worst.0 {
                    worst = (ratio / self.golden, source.as_str());
                }
            }
        }
        worst
    }

    /// This host's own reference for the pass, when its recording was measured against
    /// `golden` (the timing golden as it is now): the median of its ratios under the plain
    /// sources ([`REFERENCE_SOURCES`]), and the largest factor above it under any of this
    /// host's own conditions ([`OWN_SOURCES`]), at least 1. `None` when the golden changed
    /// since (the recording is stale for this pass) or there are no such ratios.
    pub fn reference(&self, golden: f64) -> Option<(f64, f64)> {
        if self.golden != golden {
            return None;
        }
        let of = |names: &[&str]| -> Vec<f64> {
            names
                .iter()
                .filter_map(|n| self.ratios.get(*n))
                .flatten()
                .copied()
                .collect()
        };
        let mut plain = of(&REFERENCE_SOURCES);
        if plain.is_empty() {
            return None;
        }
        plain.sort_by(f64::total_cmp);
        let middle = plain.len() / 2;
        let median = if plain.len() % 2 == 1 {
            plain[middle]
        } else {
            (plain[middle - 1] + plain[middle]) / 2.0
        };
        let noise = of(&OWN_SOURCES)
            .into_iter()
            .fold(1.0, |worst, r| f64::max(worst, r / median));
        Some((median, noise))
    }

    /// The smallest ratio over the golden.
    pub fn lowest(&self) -> f64 {
        self.ratios
            .values()
            .flatten()
            .copied()
            .fold(f64::INFINITY, f64::min)
            / self.golden
    }
}

/// A recorded host's ratios.
#[derive(Clone, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct RecordedTimings {
    /// UTC time of the recording (RFC 3339), or of each recording it holds.
    pub recorded: String,
    /// The commit probed, when it was a git tree.
    #[serde(default)]
    pub commit: Option<String>,
    /// Probes per backend, per source.
    pub probes: BTreeMap<String, usize>,
    /// The host as each backend's speed check saw it ([`super::host_fingerprint`]).
    pub hosts: BTreeMap<BackendKind, String>,
    /// The CPU's family, model and stepping ([`super::cpu_signature`]): a check reads a pass
    /// against this recording only on the same CPU, whatever the model name says. Empty in a
    /// recording made before it was kept: then never.
    #[serde(default)]
    pub cpu: String,
    /// Per scene, backend and pass.
    pub scenes: BTreeMap<String, BTreeMap<BackendKind, BTreeMap<PassId, RecordedPass>>>,
}

impl RecordedTimings {
    /// Whether this is the recording of the host whose `kind` backend has fingerprint `host`,
    /// on CPU signature `cpu` (a known one: see [`super::cpu_known`]).
    pub fn records(&self, kind: BackendKind, host: &str, cpu: &str) -> bool {
        self.hosts
            .get(&kind)
            .is_some_and(|h| super::same_host(h, &self.cpu, host, cpu))
    }

    /// The recorded ratios of `pass` of `scene` on `kind`.
    pub fn pass(&self, scene: &str, kind: BackendKind, pass: PassId) -> Option<&RecordedPass> {
        self.scenes.get(scene)?.get(&kind)?.get(&pass)
    }

    /// The file of the host `name` under the golden root.
    pub fn path(root: &Path, name: &str) -> PathBuf {
        root.join("evidence").join(name).join(RECORDED_TIMING_FILE)
    }

    /// Reads a recording; `None` when there is none.
    pub fn load(path: &Path) -> Result<Option<Self>, SpeedError> {
        super::read_toml(path)
    }

    /// Adds an earlier recording of the same host to this one: its probes' ratios go before
    /// these, source by source, except its check history where this one took the history again
    /// (a history is read whole each time). A pass whose golden changed in between keeps only
    /// this recording's ratios (the earlier ones were measured against another golden); the
    /// passes dropped so are returned.
    pub fn absorb(&mut self, earlier: RecordedTimings) -> Vec<String> {
        let mut dropped = Vec::new();
        let replaces_checks = self.probes.contains_key(CHECKS_SOURCE);
        for (scene, backends) in earlier.scenes {
            for (backend, passes) in backends {
                for (pass, old) in passes {
                    let Some(new) = self
                        .scenes
                        .get_mut(&scene)
                        .and_then(|b| b.get_mut(&backend))
                        .and_then(|p| p.get_mut(&pass))
                    else {
                        continue;
                    };
                    if new.golden != old.golden {
                        dropped.push(format!("{scene} {backend} {pass}"));
                        continue;
                    }
                    for (source, mut ratios) in old.ratios {
                        if source == CHECKS_SOURCE && replaces_checks {
                            continue;
                        }
                        let list = new.ratios.entry(source).or_default();
                        ratios.append(list);
                        *list = ratios;
                    }
                }
            }
        }
        for (source, probes) in earlier.probes {
            if source == CHECKS_SOURCE && replaces_checks {
                continue;
            }
            *self.probes.entry(source).or_default() += probes;
        }
        self.recorded = format!("{} and {}", earlier.recorded, self.recorded);
        if self.cpu.is_empty() {
            self.cpu = earlier.cpu;
        }
        dropped
    }

    /// Writes the file atomically.
    pub fn save(&self, path: &Path) -> Result<(), SpeedError> {
        super::write_toml(path, HEADER, self)
    }

    /// Each pass's factor as a measurement of the source `name` (another host's figure).
    pub fn measurements(&self, name: &str) -> Vec<TimingMeasurement> {
        let mut out = Vec::new();
        for (scene, backends) in &self.scenes {
            for (&backend, passes) in backends {
                for (&pass, recorded) in passes {
                    out.push(TimingMeasurement {
                        source: name.to_owned(),
                        tier: Tier::OtherHost,
                        scene: scene.clone(),
                        backend,
                        pass,
                        factor: recorded.factor().0,
                    });
                }
            }
        }
        out
    }

    /// What the source is, for the model's list of sources.
    pub fn description(&self, name: &str) -> String {
        let cpu = self
            .hosts
            .values()
            .next()
            .and_then(|h| h.rsplit_once("| CPU "))
            .map_or("an unknown CPU", |(_, cpu)| cpu);
        format!(
            "speed ratios recorded on {cpu} ({} probes per backend under the model's sources, {}; golden/evidence/{name}/{RECORDED_TIMING_FILE})",
            self.probes.values().sum::<usize>(),
            self.recorded.get(..10).unwrap_or(&self.recorded)
        )
    }
}

/// Every recorded host under `root`'s evidence folder, by name, as timing sources with their
/// measurements. A file that cannot be read is an error naming it.
pub fn recorded_hosts(
    root: &Path,
) -> Result<Vec<(TimingSource, Vec<TimingMeasurement>)>, SpeedError> {
    Ok(load_all(root)?
        .into_iter()
        .map(|(name, recorded)| {
            let source = TimingSource {
                name: name.clone(),
                description: recorded.description(&name),
                tier: Tier::OtherHost,
                env: Vec::new(),
                busy: false,
                probes: 0,
            };
            let measurements = recorded.measurements(&name);
            (source, measurements)
        })
        .collect())
}

/// How a check names the recording of `host` it was read against: "host-d's recording".
pub fn label(host: &str) -> String {
    format!("{host}'s recording")
}

/// The host a [`label`] names.
pub fn host_of_label(label: &str) -> Option<&str> {
    label.strip_suffix("'s recording")
}

/// The recording among `recordings` (named, as [`load_all`] reads them) of this host:
/// fingerprint `host` on `kind`, CPU signature `cpu` ([`RecordedTimings::records`]).
pub fn of_host<'a>(
    recordings: &'a [(String, RecordedTimings)],
    kind: BackendKind,
    host: &str,
    cpu: &str,
) -> Option<(&'a str, &'a RecordedTimings)> {
    recordings
        .iter()
        .find(|(_, r)| r.records(kind, host, cpu))
        .map(|(name, r)| (name.as_str(), r))
}

/// Every recording under `root`'s evidence folder, by host name, checked: every ratio and
/// golden a positive number. A file that cannot be read is an error naming it.
pub fn load_all(root: &Path) -> Result<Vec<(String, RecordedTimings)>, SpeedError> {
    let mut hosts = Vec::new();
    let Ok(entries) = std::fs::read_dir(root.join("evidence")) else {
        return Ok(hosts);
    };
    let mut names: Vec<String> = entries
        .filter_map(Result::ok)
        .filter(|e| e.path().join(RECORDED_TIMING_FILE).is_file())
        .filter_map(|e| e.file_name().to_str().map(str::to_owned))
        .collect();
    names.sort();
    for name in names {
        let path = RecordedTimings::path(root, &name);
        let recorded: RecordedTimings =
            super::read_toml(&path)?.ok_or_else(|| SpeedError::File {
                path: path.clone(),
                message: "disappeared while being read".to_owned(),
            })?;
        if let Some((scene, backend, pass)) = recorded.scenes.iter().find_map(|(s, b)| {
            b.iter().find_map(|(k, p)| {
                p.iter()
                    .find(|(_, r)| {
                        !(r.golden.is_finite() && r.golden > 0.0)
                            || r.ratios.values().all(Vec::is_empty)
                            || r.ratios
                                .values()
                                .flatten()
                                .any(|x| !(x.is_finite() && *x > 0.0))
                    })
                    .map(|(pass, _)| (s.clone(), *k, *pass))
            })
        }) {
            return Err(SpeedError::File {
                path,
                message: format!(
                    "{scene} {backend} {pass}: ratios and golden must be positive numbers, at least one ratio"
                ),
            });
        }
        hosts.push((name, recorded));
    }
    Ok(hosts)
}

/// The source name of the ratios a recording takes from this host's check history.
pub const CHECKS_SOURCE: &str = "checks";

/// Records this host: `scenes` (names and arguments) probed on each of `backends` (with the
/// host each one's check sees) under every one of `sources` that has probes, at most
/// `most_probes` per source, each in a fresh process, against the goldens under `root`; and
/// the ratios of `history`'s checks of the same commit on the same host (source
/// [`CHECKS_SOURCE`]: the drift of an unchanged build over many runs). With the probes that
/// failed.
#[allow(clippy::too_many_arguments)]
pub fn record(
    exe: &Path,
    root: &Path,
    scenes: &[(String, String)],
    backends: &[(BackendKind, String)],
    sources: &[TimingSource],
    most_probes: usize,
    history: &[super::history::HistoryEntry],
    mut progress: impl FnMut(&str),
) -> (RecordedTimings, Vec<String>) {
    let (goldens, mut errors) = super::measure::load_goldens(root, scenes);
    let arguments: Vec<String> = scenes.iter().map(|(_, a)| a.clone()).collect();
    let sources: Vec<(&TimingSource, usize)> = sources
        .iter()
        .filter(|s| s.probes > 0)
        .map(|s| (s, s.probes.min(most_probes)))
        .collect();
    let mut recorded = RecordedTimings {
        recorded: humantime::format_rfc3339_seconds(std::time::SystemTime::now()).to_string(),
        commit: super::history::commit(),
        probes: sources.iter().map(|(s, n)| (s.name.clone(), *n)).collect(),
        hosts: backends.iter().cloned().collect(),
        cpu: super::cpu_signature(),
        scenes: BTreeMap::new(),
    };
    for (source, probes) in sources {
        for (kind, _) in backends {
            for index in 1..=probes {
                progress(&format!(
                    "{} on {kind}, probe {index} of {probes}",
                    source.name
                ));
                let _neighbour = source.busy.then(super::measure::BusyNeighbour::start);
                let (speeds, failed) = crate::measure::speed::probe_in_child(
                    exe,
                    &arguments,
                    &[*kind],
                    CHECK_ROUNDS,
                    Default::default(),
                    &source.env,
                );
                errors.extend(failed.into_iter().map(|e| format!("{}: {e}", source.name)));
                for speed in speeds {
                    let Some(golden) = goldens.get(&speed.scene).and_then(|g| g.backends.get(kind))
                    else {
                        continue;
                    };
                    for pass in &speed.passes {
                        let (Some(ratio), Some(g)) = (pass.ratio(), golden.passes.get(&pass.pass))
                        else {
                            continue;
                        };
                        if let Some(why) =
                            super::measure::targets_changed(&speed.scene, *kind, pass, g)
                        {
                            if !errors.contains(&why) {
                                errors.push(why);
                            }
                            continue;
                        }
                        recorded
                            .scenes
                            .entry(speed.scene.clone())
                            .or_default()
                            .entry(*kind)
                            .or_default()
                            .entry(pass.pass)
                            .or_insert_with(|| RecordedPass {
                                ratios: BTreeMap::new(),
                                golden: g.ratio,
                            })
                            .ratios
                            .entry(source.name.clone())
                            .or_default()
                            .push(super::measure::ceil4(ratio));
                    }
                }
            }
        }
    }
    let commit = recorded.commit.clone();
    let mut checks = 0;
    for entry in history {
        if entry.command != "check" || commit.is_none() || entry.commit != commit {
            continue;
        }
        let mut counted = false;
        for (kind, host) in backends {
            if entry.hosts.get(kind) != Some(host) {
                continue;
            }
            for ratio in entry.ratios.iter().filter(|r| r.backend == *kind) {
                let Some(pass) = recorded
                    .scenes
                    .get_mut(&ratio.scene)
                    .and_then(|b| b.get_mut(kind))
                    .and_then(|p| p.get_mut(&ratio.pass))
                else {
                    continue;
                };
                counted = true;
                pass.ratios
                    .entry(CHECKS_SOURCE.to_owned())
                    .or_default()
                    .push(super::measure::ceil4(ratio.ratio));
            }
        }
        checks += usize::from(counted);
    }
    if checks > 0 {
        recorded.probes.insert(CHECKS_SOURCE.to_owned(), checks);
    }
    (recorded, errors)
}

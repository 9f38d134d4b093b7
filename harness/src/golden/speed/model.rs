//! `golden/timing-noise.toml`: the timing-noise model, per scene, backend and pass, written by
//! `harness noise --timing --write`, and the limits derived from it.

use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

use engine::backend::BackendKind;
use engine::plan::PassId;

use super::{SpeedError, DEFAULT_TIMING_MARGIN, MIN_NOISE, MIN_NOISE_SHORT, SHORT_PASS_MS};

/// The timing-noise model's file, in the golden folder.
pub const TIMING_NOISE_FILE: &str = "timing-noise.toml";

const HEADER: &str = "\
# The timing-noise model, written by `harness noise --timing --write`.
# Per scene, backend and pass: the largest factor an unchanged build's speed ratio came out
# above its golden, under this host's sources (`host`: repeated runs, a busy neighbour) and
# under another host's (`drivers`: llvmpipe's other CPU code paths, the second Mesa, and the
# hosts recorded in golden/evidence/), with where each was measured. A check's limit is
# max(noise, min_noise) ^ margin (on the log scale, margin x the noise); on a host that did not
# bless, the `drivers` figure counts too. `measured_on`: per scene and backend, the host whose
# probes gave the `host` figures; only a check there reads them as its own noise.
# See harness/src/golden/speed/mod.rs.
";

/// Which of a pass's figures a check's limit comes from.
#[derive(Clone, Copy, Debug, PartialEq, Eq, serde::Serialize, serde::Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum Tier {
    /// The host that blessed the goldens (same driver fingerprint and CPU): its own noise.
    SameHost,
    /// Another host: its noise and the drivers' too.
    OtherHost,
    /// A host recorded in golden/evidence/ (same fingerprint): checked against its own
    /// recorded ratios and their spread ([`super::recorded`]).
    RecordedHost,
    /// The host that blessed, where the model's same-host figures were measured on another
    /// (goldens moved here with `bless --speed-only --every-pass`): its goldens, at the limits
    /// for any host, until `noise --timing --write` measures this host's noise.
    MovedHere,
}

impl Tier {
    /// Whether the goldens checked are this host's own (it blessed them): a timing bless or
    /// accept here writes them, and a speed-up is this host's to bless.
    pub fn blessed_here(self) -> bool {
        matches!(self, Tier::SameHost | Tier::MovedHere)
    }

    /// Whether a timing bless or accept on this host writes the goldens checked: its own
    /// ([`Tier::blessed_here`]), or another host's read against this host's current recording,
    /// a slowdown then carried into that host's terms
    /// ([`record_scaled_check`](super::record_scaled_check)). At [`Tier::OtherHost`] only a
    /// move of the whole backend here (`--speed-only --every-pass`) writes.
    pub fn bless_writes_here(self) -> bool {
        self.blessed_here() || self == Tier::RecordedHost
    }
}

/// One pass's measured timing noise.
#[derive(Clone, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct PassNoise {
    /// Largest factor above the golden under this host's sources.
    #[serde(deserialize_with = "super::positive_finite")]
    pub host: f64,
    /// Where it was measured (`<source>`).
    pub host_at: String,
    /// Largest factor above the golden under another host's sources.
    #[serde(deserialize_with = "super::positive_finite")]
    pub drivers: f64,
    /// Where it was measured.
    pub drivers_at: String,
}

impl PassNoise {
    /// The noise a check in `tier` allows for, and where it was measured.
    pub fn noise(&self, tier: Tier) -> (f64, &str) {
        match tier {
            Tier::OtherHost | Tier::MovedHere if self.drivers > self.host => {
                (self.drivers, &self.drivers_at)
            }
            _ => (self.host, &self.host_at),
        }
    }
}

/// The timing-noise model.
#[derive(Clone, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct TimingNoise {
    /// `ln limit = margin x ln noise`.
    pub margin: f64,
    /// The smallest noise factor a limit is derived from.
    pub min_noise: f64,
    /// The command that regenerates the model.
    #[serde(default)]
    pub regenerate: String,
    /// What each source is (name: description).
    #[serde(default)]
    pub sources: BTreeMap<String, String>,
    /// Per scene and backend, the host whose sources gave the same-host figures (`host`), as
    /// `noise --timing --write` found it. Only there are they that host's own noise: a check
    /// reads them in [`Tier::SameHost`] only on this host, so goldens moved to another host
    /// (`bless --speed-only --every-pass`) are read at the limits for any host until the
    /// model is measured there too.
    #[serde(default)]
    pub measured_on: BTreeMap<String, BTreeMap<BackendKind, MeasuredOn>>,
    /// Per scene, backend and pass.
    #[serde(default)]
    pub scenes: BTreeMap<String, BTreeMap<BackendKind, BTreeMap<PassId, PassNoise>>>,
}

/// The host a scene's same-host figures on one backend were measured on.
#[derive(Clone, Debug, PartialEq, Eq, serde::Serialize, serde::Deserialize)]
pub struct MeasuredOn {
    /// The host's fingerprint for the backend ([`super::host_fingerprint`]).
    pub host: String,
    /// Its CPU signature ([`super::cpu_signature`]).
    pub cpu: String,
}

impl Default for TimingNoise {
    fn default() -> Self {
        Self {
            margin: DEFAULT_TIMING_MARGIN,
            min_noise: MIN_NOISE,
            regenerate: REGENERATE.to_owned(),
            sources: BTreeMap::new(),
            measured_on: BTreeMap::new(),
            scenes: BTreeMap::new(),
        }
    }
}

/// The command that regenerates the model.
pub const REGENERATE: &str =
    "scripts/mesa-backports.sh && cargo run -p harness -- noise --timing --write";

impl TimingNoise {
    /// The file under the golden root.
    pub fn path(root: &Path) -> PathBuf {
        root.join(TIMING_NOISE_FILE)
    }

    /// Reads the model; none yet is an empty one (every pass then borrows nothing and is
    /// untimed, with the reason).
    pub fn load(root: &Path) -> Result<Self, SpeedError> {
        let path = Self::path(root);
        let Some(model) = super::read_toml::<Self>(&path)? else {
            return Ok(Self::default());
        };
        if !(model.margin >= 1.0 && model.min_noise > 1.0) {
            return Err(SpeedError::File {
                path,
                message: format!(
                    "margin must be at least 1 and min_noise above 1 (they are {} and {})",
                    model.margin, model.min_noise
                ),
            });
        }
        // The smallest limit, min_noise ^ margin: infinite, no slowdown could exceed any limit.
        let floor = model.min_noise.powf(model.margin);
        if !floor.is_finite() {
            return Err(SpeedError::File {
                path,
                message: format!(
                    "margin {} makes even the smallest limit (min_noise {} ^ margin) x{floor}, \
                     which no slowdown can exceed",
                    model.margin, model.min_noise
                ),
            });
        }
        Ok(model)
    }

    /// Writes the model atomically; refuses, writing nothing, a figure that is not a finite
    /// positive number (what reading it back would refuse, leaving every speed check without
    /// a model).
    pub fn save(&self, root: &Path) -> Result<(), SpeedError> {
        for (scene, backends) in &self.scenes {
            for (backend, passes) in backends {
                for (pass, n) in passes {
                    // What reading it back would refuse (`positive_finite`).
                    if !(super::is_positive_finite(n.host) && super::is_positive_finite(n.drivers))
                    {
                        return Err(SpeedError::File {
                            path: Self::path(root),
                            message: format!(
                                "not written: {scene} {backend} {pass} has no figure for a tier \
                                 (host x{}, drivers x{}); measure both tiers' sources",
                                n.host, n.drivers
                            ),
                        });
                    }
                }
            }
        }
        super::write_toml(&Self::path(root), HEADER, self)
    }

    /// Whether `scene`'s same-host figures on `backend` were measured on this host (`host`,
    /// `cpu`): a model that names no host for them (written before hosts were kept), or
    /// another, or a CPU it could not read, gives no host its same-host tier.
    pub fn measured_on_host(
        &self,
        scene: &str,
        backend: BackendKind,
        host: &str,
        cpu: &str,
    ) -> bool {
        self.measured_on
            .get(scene)
            .and_then(|b| b.get(&backend))
            .is_some_and(|m| super::same_host(&m.host, &m.cpu, host, cpu))
    }

    /// Whether the same-host figures a check of `scene` on `backend` reads were measured on
    /// this host: its own ([`TimingNoise::measured_on_host`]), or, for a scene the model has
    /// no figures of (one outside the canonical set, which borrows every scene's largest:
    /// [`TimingNoise::figures`]), those of every scene it borrows from.
    pub fn figures_measured_on_host(
        &self,
        scene: &str,
        backend: BackendKind,
        host: &str,
        cpu: &str,
    ) -> bool {
        if self
            .scenes
            .get(scene)
            .is_some_and(|b| b.contains_key(&backend))
        {
            return self.measured_on_host(scene, backend, host, cpu);
        }
        let mut lenders = self
            .scenes
            .iter()
            .filter(|(_, b)| b.contains_key(&backend))
            .map(|(s, _)| s)
            .peekable();
        lenders.peek().is_some() && lenders.all(|s| self.measured_on_host(s, backend, host, cpu))
    }

    /// Records that `scene`'s same-host figures on `backend` were measured on `host`, `cpu`
    /// (what `noise --timing --write` does for the goldens this host blessed, after probing
    /// this host's sources).
    pub fn stamp_measured_on(&mut self, scene: &str, backend: BackendKind, host: &str, cpu: &str) {
        self.measured_on
            .entry(scene.to_owned())
            .or_default()
            .insert(
                backend,
                MeasuredOn {
                    host: host.to_owned(),
                    cpu: cpu.to_owned(),
                },
            );
    }

    /// The figures of one pass: its own, or where the scene has none (a scene outside the
    /// canonical set) the largest of the same backend and pass over the scenes that have them,
    /// marked borrowed (true).
    pub fn figures(
        &self,
        scene: &str,
        backend: BackendKind,
        pass: PassId,
    ) -> Option<(PassNoise, bool)> {
        if let Some(own) = self
            .scenes
            .get(scene)
            .and_then(|b| b.get(&backend))
            .and_then(|p| p.get(&pass))
        {
            return Some((own.clone(), false));
        }
        let others = self
            .scenes
            .values()
            .filter_map(|b| b.get(&backend).and_then(|p| p.get(&pass)));
        others
            .fold(None::<PassNoise>, |worst, n| match worst {
                None => Some(n.clone()),
                Some(w) => Some(PassNoise {
                    host: w.host.max(n.host),
                    host_at: if n.host > w.host {
                        n.host_at.clone()
                    } else {
                        w.host_at
                    },
                    drivers: w.drivers.max(n.drivers),
                    drivers_at: if n.drivers > w.drivers {
                        n.drivers_at.clone()
                    } else {
                        w.drivers_at
                    },
                }),
            })
            .map(|n| (n, true))
    }

    /// The limit (a factor) for a noise figure: `max(noise, min_noise) ^ margin`.
    pub fn limit(&self, noise: f64) -> f64 {
        noise.max(self.min_noise).powf(self.margin)
    }

    /// The limit for a pass that takes `ms`: as [`TimingNoise::limit`], with the noise at
    /// least [`MIN_NOISE_SHORT`] for a pass under [`SHORT_PASS_MS`].
    pub fn limit_for(&self, noise: f64, ms: f64) -> f64 {
        let floor = if ms < SHORT_PASS_MS {
            MIN_NOISE_SHORT.max(self.min_noise)
        } else {
            self.min_noise
        };
        noise.max(floor).powf(self.margin)
    }
}

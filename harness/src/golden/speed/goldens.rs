//! `golden/<scene>/timing.toml`: a scene's timing goldens, one section per backend, blessed
//! with its images.

use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

use engine::backend::BackendKind;
use engine::plan::PassId;

use super::SpeedError;
use crate::measure::speed::SceneSpeed;

/// The timing goldens' file name in a scene's golden folder.
pub const TIMING_FILE: &str = "timing.toml";

const HEADER: &str = "\
# Timing goldens, written by `harness bless` (see harness/src/golden/speed/mod.rs).
# Per backend and pass: the speed ratio `harness check` compares (the pass submitted alone,
# its fastest time over its floor's fastest, one rasterizer thread). `ms`, `floor_ms` and
# `host` are for information only: milliseconds do not travel between hosts, ratios do.
# `targets` is what the pass and its floor write: a ratio compares only at the same targets.
";

/// One pass's timing golden.
#[derive(Clone, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct PassTiming {
    /// The speed ratio.
    #[serde(deserialize_with = "super::positive_finite")]
    pub ratio: f64,
    /// The pass's fastest time, ms (information).
    pub ms: f64,
    /// Its floor's fastest time, ms (information).
    pub floor_ms: f64,
    /// What the pass and its floor wrote ([`engine::plan::RenderPlan::written_targets`]): a
    /// probe of other targets is not compared with this ratio. Absent in goldens blessed before
    /// it was kept (then nothing is compared but the ratio).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub targets: Option<String>,
    /// Why the pass's cost changed, as the person blessing said it (`harness bless --reason`);
    /// dropped when the pass is recorded again without one.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub reason: Option<String>,
    /// Where the ratio was not measured on the blessing host but scaled into its terms: the
    /// recorded host whose slowdown (against its own recording of the golden before) was
    /// applied to that golden, as [`TimingGoldens::record_scaled`] wrote it. Dropped when the
    /// pass is measured again.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub scaled: Option<String>,
}

/// Who, where and why a timing bless records ([`TimingGoldens::record`]).
#[derive(Clone, Copy, Debug)]
pub struct Stamp<'a> {
    /// The blessing host's fingerprint ([`super::host_fingerprint`]).
    pub host: &'a str,
    /// Its CPU signature ([`super::cpu_signature`]).
    pub cpu: &'a str,
    /// UTC time of the bless (RFC 3339).
    pub blessed: &'a str,
    /// Why the passes written changed (`--reason`), recorded beside each.
    pub reason: Option<&'a str>,
}

/// One backend's timing goldens.
#[derive(Clone, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct BackendTimings {
    /// UTC time of the bless (RFC 3339).
    pub blessed: String,
    /// The host that blessed ([`super::host_fingerprint`]).
    pub host: String,
    /// Its CPU's family, model and stepping ([`super::cpu_signature`]): the fingerprint's model
    /// name is generic under many hypervisors ("AMD EPYC" covers several generations). Empty
    /// in goldens blessed before it was kept: then no host can show that it blessed them.
    #[serde(default, skip_serializing_if = "String::is_empty")]
    pub cpu: String,
    /// Rounds the probe timed.
    pub rounds: usize,
    /// Per pass.
    pub passes: BTreeMap<PassId, PassTiming>,
}

impl BackendTimings {
    /// Whether these goldens were blessed on the host with fingerprint `host` and CPU
    /// signature `cpu`. Goldens that kept no signature were blessed on no host a check can
    /// name: a 2-vCPU "AMD EPYC" of another generation (family 26, 2026-11-27) has the
    /// blessing EPYC's fingerprint, and its ratios lay up to x1.39 from the goldens, next to
    /// the blessing host's limits of x1.44.
    pub fn blessed_on(&self, host: &str, cpu: &str) -> bool {
        super::same_host(&self.host, &self.cpu, host, cpu)
    }

    /// Where these goldens were blessed, as a refusal names it: the host's fingerprint and
    /// CPU, or that they keep no CPU (so no host is taken for the one that blessed them).
    pub fn blessed_by(&self) -> String {
        if super::cpu_known(&self.cpu) {
            format!("{}, {}", self.host, self.cpu)
        } else {
            format!(
                "{}, a CPU they do not record (blessed before the CPU signature was kept, so \
                 no host is taken for the one that blessed them)",
                self.host
            )
        }
    }
}

/// A scene's timing goldens, per backend.
#[derive(Clone, Debug, Default, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct TimingGoldens {
    /// Per backend.
    #[serde(flatten)]
    pub backends: BTreeMap<BackendKind, BackendTimings>,
}

impl TimingGoldens {
    /// The first of `hosts` (each backend with this host's fingerprint for it) whose goldens
    /// here were blessed on another host, or on no host a check can name (no CPU signature):
    /// where this host's probes are another host's figures, not its own noise.
    pub fn blessed_elsewhere<'a>(
        &'a self,
        hosts: &[(BackendKind, String)],
        cpu: &str,
    ) -> Option<(BackendKind, &'a BackendTimings)> {
        hosts.iter().find_map(|(kind, host)| {
            self.backends
                .get(kind)
                .filter(|g| !g.blessed_on(host, cpu))
                .map(|g| (*kind, g))
        })
    }

    /// The file of `scene` under the golden root.
    pub fn path(root: &Path, scene: &str) -> PathBuf {
        root.join(scene).join(TIMING_FILE)
    }

    /// Reads a scene's timing goldens; none yet is an empty set.
    pub fn load(root: &Path, scene: &str) -> Result<Self, SpeedError> {
        Ok(super::read_toml(&Self::path(root, scene))?.unwrap_or_default())
    }

    /// Writes them atomically (a temporary file renamed over the old one).
    pub fn save(&self, root: &Path, scene: &str) -> Result<(), SpeedError> {
        super::write_toml(&Self::path(root, scene), HEADER, self)
    }

    /// Records `probe`'s passes for its backend: every pass (`only` empty) or those in `only`,
    /// keeping the others' goldens, stamped with `stamp` (its reason beside each pass written).
    pub fn record(&mut self, probe: &SceneSpeed, only: &[PassId], stamp: &Stamp<'_>) {
        let entry = self
            .backends
            .entry(probe.backend)
            .or_insert_with(|| BackendTimings {
                blessed: String::new(),
                host: String::new(),
                cpu: String::new(),
                rounds: probe.rounds,
                passes: BTreeMap::new(),
            });
        entry.blessed = stamp.blessed.to_owned();
        entry.host = stamp.host.to_owned();
        entry.cpu = stamp.cpu.to_owned();
        // The rounds of the probe that wrote the section; a few passes written into it (an
        // accepted check's one sample) leave the figure of the rest.
        if only.is_empty() || entry.passes.is_empty() {
            entry.rounds = probe.rounds;
        }
        for pass in &probe.passes {
            if !only.is_empty() && !only.contains(&pass.pass) {
                continue;
            }
            let (Some(ratio), Some(ms), Some(floor_ms)) =
                (pass.ratio(), pass.min_ms(), pass.floor_min_ms())
            else {
                continue;
            };
            entry.passes.insert(
                pass.pass,
                PassTiming {
                    ratio: round(ratio, 4),
                    ms: round(ms, 3),
                    floor_ms: round(floor_ms, 3),
                    targets: pass.targets.clone(),
                    reason: stamp.reason.map(str::to_owned),
                    scaled: None,
                },
            );
        }
    }

    /// Writes `pass`'s golden on `backend` as `slowdown` times the golden there now: a slowdown
    /// measured on a recorded host against its own recording of that golden (its ratio over
    /// the median of its recorded ones), carried into the blessing host's terms. The section's
    /// host, CPU and time stay the blessing host's, `ms` and `floor_ms` are the recorded host's
    /// (information only), and `scaled` says where the figure came from. `None` (nothing
    /// written) where the pass has no golden to scale.
    pub fn record_scaled(
        &mut self,
        backend: BackendKind,
        pass: PassId,
        slowdown: f64,
        measured: &PassTiming,
        scaled: String,
    ) -> Option<f64> {
        let timing = self.backends.get_mut(&backend)?.passes.get_mut(&pass)?;
        let ratio = round(timing.ratio * slowdown, 4);
        *timing = PassTiming {
            ratio,
            ms: round(measured.ms, 3),
            floor_ms: round(measured.floor_ms, 3),
            scaled: Some(scaled),
            ..measured.clone()
        };
        Some(ratio)
    }
}

/// `x` to `digits` decimals, so the file reads well; no limit depends on the fifth digit.
fn round(x: f64, digits: i32) -> f64 {
    (x * 10f64.powi(digits)).round() / 10f64.powi(digits)
}

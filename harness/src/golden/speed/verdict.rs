//! A speed verdict per scene, backend and pass: the probe's ratio against its timing golden,
//! scored against the limit from the timing-noise model.

use engine::backend::BackendKind;
use engine::plan::PassId;

use super::recorded::RecordedTimings;
use super::{Tier, TimingGoldens, TimingNoise, MIN_NOISE_RECORDED, MIN_PASS_MS, MUST_CATCH};
use crate::measure::speed::SceneSpeed;

/// What a speed check found.
#[derive(Clone, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
#[serde(tag = "verdict", content = "detail", rename_all = "kebab-case")]
pub enum SpeedOutcome {
    /// Within its limit.
    Passed,
    /// Slower than its golden beyond the limit: a failure.
    Slower,
    /// Faster than its golden beyond the limit: a note suggesting a bless.
    Faster,
    /// Not checked, and why (too short, too noisy on this host).
    Untimed(String),
    /// No timing golden for this backend and pass: a failure, like a missing image golden.
    MissingGolden,
    /// The pass writes other targets than when its timing golden was blessed (what they were
    /// and are): its floor writes them too, so the ratios do not compare (a smaller shadow map
    /// shrinks the floor more than the pass and reads as a slowdown). A failure, like an image
    /// golden of another size: bless the timing with the change.
    TargetsChanged(String),
}

impl SpeedOutcome {
    /// Whether the pass moved as a bless or an accept writes it: beyond its limit either way,
    /// without a golden, or at other targets than its golden's.
    pub fn moved(&self) -> bool {
        matches!(
            self,
            SpeedOutcome::Slower
                | SpeedOutcome::Faster
                | SpeedOutcome::MissingGolden
                | SpeedOutcome::TargetsChanged(_)
        )
    }

    /// The verdict as one word, as the console, the summary and the review page show it.
    pub fn label(&self) -> &'static str {
        match self {
            SpeedOutcome::Passed => "ok",
            SpeedOutcome::Slower => "SLOWER",
            SpeedOutcome::Faster => "faster",
            SpeedOutcome::Untimed(_) => "untimed",
            SpeedOutcome::MissingGolden => "MISSING",
            SpeedOutcome::TargetsChanged(_) => "TARGETS",
        }
    }
}

/// One speed check.
#[derive(Clone, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct SpeedCheck {
    /// Scene.
    pub scene: String,
    /// Backend.
    pub backend: BackendKind,
    /// Pass.
    pub pass: PassId,
    /// The probe's speed ratio.
    pub ratio: f64,
    /// The pass's fastest time, ms.
    pub ms: f64,
    /// What the pass wrote ([`PassSpeed::targets`](crate::measure::speed::PassSpeed::targets)),
    /// which accepting this check's ratio records beside it.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub targets: Option<String>,
    /// In the speed self-test, the slowdown its injection delivered in the probe's own process
    /// ([`PassSpeed::delivered`](crate::measure::speed::PassSpeed::delivered)).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub delivered: Option<f64>,
    /// The golden ratio.
    pub golden: Option<f64>,
    /// The limit, a factor (ratio / golden above it fails).
    pub limit: Option<f64>,
    /// The noise the limit came from, and where it was measured.
    pub noise: Option<(f64, String)>,
    /// Whether the noise figures were borrowed from other scenes.
    pub borrowed: bool,
    /// Which figures the limit counts.
    pub tier: Tier,
    /// The verdict.
    pub outcome: SpeedOutcome,
}

impl SpeedCheck {
    /// ratio / golden: above 1 slower (None without a golden, or where the pass's targets
    /// changed since it: the two ratios do not compare).
    pub fn slowdown(&self) -> Option<f64> {
        if matches!(self.outcome, SpeedOutcome::TargetsChanged(_)) {
            return None;
        }
        self.golden.map(|g| self.ratio / g)
    }

    /// `ln(slowdown) / ln(limit)`: 1 at the limit, negative when faster.
    pub fn score(&self) -> Option<f64> {
        let (slowdown, limit) = (self.slowdown()?, self.limit?);
        (limit > 1.0).then(|| slowdown.ln() / limit.ln())
    }

    /// Whether a timing bless on this host writes this check's golden: at a tier whose bless
    /// writes here ([`Tier::bless_writes_here`]), except a recorded host's check of a pass whose
    /// targets changed (no slowdown to carry over to the blessing host: only a move writes it).
    pub fn bless_writes_here(&self) -> bool {
        self.tier.bless_writes_here()
            && !(self.tier == Tier::RecordedHost
                && matches!(self.outcome, SpeedOutcome::TargetsChanged(_)))
    }

    /// Whether the pass has no verdict at this tier though it was compared: untimed (too short
    /// or too noisy), or a limit too wide to catch a doubling ([`MUST_CATCH`]; such a pass still
    /// fails beyond it).
    pub fn untimed(&self) -> bool {
        match (&self.outcome, self.limit) {
            (SpeedOutcome::Untimed(_), _) => true,
            (SpeedOutcome::MissingGolden | SpeedOutcome::TargetsChanged(_), _) | (_, None) => false,
            (_, Some(limit)) => limit >= MUST_CATCH,
        }
    }

    /// Whether this check fails the run.
    pub fn failed(&self) -> bool {
        matches!(
            self.outcome,
            SpeedOutcome::Slower | SpeedOutcome::MissingGolden | SpeedOutcome::TargetsChanged(_)
        )
    }

    /// The check in one line, standing alone (a JUnit message, the review page's failures, a
    /// bless line): [`Self::measurement`] and, where it moved, the verdict in words.
    pub fn describe(&self) -> String {
        let verdict = match self.outcome {
            SpeedOutcome::Slower => " SLOWER",
            SpeedOutcome::Faster if self.tier == Tier::OtherHost => {
                " faster (this host did not bless: ratios differ between hosts)"
            }
            SpeedOutcome::Faster if self.tier == Tier::RecordedHost => {
                " faster than this host's recording: bless if intended"
            }
            SpeedOutcome::Faster => " faster: bless if intended",
            _ => "",
        };
        let measurement = self.measurement();
        if measurement.is_empty() {
            return measurement;
        }
        format!("{measurement}{verdict}")
    }

    /// The value against the limit, or why there is none, without the verdict: the console
    /// table's value column, beside its result column (the notes under it say what to do).
    pub fn measurement(&self) -> String {
        match (&self.outcome, self.slowdown(), self.limit) {
            (SpeedOutcome::Untimed(why), ..) => format!("untimed: {why}"),
            (SpeedOutcome::MissingGolden, ..) => {
                format!(
                    "no timing golden (ratio {:.3}, {:.2} ms)",
                    self.ratio, self.ms
                )
            }
            (SpeedOutcome::TargetsChanged(what), ..) => format!(
                "not comparable: {what}; its floor writes the same targets, so its ratio to the \
                 floor compares only at equal targets: bless its timing with the change ({:.2} \
                 ms now)",
                self.ms
            ),
            (_, Some(slowdown), Some(limit)) => {
                let noise = self
                    .noise
                    .as_ref()
                    .map(|(n, from)| noise_words(*n, from, self.borrowed))
                    .unwrap_or_default();
                let of = if self.tier == Tier::RecordedHost {
                    "this host's recording"
                } else {
                    "golden"
                };
                format!(
                    "x{slowdown:.3} of {of} (limit x{limit:.2}, {:.2} of it; {noise}; {:.2} ms)",
                    self.score().unwrap_or(0.0),
                    self.ms
                )
            }
            _ => String::new(),
        }
    }
}

/// A limit's noise figure and where it was measured, as the console and the review page show
/// it, from the source that gave the largest spread: "noise x1.21 from runs", "noise x1.12 from
/// host-d's recording", with ", borrowed" where other scenes lent the figure.
pub fn noise_words(noise: f64, from: &str, borrowed: bool) -> String {
    let borrowed = if borrowed { ", borrowed" } else { "" };
    format!("noise x{noise:.2} from {from}{borrowed}")
}

/// The speed checks of one probe: each pass's ratio against its golden under the limit of
/// the tier's figures. The goldens' host for this backend equal to `host`, on this CPU, is the
/// same host ([`BackendTimings::blessed_on`](super::BackendTimings::blessed_on): goldens that
/// keep no CPU signature name none) where the model's same-host figures were measured there too
/// ([`TimingNoise::figures_measured_on_host`]), and [`Tier::MovedHere`] where they were not
/// (read at the limits for any host); any other is another host.
pub fn check_speed(
    probe: &SceneSpeed,
    goldens: &TimingGoldens,
    noise: &TimingNoise,
    host: &str,
) -> Vec<SpeedCheck> {
    check_speed_with(probe, goldens, noise, host, &[])
}

/// As [`check_speed`], with the hosts recorded in golden/evidence/: on a host that did not
/// bless but was recorded (same fingerprint and CPU signature), a pass whose recording was
/// measured against its golden as it is is checked against that host's own reference and spread
/// ([`RecordedPass::reference`](super::recorded::RecordedPass::reference)), not against the
/// blessing host's ratio, which lies x0.4 to x1.7 away there.
pub fn check_speed_with(
    probe: &SceneSpeed,
    goldens: &TimingGoldens,
    noise: &TimingNoise,
    host: &str,
    recordings: &[(String, RecordedTimings)],
) -> Vec<SpeedCheck> {
    let golden_backend = goldens.backends.get(&probe.backend);
    let cpu = super::cpu_signature();
    // The same-host figures are the blessing host's noise only where it measured them.
    let host_tier = match golden_backend {
        Some(g) if g.blessed_on(host, &cpu) => {
            if noise.figures_measured_on_host(&probe.scene, probe.backend, host, &cpu) {
                Tier::SameHost
            } else {
                Tier::MovedHere
            }
        }
        _ => Tier::OtherHost,
    };
    let recording = (host_tier == Tier::OtherHost)
        .then(|| super::recorded::of_host(recordings, probe.backend, host, &cpu))
        .flatten();
    let mut checks = Vec::new();
    for pass in &probe.passes {
        let (Some(ratio), Some(ms)) = (pass.ratio(), pass.min_ms()) else {
            continue;
        };
        let blessed_pass = golden_backend.and_then(|g| g.passes.get(&pass.pass));
        let blessed = blessed_pass.map(|g| g.ratio);
        let targets_changed = match (blessed_pass.and_then(|g| g.targets.as_ref()), &pass.targets) {
            (Some(then), Some(now)) if then != now => Some(format!(
                "it writes {now}, where it wrote {then} when blessed"
            )),
            _ => None,
        };
        let own = recording.and_then(|(name, r)| {
            let recorded = r.pass(&probe.scene, probe.backend, pass.pass)?;
            let (reference, spread) = recorded.reference(blessed?)?;
            Some((name, reference, spread))
        });
        let (tier, golden, noise_figure, borrowed) = match own {
            Some((name, reference, spread)) => (
                Tier::RecordedHost,
                Some(reference),
                Some((spread, super::recorded::label(name))),
                false,
            ),
            None => {
                let figures = noise.figures(&probe.scene, probe.backend, pass.pass);
                let (figure, borrowed) = match &figures {
                    Some((n, borrowed)) => {
                        let (value, at) = n.noise(host_tier);
                        (Some((value, at.to_owned())), *borrowed)
                    }
                    None => (None, false),
                };
                (host_tier, blessed, figure, borrowed)
            }
        };
        let floor = if tier == Tier::RecordedHost {
            MIN_NOISE_RECORDED
        } else {
            1.0
        };
        let limit = noise_figure
            .as_ref()
            .map(|(n, _)| noise.limit_for(n.max(floor), ms));
        let outcome = match (golden, &noise_figure, limit) {
            (None, ..) => SpeedOutcome::MissingGolden,
            _ if targets_changed.is_some() => {
                SpeedOutcome::TargetsChanged(targets_changed.unwrap_or_default())
            }
            _ if ms < MIN_PASS_MS => SpeedOutcome::Untimed(format!(
                "too short to time ({ms:.3} ms, under {MIN_PASS_MS} ms)"
            )),
            (Some(golden), Some((n, at)), Some(limit)) => {
                if ratio / golden > limit {
                    // Beyond even a limit too wide to catch a doubling: a slowdown no noise
                    // measured explains (an unspecialised lighting pass reads x8 to x11).
                    SpeedOutcome::Slower
                } else if limit >= MUST_CATCH {
                    SpeedOutcome::Untimed(format!(
                        "too noisy to time {}: its ratio moved up to x{n:.2} ({at}{}), so a \
                         limit of x{limit:.2} would not catch a doubling (it fails only \
                         beyond it)",
                        match tier {
                            Tier::SameHost => "here",
                            Tier::OtherHost => "on a host that did not bless",
                            Tier::RecordedHost => "on this recorded host",
                            Tier::MovedHere => {
                                "here at the limits for any host (this host's timing noise \
                                 not measured yet)"
                            }
                        },
                        if borrowed { ", borrowed" } else { "" }
                    ))
                } else if ratio / golden < 1.0 / limit {
                    SpeedOutcome::Faster
                } else {
                    SpeedOutcome::Passed
                }
            }
            _ => SpeedOutcome::Untimed(format!(
                "no timing noise measured for {} on {} (measure it with `harness noise \
                 --timing --write {}` on the host that blessed its timing goldens)",
                pass.pass,
                probe.backend,
                crate::golden::command_line::scene_flag(&probe.scene)
            )),
        };
        checks.push(SpeedCheck {
            scene: probe.scene.clone(),
            backend: probe.backend,
            pass: pass.pass,
            ratio,
            ms,
            targets: pass.targets.clone(),
            delivered: pass.delivered(),
            golden,
            limit,
            noise: noise_figure,
            borrowed,
            tier,
            outcome,
        });
    }
    checks
}

/// What one backend's speed checks at one tier can catch: how many passes were timed, the
/// smallest slowdown each of them fails (its limit), and how many were left untimed.
#[derive(Clone, Debug, PartialEq)]
pub struct SpeedCoverage {
    /// Backend.
    pub backend: BackendKind,
    /// Which figures the limits count: the blessing host's, a recording's, or any host's (on
    /// another host, or on the blessing one before it measured its own: [`Tier::MovedHere`]).
    pub tier: Tier,
    /// Passes with a verdict against a limit.
    pub timed: usize,
    /// Passes left untimed (too short, or too noisy at this tier to catch a doubling).
    pub untimed: usize,
    /// Passes with nothing to compare with: no timing golden yet (a new scene before its
    /// first bless), or one of other targets.
    pub not_compared: usize,
    /// The timed passes' limits as factors: the smallest, the median and the largest.
    pub limits: Option<[f64; 3]>,
    /// How much slower than this run each timed pass must get to fail (its limit over its
    /// ratio to the golden now): the smallest, the median and the largest. Where the passes
    /// run below their goldens (on a host that did not bless, ratios lie x0.4 to x1.75 from
    /// the blessing host's) a limit of x1.6 can mean x3.5 from here.
    pub fails_beyond: Option<[f64; 3]>,
    /// At [`Tier::RecordedHost`], the recording the limits come from (`host-d's recording`).
    pub recording: Option<String>,
}

impl SpeedCoverage {
    /// One line: how many passes were timed and how, their limits (the slowdown beyond which
    /// each fails), how many were untimed, and how many had nothing to compare with.
    pub fn describe(&self) -> String {
        let how = match self.tier {
            Tier::SameHost => "on the host that blessed".to_owned(),
            Tier::RecordedHost => format!(
                "against {}",
                self.recording.as_deref().unwrap_or("this host's recording")
            ),
            Tier::OtherHost => "on a host that did not bless".to_owned(),
            Tier::MovedHere => "on the host that blessed, at the limits for any host (its \
                                timing noise not measured here)"
                .to_owned(),
        };
        // A median says something of three passes and more; of two, both are shown.
        let few = self.timed < 3;
        let limits = match self.limits {
            Some([low, _, high]) if format!("{low:.2}") == format!("{high:.2}") => {
                format!(", limits x{low:.2}")
            }
            Some([low, _, high]) if few => format!(", limits x{low:.2} and x{high:.2}"),
            Some([low, median, high]) => {
                format!(", limits x{low:.2} to x{high:.2} (median x{median:.2})")
            }
            None => String::new(),
        };
        // Said where it tells more than the limits: some pass must slow down a tenth more
        // than its limit from where it runs now.
        let from_now = match (self.fails_beyond, self.limits) {
            (Some([low, median, high]), Some([_, limit_median, limit_high]))
                if high > limit_high * 1.1 || median > limit_median * 1.1 =>
            {
                // (Its count is not the limits': a pass already slower has no room to report.)
                let range = if format!("{low:.2}") == format!("{high:.2}") {
                    format!("x{low:.2}")
                } else {
                    format!("x{low:.2} to x{high:.2}")
                };
                let whom = if self.timed == 1 {
                    "it fails"
                } else {
                    "a pass fails"
                };
                format!("; from their speed in this run {whom} only beyond {range} slower")
            }
            _ => String::new(),
        };
        let not_compared = match self.not_compared {
            0 => String::new(),
            n => format!("; {n} without a timing golden of the same targets to compare with"),
        };
        let passes = if self.timed == 1 { "pass" } else { "passes" };
        format!(
            "{} {passes} timed {how}{limits}{from_now}; {} untimed{not_compared}",
            self.timed, self.untimed
        )
    }
}

/// What to do where checks ran at [`Tier::OtherHost`]: record this host (the command as run here).
pub fn record_this_host() -> String {
    format!(
        "this host is neither the one that blessed the timing goldens nor a recorded one (by \
         driver fingerprint and CPU signature; goldens that keep no signature name no host), so \
         its speed checks use limits wide enough for any host, and catch less. `{}` records it \
         (golden/evidence/NAME/timing.toml, to commit); its checks then read its own ratios",
        crate::golden::command_line::harness_command("noise --timing --record-host NAME")
    )
}

/// Where some of `coverage` (with goldens) ran at [`Tier::OtherHost`], the advice every place
/// that shows the coverage adds under it: [`record_this_host`] on a host with no recording, or,
/// on a recorded one (`recorded_as`: the recording's host name per backend, as the check found
/// it, [`super::SpeedRun`]; or, from an older last-check.json, as a pass read against it names
/// it), that its recording does not hold those passes' goldens as they are (blessed since, or a
/// scene newer than it; or that backend is not in it), and the command that takes it again.
pub fn record_advice(
    coverage: &[SpeedCoverage],
    recorded_as: &std::collections::BTreeMap<BackendKind, String>,
) -> Option<String> {
    // Passes with nothing to compare with (a new scene before its bless) want a bless first.
    let other: Vec<&SpeedCoverage> = coverage
        .iter()
        .filter(|c| c.tier == Tier::OtherHost && c.timed + c.untimed > 0)
        .collect();
    if other.is_empty() {
        return None;
    }
    // This host's recording per backend: as the check found it on disk, or (a last-check.json
    // from before it said so) as some pass read against it names it.
    let in_coverage = |backend: Option<BackendKind>| {
        coverage
            .iter()
            .filter(|c| backend.is_none_or(|b| c.backend == b))
            .find_map(|c| super::recorded::host_of_label(c.recording.as_deref()?))
            .map(str::to_owned)
    };
    let name_on = |backend: BackendKind| {
        (recorded_as.get(&backend).cloned()).or_else(|| in_coverage(Some(backend)))
    };
    let names: Vec<(BackendKind, Option<String>)> = other
        .iter()
        .map(|o| (o.backend, name_on(o.backend)))
        .collect();
    // Recorded on some backend: record it again (on every backend), naming the others.
    let any_recording = || (recorded_as.values().next().cloned()).or_else(|| in_coverage(None));
    let Some(name) = names
        .iter()
        .find_map(|(_, n)| n.clone())
        .or_else(any_recording)
    else {
        return Some(record_this_host());
    };
    let unrecorded: Vec<BackendKind> = names
        .iter()
        .filter(|(_, n)| n.is_none())
        .map(|(b, _)| *b)
        .collect();
    let not_on = if unrecorded.is_empty() {
        String::new()
    } else {
        format!(", not on {}", crate::names(&unrecorded))
    };
    let again = crate::golden::command_line::harness_command(&format!(
        "noise --timing --record-host {name}"
    ));
    Some(format!(
        "this host is recorded ({name}'s recording{not_on}), but it does not hold some passes' \
         timing goldens as they are (blessed since it was taken, or of a scene newer than it), \
         so those were read at the limits for any host. `{again}` records this host again, on \
         every backend (to commit)"
    ))
}

/// Per backend and tier, in the order the checks came: what the speed checks of a run can
/// catch on this host. Checks without a golden, or of other targets than their golden's, count
/// as `not_compared` (they fail), whatever their limit.
pub fn coverage(checks: &[SpeedCheck]) -> Vec<SpeedCoverage> {
    /// One backend and tier's checks as they are gathered.
    struct Group {
        backend: BackendKind,
        tier: Tier,
        limits: Vec<f64>,
        untimed: usize,
        not_compared: usize,
        fails_beyond: Vec<f64>,
        recording: Option<String>,
    }
    let mut groups: Vec<Group> = Vec::new();
    for c in checks {
        let index = match groups
            .iter()
            .position(|g| g.backend == c.backend && g.tier == c.tier)
        {
            Some(i) => i,
            None => {
                groups.push(Group {
                    backend: c.backend,
                    tier: c.tier,
                    limits: Vec::new(),
                    untimed: 0,
                    not_compared: 0,
                    fails_beyond: Vec::new(),
                    recording: None,
                });
                groups.len() - 1
            }
        };
        let group = &mut groups[index];
        if c.tier == Tier::RecordedHost && group.recording.is_none() {
            group.recording = c.noise.as_ref().map(|(_, at)| at.clone());
        }
        match (&c.outcome, c.limit) {
            // A limit too wide to catch a doubling times nothing, failing beyond it or not.
            _ if c.untimed() => group.untimed += 1,
            (SpeedOutcome::MissingGolden | SpeedOutcome::TargetsChanged(_), _) | (_, None) => {
                group.not_compared += 1;
            }
            (_, Some(limit)) => {
                group.limits.push(limit);
                // From a pass's speed in this run, how much slower it may get; a pass already
                // failing has no such room to report.
                if let Some(slowdown) = c
                    .slowdown()
                    .filter(|s| *s > 0.0 && c.outcome != SpeedOutcome::Slower)
                {
                    group.fails_beyond.push(limit / slowdown);
                }
            }
        }
    }
    groups
        .into_iter()
        .map(|g| SpeedCoverage {
            backend: g.backend,
            tier: g.tier,
            timed: g.limits.len(),
            untimed: g.untimed,
            not_compared: g.not_compared,
            limits: spread(g.limits),
            fails_beyond: spread(g.fails_beyond),
            recording: g.recording,
        })
        .collect()
}

/// The smallest, the median and the largest of `values` (None when empty).
fn spread(mut values: Vec<f64>) -> Option<[f64; 3]> {
    values.sort_by(f64::total_cmp);
    (!values.is_empty()).then(|| {
        [
            values[0],
            values[values.len() / 2],
            values[values.len() - 1],
        ]
    })
}

//! A speed verdict per scene, backend and pass: the probe's ratio against its timing golden,
//! scored against the limit from the timing-noise model.

use engine::backend::BackendKind;
use engine::plan::PassId;

use super::{Tier, TimingGoldens, TimingNoise, MIN_PASS_MS, MUST_CATCH};
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
    /// ratio / golden: above 1 slower.
    pub fn slowdown(&self) -> Option<f64> {
        self.golden.map(|g| self.ratio / g)
    }

    /// `ln(slowdown) / ln(limit)`: 1 at the limit, negative when faster.
    pub fn score(&self) -> Option<f64> {
        let (slowdown, limit) = (self.slowdown()?, self.limit?);
        (limit > 1.0).then(|| slowdown.ln() / limit.ln())
    }

    /// Whether this check fails the run.
    pub fn failed(&self) -> bool {
        matches!(
            self.outcome,
            SpeedOutcome::Slower | SpeedOutcome::MissingGolden
        )
    }

    /// One line for the table: the value against the limit, or why there is none.
    pub fn describe(&self) -> String {
        match (&self.outcome, self.slowdown(), self.limit) {
            (SpeedOutcome::Untimed(why), ..) => format!("untimed: {why}"),
            (SpeedOutcome::MissingGolden, ..) => {
                format!(
                    "no timing golden (ratio {:.3}, {:.2} ms)",
                    self.ratio, self.ms
                )
            }
            (outcome, Some(slowdown), Some(limit)) => {
                let noise = self
                    .noise
                    .as_ref()
                    .map(|(n, at)| {
                        format!(
                            "noise x{n:.2} at {at}{}",
                            if self.borrowed { ", borrowed" } else { "" }
                        )
                    })
                    .unwrap_or_default();
                let what = match outcome {
                    SpeedOutcome::Slower => " SLOWER",
                    SpeedOutcome::Faster => " faster: bless if intended",
                    _ => "",
                };
                format!(
                    "x{slowdown:.3} of golden (limit x{limit:.2}, {:.2} of it; {noise}; {:.2} ms){what}",
                    self.score().unwrap_or(0.0),
                    self.ms
                )
            }
            _ => String::new(),
        }
    }
}

/// The speed checks of one probe: each pass's ratio against its golden under the limit of
/// `tier`'s figures. `blessed_host` decides the tier: the goldens' host for this backend equal
/// to `host` is the same host.
pub fn check_speed(
    probe: &SceneSpeed,
    goldens: &TimingGoldens,
    noise: &TimingNoise,
    host: &str,
) -> Vec<SpeedCheck> {
    let golden_backend = goldens.backends.get(&probe.backend);
    let tier = match golden_backend {
        Some(g) if g.host == host => Tier::SameHost,
        _ => Tier::OtherHost,
    };
    let mut checks = Vec::new();
    for pass in &probe.passes {
        let (Some(ratio), Some(ms)) = (pass.ratio(), pass.min_ms()) else {
            continue;
        };
        let golden = golden_backend
            .and_then(|g| g.passes.get(&pass.pass))
            .map(|g| g.ratio);
        let figures = noise.figures(&probe.scene, probe.backend, pass.pass);
        let (noise_figure, borrowed) = match &figures {
            Some((n, borrowed)) => {
                let (value, at) = n.noise(tier);
                (Some((value, at.to_owned())), *borrowed)
            }
            None => (None, false),
        };
        let limit = noise_figure.as_ref().map(|(n, _)| noise.limit_for(*n, ms));
        let outcome = match (golden, &noise_figure, limit) {
            (None, ..) => SpeedOutcome::MissingGolden,
            _ if ms < MIN_PASS_MS => SpeedOutcome::Untimed(format!(
                "too short to time ({ms:.3} ms, under {MIN_PASS_MS} ms)"
            )),
            (Some(golden), Some((n, at)), Some(limit)) => {
                if limit >= MUST_CATCH {
                    SpeedOutcome::Untimed(format!(
                        "too noisy to time {}: its ratio moved up to x{n:.2} ({at}), so a \
                         limit of x{limit:.2} would not catch a doubling",
                        match tier {
                            Tier::SameHost => "here",
                            Tier::OtherHost => "on a host that did not bless",
                        }
                    ))
                } else if ratio / golden > limit {
                    SpeedOutcome::Slower
                } else if ratio / golden < 1.0 / limit {
                    SpeedOutcome::Faster
                } else {
                    SpeedOutcome::Passed
                }
            }
            _ => SpeedOutcome::Untimed(format!(
                "no timing noise measured for {} on {} (measure it with `harness noise \
                 --timing --write`)",
                pass.pass, probe.backend
            )),
        };
        checks.push(SpeedCheck {
            scene: probe.scene.clone(),
            backend: probe.backend,
            pass: pass.pass,
            ratio,
            ms,
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

#[cfg(test)]
mod tests {
    use super::*;
    use crate::golden::speed::PassNoise;
    use crate::measure::speed::PassSpeed;

    fn probe(tonemap_ms: f64, geometry_ms: f64) -> SceneSpeed {
        SceneSpeed {
            scene: "s".to_owned(),
            backend: BackendKind::Gl,
            rounds: 1,
            passes: vec![
                PassSpeed {
                    pass: PassId::ToneMap,
                    pass_ms: vec![tonemap_ms],
                    floor_ms: vec![0.5],
                },
                PassSpeed {
                    pass: PassId::Geometry,
                    pass_ms: vec![geometry_ms],
                    floor_ms: vec![1.0],
                },
            ],
        }
    }

    fn model() -> TimingNoise {
        let mut model = TimingNoise::default();
        let figures = |host: f64, drivers: f64| PassNoise {
            host,
            host_at: "busy".to_owned(),
            drivers,
            drivers_at: "cpu-sse4.1".to_owned(),
        };
        model.scenes.entry("s".to_owned()).or_default().insert(
            BackendKind::Gl,
            [
                (PassId::ToneMap, figures(1.1, 1.2)),
                (PassId::Geometry, figures(1.1, 1.5)),
            ]
            .into_iter()
            .collect(),
        );
        model
    }

    #[test]
    fn a_slower_pass_fails_a_faster_one_is_a_note_and_noise_decides_what_is_timed() {
        // Tone mapping takes 3 ms (its floor 0.5 ms), geometry 4 ms (its floor 1 ms).
        let mut goldens = TimingGoldens::default();
        goldens.record(&probe(3.0, 4.0), &[], "here", "t");
        let noise = model();
        let verdict = |p: &SceneSpeed, host: &str, pass: PassId| {
            check_speed(p, &goldens, &noise, host)
                .into_iter()
                .find(|c| c.pass == pass)
                .unwrap()
        };
        let same = verdict(&probe(3.0, 4.0), "here", PassId::ToneMap);
        assert_eq!(
            (same.outcome.clone(), same.tier),
            (SpeedOutcome::Passed, Tier::SameHost)
        );
        assert_eq!(same.score(), Some(0.0));
        // Limit 1.2^2 (the noise floor) = 1.44 here: x1.5 fails, x1.3 passes, x0.65 (geometry)
        // is a note.
        assert_eq!(
            verdict(&probe(4.5, 4.0), "here", PassId::ToneMap).outcome,
            SpeedOutcome::Slower
        );
        let within = verdict(&probe(3.9, 4.0), "here", PassId::ToneMap);
        assert_eq!(within.outcome, SpeedOutcome::Passed);
        let limit = super::super::MIN_NOISE.powi(2);
        assert!((within.score().unwrap() - 1.3f64.ln() / limit.ln()).abs() < 1e-9);
        assert_eq!(
            verdict(&probe(3.0, 2.6), "here", PassId::Geometry).outcome,
            SpeedOutcome::Faster
        );
        // Another host: geometry's drivers figure (1.5, limit 2.25) leaves it untimed there.
        let other = verdict(&probe(3.9, 4.0), "there", PassId::ToneMap);
        assert_eq!(
            (other.outcome, other.tier),
            (SpeedOutcome::Passed, Tier::OtherHost)
        );
        let noisy = verdict(&probe(3.0, 8.0), "there", PassId::Geometry);
        assert!(
            matches!(&noisy.outcome, SpeedOutcome::Untimed(why) if why.contains("x1.50 (cpu-sse4.1)")),
            "{noisy:?}"
        );
        assert!(!noisy.failed());
        assert_eq!(
            verdict(&probe(3.0, 8.0), "here", PassId::Geometry).outcome,
            SpeedOutcome::Slower
        );
        // A short pass (under 2 ms) has a noise floor of 1.3: limit 1.69 even here.
        let mut short_goldens = TimingGoldens::default();
        short_goldens.record(&probe(1.0, 4.0), &[], "here", "t");
        let short_pass = |ms: f64| {
            check_speed(&probe(ms, 4.0), &short_goldens, &noise, "here")
                .into_iter()
                .find(|c| c.pass == PassId::ToneMap)
                .unwrap()
        };
        assert_eq!(short_pass(1.6).outcome, SpeedOutcome::Passed);
        assert_eq!(short_pass(1.8).outcome, SpeedOutcome::Slower);
        // Too short, and no golden.
        let short = verdict(&probe(0.1, 4.0), "here", PassId::ToneMap);
        assert!(
            matches!(short.outcome, SpeedOutcome::Untimed(ref why) if why.contains("too short"))
        );
        let missing = check_speed(&probe(1.0, 4.0), &TimingGoldens::default(), &noise, "here");
        assert!(missing
            .iter()
            .all(|c| c.outcome == SpeedOutcome::MissingGolden && c.failed()));
    }
}

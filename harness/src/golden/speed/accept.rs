//! Accepting a check's speed verdicts as timing goldens (`harness bless --from-last-check`,
//! the review page's Accept): the pass's ratio as the check measured it, on the host that
//! blessed the section; on a host recorded against it, the slowdown against that recording
//! carried into the blessing host's terms ([`super::record_scaled_check`]).

use std::time::SystemTime;

use engine::backend::BackendKind;

use super::recorded::RecordedTimings;
use super::{SpeedCheck, Tier};
use crate::golden::accept::CheckContext;
use crate::golden::{GoldenStore, SceneLock};

/// What accepting a scene's speed checks did ([`accept_timings`]).
#[derive(Debug, Default)]
pub struct TimingAcceptance {
    /// A line per timing golden written (or, in a dry run, that would be).
    pub written: Vec<String>,
    /// The speed checks not accepted.
    pub kept: Vec<KeptTiming>,
}

/// A speed check not accepted as its timing golden, and why.
#[derive(Debug)]
pub struct KeptTiming {
    /// The plan pass.
    pub pass: engine::plan::PassId,
    /// The backend.
    pub backend: BackendKind,
    /// One line: the check and why it was not accepted.
    pub why: String,
}

/// Records `checks` (those of the locked scene) as its timing goldens: each pass's ratio as the
/// check measured it (its fastest time and its floor's), with `reason` beside each; nothing with
/// `dry_run`. The check must have judged it on the blessing host (its tier, decided where it
/// ran), and that host (`check`, [`speed_candidates`](crate::golden::accept::speed_candidates))
/// must still have blessed the section as the file is now, so a section re-blessed elsewhere
/// since the check is not written into. A check read against this host's own recording
/// ([`Tier::RecordedHost`]) is carried into the blessing host's terms instead
/// ([`super::record_scaled_check`]), while that recording is still of the golden there. A
/// check is kept out, with why, elsewhere: on a host neither blessing nor recorded (it measured
/// another host's ratio, and one backend's goldens are one host's, see
/// [`super::kept_as_another_hosts`]), and where the backend has no timing goldens yet (a first
/// golden is a bless's three probes, not one check).
pub fn accept_timings(
    store: &GoldenStore,
    lock: &SceneLock,
    checks: &[crate::golden::speed::SpeedCheck],
    check: &CheckContext,
    dry_run: bool,
    reason: Option<&str>,
) -> Result<TimingAcceptance, String> {
    use crate::golden::speed::{cpu_signature, Stamp, TimingGoldens};
    use crate::measure::speed::{PassSpeed, SceneSpeed};
    let scene = lock.scene();
    // Timings of the scene as it was are not the scene's as it is, as for its images.
    if let Some(then) = check.inputs.iter().find(|i| i.scene == scene) {
        let changed = then.changed_on_disk(&crate::workspace_root());
        if let Some(why) = then.refusal(&changed, check.scene_argument(scene), Some(&check.out)) {
            return Err(why);
        }
    }
    let cpu = cpu_signature();
    let mut goldens = TimingGoldens::load(store.root(), scene).map_err(|e| e.to_string())?;
    let recordings = super::recorded::load_all(store.root()).map_err(|e| e.to_string())?;
    let blessed = humantime::format_rfc3339_seconds(SystemTime::now()).to_string();
    let bless = |on_blessing_host| {
        crate::golden::command_line::speed_bless_command(
            check.scene_argument(scene),
            on_blessing_host,
        )
    };
    let mut done = TimingAcceptance::default();
    for c in checks.iter().filter(|c| c.scene == scene) {
        let name = format!("{scene}/{} on {} (speed)", c.pass, c.backend);
        let kept = |why: String| KeptTiming {
            pass: c.pass,
            backend: c.backend,
            why: format!("{name}: not accepted: {why}"),
        };
        let Some(section) = goldens.backends.get(&c.backend) else {
            done.kept.push(kept(format!(
                "no timing goldens there yet, and one check's probe is not one; bless them \
                 with `{}`",
                bless(true)
            )));
            continue;
        };
        // Judged on the blessing host by the check (the CPU it ran on), and still that host's
        // section now (not re-blessed elsewhere since).
        let blessed_here = c.tier.blessed_here()
            && check
                .hosts
                .get(&c.backend)
                .is_some_and(|host| section.blessed_on(host, &cpu));
        if !blessed_here && c.tier == Tier::RecordedHost {
            let golden_now = section.passes.get(&c.pass).map(|p| p.ratio);
            let recorded = check
                .hosts
                .get(&c.backend)
                .and_then(|host| current_reference(&recordings, scene, c, host, &cpu, golden_now?));
            match recorded {
                Some((host_name, reference)) if Some(reference) == c.golden => {
                    match super::record_scaled_check(&mut goldens, c, &blessed, reason) {
                        Ok(ratio) => done.written.push(format!(
                            "{name}: x{:.3} against {host_name}'s recording, carried into the \
                             blessing host's terms as ratio {ratio:.4}; {}. {host_name}'s recording \
                             of it is then of the golden before: the pass is read at the limits \
                             for any host here until `{}` records this host again",
                            c.ratio / reference,
                            if dry_run {
                                "would be written"
                            } else {
                                "written"
                            },
                            crate::golden::command_line::harness_command(&format!(
                                "noise --timing --record-host {host_name}"
                            ))
                        )),
                        Err(why) => done.kept.push(kept(why)),
                    }
                }
                _ => done.kept.push(kept(
                    "the check read it against this host's recording of the golden as it was \
                     then, and the golden or the recording changed since: check again"
                        .to_owned(),
                )),
            }
            continue;
        }
        if !blessed_here {
            let recorded_as = check
                .hosts
                .get(&c.backend)
                .and_then(|host| super::recorded::of_host(&recordings, c.backend, host, &cpu))
                .map(|(name, _)| name);
            done.kept.push(kept(match recorded_as {
                // Recorded, but not of this golden as it is: the check read it at any host's
                // limits, which no slowdown carries over from.
                Some(name) => format!(
                    "this host's recording ({name}'s) does not hold {}'s timing golden of it as \
                     it is, so the check read it at the limits for any host. Record the host \
                     again (`{}`) and check again to accept from here, or move {}'s timing \
                     goldens to this host: `{}`",
                    c.backend,
                    crate::golden::command_line::harness_command(&format!(
                        "noise --timing --record-host {name}"
                    )),
                    c.backend,
                    bless(false)
                ),
                None => format!(
                    "the check ran on a host that did not bless {}'s timing goldens (blessed \
                     on {}) and is not recorded against them, and a backend's timing goldens \
                     are one host's ratios. Record this host (`harness noise --timing \
                     --record-host NAME`) and check again to accept from here, or move them all \
                     to this host: `{}`",
                    c.backend,
                    section.blessed_by(),
                    bless(false)
                ),
            }));
            continue;
        }
        // The check's host blessed the section: its stamp stays.
        let (section_host, section_cpu) = (section.host.clone(), section.cpu.clone());
        // The check's figures as a probe of one sample: its fastest time over its floor's.
        let probe = SceneSpeed {
            scene: scene.to_owned(),
            backend: c.backend,
            rounds: 1,
            passes: vec![PassSpeed {
                pass: c.pass,
                pass_ms: vec![c.ms],
                floor_ms: vec![c.ms / c.ratio],
                targets: c.targets.clone(),
                unslowed_ms: Vec::new(),
            }],
        };
        let stamp = Stamp {
            host: &section_host,
            cpu: &section_cpu,
            blessed: &blessed,
            reason,
        };
        goldens.record(&probe, &[c.pass], &stamp);
        done.written.push(format!(
            "{name}: ratio {:.3} as the check measured it; {}",
            c.ratio,
            if dry_run {
                "would be written"
            } else {
                "written"
            }
        ));
    }
    if !dry_run && !done.written.is_empty() {
        goldens
            .save(store.root(), scene)
            .map_err(|e| e.to_string())?;
    }
    Ok(done)
}

/// The recording in `recordings` of this host (`host`, `cpu`) on the check's backend, and its
/// reference for the check's pass while it is of `golden` (the timing golden there now).
fn current_reference<'a>(
    recordings: &'a [(String, RecordedTimings)],
    scene: &str,
    check: &SpeedCheck,
    host: &str,
    cpu: &str,
    golden: f64,
) -> Option<(&'a str, f64)> {
    let (name, recording) = super::recorded::of_host(recordings, check.backend, host, cpu)?;
    let (reference, _) = recording
        .pass(scene, check.backend, check.pass)?
        .reference(golden)?;
    Some((name, reference))
}

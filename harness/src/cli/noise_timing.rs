//! `harness noise --timing`: the timing-noise model (golden/timing-noise.toml) measured from
//! this host's sources and the hosts recorded in golden/evidence/ (`--record-host`, which
//! records this host's speed ratios there, is [`super::noise_record`]).

use std::process::ExitCode;

use engine::backend::BackendKind;
use harness::golden::noise::MAX_NOISE_RATIO;
use harness::golden::speed::Tier;
use harness::golden::GoldenStore;

use super::load_cases;

/// Whether `noise --timing` writes the model, and whether it may measure on a busy machine.
#[derive(Clone, Copy, Debug)]
pub(super) struct Writing {
    /// `--write`: record golden/timing-noise.toml.
    pub write: bool,
    /// `--busy-ok`: measure and write although other tasks keep the machine busy.
    pub busy_ok: bool,
}

/// Refuses to measure or write timing noise on a busy machine
/// ([`too_busy`](harness::golden::speed::measure::too_busy)), unless `busy_ok`; with
/// `warn_only`, a warning instead. `when` says at which point it was found busy.
pub(super) fn refuse_if_busy(busy_ok: bool, warn_only: bool, when: &str) -> anyhow::Result<()> {
    use harness::golden::speed::measure::{machine_load, too_busy};
    if busy_ok {
        return Ok(());
    }
    let Some(why) = machine_load(10).and_then(|(others, cpus)| too_busy(others, cpus)) else {
        return Ok(());
    };
    if warn_only {
        eprintln!("warning: {why}");
        Ok(())
    } else {
        anyhow::bail!("{when}: {why}")
    }
}

/// `harness noise --timing`: probes the scenes named (every canonical one by default) on every
/// available backend under every timing source (or those named), counts the hosts recorded in
/// golden/evidence/, prints each pass's worst factor per tier with its limit and its score (or
/// JSON), and with `write` records golden/timing-noise.toml: from every source, or with sources
/// named, their figures merged into the model (raised where they measure more, the rest kept).
/// Exits 1 when a measurement is above half its limit or a probe failed.
pub(super) fn timing(
    only: &[String],
    scenes: &[String],
    writing: Writing,
    margin: f64,
    json: bool,
) -> anyhow::Result<ExitCode> {
    let write = writing.write;
    use harness::golden::speed::{measure, recorded, TimingNoise};
    let store = GoldenStore::workspace();
    let scenes = named(&load_cases(scenes)?);
    let (mut sources, mut missing) = measure::timing_sources();
    let mut recorded_measurements = Vec::new();
    for (source, measurements) in recorded::recorded_hosts(store.root())? {
        sources.push(source);
        recorded_measurements.push(measurements);
    }
    if !only.is_empty() {
        let known: Vec<&str> = sources
            .iter()
            .map(|s| s.name.as_str())
            .chain(missing.iter().map(|(name, _)| name.as_str()))
            .collect();
        if let Some(unknown) = only.iter().find(|n| !known.contains(&n.as_str())) {
            anyhow::bail!(
                "unknown timing source {unknown}: the sources are {}",
                known.join(", ")
            );
        }
        missing.retain(|(name, _)| only.contains(name));
    }
    let chosen = |name: &str| only.is_empty() || only.iter().any(|n| n == name);
    for (name, why) in &missing {
        eprintln!("note: timing source {name} not measured: {why}");
    }
    let hosts = this_hosts();
    let backends: Vec<BackendKind> = hosts.iter().map(|(kind, _)| *kind).collect();
    let exe = std::env::current_exe()?;
    let probed: Vec<measure::TimingSource> = sources
        .iter()
        .filter(|s| s.probes > 0 && chosen(&s.name))
        .cloned()
        .collect();
    if !probed.is_empty() {
        if let Some((why, instead)) = blessed_elsewhere(store.root(), &scenes, &hosts)? {
            if write {
                anyhow::bail!(
                    "{why}. This host's probes of them are another host's figures, and --write \
                     would take them for the blessing host's own noise: {instead}"
                );
            }
            eprintln!(
                "note: {why}. This host's sources are read against another host's goldens, \
                 so their factors are that host's offset as much as noise: {instead}"
            );
        }
    }
    if write && !missing.is_empty() {
        anyhow::bail!(
            "--write needs every timing source asked for ({} missing); install them first, or \
             name the ones to measure (`--source runs --source busy-neighbour --write`)",
            missing
                .iter()
                .map(|(name, _)| name.as_str())
                .collect::<Vec<_>>()
                .join(", ")
        );
    }
    // What is written is refused on a busy machine; a report only warns.
    refuse_if_busy(writing.busy_ok, !write, "before measuring")?;
    let (mut measurements, errors) =
        measure::measure_timing(&exe, store.root(), &scenes, &backends, &probed, |what| {
            eprintln!("timing noise: {what} ...")
        });
    let wanted: Vec<&str> = scenes.iter().map(|(name, _)| name.as_str()).collect();
    measurements.extend(recorded_measurements.into_iter().flatten().filter(|m| {
        // Figures of a backend not probed here would stand alone, without this host's.
        chosen(&m.source) && wanted.contains(&m.scene.as_str()) && backends.contains(&m.backend)
    }));
    sources.retain(|s| chosen(&s.name));
    for e in &errors {
        eprintln!("error: {e}");
    }
    let model = if write {
        // A model with a probe missing, or measured beside a load, is not this host's noise.
        if !errors.is_empty() {
            anyhow::bail!("{} probe(s) failed; nothing written", errors.len());
        }
        refuse_if_busy(writing.busy_ok, false, "after the probes, nothing written")?;
        let measured = measure::model_from(&measurements, &sources, margin);
        let here = measured_here_now(store.root(), &scenes, &hosts, &probed)?;
        let cpu = harness::golden::speed::cpu_signature();
        let model = match TimingNoise::load(store.root()) {
            Ok(old) if !only.is_empty() => {
                let moved: Vec<(String, BackendKind)> = here
                    .iter()
                    .filter(|(scene, kind, host)| !old.measured_on_host(scene, *kind, host, &cpu))
                    .map(|(scene, kind, _)| (scene.clone(), *kind))
                    .collect();
                measure::merged_replacing(old, measured, &moved)
            }
            // Scenes, backends and passes not measured in this run keep their figures.
            Ok(old) => measure::remeasured(measured, old),
            Err(e) if !only.is_empty() => return Err(e.into()),
            Err(_) => measured,
        };
        let mut model = model;
        for (scene, kind, host) in &here {
            model.stamp_measured_on(scene, *kind, host, &cpu);
        }
        model.save(store.root())?;
        eprintln!("wrote {}", TimingNoise::path(store.root()).display());
        model
    } else {
        TimingNoise::load(store.root())?
    };
    let scores = measure::scores(&model, &measurements);
    let too_noisy = scores
        .iter()
        .filter(|(_, _, s)| *s > MAX_NOISE_RATIO)
        .count();
    if json {
        print_timing_json(&scores, &errors)?;
    } else {
        print_timing_table(&model, store.root(), &wanted, &scores);
    }
    Ok(if too_noisy == 0 && errors.is_empty() {
        ExitCode::SUCCESS
    } else {
        ExitCode::FAILURE
    })
}

/// The scenes and backends (with this host's fingerprint for each) whose same-host figures
/// this run measures as this host's own: a same-host source among `probed`, and timing goldens
/// this host blessed. Only there does a check read them as its own noise
/// ([`Tier::SameHost`]); where the model has them from another host they are replaced, not
/// merged with this host's.
fn measured_here_now(
    root: &std::path::Path,
    scenes: &[(String, String)],
    hosts: &[(BackendKind, String)],
    probed: &[harness::golden::speed::measure::TimingSource],
) -> anyhow::Result<Vec<(String, BackendKind, String)>> {
    let mut here = Vec::new();
    if !probed.iter().any(|s| s.tier == Tier::SameHost) {
        return Ok(here);
    }
    let cpu = harness::golden::speed::cpu_signature();
    for (scene, _) in scenes {
        let goldens = harness::golden::speed::TimingGoldens::load(root, scene)?;
        for (kind, host) in hosts {
            if goldens
                .backends
                .get(kind)
                .is_some_and(|g| g.blessed_on(host, &cpu))
            {
                here.push((scene.clone(), *kind, host.clone()));
            }
        }
    }
    Ok(here)
}

/// Every available backend with this host's fingerprint for it (as the speed checks name it).
pub(super) fn this_hosts() -> Vec<(BackendKind, String)> {
    BackendKind::ALL
        .into_iter()
        .filter_map(|kind| {
            let info = engine::backend::probe(kind).info?;
            Some((
                kind,
                harness::golden::speed::host_fingerprint(&harness::golden::store::fingerprint(
                    &info,
                )),
            ))
        })
        .collect()
}

/// Where some of `scenes`' timing goldens on `hosts`' backends were not blessed on this host:
/// which scenes and why for the first (another host, or goldens that keep no CPU signature),
/// and what to do instead: measure the scenes this host blessed, move the others here, or
/// record this host (naming its recording where it has one). None where this host blessed
/// them all.
fn blessed_elsewhere(
    root: &std::path::Path,
    scenes: &[(String, String)],
    hosts: &[(BackendKind, String)],
) -> anyhow::Result<Option<(String, String)>> {
    let cpu = harness::golden::speed::cpu_signature();
    // Each scene blessed elsewhere: the first backend found so, where it was blessed, and
    // whether that names a CPU.
    let mut elsewhere: Vec<(&str, BackendKind, String, bool)> = Vec::new();
    let mut here: Vec<&str> = Vec::new();
    for (scene, _) in scenes {
        let goldens = harness::golden::speed::TimingGoldens::load(root, scene)?;
        match goldens.blessed_elsewhere(hosts, &cpu) {
            Some((kind, g)) => elsewhere.push((
                scene,
                kind,
                g.blessed_by(),
                harness::golden::speed::cpu_known(&g.cpu),
            )),
            None => here.push(scene),
        }
    }
    let Some((first, kind, blessed_by, cpu_known)) = elsewhere.first().cloned() else {
        return Ok(None);
    };
    let scene_args = |names: &[&str]| -> String {
        names
            .iter()
            .map(|n| format!(" {}", harness::golden::command_line::scene_flag(n)))
            .collect()
    };
    // The scenes blessed where the first was are said with it; any others after it.
    let (alike, unlike): (Vec<&str>, Vec<&str>) = {
        let (alike, unlike): (Vec<_>, Vec<_>) = elsewhere[1..]
            .iter()
            .partition(|(_, _, by, _)| *by == blessed_by);
        (
            alike.iter().map(|(scene, ..)| *scene).collect(),
            unlike.iter().map(|(scene, ..)| *scene).collect(),
        )
    };
    let others = match alike.as_slice() {
        [] => String::new(),
        [one] => format!(" (and {one}'s)"),
        [many @ .., last] => format!(" (and {}'s and {last}'s)", many.join("'s, ")),
    };
    let first = format!("{first}'s timing goldens on {kind}");
    let mut why = if cpu_known {
        format!("{first}{others} were blessed on {blessed_by}, not on this host ({cpu})")
    } else {
        format!(
            "{first}{others} keep no CPU signature (blessed before it was kept), so no host, \
             this one included, is taken for the one that blessed them"
        )
    };
    if !unlike.is_empty() {
        why += &format!(
            "; {}'s were blessed on other hosts, not here, too",
            unlike.join("'s, ")
        );
    }
    let elsewhere: Vec<&str> = elsewhere.iter().map(|(scene, ..)| *scene).collect();
    let measure_here = if here.is_empty() {
        String::new()
    } else {
        format!(
            "measure only the scenes this host blessed (`harness noise --timing --write{}`); ",
            scene_args(&here)
        )
    };
    let recorded = harness::golden::speed::recorded::load_all(root)?
        .into_iter()
        .find(|(_, r)| {
            hosts
                .iter()
                .all(|(kind, host)| r.records(*kind, host, &cpu))
        })
        .map(|(name, _)| name);
    let record = match recorded {
        Some(name) => format!(
            "this host is recorded as {name} already (`{}` records it again)",
            harness::golden::command_line::harness_command(&format!(
                "noise --timing --record-host {name}"
            ))
        ),
        None => format!(
            "or record this host's figures (`{}`)",
            harness::golden::command_line::harness_command("noise --timing --record-host NAME")
        ),
    };
    Ok(Some((
        why,
        format!(
            "{measure_here}make this host the blessing one first (`harness bless --speed-only \
             --every-pass{}`); {record}",
            scene_args(&elsewhere)
        ),
    )))
}

/// `harness noise --timing --json`: every measurement with its limit and score, and the errors.
fn print_timing_json(
    scores: &[(harness::golden::speed::measure::TimingMeasurement, f64, f64)],
    errors: &[String],
) -> anyhow::Result<()> {
    let rows: Vec<serde_json::Value> = scores
        .iter()
        .map(|(m, limit, score)| {
            serde_json::json!({
                "source": m.source, "tier": m.tier, "scene": m.scene,
                "backend": m.backend, "pass": m.pass, "factor": m.factor,
                "limit": limit, "score": score,
            })
        })
        .collect();
    println!(
        "{}",
        serde_json::to_string_pretty(&serde_json::json!({
            "measurements": rows, "errors": errors,
        }))?
    );
    Ok(())
}

/// `harness noise --timing`'s table: each pass of the `wanted` scenes with its figures per tier
/// and its limits here and elsewhere, as a check applies them (with the floor of a pass under 2
/// ms, from its timing golden's ms under `root`), and the worst measurement against its limit.
fn print_timing_table(
    model: &harness::golden::speed::TimingNoise,
    root: &std::path::Path,
    wanted: &[&str],
    scores: &[(harness::golden::speed::measure::TimingMeasurement, f64, f64)],
) {
    let too_noisy = scores
        .iter()
        .filter(|(_, _, s)| *s > MAX_NOISE_RATIO)
        .count();
    println!(
        "{:<8} {:<12} {:<22} {:>20} {:>20} {:>16} {:>16}",
        "scene", "backend", "pass", "host noise", "driver noise", "limit", "elsewhere"
    );
    for scene in wanted.iter().filter(|s| !model.scenes.contains_key(**s)) {
        println!(
            "{scene:<8} no figures of its own in golden/timing-noise.toml yet: its checks borrow \
             every scene's (`--write` records this run's, the other hosts' kept at least as \
             borrowed)"
        );
    }
    let named = model
        .scenes
        .iter()
        .filter(|(scene, _)| wanted.contains(&scene.as_str()));
    for (scene, backends) in named {
        // A scene without timing goldens yet gives no ms: the limits without the short floor.
        let goldens = harness::golden::speed::TimingGoldens::load(root, scene).unwrap_or_default();
        for (backend, passes) in backends {
            for (pass, noise) in passes {
                let ms = goldens
                    .backends
                    .get(backend)
                    .and_then(|b| b.passes.get(pass))
                    .map_or(f64::INFINITY, |p| p.ms);
                let here = model.limit_for(noise.noise(Tier::SameHost).0, ms);
                let elsewhere = model.limit_for(noise.noise(Tier::OtherHost).0, ms);
                let cell = |limit: f64| {
                    if limit >= harness::golden::speed::MUST_CATCH {
                        format!("x{limit:.2} (untimed)")
                    } else {
                        format!("x{limit:.2}")
                    }
                };
                println!(
                    "{scene:<8} {backend:<12} {pass:<22} {:>20} {:>20} {:>16} {:>16}",
                    format!("x{:.2} {}", noise.host, short(&noise.host_at)),
                    format!("x{:.2} {}", noise.drivers, short(&noise.drivers_at)),
                    cell(here),
                    cell(elsewhere),
                );
            }
        }
    }
    let borrowed = model
        .scenes
        .iter()
        .filter(|(scene, _)| wanted.contains(&scene.as_str()))
        .flat_map(|(_, backends)| backends.values().flat_map(|p| p.values()))
        .any(|n| n.host_at.ends_with(", borrowed") || n.drivers_at.ends_with(", borrowed"));
    if borrowed {
        println!(
            "* borrowed from the other scenes (their largest): no host has recorded this scene \
             yet"
        );
    }
    let worst = scores
        .iter()
        .max_by(|a, b| a.2.total_cmp(&b.2))
        .map(|(m, limit, score)| {
            format!(
                "{score:.2} of its limit ({} {} {} under {}: x{:.3}, limit x{limit:.2} before \
                 the floor of a pass under 2 ms: sources are held to the model's own)",
                m.scene, m.backend, m.pass, m.source, m.factor
            )
        })
        .unwrap_or_else(|| "-".to_owned());
    println!(
        "{} measurements, {too_noisy} above {MAX_NOISE_RATIO} of their limits; worst {worst}",
        scores.len()
    );
}

/// Each of `cases` as its name and the argument a probe child takes (a name or a scene file).
pub(super) fn named(cases: &[harness::golden::suite::Case]) -> Vec<(String, String)> {
    cases
        .iter()
        .map(|c| (c.name().to_owned(), c.argument()))
        .collect()
}

/// A source name short enough for the table (`busy-neighbour` whole).
pub(super) fn short(source: &str) -> String {
    // A figure borrowed from other scenes keeps its mark, `*`, whatever is cut.
    let (name, mark) = match source.strip_suffix(", borrowed") {
        Some(name) => (name, "*"),
        None => (source, ""),
    };
    format!("{}{mark}", name.get(..name.len().min(14)).unwrap_or(name))
}

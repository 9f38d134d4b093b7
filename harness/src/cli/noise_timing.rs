//! `harness noise --timing`: the timing-noise model (golden/timing-noise.toml) measured from
//! this host's sources and the hosts recorded in golden/evidence/, and `--record-host`, which
//! records this host's speed ratios there.

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
    measurements.extend(
        recorded_measurements
            .into_iter()
            .flatten()
            .filter(|m| chosen(&m.source) && wanted.contains(&m.scene.as_str())),
    );
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
        let model = match TimingNoise::load(store.root()) {
            Ok(old) if !only.is_empty() => {
                let moved = moved_here(&old, store.root(), &scenes, &hosts, &probed)?;
                measure::merged_replacing(old, measured, &moved)
            }
            // Scenes not measured in this run keep their figures.
            Ok(old) => {
                let mut model = measured;
                for (scene, figures) in old.scenes {
                    model.scenes.entry(scene).or_insert(figures);
                }
                model.measured_on = old.measured_on;
                model
            }
            Err(e) if !only.is_empty() => return Err(e.into()),
            Err(_) => measured,
        };
        let mut model = model;
        stamp_this_host(&mut model, store.root(), &scenes, &hosts, &probed)?;
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
        print_timing_table(&model, &wanted, &scores);
    }
    Ok(if too_noisy == 0 && errors.is_empty() {
        ExitCode::SUCCESS
    } else {
        ExitCode::FAILURE
    })
}

/// Stamps the model's same-host figures of `scenes` on `hosts`' backends as this host's where
/// `probed` measured them here (a same-host source among them) against goldens this host
/// blessed: only there does a check read them as its own noise ([`Tier::SameHost`]).
fn stamp_this_host(
    model: &mut harness::golden::speed::TimingNoise,
    root: &std::path::Path,
    scenes: &[(String, String)],
    hosts: &[(BackendKind, String)],
    probed: &[harness::golden::speed::measure::TimingSource],
) -> anyhow::Result<()> {
    if !probed.iter().any(|s| s.tier == Tier::SameHost) {
        return Ok(());
    }
    let cpu = harness::golden::speed::cpu_signature();
    for (scene, _) in scenes {
        let goldens = harness::golden::speed::TimingGoldens::load(root, scene)?;
        model.stamp_where_blessed(scene, &goldens, hosts, &cpu);
    }
    Ok(())
}

/// The scenes and backends whose same-host figures `probed` measures here (a same-host source
/// among them, goldens this host blessed) where `model` has them from another host: replaced by
/// this host's, not merged with them.
fn moved_here(
    model: &harness::golden::speed::TimingNoise,
    root: &std::path::Path,
    scenes: &[(String, String)],
    hosts: &[(BackendKind, String)],
    probed: &[harness::golden::speed::measure::TimingSource],
) -> anyhow::Result<Vec<(String, BackendKind)>> {
    let mut moved = Vec::new();
    if !probed.iter().any(|s| s.tier == Tier::SameHost) {
        return Ok(moved);
    }
    let cpu = harness::golden::speed::cpu_signature();
    for (scene, _) in scenes {
        let goldens = harness::golden::speed::TimingGoldens::load(root, scene)?;
        for (kind, host) in hosts {
            let blessed_here = goldens
                .backends
                .get(kind)
                .is_some_and(|g| g.blessed_on(host, &cpu));
            if blessed_here && !model.measured_on_host(scene, *kind, host, &cpu) {
                moved.push((scene.clone(), *kind));
            }
        }
    }
    Ok(moved)
}

/// Every available backend with this host's fingerprint for it (as the speed checks name it).
fn this_hosts() -> Vec<(BackendKind, String)> {
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
    let mut elsewhere: Vec<&str> = Vec::new();
    let mut here: Vec<&str> = Vec::new();
    let mut first = None;
    for (scene, _) in scenes {
        let goldens = harness::golden::speed::TimingGoldens::load(root, scene)?;
        match goldens.blessed_elsewhere(hosts, &cpu) {
            Some((kind, g)) => {
                elsewhere.push(scene);
                first.get_or_insert_with(|| {
                    let known = harness::golden::speed::cpu_known(&g.cpu);
                    (
                        format!("{scene}'s timing goldens on {kind}"),
                        known,
                        g.blessed_by(),
                    )
                });
            }
            None => here.push(scene),
        }
    }
    let Some((first, cpu_known, blessed_by)) = first else {
        return Ok(None);
    };
    let scene_args =
        |names: &[&str]| -> String { names.iter().map(|n| format!(" --scene {n}")).collect() };
    let others = match &elsewhere[1..] {
        [] => String::new(),
        [one] => format!(" (and {one}'s)"),
        [many @ .., last] => format!(" (and {}'s and {last}'s)", many.join("'s, ")),
    };
    let why = if cpu_known {
        format!("{first}{others} were blessed on {blessed_by}, not on this host ({cpu})")
    } else {
        format!(
            "{first}{others} keep no CPU signature (blessed before it was kept), so no host, \
             this one included, is taken for the one that blessed them"
        )
    };
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
                .any(|(kind, host)| r.records(*kind, host, &cpu))
        })
        .map(|(name, _)| name);
    let record = match recorded {
        Some(name) => format!(
            "this host is recorded as {name} already (`harness noise --timing --record-host \
             {name}` records it again)"
        ),
        None => {
            "or record this host's figures (`harness noise --timing --record-host NAME`)".to_owned()
        }
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

/// Says where this host (`backends`' fingerprints, `cpu`) is recorded already under another
/// name than `name`: checks read a host against the first recording that matches it, so a
/// second name for the same host would never be read.
fn note_recorded_as_another(
    root: &std::path::Path,
    name: &str,
    backends: &[(BackendKind, String)],
    cpu: &str,
) -> anyhow::Result<()> {
    for (other, recording) in harness::golden::speed::recorded::load_all(root)? {
        let same_host = other != name
            && backends
                .iter()
                .all(|(kind, host)| recording.records(*kind, host, cpu));
        if same_host {
            eprintln!(
                "note: this host is recorded already, as {other} (golden/evidence/{other}/: the \
                 same driver fingerprints and CPU); checks read it against that recording, not \
                 a second one: `--record-host {other}` adds to it"
            );
        }
    }
    Ok(())
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
/// and its limits here and elsewhere, and the worst measurement against its limit.
fn print_timing_table(
    model: &harness::golden::speed::TimingNoise,
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
    let named = model
        .scenes
        .iter()
        .filter(|(scene, _)| wanted.contains(&scene.as_str()));
    for (scene, backends) in named {
        for (backend, passes) in backends {
            for (pass, noise) in passes {
                let here = model.limit(noise.noise(Tier::SameHost).0);
                let elsewhere = model.limit(noise.noise(Tier::OtherHost).0);
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
    let worst = scores
        .iter()
        .max_by(|a, b| a.2.total_cmp(&b.2))
        .map(|(m, limit, score)| {
            format!(
                "{score:.2} of its limit ({} {} {} under {}: x{:.3}, limit x{limit:.2})",
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
fn named(cases: &[harness::golden::suite::Case]) -> Vec<(String, String)> {
    cases
        .iter()
        .map(|c| (c.name().to_owned(), c.argument()))
        .collect()
}

/// A source name short enough for the table (`busy-neighbour` whole).
fn short(source: &str) -> &str {
    source.get(..source.len().min(14)).unwrap_or(source)
}

/// `harness noise --timing --record-host NAME`: on a host that did not bless the timing goldens,
/// probes the scenes named (every canonical one by default) on every available backend under
/// each timing source this machine has (at most
/// [`RECORD_PROBES`](harness::golden::speed::recorded::RECORD_PROBES) per source), each a fresh
/// process, and writes golden/evidence/NAME/timing.toml. Refuses on the host that blessed (its
/// figures are this host's noise, not another's) and writes nothing when a probe failed.
pub(super) fn record_host(
    name: &str,
    scenes: &[String],
    history: Option<&std::path::Path>,
    busy_ok: bool,
) -> anyhow::Result<ExitCode> {
    use harness::golden::speed::{measure, recorded, TimingGoldens};
    if name.is_empty()
        || !name
            .chars()
            .all(|c| c.is_ascii_alphanumeric() || c == '-' || c == '_')
    {
        anyhow::bail!("--record-host {name:?}: a host's name is letters, digits, '-' and '_'");
    }
    let store = GoldenStore::workspace();
    let cases = load_cases(scenes)?;
    let input_digests = harness::golden::scene_inputs::digests(cases.iter().map(|c| &c.inputs));
    let scenes = named(&cases);
    let backends = this_hosts();
    if backends.is_empty() {
        anyhow::bail!("no backend is available here (`harness backends` says why)");
    }
    // A scene whose goldens this host blessed (on some backend) is its own noise there, not
    // another host's figures: left out, and refused only when that leaves nothing.
    let cpu = harness::golden::speed::cpu_signature();
    let mut kept = Vec::new();
    for (scene, argument) in scenes {
        let goldens = TimingGoldens::load(store.root(), &scene)?;
        let blessed_here = backends.iter().find(|(kind, host)| {
            goldens
                .backends
                .get(kind)
                .is_some_and(|g| g.blessed_on(host, &cpu))
        });
        match blessed_here {
            Some((kind, host)) => eprintln!(
                "note: {scene} left out: this host blessed its timing goldens on {kind} \
                 ({host}), so its figures there are this host's own noise (`harness noise \
                 --timing --scene {scene}`), not another host's"
            ),
            None => kept.push((scene, argument)),
        }
    }
    if kept.is_empty() {
        anyhow::bail!(
            "this host blessed the timing goldens of every scene asked for: its figures are its \
             own noise (`harness noise --timing`), not another host's"
        );
    }
    let scenes = kept;
    refuse_if_busy(busy_ok, false, "before measuring")?;
    note_recorded_as_another(store.root(), name, &backends, &cpu)?;
    let path = recorded::RecordedTimings::path(store.root(), name);
    let earlier = recorded::RecordedTimings::load(&path)?;
    if let Some(earlier) = &earlier {
        let hosts: std::collections::BTreeMap<BackendKind, String> =
            backends.iter().cloned().collect();
        if earlier.hosts != hosts
            || !(earlier.cpu.is_empty() || earlier.cpu == harness::golden::speed::cpu_signature())
        {
            anyhow::bail!(
                "{} was recorded on another host ({}); record this one under another name",
                path.display(),
                earlier.hosts.values().next().map_or("-", String::as_str)
            );
        }
    }
    let (sources, missing) = measure::timing_sources();
    for (source, why) in &missing {
        eprintln!("note: timing source {source} not recorded: {why}");
    }
    let history = match history {
        Some(out) => {
            let (entries, skipped) = harness::golden::speed::history::read(out);
            if entries.is_empty() {
                anyhow::bail!(
                    "--history {}: no speed history there ({} lines unreadable)",
                    out.join(harness::golden::speed::history::HISTORY_FILE)
                        .display(),
                    skipped
                );
            }
            // Only an unchanged build's checks: this executable, each scene loaded from the
            // bytes it is now (a check of an edited scene, or of a rebuilt harness, under the
            // same commit measured something else).
            let (kept, left_out) =
                harness::golden::speed::history::of_this_build(&entries, &input_digests);
            if left_out > 0 {
                eprintln!(
                    "note: {left_out} check(s) of the history left out: another build of the \
                     harness, or their scenes edited since (only this executable's checks of \
                     the scenes as they are now count)"
                );
            }
            kept
        }
        None => Vec::new(),
    };
    let exe = std::env::current_exe()?;
    let (mut recorded, errors) = recorded::record(
        &exe,
        store.root(),
        &scenes,
        &backends,
        &sources,
        recorded::RECORD_PROBES,
        &history,
        |what| eprintln!("recording {name}: {what} ..."),
    );
    if !errors.is_empty() {
        for e in &errors {
            eprintln!("error: {e}");
        }
        anyhow::bail!("{} probe(s) failed; nothing written", errors.len());
    }
    if let Some(earlier) = earlier {
        let probes: usize = earlier.probes.values().sum();
        let dropped = recorded.absorb(earlier);
        eprintln!(
            "adding to the {probes} earlier probe(s) and check(s) per backend in {}",
            path.display()
        );
        if !dropped.is_empty() {
            eprintln!(
                "note: their goldens changed since, so the earlier ratios of {} are dropped",
                dropped.join(", ")
            );
        }
    }
    refuse_if_busy(busy_ok, false, "after the probes, nothing written")?;
    if let Some(dir) = path.parent() {
        std::fs::create_dir_all(dir)?;
    }
    recorded.save(&path)?;
    start_readme(&path, name, &recorded)?;
    println!(
        "{:<8} {:<12} {:<22} {:>24} {:>8}",
        "scene", "backend", "pass", "largest of golden", "lowest"
    );
    for (scene, backends) in &recorded.scenes {
        for (backend, passes) in backends {
            for (pass, r) in passes {
                let (factor, at) = r.factor();
                println!(
                    "{scene:<8} {backend:<12} {pass:<22} {:>24} {:>8}",
                    format!("x{factor:.3} {}", short(at)),
                    format!("x{:.3}", r.lowest())
                );
            }
        }
    }
    eprintln!(
        "wrote {}; `harness noise --timing --source {name} --write` counts it in the model",
        path.display()
    );
    Ok(ExitCode::SUCCESS)
}

/// Writes the README.md beside the recording at `path` of host `name`, where there is none: what
/// the tool knows of the host (its drivers as the checks fingerprint them, its CPU signature,
/// when and at which commit), and what the person committing it must add.
fn start_readme(
    path: &std::path::Path,
    name: &str,
    recorded: &harness::golden::speed::recorded::RecordedTimings,
) -> anyhow::Result<()> {
    let readme = path.with_file_name("README.md");
    if !readme.exists() {
        let hosts: Vec<String> = recorded
            .hosts
            .iter()
            .map(|(kind, host)| format!("- {kind}: `{host}`"))
            .collect();
        let text = format!(
            "# {name}\n\nSpeed ratios recorded with `harness noise --timing --record-host {name}` \
             on {} (commit {}), CPU signature {}.\n\nDrivers as the checks fingerprint them:\n\n{}\n\n\
             TODO before committing: say what this host is (the machine or CI runner class, its \
             CPU, cores and memory, the OS and Mesa release), why it was recorded, and anything \
             that was running beside it.\n",
            recorded.recorded,
            recorded.commit.as_deref().unwrap_or("not a git tree"),
            recorded.cpu,
            hosts.join("\n")
        );
        std::fs::write(&readme, text)?;
        eprintln!(
            "wrote {}: a start; say there what this host is before committing",
            readme.display()
        );
    }
    Ok(())
}

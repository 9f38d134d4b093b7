//! `harness noise --timing --record-host NAME`: this host's speed ratios recorded in
//! golden/evidence/NAME/timing.toml, as another host's figures for the timing-noise model
//! ([`super::noise_timing`] measures and writes the model).

use std::process::ExitCode;

use engine::backend::BackendKind;
use harness::golden::GoldenStore;

use super::load_cases;
use super::noise_timing::{named, refuse_if_busy, short, this_hosts};

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
                 --timing {}`), not another host's",
                harness::golden::command_line::scene_flag(&scene)
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

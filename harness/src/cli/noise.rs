//! `harness noise`: measures how far unchanged renders move from the goldens under every source
//! of variation, judges them against the limits, and with `--write` records the noise model
//! (golden/noise.toml) the limits derive from.

use std::collections::BTreeMap;
use std::process::ExitCode;

use engine::backend::BackendKind;
use harness::golden::noise::{NoiseModel, MAX_NOISE_RATIO};
use harness::golden::portability::{self, Measurement, Missed, Ratio, Source, SourceRun};
use harness::golden::suite::Case;
use harness::golden::GoldenStore;

use super::load_cases;

/// The sources that cannot be measured here, each with why.
type Unmeasured = Vec<(String, String)>;

/// The command line of `harness noise`.
#[derive(clap::Args)]
pub(crate) struct NoiseArgs {
    /// Only these sources (repeatable): drivers, cpu-sse4.1, cpu-avx, vector-128, threads-1,
    /// mesa-<version>, synthetic-rounding, a recorded host; `cheap` for the quick ones. With
    /// --timing: runs, busy-neighbour, cpu-sse4.1, cpu-avx, mesa-<version>, a recorded host;
    /// --write then raises the model's figures where these measure more and keeps the rest.
    #[arg(long = "source")]
    sources: Vec<String>,
    /// Only these scenes (canonical names or scene files; repeatable).
    #[arg(long = "scene")]
    scenes: Vec<String>,
    /// Write golden/noise.toml from this run (needs every source).
    #[arg(long)]
    write: bool,
    /// With --write: limit = margin x max(noise, resolution) [default: 3]; with --timing,
    /// ln limit = margin x ln noise [default: 2].
    #[arg(long)]
    margin: Option<f64>,
    /// Print JSON.
    #[arg(long)]
    json: bool,
    /// Measure the timing-noise model instead (golden/timing-noise.toml): each pass's
    /// speed ratio against its timing golden over repeated probes, beside a busy
    /// neighbour, under the CPU code paths and the second Mesa.
    #[arg(long)]
    timing: bool,
    /// With --timing, on a host that did not bless: probe every scene on each backend in
    /// fresh processes and keep the ratios as this recorded host's figures
    /// (golden/evidence/<NAME>/timing.toml), a source of the other-host limits.
    #[arg(
        long,
        value_name = "NAME",
        requires = "timing",
        conflicts_with = "write"
    )]
    record_host: Option<String>,
    /// With --record-host: also count the ratios of this host's earlier checks of the same
    /// commit, from the speed history in OUT (the folder `check` wrote to: target/harness
    /// unless its --out said otherwise): the drift of an unchanged build over many runs.
    #[arg(long, value_name = "OUT", requires = "record_host")]
    history: Option<std::path::PathBuf>,
    /// With --timing: measure although other tasks keep this machine busy (by default
    /// --write and --record-host refuse to: the figures would be that load's).
    #[arg(long, requires = "timing")]
    busy_ok: bool,
}

/// `harness noise` as its command line asks: a host's recording, the timing-noise model, or
/// the image noise model, each with its default margin unless one is given.
pub(crate) fn entry(args: NoiseArgs) -> anyhow::Result<ExitCode> {
    if let Some(name) = &args.record_host {
        return super::noise_record::record_host(
            name,
            &args.scenes,
            args.history.as_deref(),
            args.busy_ok,
        );
    }
    if args.timing {
        let margin = args
            .margin
            .unwrap_or(harness::golden::speed::DEFAULT_TIMING_MARGIN);
        super::noise_timing::timing(
            &args.sources,
            &args.scenes,
            super::noise_timing::Writing {
                write: args.write,
                busy_ok: args.busy_ok,
            },
            margin,
            args.json,
        )
    } else {
        let margin = args
            .margin
            .unwrap_or(harness::golden::noise::DEFAULT_MARGIN);
        run(&args.sources, &args.scenes, args.write, margin, args.json)
    }
}

/// Measures the sources named (every one by default) on the scenes named (every canonical one by
/// default), writes golden/noise.toml with `write`, and prints each source's worst value against
/// every limit (or JSON); exits 1 when one is above half its limit or a render failed.
pub(crate) fn run(
    names: &[String],
    scenes: &[String],
    write: bool,
    margin: f64,
    json: bool,
) -> anyhow::Result<ExitCode> {
    let store = GoldenStore::workspace();
    let cases = load_cases(scenes)?;
    let (chosen, missing) = choose_sources(&store, names, write)?;
    let (backends, reference) = available_backends()?;
    let runs = measure_with_spinner(&store, &cases, &chosen, &backends, reference)?;
    let measurements: Vec<Measurement> = runs
        .iter()
        .flat_map(|(_, r)| r.measurements.iter().cloned())
        .collect();
    let missed: Vec<Missed> = runs
        .iter()
        .flat_map(|(_, r)| r.missed.iter().cloned())
        .collect();
    let cases = if write {
        write_model(&store, &cases, &runs, &measurements, &missed, margin)?
    } else {
        cases
    };
    let ratios = portability::ratios(&cases, &measurements);
    let too_noisy: Vec<&Ratio> = ratios
        .iter()
        .filter(|r| r.ratio > MAX_NOISE_RATIO)
        .collect();
    let failed_renders: Vec<&Missed> = missed.iter().filter(|m| !m.known).collect();
    if json {
        print_json(&runs, &missing, &ratios, &missed, &measurements)?;
    } else {
        print_table(
            &runs,
            &ratios,
            &missed,
            &too_noisy,
            measurements.len(),
            failed_renders.len(),
        );
    }
    Ok(if too_noisy.is_empty() && failed_renders.is_empty() {
        ExitCode::SUCCESS
    } else {
        ExitCode::FAILURE
    })
}

/// The sources to measure (those named, or every one) and those that cannot be measured here
/// with why (each noted on stderr). `--write` needs every source: naming some, or missing one,
/// is an error then.
fn choose_sources(
    store: &GoldenStore,
    names: &[String],
    write: bool,
) -> anyhow::Result<(Vec<Source>, Unmeasured)> {
    let (all, missing) = portability::sources(store);
    let chosen = portability::select(&all, &missing, names).map_err(anyhow::Error::msg)?;
    if write && (!names.is_empty() || !missing.is_empty()) {
        anyhow::bail!(
            "--write records every source; {}",
            if missing.is_empty() {
                "leave out --source".to_owned()
            } else {
                missing
                    .iter()
                    .map(|(_, why)| why.clone())
                    .collect::<Vec<_>>()
                    .join("; ")
            }
        );
    }
    for (name, why) in &missing {
        eprintln!("note: not measured: {name}: {why}");
    }
    Ok((chosen, missing))
}

/// Every available backend, and the one synthetic rounding renders on: the golden suite's
/// reference backend when available, else the first. Fails when none is available.
fn available_backends() -> anyhow::Result<(Vec<BackendKind>, BackendKind)> {
    let backends: Vec<BackendKind> = BackendKind::ALL
        .into_iter()
        .filter(|&k| engine::backend::probe(k).available)
        .collect();
    let Some(reference) = harness::golden::suite::reference_among(&backends) else {
        anyhow::bail!("no backend is available; run `harness backends` for the reasons");
    };
    Ok((backends, reference))
}

/// Measures every chosen source (environment sources through this binary in child processes),
/// showing what is being measured on a spinner. One run per source, in order.
fn measure_with_spinner(
    store: &GoldenStore,
    cases: &[Case],
    chosen: &[Source],
    backends: &[BackendKind],
    reference: BackendKind,
) -> anyhow::Result<Vec<(Source, SourceRun)>> {
    let exe = std::env::current_exe()?;
    let bar = indicatif::ProgressBar::new_spinner().with_style(
        indicatif::ProgressStyle::with_template("{spinner} {elapsed} {msg}")
            .unwrap_or_else(|_| indicatif::ProgressStyle::default_spinner()),
    );
    bar.enable_steady_tick(std::time::Duration::from_millis(200));
    let runs = portability::measure(&exe, store, cases, chosen, backends, reference, |what| {
        bar.set_message(what.to_owned())
    });
    bar.finish_and_clear();
    Ok(runs)
}

/// Builds the noise model from the measurements, saves it as golden/noise.toml, and returns the
/// cases loaded again with the limits just written, so that the run is judged against them.
fn write_model(
    store: &GoldenStore,
    cases: &[Case],
    runs: &[(Source, SourceRun)],
    measurements: &[Measurement],
    missed: &[Missed],
    margin: f64,
) -> anyhow::Result<Vec<Case>> {
    let previous = NoiseModel::load(store)?;
    let model = portability::build_model(
        cases,
        measurements,
        margin,
        source_descriptions(runs),
        missed,
        &previous,
    );
    let path = model.save(store)?;
    eprintln!("wrote {}", path.display());
    // Judge the run against the limits just written.
    let cases = cases
        .iter()
        .map(|c| harness::golden::suite::Case::load_with(&c.loaded.path.to_string_lossy(), &model))
        .collect::<Result<_, _>>()?;
    Ok(cases)
}

/// Each source's description for the noise model, with the driver each backend reported under
/// it, and paths inside this checkout written relative to it.
fn source_descriptions(runs: &[(Source, SourceRun)]) -> BTreeMap<String, String> {
    runs.iter()
        .map(|(source, run)| {
            let mut text = source.description.clone();
            // By name, as the file has always listed them.
            let mut drivers: Vec<_> = run.drivers.iter().collect();
            drivers.sort_by_key(|(backend, _)| backend.name());
            for (backend, driver) in drivers {
                text.push_str(&format!("; {backend}: {driver}"));
            }
            // Paths inside this checkout (the second Mesa's prefix) are the same on every
            // machine relative to it.
            let root = harness::workspace_root().to_string_lossy().into_owned();
            (source.name.clone(), text.replace(&root, "<workspace>"))
        })
        .collect()
}

/// The whole run as one JSON object on stdout: the sources with their drivers, those not
/// measured, the ratios, the renders missed and every measurement.
fn print_json(
    runs: &[(Source, SourceRun)],
    missing: &[(String, String)],
    ratios: &[Ratio],
    missed: &[Missed],
    measurements: &[Measurement],
) -> anyhow::Result<()> {
    println!(
        "{}",
        serde_json::to_string_pretty(&serde_json::json!({
            "sources": runs.iter().map(|(s, r)| serde_json::json!({
                "name": s.name, "description": s.description, "drivers": r.drivers,
            })).collect::<Vec<_>>(),
            "not_measured": missing,
            "ratios": ratios,
            "missed": missed,
            "measurements": measurements,
        }))?
    );
    Ok(())
}

/// The table of each source's worst value against every limit, then each render missed, each
/// value above half its limit, and a summary line.
fn print_table(
    runs: &[(Source, SourceRun)],
    ratios: &[Ratio],
    missed: &[Missed],
    too_noisy: &[&Ratio],
    measurement_count: usize,
    failed_render_count: usize,
) {
    let names: Vec<String> = runs.iter().map(|(s, _)| s.name.clone()).collect();
    print!("{}", portability::table(ratios, &names));
    for m in missed {
        println!(
            "{} {} on {} {}: {}",
            if m.known { "known crash:" } else { "FAILED:" },
            m.source,
            m.backend,
            m.scene,
            m.error
        );
    }
    for r in too_noisy {
        println!(
            "{}: {} {} {} on {}: {:.4e} is {:.2} of its limit {:.4e}",
            if r.ratio > 1.0 {
                "FAILED"
            } else {
                "ABOVE HALF"
            },
            r.source,
            r.scene,
            r.pass,
            r.backend.map_or("-", BackendKind::name),
            r.value,
            r.ratio,
            r.limit
        );
    }
    println!(
        "{} sources, {} measurements: {} above {MAX_NOISE_RATIO} of a limit, {} failed renders",
        runs.len(),
        measurement_count,
        too_noisy.len(),
        failed_render_count
    );
}

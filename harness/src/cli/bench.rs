//! `harness bench`: GPU timings of every pass against its floor, scaling series, and the
//! breakdown of the lighting passes, kept for the check report.

use std::path::Path;
use std::process::ExitCode;

use engine::backend::BackendKind;
use harness::measure::bench::Series;

use super::scenes_or_canonical;

/// `harness bench`: times every pass of each scene asked for (every canonical one by default)
/// on each backend (every one by default) and keeps bench.json in `out`; exits 1 when a
/// backend asked for is missing or a scene fails to render.
pub(crate) fn pass_table(
    scenes: &[String],
    backends: &[BackendKind],
    frames: usize,
    slow: Option<engine::renderer::SlowPass>,
    out: &Path,
    json: bool,
) -> anyhow::Result<ExitCode> {
    let variations = engine::renderer::Variations {
        slow_pass: slow,
        ..Default::default()
    };
    let loaded = load_scenes(scenes)?;
    // An injected slowdown is a test of the speed checks, not this build's speed: said on every
    // output, and kept out of the history (whose series are an unchanged build's ratios).
    let injected = slow.map(|s| format!("{} slowed x{} (--slow-pass)", s.pass, s.factor));
    if let Some(injected) = &injected {
        eprintln!(
            "note: injected slowdown: {injected}; these timings are not this build's, and \
             the speed history is not appended"
        );
    }
    let (results, failed) = each_scene_and_backend(&loaded, backends, |scene, kind| {
        eprintln!("timing {} on {kind} ({frames} frames) ...", scene.name);
        let result = harness::measure::bench::bench_scene_with(scene, kind, frames, variations)?;
        if !json {
            println!("{}", harness::measure::bench::table(&result));
        }
        Ok(result)
    });
    let precompute = harness::measure::bench::precompute(&loaded);
    if !json {
        println!("precomputation (apart from frames):");
        for p in &precompute {
            println!("  {:<44} {:>8.3} ms  ({})", p.what, p.ms, p.on);
        }
    }
    let text = serde_json::to_string_pretty(&serde_json::json!({
        "precompute": precompute,
        "scenes": results,
        "injected": injected,
    }))?;
    save_bench_json(out, harness::measure::bench::BENCH_JSON, &text)?;
    if injected.is_none() {
        append_bench_history(out, &results);
    }
    if json {
        println!("{text}");
    }
    Ok(if failed {
        ExitCode::FAILURE
    } else {
        ExitCode::SUCCESS
    })
}

/// `--series`: a scaling series, or all of them.
#[derive(Clone, Copy, Debug, PartialEq, Eq, clap::ValueEnum)]
pub(crate) enum SeriesArg {
    /// Chess at 256..2048 pixels a side.
    Resolution,
    /// 1..256 point lights.
    Lights,
    /// Chess's meshes subdivided 1x..64x.
    Triangles,
    /// Chess's sun with 512..4096 shadow maps.
    ShadowMap,
    /// Every series.
    All,
}

impl SeriesArg {
    /// The series chosen (none for `all`).
    fn series(self) -> Option<Series> {
        match self {
            SeriesArg::Resolution => Some(Series::Resolution),
            SeriesArg::Lights => Some(Series::Lights),
            SeriesArg::Triangles => Some(Series::Triangles),
            SeriesArg::ShadowMap => Some(Series::ShadowMap),
            SeriesArg::All => None,
        }
    }
}

/// `harness bench --series`: the scaling series named (`all` for every one) on each backend
/// asked for (gl by default), kept as bench_series.json in `out`.
pub(crate) fn series(
    chosen: &[SeriesArg],
    backends: &[BackendKind],
    frames: usize,
    out: &Path,
    json: bool,
) -> anyhow::Result<ExitCode> {
    let names: Vec<Series> = if chosen.contains(&SeriesArg::All) {
        Series::ALL.to_vec()
    } else {
        chosen.iter().filter_map(|s| s.series()).collect()
    };
    let kinds = backends_or_gl(backends);
    let mut all = Vec::new();
    for kind in kinds {
        for name in &names {
            let points = harness::measure::bench::series(*name, kind, frames, |what| {
                eprintln!("  {kind}: {what} ...");
            })?;
            if !json {
                println!(
                    "{} series on {kind} (median of {frames} frames, GPU ms)",
                    name.name()
                );
                println!("{}", harness::measure::bench::series_table(&points));
            }
            all.push(serde_json::json!({ "backend": kind.name(), "points": points }));
        }
    }
    let text = serde_json::to_string_pretty(&all)?;
    save_bench_json(out, harness::measure::bench::SERIES_JSON, &text)?;
    if json {
        println!("{text}");
    }
    Ok(ExitCode::SUCCESS)
}

/// `harness bench --breakdown`: each lighting pass's cost, part by part.
pub(crate) fn breakdown(
    scenes: &[String],
    backends: &[BackendKind],
    frames: usize,
    json: bool,
) -> anyhow::Result<ExitCode> {
    let names = scenes_or_canonical(scenes);
    let kinds = backends_or_gl(backends);
    let mut all = Vec::new();
    for kind in kinds {
        for name in &names {
            let scene = harness::load_scene(name)?.scene;
            let passes = harness::measure::bench::breakdown(&scene, kind, frames, |what| {
                eprintln!("  {} on {kind}: {what} ({frames} frames) ...", scene.name);
            })?;
            if !json {
                for pass in &passes {
                    println!("{}", harness::measure::bench::breakdown_table(pass));
                }
            }
            all.extend(passes);
        }
    }
    if json {
        println!("{}", serde_json::to_string_pretty(&all)?);
    }
    Ok(ExitCode::SUCCESS)
}

/// The backends asked for, or gl.
fn backends_or_gl(backends: &[BackendKind]) -> Vec<BackendKind> {
    if backends.is_empty() {
        vec![BackendKind::Gl]
    } else {
        backends.to_vec()
    }
}

/// Keeps the latest bench results (in target/harness/ by default) for the check report.
fn save_bench_json(dir: &Path, name: &str, text: &str) -> anyhow::Result<()> {
    std::fs::create_dir_all(dir)?;
    let path = dir.join(name);
    harness::images::write_atomically(&path, text.as_bytes())?;
    eprintln!(
        "wrote {} (shown in the next `harness check` report)",
        path.display()
    );
    Ok(())
}

/// `harness speed --in-process`: the probe in this process, as JSON (or a table); exits 1 when
/// a backend asked for is missing or a scene fails. Every probe is prepared first (started,
/// recorded, warmed up), then each takes its timed rounds in turn; with `wait_for_go`, only
/// once a line (or the end) comes on stdin.
pub(crate) fn speed_in_process(
    scenes: &[String],
    backends: &[BackendKind],
    rounds: usize,
    variations: engine::renderer::Variations,
    json: bool,
    wait_for_go: bool,
) -> anyhow::Result<ExitCode> {
    let loaded = load_scenes(scenes)?;
    let (prepared, mut failed) = each_scene_and_backend(&loaded, backends, |scene, kind| {
        eprintln!("preparing {} on {kind} ...", scene.name);
        harness::measure::speed::PreparedProbe::new(scene, kind, variations)
    });
    if wait_for_go {
        eprintln!(
            "prepared {} probe(s); waiting for a line on stdin",
            prepared.len()
        );
        let mut line = String::new();
        std::io::stdin().read_line(&mut line)?;
    }
    let mut results = Vec::new();
    for probe in prepared {
        eprintln!(
            "probing {} on {} ({rounds} rounds) ...",
            probe.scene(),
            probe.backend()
        );
        match probe.sample(rounds) {
            Ok(result) => {
                if !json {
                    print_speed(&result);
                }
                results.push(result);
            }
            Err(e) => {
                eprintln!("error: {e}");
                failed = true;
            }
        }
    }
    if json {
        println!("{}", serde_json::to_string_pretty(&results)?);
    }
    Ok(if failed {
        ExitCode::FAILURE
    } else {
        ExitCode::SUCCESS
    })
}

/// `harness speed`: the speed probe of each scene asked for (every canonical one by default) on
/// each backend (every available one by default), each backend in a child process on one
/// rasterizer thread, as a table or JSON; exits 1 when a backend asked for is missing or a
/// scene fails.
pub(crate) fn speed(
    scenes: &[String],
    backends: &[BackendKind],
    rounds: usize,
    variations: engine::renderer::Variations,
    json: bool,
) -> anyhow::Result<ExitCode> {
    let exe = std::env::current_exe()?;
    let names = scenes_or_canonical(scenes);
    let kinds = backends_or_all(backends);
    let mut results = Vec::new();
    let mut failed = false;
    for kind in kinds {
        let status = engine::backend::probe(kind);
        if !status.available {
            eprintln!("skipping {kind}: {}", status.reason.unwrap_or_default());
            failed |= !backends.is_empty();
            continue;
        }
        eprintln!(
            "probing {} scene(s) on {kind} ({rounds} rounds, one rasterizer thread) ...",
            names.len()
        );
        let (probed, errors) =
            harness::measure::speed::probe_in_child(&exe, &names, &[kind], rounds, variations, &[]);
        for e in &errors {
            eprintln!("error: {e}");
        }
        failed |= !errors.is_empty();
        for result in probed {
            if !json {
                print_speed(&result);
            }
            results.push(result);
        }
    }
    if json {
        println!("{}", serde_json::to_string_pretty(&results)?);
    }
    Ok(if failed {
        ExitCode::FAILURE
    } else {
        ExitCode::SUCCESS
    })
}

/// One probe as a table: each pass's fastest time, its floor's, and the ratio.
fn print_speed(result: &harness::measure::speed::SceneSpeed) {
    println!("{} on {}", result.scene, result.backend);
    for pass in &result.passes {
        println!(
            "  {:<24} {:>8.3} ms  floor {:>7.3} ms  ratio {:>7.3}",
            pass.pass,
            pass.min_ms().unwrap_or(f64::NAN),
            pass.floor_min_ms().unwrap_or(f64::NAN),
            pass.ratio().unwrap_or(f64::NAN)
        );
    }
}

/// The arguments of `harness speed`.
#[derive(clap::Args)]
pub(crate) struct SpeedArgs {
    /// Only these scenes (canonical names or scene files; repeatable).
    #[arg(long = "scene")]
    pub scenes: Vec<String>,
    /// Only this backend: gl, wgpu-vulkan or wgpu-gl (repeatable). Default: every available one.
    #[arg(long = "backend")]
    pub backends: Vec<BackendKind>,
    /// The most rounds per scene and backend (a pass stops once it has settled).
    #[arg(long, default_value_t = harness::measure::speed::SPEED_ROUNDS)]
    pub rounds: usize,
    /// Slow this pass down by --slowdown (what the speed self-test injects).
    #[arg(long)]
    pub slow_pass: Option<String>,
    /// How many times over --slow-pass submits its pass's work (1.5: half of it again).
    #[arg(long, default_value_t = 2.0, requires = "slow_pass")]
    pub slowdown: f32,
    /// Give the lighting passes the generic, unspecialised shader variant (a debug setting
    /// that reproduces a real slowdown).
    #[arg(long)]
    pub debug_unspecialised_lighting: bool,
    /// Print JSON with every sample.
    #[arg(long)]
    pub json: bool,
    /// Probe in this process, with the drivers as the environment sets them (what the
    /// child processes that `speed`, `check`, `bless` and `noise` start do). Without it,
    /// each backend is probed in a child process on one rasterizer thread.
    #[arg(long, hide = true)]
    pub in_process: bool,
    /// With --in-process: prepare every probe, then wait for a line on stdin before the timed
    /// rounds (how `check` lets its probe child prepare while it renders the images).
    #[arg(long, hide = true, requires = "in_process")]
    pub wait_for_go: bool,
}

/// `harness speed`: parses the slowdown asked for and probes, in child processes (or in this
/// one with `--in-process`).
pub(crate) fn speed_command(args: SpeedArgs) -> anyhow::Result<ExitCode> {
    let slow = match args
        .slow_pass
        .map(|name| name.parse::<engine::plan::PassId>())
    {
        Some(Ok(pass)) => Some(engine::renderer::SlowPass {
            pass,
            factor: args.slowdown,
        }),
        Some(Err(e)) => {
            eprintln!("error: --slow-pass: {e}");
            return Ok(ExitCode::from(2));
        }
        None => None,
    };
    let variations = engine::renderer::Variations {
        slow_pass: slow,
        unspecialised_lighting: args.debug_unspecialised_lighting,
        ..Default::default()
    };
    // A name that is no scene is one error here, not one per backend's probe child.
    for name in &args.scenes {
        engine::scene_file::resolve(name, &harness::scenes_dir())?;
    }
    if args.in_process {
        speed_in_process(
            &args.scenes,
            &args.backends,
            args.rounds,
            variations,
            args.json,
            args.wait_for_go,
        )
    } else {
        speed(
            &args.scenes,
            &args.backends,
            args.rounds,
            variations,
            args.json,
        )
    }
}

/// The scenes asked for (every canonical one when none is).
fn load_scenes(scenes: &[String]) -> anyhow::Result<Vec<engine::scene::Scene>> {
    Ok(scenes_or_canonical(scenes)
        .iter()
        .map(|n| harness::load_scene(n).map(|l| l.scene))
        .collect::<Result<Vec<_>, _>>()?)
}

/// Runs `measure` on each scene on each backend asked for (every one when none is; a backend
/// that does not start is skipped with a note, a failure when it was asked for), printing each
/// error: the results and whether anything failed.
fn each_scene_and_backend<R>(
    scenes: &[engine::scene::Scene],
    backends: &[BackendKind],
    mut measure: impl FnMut(
        &engine::scene::Scene,
        BackendKind,
    ) -> Result<R, harness::measure::bench::BenchError>,
) -> (Vec<R>, bool) {
    let kinds = backends_or_all(backends);
    let mut results = Vec::new();
    let mut failed = false;
    for kind in kinds {
        if let Err(e) = harness::faults::create_backend(kind) {
            eprintln!("skipping {kind}: {e}");
            failed |= !backends.is_empty();
            continue;
        }
        for scene in scenes {
            match measure(scene, kind) {
                Ok(result) => results.push(result),
                Err(e) => {
                    eprintln!("error: {e}");
                    failed = true;
                }
            }
        }
    }
    (results, failed)
}

/// Appends the pass table's ratios (each pass over its floor, interleaved frames, lower
/// quartile) to the speed history in `out`, as a `bench` entry.
fn append_bench_history(out: &Path, results: &[harness::measure::bench::SceneBench]) {
    use harness::golden::speed::{history, host_fingerprint};
    let mut hosts = std::collections::BTreeMap::new();
    let mut ratios = Vec::new();
    for result in results {
        hosts.entry(result.backend).or_insert_with(|| {
            let driver = engine::backend::probe(result.backend)
                .info
                .map(|info| harness::golden::fingerprint(&info))
                .unwrap_or_default();
            host_fingerprint(&driver)
        });
        for pass in &result.passes {
            if let (Some(ratio), Some(ms)) = (pass.ratio, pass.median_ms) {
                ratios.push(history::HistoryRatio {
                    scene: result.scene.clone(),
                    backend: result.backend,
                    pass: pass.pass,
                    ratio,
                    ms,
                });
            }
        }
    }
    // A bench's ratios are not pooled with a recording's: no scene digests needed.
    history::record(out, "bench", hosts, ratios, Default::default());
}

/// The backends asked for, or every one when none is.
fn backends_or_all(backends: &[BackendKind]) -> Vec<BackendKind> {
    if backends.is_empty() {
        BackendKind::ALL.to_vec()
    } else {
        backends.to_vec()
    }
}

//! `harness`: the command line of the render regression harness.
//!
//! `cargo run --release -p harness` runs `check`, the main job.

use std::path::{Path, PathBuf};
use std::process::ExitCode;

use clap::{Parser, Subcommand};

use engine::backend::BackendKind;
use harness::first_scene;

#[derive(Parser)]
#[command(
    name = "harness",
    version,
    about = "Render regression and validation harness"
)]
struct Cli {
    #[command(subcommand)]
    command: Option<Command>,
}

#[derive(Subcommand)]
enum Command {
    /// Render every canonical scene on every available backend, check every pass against its
    /// golden, compare the backends with each other, print a table and write the HTML report
    /// (the default command). Exits 1 on any failure.
    Check {
        /// Where to write the report (report.html) and failure images.
        #[arg(long, default_value_os_t = default_out_dir())]
        out: PathBuf,
        /// Only these scenes (canonical names or scene files; repeatable).
        #[arg(long = "scene")]
        scenes: Vec<String>,
        /// Only this backend (repeatable). Default: every available one.
        #[arg(long = "backend")]
        backends: Vec<BackendKind>,
        /// Print the results as JSON on stdout.
        #[arg(long)]
        json: bool,
    },
    /// Measure the noise model behind the golden tolerances: how far unchanged renders move
    /// from the goldens under every source of variation (the backends, llvmpipe's CPU code
    /// paths, a second Mesa from scripts/mesa-backports.sh, synthetic rounding, renders recorded
    /// on other hosts in golden/evidence/). Prints each source's worst value against every limit
    /// and exits 1 if any is above half its limit or a render failed. With --write, records the
    /// figures and the limits derived from them (margin x noise) in golden/noise.toml.
    Noise {
        /// Only these sources (repeatable): drivers, cpu-sse4.1, cpu-avx, vector-128, threads-1,
        /// mesa-<version>, synthetic-rounding, a recorded host; `cheap` for the quick ones.
        #[arg(long = "source")]
        sources: Vec<String>,
        /// Only these scenes (canonical names or scene files; repeatable).
        #[arg(long = "scene")]
        scenes: Vec<String>,
        /// Write golden/noise.toml from this run (needs every source).
        #[arg(long)]
        write: bool,
        /// With --write: limit = margin x max(noise, resolution).
        #[arg(long, default_value_t = harness::golden::noise::DEFAULT_MARGIN)]
        margin: f64,
        /// Print JSON.
        #[arg(long)]
        json: bool,
    },
    /// Write new goldens after an intended change: renders the scene, compares each pass with
    /// its golden, and rewrites only the passes that changed (outside tolerance) or have no
    /// golden, atomically, recording the driver and date in golden/<scene>/blessed.toml. Passes
    /// within tolerance and their records are left alone.
    Bless {
        /// Only this scene: a name in scenes/ or a path to a scene file (repeatable).
        #[arg(long = "scene")]
        scenes: Vec<String>,
        /// Only this pass (repeatable); a pass named here is rewritten even within tolerance.
        #[arg(long = "pass")]
        passes: Vec<String>,
        /// Rewrite every pass considered, also those within tolerance (after a driver change).
        #[arg(long)]
        every_pass: bool,
        /// Backend to render the goldens with.
        #[arg(long, default_value = "gl")]
        backend: BackendKind,
        /// Bless every pass of every canonical scene (required when no --scene is given).
        #[arg(long)]
        all: bool,
        /// Show what would change without writing anything.
        #[arg(long)]
        dry_run: bool,
    },
    /// Render a scene on one backend and write pass outputs (`.png`, or `.exr` for float passes).
    Render {
        /// Canonical scene name (`chess`) or path to a scene file.
        #[arg(long)]
        scene: String,
        /// Backend: gl, wgpu-vulkan or wgpu-gl.
        #[arg(long, default_value = "gl")]
        backend: BackendKind,
        /// Pass output to write (repeatable; `all` for every output). Default: final.
        #[arg(long = "pass")]
        passes: Vec<String>,
        /// Output file (one pass) or folder (several). Default:
        /// target/harness/render/<scene>/<backend>/<pass>.<png|exr>.
        #[arg(long)]
        out: Option<PathBuf>,
    },
    /// Print the render plan of a scene: the passes and targets it needs.
    Plan {
        /// Canonical scene name (`chess`) or path to a scene file.
        #[arg(long)]
        scene: String,
    },
    /// Load an OBJ, MTL, scene file (.toml), EXR or PNG and report what was loaded; exit 1 if it
    /// does not load.
    Inspect {
        /// The file.
        path: PathBuf,
        /// Print JSON.
        #[arg(long)]
        json: bool,
    },
    /// Mutation self-test: 15 small known changes (light x1.02, exposure x1.03, roughness +0.05,
    /// shadow bias x4, a G-buffer channel swap, ...) must each fail in the pass where they
    /// originate by at least 3x its limit on every backend, while unchanged renders (every
    /// backend, synthetic rounding, and the sources golden/noise.toml recorded) stay at or
    /// below half of every limit. Prints the margin and noise tables.
    Selftest {
        /// Print JSON.
        #[arg(long)]
        json: bool,
    },
    /// Speed against error for a quality knob, timed with GPU timestamps: `shadow` (filter x map
    /// size, against ray casting and the converged soft filter) or `ibl` (samples, specular size,
    /// SH9 irradiance, against a Monte Carlo reference, with the precompute time) or `gbuffer`
    /// (position storage x normal encoding, at 0, 1 km and 10 km from the origin).
    Sweep {
        /// Canonical scene name or scene file.
        #[arg(long, default_value = "chess")]
        scene: String,
        /// The knob: shadow, ibl or gbuffer.
        #[arg(long, default_value = "shadow")]
        knob: String,
        /// Backend.
        #[arg(long, default_value = "gl")]
        backend: BackendKind,
        /// Renders per setting (timings are their median).
        #[arg(long, default_value_t = 3)]
        repeats: usize,
        /// Light the scene with this environment (EXR or .hdr) instead of its own, keeping its
        /// rotation and intensity: the IBL sweep under another sky.
        #[arg(long)]
        environment: Option<PathBuf>,
        /// Print JSON.
        #[arg(long)]
        json: bool,
    },
    /// Time every pass of every canonical scene on every available backend (GPU timestamps,
    /// median of a few frames) against its floor: a trivial pass writing the same targets.
    /// A quick version of `cargo bench`.
    Bench {
        /// Only these scenes (canonical names or scene files; repeatable).
        #[arg(long = "scene")]
        scenes: Vec<String>,
        /// Only this backend (repeatable). Default: every available one.
        #[arg(long = "backend")]
        backends: Vec<BackendKind>,
        /// Frames timed per scene and backend, after one warm-up frame.
        #[arg(long, default_value_t = 5)]
        frames: usize,
        /// Instead of the scenes, a scaling series: resolution, lights, triangles, shadow-map,
        /// or all (repeatable).
        #[arg(long = "series")]
        series: Vec<String>,
        /// Instead of the pass table, where each lighting pass's time goes: its input floor
        /// (reading the G-buffer, no shading), its per-pixel setup, then the time it loses
        /// without IBL, without each light, and (parts of those) without shadow lookups and
        /// clearcoat; against the pass as it is.
        #[arg(long, conflicts_with = "series")]
        breakdown: bool,
        /// Where to keep the results (bench.json, bench_series.json) for the check report.
        #[arg(long, default_value_os_t = default_out_dir())]
        out: PathBuf,
        /// Print JSON.
        #[arg(long)]
        json: bool,
    },
    /// Run the numerical hard cases (scenes/hard/ and chess moved 1e4/1e5 and scaled
    /// 0.001/1000) on every available backend: no NaN/Inf, the light buffer in range, and each
    /// case's own check. Prints the table, keeps it for the check report, exits 1 on a failure.
    Hard {
        /// Only this backend (repeatable). Default: every available one.
        #[arg(long = "backend")]
        backends: Vec<BackendKind>,
        /// Print JSON.
        #[arg(long)]
        json: bool,
    },
    /// List the canonical scenes with their descriptions.
    Scenes,
    /// List every backend with its availability, the reason and fix when unavailable, and the
    /// driver fingerprint when available.
    Backends {
        /// Print a JSON array instead of a table.
        #[arg(long)]
        json: bool,
    },
}

/// `target/harness` in the workspace.
fn default_out_dir() -> PathBuf {
    harness::workspace_root().join("target/harness")
}

/// Gives the process a private runtime directory when XDG_RUNTIME_DIR is unset or unusable:
/// the Vulkan loader and Mesa's window-system probes print "XDG_RUNTIME_DIR is invalid or not
/// set" once per device otherwise (eight times a check), although no display is used. Runs
/// first in `main`, before any thread or driver exists.
fn private_runtime_dir() {
    use std::os::unix::fs::{MetadataExt, PermissionsExt};
    let Ok(me) = std::fs::metadata("/proc/self").map(|m| m.uid()) else {
        return;
    };
    let usable = |dir: &std::path::Path| {
        std::fs::metadata(dir)
            .is_ok_and(|m| m.is_dir() && m.uid() == me && m.permissions().mode() & 0o077 == 0)
    };
    if std::env::var_os("XDG_RUNTIME_DIR").is_some_and(|d| usable(std::path::Path::new(&d))) {
        return;
    }
    let dir = std::env::temp_dir().join(format!("harness-runtime-{me}"));
    let _ = std::fs::create_dir(&dir);
    let _ = std::fs::set_permissions(&dir, std::fs::Permissions::from_mode(0o700));
    if usable(&dir) {
        std::env::set_var("XDG_RUNTIME_DIR", &dir);
    }
}

fn main() -> ExitCode {
    private_runtime_dir();
    env_logger::Builder::from_env(env_logger::Env::default().default_filter_or("warn")).init();
    let cli = Cli::parse();
    harness::use_ibl_cache();
    let command = cli.command.unwrap_or(Command::Check {
        out: default_out_dir(),
        scenes: vec![],
        backends: vec![],
        json: false,
    });
    let result = match command {
        Command::Backends { json } => backends(json),
        Command::Check {
            out,
            scenes,
            backends,
            json,
        } => check(&out, &scenes, &backends, json),
        Command::Noise {
            sources,
            scenes,
            write,
            margin,
            json,
        } => noise(&sources, &scenes, write, margin, json),
        Command::Bless {
            scenes,
            passes,
            backend,
            all,
            every_pass,
            dry_run,
        } => bless(&scenes, &passes, backend, all, every_pass, dry_run),
        Command::Render {
            scene,
            backend,
            passes,
            out,
        } => render(&scene, backend, &passes, out),
        Command::Plan { scene } => harness::load_scene(&scene)
            .map(|loaded| {
                print!("{}", engine::plan::RenderPlan::new(&loaded.scene));
                ExitCode::SUCCESS
            })
            .map_err(Into::into),
        Command::Inspect { path, json } => inspect(&path, json),
        Command::Scenes => scenes(),
        Command::Hard { backends, json } => hard(&backends, json),
        Command::Selftest { json } => selftest(json),
        Command::Sweep {
            scene,
            knob,
            backend,
            repeats,
            environment,
            json,
        } => sweep(
            &scene,
            &knob,
            backend,
            repeats,
            environment.as_deref(),
            json,
        ),
        Command::Bench {
            scenes,
            backends,
            frames,
            series,
            breakdown,
            out,
            json,
        } => {
            if breakdown {
                bench_breakdown(&scenes, &backends, frames, json)
            } else if series.is_empty() {
                bench(&scenes, &backends, frames, &out, json)
            } else {
                bench_series(&series, &backends, frames, &out, json)
            }
        }
    };
    match result {
        Ok(code) => code,
        Err(e) => {
            eprintln!("error: {}", harness::error_text(e.as_ref()));
            ExitCode::FAILURE
        }
    }
}

fn backends(json: bool) -> anyhow::Result<ExitCode> {
    let statuses = first_scene::probe_all();
    if json {
        println!("{}", serde_json::to_string_pretty(&statuses)?);
        return Ok(ExitCode::SUCCESS);
    }
    for status in &statuses {
        match (&status.info, &status.reason) {
            (Some(info), _) => println!(
                "{:<12} available    {} | {} | Mesa {} | LLVM {} | timestamps {}",
                status.name,
                info.api_version,
                info.renderer,
                info.mesa_version.as_deref().unwrap_or("-"),
                info.llvm_version.as_deref().unwrap_or("-"),
                if info.timestamps { "yes" } else { "no" },
            ),
            (None, reason) => println!(
                "{:<12} UNAVAILABLE  {}\n{:<12}   fix: {}",
                status.name,
                reason.as_deref().unwrap_or("unknown"),
                "",
                status.fix.as_deref().unwrap_or("-"),
            ),
        }
    }
    Ok(ExitCode::SUCCESS)
}

/// The scenes named (every canonical one when none is), each that loads as a case and each that
/// does not as a broken scene with its error (printed here), so that a run can go on with the
/// others. Fails only when the noise model cannot be read.
fn load_cases_isolated(
    scenes: &[String],
) -> anyhow::Result<(
    Vec<harness::golden::suite::Case>,
    Vec<harness::golden::suite::BrokenScene>,
)> {
    let (cases, broken) = harness::golden::suite::load_suite(&scenes_or_canonical(scenes))?;
    for case in &cases {
        print_load_warnings(&case.loaded);
    }
    for b in &broken {
        eprintln!("error: scene `{}` did not load: {}", b.scene, b.error);
    }
    Ok((cases, broken))
}

/// The scenes named (every canonical one when none is); any that does not load fails the
/// command (bless and noise need every scene they were asked for).
fn load_cases(scenes: &[String]) -> anyhow::Result<Vec<harness::golden::suite::Case>> {
    let (cases, broken) = load_cases_isolated(scenes)?;
    if !broken.is_empty() {
        anyhow::bail!(
            "{} scene(s) did not load: {}",
            broken.len(),
            broken
                .iter()
                .map(|b| b.scene.as_str())
                .collect::<Vec<_>>()
                .join(", ")
        );
    }
    Ok(cases)
}

/// A scene's asset warnings on stderr, once per asset (the loader collects each once).
fn print_load_warnings(loaded: &engine::scene_file::LoadedScene) {
    for warning in &loaded.warnings {
        eprintln!("warning: {warning}");
    }
}

fn check(
    out: &std::path::Path,
    scenes: &[String],
    backends: &[BackendKind],
    json: bool,
) -> anyhow::Result<ExitCode> {
    let (cases, broken) = load_cases_isolated(scenes)?;
    let store = harness::golden::GoldenStore::workspace();
    let bar = indicatif::ProgressBar::new(0).with_style(
        indicatif::ProgressStyle::with_template("{bar:30} {pos}/{len} renders  {msg}")
            .unwrap_or_else(|_| indicatif::ProgressStyle::default_bar()),
    );
    let failures = out.join("failures");
    let (run, outputs) =
        harness::golden::check::run(&cases, &store, backends, &failures, |done, total, what| {
            bar.set_length(total as u64);
            bar.set_position(done as u64);
            bar.set_message(what.to_owned());
        });
    bar.finish_and_clear();
    let mut run = run;
    run.load_errors = broken;
    for b in &run.backends {
        if let Some(reason) = &b.unavailable {
            eprintln!("note: {} unavailable: {reason}", b.backend);
        }
    }
    if run.backends.iter().all(|b| b.unavailable.is_some()) {
        anyhow::bail!("no backend is available; run `harness backends` for the reasons");
    }
    for note in &run.driver_notes {
        eprintln!("note: {note}");
    }
    for case in &cases {
        use harness::golden::suite::LimitSource;
        let borrowed: Vec<&str> = case
            .limit_sources
            .iter()
            .filter(|(_, s)| matches!(s, LimitSource::Borrowed | LimitSource::Fallback))
            .map(|(p, _)| p.as_str())
            .collect();
        if !borrowed.is_empty() {
            eprintln!(
                "note: golden/noise.toml has no figures for {} ({}): its limits are the \
                 canonical scenes' largest; measure its own with `harness noise --scene {} --write`",
                case.name(),
                borrowed.join(", "),
                case.loaded.path.display()
            );
        }
    }
    let html = harness::report::html(
        &run,
        &outputs,
        &store,
        Some(out),
        &harness::measure::report_sections(),
    );
    let report = out.join("report.html");
    harness::images::write_atomically(&report, html.as_bytes())?;
    if json {
        println!("{}", serde_json::to_string_pretty(&run)?);
    } else {
        println!(
            "{:<8} {:<17} {:<12} {:<8} worst metric",
            "scene", "pass", "backend", "result"
        );
        for r in &run.results {
            let (label, worst) = match &r.outcome {
                harness::golden::Outcome::Passed(v) | harness::golden::Outcome::Failed(v) => (
                    if r.outcome.passed() { "ok" } else { "FAILED" },
                    // The check closest to (or furthest past) its limit, and for a failure
                    // where the largest difference is.
                    v.checks
                        .iter()
                        .max_by(|a, b| a.ratio().total_cmp(&b.ratio()))
                        .map(ToString::to_string)
                        .unwrap_or_default()
                        + &v.largest_difference
                            .map(|l| format!("; {l}"))
                            .unwrap_or_default(),
                ),
                harness::golden::Outcome::MissingGolden => (
                    "MISSING",
                    format!("no golden at {}", r.golden_path.display()),
                ),
                harness::golden::Outcome::Incomparable(why) => ("FAILED", why.clone()),
            };
            println!(
                "{:<8} {:<17} {:<12} {:<8} {worst}",
                r.scene, r.pass, r.backend, label
            );
        }
        for (scene, backend, error) in &run.render_errors {
            println!(
                "{scene:<8} {:<17} {backend:<12} FAILED   render: {error}",
                "-"
            );
        }
        for b in &run.load_errors {
            println!(
                "{:<8} {:<17} {:<12} FAILED   load: {}",
                b.scene, "-", "-", b.error
            );
        }
        let worst_cross = run
            .cross
            .iter()
            .filter(|c| !c.within_tolerance)
            .map(|c| format!("{}/{} {} vs {}", c.scene, c.pass, c.a, c.b))
            .collect::<Vec<_>>();
        if !worst_cross.is_empty() {
            println!(
                "backends disagree beyond tolerance on: {}",
                worst_cross.join(", ")
            );
        }
        let failed = run.results.iter().filter(|r| !r.outcome.passed()).count();
        let unloaded = if run.load_errors.is_empty() {
            String::new()
        } else {
            format!(", {} scene(s) did not load", run.load_errors.len())
        };
        println!(
            "{} checks, {failed} failed{unloaded}; report: {}",
            run.results.len(),
            report.display()
        );
        if failed > 0 {
            println!("failure images: {}", failures.display());
            println!(
                "after reviewing the report, bless what changed on purpose (one command per \
                 scene; it rewrites only the passes outside tolerance or without a golden):"
            );
            for command in run.bless_commands() {
                println!("  {command}");
            }
        }
    }
    Ok(if run.passed() {
        ExitCode::SUCCESS
    } else {
        ExitCode::FAILURE
    })
}

fn bless(
    scenes: &[String],
    passes: &[String],
    kind: BackendKind,
    all: bool,
    every_pass: bool,
    dry_run: bool,
) -> anyhow::Result<ExitCode> {
    if scenes.is_empty() && !all {
        anyhow::bail!("name what to bless with --scene (and optionally --pass), or bless everything with --all");
    }
    let cases = load_cases(scenes)?;
    let store = harness::golden::GoldenStore::workspace();
    let mut backend = engine::backend::create(kind)?;
    let driver = harness::golden::fingerprint(backend.info());
    for case in &cases {
        for pass in passes {
            if !case.passes.contains(pass) {
                anyhow::bail!(
                    "scene {} has no golden pass `{pass}` (it has: {})",
                    case.name(),
                    case.passes.join(", ")
                );
            }
        }
        let wanted: Vec<&str> = case
            .passes
            .iter()
            .filter(|p| passes.is_empty() || passes.contains(p))
            .map(String::as_str)
            .collect();
        eprintln!("rendering {} on {kind} ...", case.name());
        let frame = engine::renderer::render(
            backend.as_mut(),
            &case.loaded.scene,
            engine::renderer::Readback::Only(&wanted),
        )?;
        let mut kept = 0;
        for pass in wanted {
            let image = &frame.outputs[pass];
            let change = harness::golden::suite::bless_change(&store, case, pass, image);
            // A pass named with --pass is rewritten even when it is within tolerance.
            let write = change.changed || every_pass || passes.iter().any(|p| p == pass);
            if !write {
                kept += 1;
                println!("{}/{pass}: {}; kept", case.name(), change.previous);
                continue;
            }
            println!("{}/{pass}: {}", case.name(), change.previous);
            if !dry_run {
                let path = store.bless(
                    case.name(),
                    pass,
                    image,
                    kind.name(),
                    &driver,
                    &change.previous,
                )?;
                println!("  wrote {}", path.display());
            }
        }
        if kept > 0 {
            println!(
                "{}: {kept} pass(es) within tolerance kept as they are (--every-pass rewrites them)",
                case.name()
            );
        }
    }
    Ok(ExitCode::SUCCESS)
}

fn render(
    scene: &str,
    kind: BackendKind,
    passes: &[String],
    out: Option<PathBuf>,
) -> anyhow::Result<ExitCode> {
    let loaded = harness::load_scene(scene)?;
    print_load_warnings(&loaded);
    let scene = &loaded.scene;
    let plan = engine::plan::RenderPlan::new(scene);
    let names: Vec<String> = if passes.is_empty() {
        vec![engine::plan::FINAL.to_owned()]
    } else if passes.iter().any(|p| p == "all") {
        plan.target_names()
            .iter()
            .map(|s| (*s).to_owned())
            .collect()
    } else {
        passes.to_vec()
    };
    // Pass names are checked against the plan before anything is rendered.
    let known = plan.target_names();
    if let Some(unknown) = names.iter().find(|n| !known.contains(&n.as_str())) {
        anyhow::bail!(
            "scene `{}` has no pass output `{unknown}` (its outputs: {}, or `all`)",
            scene.name,
            known.join(", ")
        );
    }
    let mut backend = engine::backend::create(kind)?;
    let wanted: Vec<&str> = names.iter().map(String::as_str).collect();
    eprintln!(
        "rendering {} ({}x{}) on {kind} ...",
        scene.name, scene.quality.width, scene.quality.height
    );
    let frame = engine::renderer::render(
        backend.as_mut(),
        scene,
        engine::renderer::Readback::Only(&wanted),
    )?;
    let default_dir = default_out_dir()
        .join("render")
        .join(&scene.name)
        .join(kind.name());
    for name in &names {
        let image = &frame.outputs[name];
        let extension = if image.as_u8().is_some() {
            "png"
        } else {
            "exr"
        };
        let path = match &out {
            Some(path) if names.len() == 1 && path.extension().is_some() => path.clone(),
            Some(dir) => dir.join(format!("{name}.{extension}")),
            None => default_dir.join(format!("{name}.{extension}")),
        };
        harness::images::write_image(image, &path, harness::images::PngCompression::Fast)?;
        println!("{name:<17} -> {}", path.display());
    }
    for timing in &frame.timings {
        if let Some(ns) = timing.gpu_ns {
            eprintln!("  {:<20} {:8.3} ms GPU", timing.name, ns / 1e6);
        }
    }
    Ok(ExitCode::SUCCESS)
}

fn inspect(path: &std::path::Path, json: bool) -> anyhow::Result<ExitCode> {
    match harness::inspect::inspect(path) {
        Ok(value) => {
            if json {
                println!("{}", serde_json::to_string_pretty(&value)?);
            } else {
                print!("{}", harness::inspect::to_text(&value));
            }
            Ok(ExitCode::SUCCESS)
        }
        Err(e) => {
            if json {
                println!("{}", serde_json::json!({ "error": e.to_string() }));
            }
            eprintln!("error: {e}");
            Ok(ExitCode::FAILURE)
        }
    }
}

/// Lists the canonical scenes with their descriptions, loading each with its assets: one that
/// does not load is listed with its error, and the command exits 1.
fn scenes() -> anyhow::Result<ExitCode> {
    let dir = harness::scenes_dir();
    let mut broken = false;
    for name in engine::scene_file::canonical_scenes(&dir) {
        let path = dir.join(format!("{name}.toml"));
        match engine::scene_file::load(&path) {
            Ok(loaded) => println!("{name:<10} {}", loaded.description.unwrap_or_default()),
            Err(e) => {
                broken = true;
                println!("{name:<10} DOES NOT LOAD: {}", harness::error_text(&e));
            }
        }
    }
    Ok(if broken {
        ExitCode::FAILURE
    } else {
        ExitCode::SUCCESS
    })
}

fn noise(
    names: &[String],
    scenes: &[String],
    write: bool,
    margin: f64,
    json: bool,
) -> anyhow::Result<ExitCode> {
    use harness::golden::noise::{NoiseModel, MAX_NOISE_RATIO};
    use harness::golden::portability;
    let store = harness::golden::GoldenStore::workspace();
    let cases = load_cases(scenes)?;
    let (all, missing) = portability::sources(&store);
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
    let backends: Vec<BackendKind> = BackendKind::ALL
        .into_iter()
        .filter(|&k| engine::backend::probe(k).available)
        .collect();
    let Some(&reference) = backends
        .iter()
        .find(|&&k| k == harness::golden::suite::REFERENCE_BACKEND)
        .or(backends.first())
    else {
        anyhow::bail!("no backend is available; run `harness backends` for the reasons");
    };
    let exe = std::env::current_exe()?;
    let bar = indicatif::ProgressBar::new_spinner().with_style(
        indicatif::ProgressStyle::with_template("{spinner} {elapsed} {msg}")
            .unwrap_or_else(|_| indicatif::ProgressStyle::default_spinner()),
    );
    bar.enable_steady_tick(std::time::Duration::from_millis(200));
    let runs = portability::measure(
        &exe,
        &store,
        &cases,
        &chosen,
        &backends,
        reference,
        |what| bar.set_message(what.to_owned()),
    );
    bar.finish_and_clear();
    let measurements: Vec<portability::Measurement> = runs
        .iter()
        .flat_map(|(_, r)| r.measurements.iter().cloned())
        .collect();
    let missed: Vec<portability::Missed> = runs
        .iter()
        .flat_map(|(_, r)| r.missed.iter().cloned())
        .collect();
    let mut cases = cases;
    if write {
        let descriptions = runs
            .iter()
            .map(|(source, run)| {
                let mut text = source.description.clone();
                for (backend, driver) in &run.drivers {
                    text.push_str(&format!("; {backend}: {driver}"));
                }
                // Paths inside this checkout (the second Mesa's prefix) are the same on every
                // machine relative to it.
                let root = harness::workspace_root().to_string_lossy().into_owned();
                (source.name.clone(), text.replace(&root, "<workspace>"))
            })
            .collect();
        let previous = NoiseModel::load(&store)?;
        let model = portability::build_model(
            &cases,
            &measurements,
            margin,
            descriptions,
            &missed,
            &previous,
        );
        let path = model.save(&store)?;
        eprintln!("wrote {}", path.display());
        // Judge the run against the limits just written.
        cases = cases
            .iter()
            .map(|c| {
                harness::golden::suite::Case::load_with(&c.loaded.path.to_string_lossy(), &model)
            })
            .collect::<Result<_, _>>()?;
    }
    let ratios = portability::ratios(&cases, &measurements);
    let names: Vec<String> = runs.iter().map(|(s, _)| s.name.clone()).collect();
    let too_noisy: Vec<&portability::Ratio> = ratios
        .iter()
        .filter(|r| r.ratio > MAX_NOISE_RATIO)
        .collect();
    let failed_renders: Vec<&portability::Missed> = missed.iter().filter(|m| !m.known).collect();
    if json {
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
    } else {
        print!("{}", portability::table(&ratios, &names));
        for m in &missed {
            println!(
                "{} {} on {} {}: {}",
                if m.known { "known crash:" } else { "FAILED:" },
                m.source,
                m.backend,
                m.scene,
                m.error
            );
        }
        for r in &too_noisy {
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
                r.backend,
                r.value,
                r.ratio,
                r.limit
            );
        }
        println!(
            "{} sources, {} measurements: {} above {MAX_NOISE_RATIO} of a limit, {} failed renders",
            runs.len(),
            measurements.len(),
            too_noisy.len(),
            failed_renders.len()
        );
    }
    Ok(if too_noisy.is_empty() && failed_renders.is_empty() {
        ExitCode::SUCCESS
    } else {
        ExitCode::FAILURE
    })
}

fn selftest(json: bool) -> anyhow::Result<ExitCode> {
    let store = harness::golden::GoldenStore::workspace();
    let model = harness::golden::noise::NoiseModel::load(&store)?;
    let (cases, broken) = load_cases_isolated(&[])?;
    let available: Vec<BackendKind> = BackendKind::ALL
        .into_iter()
        .filter(|&k| engine::backend::probe(k).available)
        .collect();
    if available.is_empty() {
        anyhow::bail!("no backend is available; run `harness backends` for the reasons");
    }
    eprintln!(
        "self-test: {} scenes x {} mutations and unchanged renders on {} ...",
        cases.len(),
        harness::golden::selftest::Mutation::ALL.len(),
        available
            .iter()
            .map(|k| k.name())
            .collect::<Vec<_>>()
            .join(", ")
    );
    let mut result = harness::golden::selftest::run(&cases, &store, &available, &model);
    result.errors.extend(
        broken
            .iter()
            .map(|b| format!("scene `{}` did not load: {}", b.scene, b.error)),
    );
    if json {
        println!("{}", serde_json::to_string_pretty(&result)?);
    } else {
        println!(
            "Known changes: value / limit in the pass where each originates (at least {} to pass)",
            harness::golden::noise::MIN_MUTATION_RATIO
        );
        print!("{}", result.margin_table());
        println!(
            "\nUnchanged renders: worst value / limit over every pass (at most {} to pass)",
            harness::golden::noise::MAX_NOISE_RATIO
        );
        print!("{}", result.noise_table());
        for m in result.weak_detections() {
            println!(
                "WEAK: `{}` on {} ({}): {} is {} of its limit, under {}",
                m.mutation.describe(),
                m.scene,
                m.backend,
                m.mutation.origin(),
                m.origin_ratio()
                    .map_or("not golden".to_owned(), |r| format!("{r:.2}x")),
                harness::golden::noise::MIN_MUTATION_RATIO
            );
        }
        for n in result.noisy() {
            println!(
                "NOISY: unchanged {} under {} on {}: {} at {:.2} of its limit",
                n.scene, n.source, n.backend, n.pass, n.ratio
            );
        }
        for e in &result.errors {
            println!("ERROR: {e}");
        }
    }
    Ok(if result.passed() {
        ExitCode::SUCCESS
    } else {
        ExitCode::FAILURE
    })
}

fn sweep(
    scene: &str,
    knob: &str,
    kind: BackendKind,
    repeats: usize,
    environment: Option<&Path>,
    json: bool,
) -> anyhow::Result<ExitCode> {
    let mut loaded = harness::load_scene(scene)?;
    if let Some(path) = environment {
        replace_environment(&mut loaded.scene, path)?;
    }
    if knob == "ibl" {
        let rows = harness::measure::sweep::ibl_sweep(&loaded.scene, kind, repeats, |what| {
            eprintln!("  {what} ...");
        })?;
        let text = serde_json::to_string_pretty(&rows)?;
        save_sweep(&loaded.scene.name, "ibl", &text);
        if json {
            println!("{text}");
        } else {
            println!(
                "ibl sweep of {} on {kind} ({repeats} renders per setting, median GPU time; error = mean relative error of r+g+b against the Monte Carlo reference, {} pixels, {} directions per strategy)",
                loaded.scene.name,
                harness::measure::sweep::IBL_REFERENCE_PIXELS,
                harness::measure::sweep::IBL_REFERENCE_SAMPLES
            );
            print!("{}", harness::measure::sweep::ibl_table(&rows));
        }
        return Ok(ExitCode::SUCCESS);
    }
    if knob == "gbuffer" {
        let rows = harness::measure::sweep::gbuffer_sweep(&loaded.scene, kind, repeats, |what| {
            eprintln!("  {what} ...");
        })?;
        let text = serde_json::to_string_pretty(&rows)?;
        save_sweep(&loaded.scene.name, "gbuffer", &text);
        if json {
            println!("{text}");
        } else {
            println!(
                "gbuffer sweep of {} on {kind} ({repeats} renders per setting, median GPU time; error = light buffer against the scene at the origin with the default storage)",
                loaded.scene.name
            );
            print!("{}", harness::measure::sweep::gbuffer_table(&rows));
        }
        return Ok(ExitCode::SUCCESS);
    }
    if knob != "shadow" {
        return Err(harness::measure::sweep::SweepError::UnknownKnob(knob.to_owned()).into());
    }
    let rows = harness::measure::sweep::shadow_sweep(&loaded.scene, kind, repeats, |what| {
        eprintln!("  {what} ...");
    })?;
    let text = serde_json::to_string_pretty(&rows)?;
    save_sweep(&loaded.scene.name, "shadow", &text);
    if json {
        println!("{text}");
    } else {
        println!(
            "shadow sweep of {} on {kind} ({repeats} renders per setting, median GPU time)",
            loaded.scene.name
        );
        print!("{}", harness::measure::sweep::table(&rows));
    }
    Ok(ExitCode::SUCCESS)
}

fn hard(backends: &[BackendKind], json: bool) -> anyhow::Result<ExitCode> {
    let kinds: Vec<BackendKind> = if backends.is_empty() {
        BackendKind::ALL
            .into_iter()
            .filter(|&k| {
                let status = engine::backend::probe(k);
                if !status.available {
                    eprintln!(
                        "skipping {k}: {} (fix: {})",
                        status.reason.unwrap_or_default(),
                        status.fix.unwrap_or_default()
                    );
                }
                status.available
            })
            .collect()
    } else {
        backends.to_vec()
    };
    let mut rows = Vec::new();
    for kind in kinds {
        rows.extend(
            harness::measure::hard_cases::run(kind, |case| eprintln!("  {case} on {kind} ..."))
                .map_err(|e| anyhow::anyhow!("{kind}: {e}"))?,
        );
    }
    let text = serde_json::to_string_pretty(&rows)?;
    let path = default_out_dir().join(harness::measure::hard_cases::RESULTS_JSON);
    match std::fs::create_dir_all(default_out_dir())
        .map_err(|e| e.to_string())
        .and_then(|_| {
            harness::images::write_atomically(&path, text.as_bytes()).map_err(|e| e.to_string())
        }) {
        Ok(()) => eprintln!(
            "wrote {} (shown in the next `harness check` report)",
            path.display()
        ),
        Err(e) => eprintln!("warning: hard-case results not kept: {e}"),
    }
    if json {
        println!("{text}");
    } else {
        print!("{}", harness::measure::hard_cases::table(&rows));
    }
    Ok(if rows.iter().all(|r| r.passed) {
        ExitCode::SUCCESS
    } else {
        ExitCode::FAILURE
    })
}

/// Lights `scene` with the environment at `path` (its rotation and intensity kept, or none and
/// 1 where it had no environment) and names it `<scene>-<file stem>`, so that the sweep's
/// results are kept apart from the scene's own.
fn replace_environment(scene: &mut engine::scene::Scene, path: &Path) -> anyhow::Result<()> {
    let loaded = engine::assets::load_environment(path)?;
    let (rotation_degrees, intensity) = scene
        .environment
        .as_ref()
        .map_or((0.0, 1.0), |e| (e.rotation_degrees, e.intensity));
    scene.environment = Some(engine::scene::Environment {
        image: std::sync::Arc::new(engine::scene::EnvironmentImage {
            label: path.display().to_string(),
            width: loaded.width,
            height: loaded.height,
            texels: loaded.texels,
        }),
        rotation_degrees,
        intensity,
    });
    let stem = path.file_stem().map_or_else(
        || "environment".to_owned(),
        |s| s.to_string_lossy().into_owned(),
    );
    scene.name = format!("{}-{stem}", scene.name);
    Ok(())
}

/// Keeps a sweep's results (target/harness/sweep_<scene>_<knob>.json) for the check report; a
/// failure to write them is a warning.
fn save_sweep(scene: &str, knob: &str, json: &str) {
    let path = default_out_dir().join(harness::measure::sweep::result_file(scene, knob));
    let written = std::fs::create_dir_all(default_out_dir())
        .map_err(|e| e.to_string())
        .and_then(|_| {
            harness::images::write_atomically(&path, json.as_bytes()).map_err(|e| e.to_string())
        });
    match written {
        Ok(()) => eprintln!(
            "wrote {} (shown in the next `harness check` report)",
            path.display()
        ),
        Err(e) => eprintln!("warning: sweep results not kept: {e}"),
    }
}

fn bench(
    scenes: &[String],
    backends: &[BackendKind],
    frames: usize,
    out: &std::path::Path,
    json: bool,
) -> anyhow::Result<ExitCode> {
    let names = scenes_or_canonical(scenes);
    let loaded = names
        .iter()
        .map(|n| harness::load_scene(n).map(|l| l.scene))
        .collect::<Result<Vec<_>, _>>()?;
    let kinds: Vec<BackendKind> = if backends.is_empty() {
        BackendKind::ALL.to_vec()
    } else {
        backends.to_vec()
    };
    let mut results = Vec::new();
    let mut failed = false;
    for kind in kinds {
        if let Err(e) = engine::backend::create(kind) {
            eprintln!("skipping {kind}: {e}");
            if !backends.is_empty() {
                failed = true;
            }
            continue;
        }
        for scene in &loaded {
            eprintln!("timing {} on {kind} ({frames} frames) ...", scene.name);
            match harness::measure::bench::bench_scene(scene, kind, frames) {
                Ok(result) => {
                    if !json {
                        println!("{}", harness::measure::bench::table(&result));
                    }
                    results.push(result);
                }
                Err(e) => {
                    eprintln!("error: {e}");
                    failed = true;
                }
            }
        }
    }
    let precompute = harness::measure::bench::precompute();
    if !json {
        println!("precomputation (apart from frames):");
        for p in &precompute {
            println!("  {:<44} {:>8.3} ms  ({})", p.what, p.ms, p.on);
        }
    }
    let text = serde_json::to_string_pretty(
        &serde_json::json!({ "precompute": precompute, "scenes": results }),
    )?;
    save_bench_json(out, harness::measure::bench::BENCH_JSON, &text)?;
    if json {
        println!("{text}");
    }
    Ok(if failed {
        ExitCode::FAILURE
    } else {
        ExitCode::SUCCESS
    })
}

fn bench_series(
    names: &[String],
    backends: &[BackendKind],
    frames: usize,
    out: &std::path::Path,
    json: bool,
) -> anyhow::Result<ExitCode> {
    let names: Vec<String> = if names.iter().any(|n| n == "all") {
        harness::measure::bench::SERIES
            .iter()
            .map(|s| (*s).to_owned())
            .collect()
    } else {
        names.to_vec()
    };
    let kinds = backends_or_gl(backends);
    let mut all = Vec::new();
    for kind in kinds {
        for name in &names {
            let points = harness::measure::bench::series(name, kind, frames, |what| {
                eprintln!("  {kind}: {what} ...");
            })?;
            if !json {
                println!("{name} series on {kind} (median of {frames} frames, GPU ms)");
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

/// The scenes asked for, or every canonical scene.
fn scenes_or_canonical(scenes: &[String]) -> Vec<String> {
    if scenes.is_empty() {
        engine::scene_file::canonical_scenes(&harness::scenes_dir())
    } else {
        scenes.to_vec()
    }
}

/// The backends asked for, or gl.
fn backends_or_gl(backends: &[BackendKind]) -> Vec<BackendKind> {
    if backends.is_empty() {
        vec![BackendKind::Gl]
    } else {
        backends.to_vec()
    }
}

/// `harness bench --breakdown`: each lighting pass's cost, part by part.
fn bench_breakdown(
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

/// Keeps the latest bench results (in target/harness/ by default) for the check report.
fn save_bench_json(dir: &std::path::Path, name: &str, text: &str) -> anyhow::Result<()> {
    std::fs::create_dir_all(dir)?;
    let path = dir.join(name);
    harness::images::write_atomically(&path, text.as_bytes())?;
    eprintln!(
        "wrote {} (shown in the next `harness check` report)",
        path.display()
    );
    Ok(())
}

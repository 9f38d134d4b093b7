//! `harness`: the command line of the render regression harness.
//!
//! `cargo run --release -p harness` runs `check`, the main job.
//!
//! This file holds the clap definitions and the dispatch only; each command's body is in
//! [`cli`], one module per command or group of small commands.

mod cli;

use std::path::PathBuf;
use std::process::ExitCode;

use clap::{Parser, Subcommand};

use engine::backend::BackendKind;

use cli::default_out_dir;

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
    /// Load an OBJ, MTL, scene file (.toml), environment (EXR, .hdr) or texture (PNG, JPEG, TGA,
    /// BMP) and report what was loaded; exit 1 if it does not load.
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
        #[arg(long, value_enum, default_value = "shadow")]
        knob: harness::measure::sweep::Knob,
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
        /// Where to keep the results (sweep_<scene>_<knob>.json) for the check report (a
        /// `harness check` with the same --out shows them).
        #[arg(long, default_value_os_t = default_out_dir())]
        out: PathBuf,
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
        /// Frames timed per scene and backend, after one warm-up frame [default: 5, or 21 per
        /// variant with --breakdown].
        #[arg(long)]
        frames: Option<usize>,
        /// Submit this pass's render passes --repeat-times times in every frame timed: how a
        /// pass that many times slower shows in the ratios (its pixels are not the point).
        #[arg(long, conflicts_with_all = ["series", "breakdown"])]
        repeat_pass: Option<String>,
        /// How many times --repeat-pass submits its pass.
        #[arg(long, default_value_t = 2, requires = "repeat_pass")]
        repeat_times: u32,
        /// Instead of the scenes, a scaling series: resolution, lights, triangles, shadow-map,
        /// or all (repeatable).
        #[arg(long = "series", value_enum)]
        series: Vec<cli::bench::SeriesArg>,
        /// Instead of the pass table, where each lighting pass's time goes: its input floor
        /// (reading the G-buffer, no shading), its per-pixel setup, then the time it loses
        /// without IBL, without each light, and (parts of those) without shadow lookups and
        /// clearcoat (each from a baseline that re-reads its inputs as the variants do, and a row
        /// taking that re-read away); against the pass as it is. Each variant's time is the
        /// lower quartile of its frames (gl unless --backend is given).
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

fn main() -> ExitCode {
    cli::private_runtime_dir();
    env_logger::Builder::from_env(env_logger::Env::default().default_filter_or("warn")).init();
    let args = Cli::parse();
    harness::use_ibl_cache();
    let command = args.command.unwrap_or(Command::Check {
        out: default_out_dir(),
        scenes: vec![],
        backends: vec![],
        json: false,
    });
    let result = match command {
        Command::Backends { json } => cli::info::backends(json),
        Command::Check {
            out,
            scenes,
            backends,
            json,
        } => cli::check::run(&out, &scenes, &backends, json),
        Command::Noise {
            sources,
            scenes,
            write,
            margin,
            json,
        } => cli::noise::run(&sources, &scenes, write, margin, json),
        Command::Bless {
            scenes,
            passes,
            backend,
            all,
            every_pass,
            dry_run,
        } => cli::bless::run(&scenes, &passes, backend, all, every_pass, dry_run),
        Command::Render {
            scene,
            backend,
            passes,
            out,
        } => cli::render::run(&scene, backend, &passes, out),
        Command::Plan { scene } => cli::info::plan(&scene),
        Command::Inspect { path, json } => cli::info::inspect(&path, json),
        Command::Scenes => cli::info::scenes(),
        Command::Hard { backends, json } => cli::hard::run(&backends, json),
        Command::Selftest { json } => cli::selftest::run(json),
        Command::Sweep {
            scene,
            knob,
            backend,
            repeats,
            environment,
            out,
            json,
        } => cli::sweep::run(
            &scene,
            knob,
            backend,
            repeats,
            environment.as_deref(),
            &out,
            json,
        ),
        Command::Bench {
            scenes,
            backends,
            frames,
            repeat_pass,
            repeat_times,
            series,
            breakdown,
            out,
            json,
        } => {
            if breakdown {
                let frames = frames.unwrap_or(harness::measure::bench::BREAKDOWN_FRAMES);
                cli::bench::breakdown(&scenes, &backends, frames, json)
            } else if series.is_empty() {
                let frames = frames.unwrap_or(harness::measure::bench::BENCH_FRAMES);
                let repeat = match repeat_pass {
                    Some(name) => match name.parse::<engine::plan::PassId>() {
                        Ok(pass) => Some((pass, repeat_times)),
                        Err(e) => {
                            eprintln!("error: --repeat-pass: {e}");
                            return ExitCode::from(2);
                        }
                    },
                    None => None,
                };
                cli::bench::pass_table(&scenes, &backends, frames, repeat, &out, json)
            } else {
                let frames = frames.unwrap_or(harness::measure::bench::BENCH_FRAMES);
                cli::bench::series(&series, &backends, frames, &out, json)
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

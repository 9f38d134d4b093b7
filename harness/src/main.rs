//! `harness`: the command line of the render regression harness.
//!
//! `cargo run -p harness` runs `check`, the main job.
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
        /// Only this backend: gl, wgpu-vulkan or wgpu-gl (repeatable). Default: every available
        /// one (the others noted as not checked). A backend named here is asked for: if it is
        /// unavailable, the check fails.
        #[arg(long = "backend")]
        backends: Vec<BackendKind>,
        /// Only these golden passes' image checks (repeatable; the renders run only what they
        /// need). No verdicts are given (where a change starts needs every pass), and the
        /// speed checks are not narrowed (`--no-speed` skips them).
        #[arg(long = "pass")]
        passes: Vec<String>,
        /// Print the results as JSON on stdout.
        #[arg(long)]
        json: bool,
        /// Skip the speed checks (each pass's speed ratio against its timing golden).
        #[arg(long)]
        no_speed: bool,
        /// Do not verify the outputs kept of failing passes (`check` otherwise renders them
        /// again under the cheap noise sources, so that accepting them later renders nothing;
        /// without it, the accept verifies).
        #[arg(long)]
        no_verify: bool,
        /// Also write the results as JUnit XML (a test case per scene, pass and backend), for
        /// CI test-report actions.
        #[arg(long, value_name = "FILE")]
        junit: Option<PathBuf>,
        /// Also write a Markdown summary, failing checks first, for a CI job's page (for
        /// example `--summary "$GITHUB_STEP_SUMMARY"`).
        #[arg(long, value_name = "FILE")]
        summary: Option<PathBuf>,
        /// Debug: give the lighting passes the generic, unspecialised shader variant, in the
        /// renders and the speed probes (a real slowdown, reproduced: the lighting passes'
        /// speed checks fail and nothing else does). Not with --no-speed: the picture is the
        /// same, only the speed checks show it.
        #[arg(long, conflicts_with = "no_speed")]
        debug_unspecialised_lighting: bool,
    },
    /// Measure the noise model behind the golden tolerances: how far unchanged renders move
    /// from the goldens under every source of variation (the backends, llvmpipe's CPU code
    /// paths, a second Mesa from scripts/mesa-backports.sh, synthetic rounding, renders recorded
    /// on other hosts in golden/evidence/). Prints each source's worst value against every limit
    /// and exits 1 if any is above half its limit or a render failed. With --write, records the
    /// figures and the limits derived from them (margin x noise) in golden/noise.toml.
    Noise(cli::noise::NoiseArgs),
    /// Write new goldens after an intended change: renders the scene, compares each pass with
    /// its golden, and rewrites only the passes that changed (outside tolerance) or have no
    /// golden, atomically, recording the driver and date in golden/<scene>/blessed.toml. Passes
    /// within tolerance and their records are left alone.
    Bless(cli::bless::BlessArgs),
    /// Serve the last check's review page on 127.0.0.1 with Accept buttons on each failing pass,
    /// scene and the whole run: accepting blesses the outputs the check kept (verified, never
    /// rendered again). Prints the page's address (with its token) and opens nothing; Ctrl-C
    /// stops it.
    Review {
        /// The folder `check --out` wrote to.
        #[arg(long, default_value_os_t = default_out_dir())]
        out: PathBuf,
        /// Port to listen on (0: any free one).
        #[arg(long, default_value_t = 0)]
        port: u16,
    },
    /// Join sharded checks (`check --scene S --out DIR` on several jobs) into one run: one review
    /// page and last-check.json under --out, and one JUnit file and summary if asked. Exits 1 if
    /// the joined run failed.
    Report {
        /// The shards' `--out` folders (each with its last-check.json and failures/).
        #[arg(long = "merge", required = true, num_args = 1..)]
        shards: Vec<PathBuf>,
        /// Where to write the joined page and last-check.json.
        #[arg(long, default_value_os_t = default_out_dir())]
        out: PathBuf,
        /// Also write the joined results as JUnit XML.
        #[arg(long, value_name = "FILE")]
        junit: Option<PathBuf>,
        /// Also write the joined Markdown summary.
        #[arg(long, value_name = "FILE")]
        summary: Option<PathBuf>,
        /// Print the joined results as JSON.
        #[arg(long)]
        json: bool,
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
    /// Mutation self-test: 16 small known changes (light x1.02, exposure x1.03, roughness +0.05,
    /// shadow bias x4, a G-buffer channel swap, ...) must each fail in the pass where they
    /// originate by at least 3x its limit on every backend, while unchanged renders (every
    /// backend, synthetic rounding, and the sources golden/noise.toml recorded) stay at or
    /// below half of every limit. Prints the margin and noise tables.
    Selftest {
        /// Print JSON.
        #[arg(long)]
        json: bool,
        /// The speed self-test instead: each pass slowed down x1.5 and x2 in turn must fail
        /// its own speed check and no other (run it on a host recorded in golden/evidence/, or
        /// the one that blessed the timing goldens where they name one: elsewhere most passes
        /// are untimed).
        #[arg(long)]
        speed: bool,
        /// With --speed: only these scenes (repeatable).
        #[arg(long = "scene", requires = "speed")]
        scenes: Vec<String>,
        /// With --speed: only this backend (repeatable).
        #[arg(long = "backend", requires = "speed")]
        backends: Vec<BackendKind>,
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
        /// Timed renders per setting, their median kept (the shadow and IBL sweeps render every
        /// setting in turn, this many rounds).
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
        /// Only the IBL sweep's settings whose names contain this text (repeatable; the
        /// default is always kept, as the baseline of the lighting times).
        #[arg(long = "only")]
        only: Vec<String>,
        /// Also sweep this IBL setting: keys of a scene file's `[quality.ibl]`, comma-separated,
        /// e.g. `--try "extract_sun = true, anisotropic_samples = 8"` (repeatable; with --try
        /// and no --only, the built-in settings other than the default are left out).
        #[arg(long = "try")]
        tried: Vec<String>,
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
        /// Only this backend: gl, wgpu-vulkan or wgpu-gl (repeatable). Default: every available one.
        #[arg(long = "backend")]
        backends: Vec<BackendKind>,
        /// Frames timed per scene and backend, after one warm-up frame [default: 5, or 21 per
        /// variant with --breakdown].
        #[arg(long, value_parser = at_least_one)]
        frames: Option<usize>,
        /// Slow this pass down by --slowdown in every frame timed (its render passes submitted
        /// that many times over): how a slower pass shows in the ratios (its pixels are not
        /// the point).
        #[arg(long, conflicts_with_all = ["series", "breakdown"])]
        slow_pass: Option<String>,
        /// How many times over --slow-pass submits its pass's work (1.5: half of it again).
        #[arg(long, default_value_t = 2.0, requires = "slow_pass")]
        slowdown: f32,
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
    /// Probe each pass's speed ratio, what the timing goldens record: per scene and backend,
    /// every pass submitted alone and its floor right after it, round after round; the ratio is
    /// the pass's fastest time over its floor's. Prints a table (or JSON with every sample).
    Speed(cli::bench::SpeedArgs),
    /// Run the numerical hard cases (scenes/hard/ and chess moved 1e4/1e5 and scaled
    /// 0.001/1000) on every available backend: no NaN/Inf, the light buffer in range, and each
    /// case's own check. Prints the table, keeps it for the check report, exits 1 on a failure.
    Hard {
        /// Only this backend: gl, wgpu-vulkan or wgpu-gl (repeatable). Default: every available one.
        #[arg(long = "backend")]
        backends: Vec<BackendKind>,
        /// Where to keep the table (hard_cases.json) for the check report (a `harness check`
        /// with the same --out shows it).
        #[arg(long, default_value_os_t = default_out_dir())]
        out: PathBuf,
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

/// The log filter when `RUST_LOG` is unset: warnings and errors, less those of wgpu's EGL
/// display probing, which logs an error for every display it tries and cannot use (`DRI2:
/// failed to load driver` on a machine without a GPU) before it finds llvmpipe's, on runs that
/// then pass. Whether a backend is usable, and why not, is what `harness backends` reports;
/// `RUST_LOG=warn` shows the probing again.
const DEFAULT_LOG_FILTER: &str = "warn,wgpu_hal::gles::egl=off";

impl Command {
    /// What `harness` with no subcommand runs: `check` of every scene on every backend.
    fn default_check() -> Command {
        Command::Check {
            out: default_out_dir(),
            scenes: vec![],
            backends: vec![],
            passes: vec![],
            json: false,
            no_speed: false,
            no_verify: false,
            junit: None,
            summary: None,
            debug_unspecialised_lighting: false,
        }
    }
}

fn main() -> ExitCode {
    cli::end_quietly_on_closed_output();
    cli::private_runtime_dir();
    env_logger::Builder::from_env(env_logger::Env::default().default_filter_or(DEFAULT_LOG_FILTER))
        .init();
    let args = Cli::parse_from(with_default_command(std::env::args_os().collect()));
    harness::use_ibl_cache();
    // A precompute can take from a second to minutes (large or many-sample settings): said.
    engine::ibl::set_build_notice(Some(|what| eprintln!("{what} ...")));
    let command = args.command.unwrap_or_else(Command::default_check);
    let result = match command {
        Command::Backends { json } => cli::info::backends(json),
        Command::Check {
            out,
            scenes,
            backends,
            passes,
            json,
            no_speed,
            no_verify,
            junit,
            summary,
            debug_unspecialised_lighting,
        } => cli::check::run(
            &out,
            &scenes,
            &backends,
            cli::check::Options {
                json,
                passes,
                speed: !no_speed,
                verify: !no_verify,
                unspecialised_lighting: debug_unspecialised_lighting,
                junit,
                summary,
            },
        ),
        Command::Speed(args) => cli::bench::speed_command(args),
        Command::Noise(args) => cli::noise::entry(args),
        Command::Bless(args) => cli::bless::command(args),
        Command::Review { out, port } => cli::review::run(&out, port),
        Command::Report {
            shards,
            out,
            junit,
            summary,
            json,
        } => cli::check::merge(
            &shards,
            &out,
            &cli::check::Options {
                json,
                passes: vec![],
                speed: false,
                verify: false,
                unspecialised_lighting: false,
                junit,
                summary,
            },
        ),
        Command::Render {
            scene,
            backend,
            passes,
            out,
        } => cli::render::run(&scene, backend, &passes, out),
        Command::Plan { scene } => cli::info::plan(&scene),
        Command::Inspect { path, json } => cli::info::inspect(&path, json),
        Command::Scenes => cli::info::scenes(),
        Command::Hard {
            backends,
            out,
            json,
        } => cli::hard::run(&backends, &out, json),
        Command::Selftest {
            json,
            speed,
            scenes,
            backends,
        } => cli::selftest::command(json, speed, &scenes, &backends),
        Command::Sweep {
            scene,
            knob,
            backend,
            repeats,
            environment,
            out,
            only,
            tried,
            json,
        } => cli::sweep::run(
            &scene,
            cli::sweep::SweepArgs {
                knob,
                kind: backend,
                repeats,
                environment: environment.as_deref(),
                only: &only,
                tried: &tried,
            },
            &out,
            json,
        ),
        Command::Bench {
            scenes,
            backends,
            frames,
            slow_pass,
            slowdown,
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
                let slow = match slow_pass {
                    Some(name) => match name.parse::<engine::plan::PassId>() {
                        Ok(pass) => Some(engine::renderer::SlowPass {
                            pass,
                            factor: slowdown,
                        }),
                        Err(e) => {
                            eprintln!("error: --slow-pass: {e}");
                            return ExitCode::from(2);
                        }
                    },
                    None => None,
                };
                cli::bench::pass_table(&scenes, &backends, frames, slow, &out, json)
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

/// The command line with `check`, the default command, put first when it starts with an
/// option other than help or version: `harness --scene arrow` is `harness check --scene arrow`
/// (clap alone would refuse `--scene` as an argument of no command).
fn with_default_command(mut args: Vec<std::ffi::OsString>) -> Vec<std::ffi::OsString> {
    let first = args.get(1).and_then(|a| a.to_str());
    let global = ["-h", "--help", "-V", "--version"];
    if first.is_some_and(|a| a.starts_with('-') && !global.contains(&a)) {
        args.insert(1, "check".into());
    }
    args
}

/// A count of at least one (`--frames 0` would time nothing, and ran one frame instead).
fn at_least_one(text: &str) -> Result<usize, String> {
    match text.parse::<usize>() {
        Ok(0) => Err("must be at least 1".to_owned()),
        Ok(n) => Ok(n),
        Err(e) => Err(e.to_string()),
    }
}

//! `harness`: the command line of the render regression harness.
//!
//! `cargo run --release -p harness` runs `check`, the main job.

use std::path::PathBuf;
use std::process::ExitCode;

use anyhow::Context;
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
    /// Render on every available backend, compare, and write images (the default command).
    Check {
        /// Where to write images.
        #[arg(long, default_value_os_t = default_out_dir())]
        out: PathBuf,
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
    PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../target/harness")
}

fn main() -> ExitCode {
    env_logger::Builder::from_env(env_logger::Env::default().default_filter_or("warn")).init();
    let cli = Cli::parse();
    let command = cli.command.unwrap_or(Command::Check {
        out: default_out_dir(),
    });
    let result = match command {
        Command::Backends { json } => backends(json),
        Command::Check { out } => check(&out),
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
    };
    match result {
        Ok(code) => code,
        Err(e) => {
            eprintln!("error: {e:#}");
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

fn check(out: &std::path::Path) -> anyhow::Result<ExitCode> {
    let dir = out.join("first_scene");
    std::fs::create_dir_all(&dir).with_context(|| format!("creating {}", dir.display()))?;
    let mut renders = Vec::new();
    let mut failed = false;
    for kind in BackendKind::ALL {
        eprint!("rendering the first scene on {kind} ... ");
        match first_scene::render(kind) {
            Ok(images) => {
                let ms: f64 = images.timings.iter().filter_map(|t| t.gpu_ns).sum::<f64>() / 1e6;
                eprintln!("ok ({ms:.2} ms GPU)");
                let path = dir.join(format!("{kind}_ldr.png"));
                std::fs::write(&path, first_scene::png_bytes(&images.ldr)?)
                    .with_context(|| format!("writing {}", path.display()))?;
                renders.push((kind, images));
            }
            Err(engine::backend::BackendError::Unavailable { reason, fix, .. }) => {
                eprintln!("unavailable: {reason} (fix: {fix})");
            }
            Err(e) => {
                eprintln!("FAILED: {e}");
                failed = true;
            }
        }
    }
    let Some((reference, reference_images)) = renders.first() else {
        anyhow::bail!("no backend is available; run `harness backends` for the reasons");
    };
    for (kind, images) in &renders[1..] {
        let a = first_scene::agreement(*kind, images, *reference, reference_images)?;
        println!(
            "{kind:<12} vs {reference}: RGBA8 {:.4}% within 1/255 (max {}), RGBA16F {:.4}% within rel 1e-3 (max rel {:.2e} at {:?}, max abs {:.1e}), depth max rel {:.2e} -> {}",
            a.ldr.fraction_within * 100.0,
            a.ldr.max_abs,
            a.hdr.fraction_within * 100.0,
            a.hdr.max_relative,
            a.hdr.worst_pixel,
            a.hdr.max_abs,
            a.depth.max_relative,
            if a.passes() { "agree" } else { "DISAGREE" },
        );
        failed |= !a.passes();
    }
    println!("images: {}", dir.display());
    Ok(if failed {
        ExitCode::FAILURE
    } else {
        ExitCode::SUCCESS
    })
}

fn render(
    scene: &str,
    kind: BackendKind,
    passes: &[String],
    out: Option<PathBuf>,
) -> anyhow::Result<ExitCode> {
    let loaded = harness::load_scene(scene)?;
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
        harness::images::write_image(image, &path)?;
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

fn scenes() -> anyhow::Result<ExitCode> {
    let dir = harness::scenes_dir();
    for name in engine::scene_file::canonical_scenes(&dir) {
        let path = dir.join(format!("{name}.toml"));
        let description = std::fs::read_to_string(&path)
            .ok()
            .and_then(|text| engine::scene_file::parse(&path, &text).ok())
            .and_then(|file| file.description)
            .unwrap_or_default();
        println!("{name:<10} {description}");
    }
    Ok(ExitCode::SUCCESS)
}

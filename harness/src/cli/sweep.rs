//! `harness sweep`: speed against error for a quality knob (shadow, ibl or gbuffer), kept for
//! the check report.

use std::path::Path;
use std::process::ExitCode;

use engine::backend::BackendKind;
use harness::measure::sweep::Knob;

/// What `harness sweep` sweeps, and how.
pub(crate) struct SweepArgs<'a> {
    /// The knob swept.
    pub knob: Knob,
    /// The backend rendering.
    pub kind: BackendKind,
    /// Timed rounds over every setting.
    pub repeats: usize,
    /// Another sky for the scene, if any.
    pub environment: Option<&'a Path>,
    /// The IBL sweep's built-in settings kept by name.
    pub only: &'a [String],
    /// The IBL sweep's settings of the user's own (`[quality.ibl]` keys).
    pub tried: &'a [String],
}

/// Sweeps the knob over its settings on `scene` (lit by the environment when one is given)
/// and prints the table (or JSON).
pub(crate) fn run(
    scene: &str,
    args: SweepArgs<'_>,
    out: &Path,
    json: bool,
) -> anyhow::Result<ExitCode> {
    let SweepArgs {
        knob,
        kind,
        repeats,
        environment,
        only,
        tried,
    } = args;
    if (!only.is_empty() || !tried.is_empty()) && knob != Knob::Ibl {
        anyhow::bail!(
            "--only and --try choose settings of the ibl sweep; the {} sweep visits all of its own",
            knob.name()
        );
    }
    let mut choice = harness::measure::sweep::IblSweepChoice {
        only: only.to_vec(),
        tried: Vec::new(),
    };
    for text in tried {
        let settings = harness::measure::sweep::parse_tried_setting(text)
            .map_err(|e| anyhow::anyhow!("--try {text:?}: {e}"))?;
        choice.tried.push((text.clone(), settings));
    }
    let mut loaded = harness::load_scene(scene)?;
    if let Some(path) = environment {
        replace_environment(&mut loaded.scene, path)?;
    }
    if knob == Knob::Ibl {
        let rows =
            harness::measure::sweep::ibl_sweep(&loaded.scene, kind, repeats, &choice, |what| {
                eprintln!("  {what} ...");
            })?;
        let text = serde_json::to_string_pretty(&rows)?;
        save_sweep(out, &loaded.scene.name, knob, &text);
        if json {
            println!("{text}");
        } else {
            println!(
                "ibl sweep of {} on {kind} ({repeats} rounds over every setting, median GPU time; error = mean relative error of r+g+b against the Monte Carlo reference, {} pixels, {} directions per strategy)",
                loaded.scene.name,
                harness::measure::sweep::IBL_REFERENCE_PIXELS,
                harness::measure::sweep::IBL_REFERENCE_SAMPLES
            );
            print!("{}", harness::measure::sweep::ibl_table(&rows));
        }
        return Ok(ExitCode::SUCCESS);
    }
    if knob == Knob::Gbuffer {
        let rows = harness::measure::sweep::gbuffer_sweep(&loaded.scene, kind, repeats, |what| {
            eprintln!("  {what} ...");
        })?;
        let text = serde_json::to_string_pretty(&rows)?;
        save_sweep(out, &loaded.scene.name, knob, &text);
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
    let rows = harness::measure::sweep::shadow_sweep(&loaded.scene, kind, repeats, |what| {
        eprintln!("  {what} ...");
    })?;
    let text = serde_json::to_string_pretty(&rows)?;
    save_sweep(out, &loaded.scene.name, knob, &text);
    if json {
        println!("{text}");
    } else {
        println!(
            "shadow sweep of {} on {kind} ({repeats} rounds over every setting, median GPU time)",
            loaded.scene.name
        );
        print!("{}", harness::measure::sweep::table(&rows));
    }
    Ok(ExitCode::SUCCESS)
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

/// Keeps a sweep's results (`out`/sweep_<scene>_<knob>.json, target/harness by default) for the
/// check report; a failure to write them is a warning.
fn save_sweep(out: &Path, scene: &str, knob: Knob, json: &str) {
    let path = out.join(harness::measure::sweep::result_file(scene, knob.name()));
    let written = std::fs::create_dir_all(out)
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

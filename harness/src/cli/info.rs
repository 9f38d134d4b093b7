//! The commands that only report what is there: `backends`, `scenes`, `plan` and `inspect`.

use std::path::Path;
use std::process::ExitCode;

use harness::first_scene;

/// `harness backends`: every backend with its availability, and the reason and fix when it is
/// unavailable or its driver when it is available.
pub(crate) fn backends(json: bool) -> anyhow::Result<ExitCode> {
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

/// Lists the canonical scenes with their descriptions, loading each with its assets: one that
/// does not load is listed with its error, and the command exits 1.
pub(crate) fn scenes() -> anyhow::Result<ExitCode> {
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

/// `harness inspect`: what a file loads as; exits 1 when it does not load.
pub(crate) fn inspect(path: &Path, json: bool) -> anyhow::Result<ExitCode> {
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

/// `harness plan`: the render plan of a scene, the passes and targets it needs.
pub(crate) fn plan(scene: &str) -> anyhow::Result<ExitCode> {
    let loaded = harness::load_scene(scene)?;
    // The plan of the scene as drawn: an extracted sun's light and shadow map are in it.
    let prepared = engine::renderer::PreparedFrame::new(&loaded.scene)?;
    print!("{}", prepared.plan());
    // The shadow terms are debug outputs, planned only when asked for (`render --pass`, and
    // the golden suite, which always asks): named here, since they have goldens too.
    let mut with_terms = prepared.scene().clone();
    with_terms.quality.debug_shadow_terms = true;
    let planned = prepared.plan().target_ids();
    let terms: Vec<engine::plan::TargetId> = prepared
        .varied(with_terms)?
        .plan()
        .target_ids()
        .into_iter()
        .filter(|t| !planned.contains(t))
        .collect();
    if !terms.is_empty() {
        println!(
            "debug outputs (planned when asked for: `render --pass NAME` or `--pass all`; \
             golden outputs too): {}",
            harness::names(&terms)
        );
    }
    Ok(ExitCode::SUCCESS)
}

//! `harness render`: renders a scene on one backend and writes the pass outputs as images.

use std::path::PathBuf;
use std::process::ExitCode;

use engine::backend::BackendKind;

use super::{default_out_dir, print_load_warnings};

/// Renders `scene` on `kind` and writes the passes asked for (the final image by default) to
/// `out` or under target/harness/render/, printing where each went and the GPU timings.
pub(crate) fn run(
    scene: &str,
    kind: BackendKind,
    passes: &[String],
    out: Option<PathBuf>,
) -> anyhow::Result<ExitCode> {
    let loaded = harness::load_scene(scene)?;
    print_load_warnings(&loaded);
    let scene = &loaded.scene;
    // The plan of the scene as drawn: an extracted sun's light and shadow map are outputs too.
    let plan = engine::plan::RenderPlan::new(&engine::renderer::scene_as_drawn(scene));
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
    // Only the passes the asked-for outputs depend on run (`harness bench` times whole frames).
    let frame = engine::renderer::render(
        backend.as_mut(),
        scene,
        engine::renderer::Readback::Needed(&wanted),
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

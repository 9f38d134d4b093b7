//! `harness render`: renders a scene on one backend and writes the pass outputs as images.

use std::path::PathBuf;
use std::process::ExitCode;

use engine::backend::BackendKind;
use engine::plan::TargetId;
use engine::renderer::{PreparedFrame, Readback};

use super::{default_out_dir, print_load_warnings};

/// Renders `scene` on `kind` and writes the passes asked for (the final image by default) to
/// `out` or under target/harness/render/, printing where each went and the GPU timings.
pub(crate) fn run(
    scene: &str,
    kind: BackendKind,
    passes: &[String],
    out: Option<PathBuf>,
) -> anyhow::Result<ExitCode> {
    let mut loaded = harness::load_scene(scene)?;
    print_load_warnings(&loaded);
    // A shadow term is a debug output, planned when asked for (the golden suite always asks):
    // by name, or by `all`, which writes every output a golden holds.
    let shadow_term = |name: &String| {
        name == "all"
            || name
                .parse::<TargetId>()
                .is_ok_and(|t| matches!(t, TargetId::ShadowTerm { .. }))
    };
    if passes.iter().any(shadow_term) {
        loaded.scene.quality.debug_shadow_terms = true;
    }
    // The scene as drawn and its plan: an extracted sun's light and shadow map are outputs too.
    let prepared = PreparedFrame::new(&loaded.scene)?;
    let (scene, plan) = (prepared.scene(), prepared.plan());
    // Pass names (an edge) are checked against the plan before anything is rendered.
    let targets: Vec<TargetId> = if passes.is_empty() {
        vec![TargetId::Final]
    } else if passes.iter().any(|p| p == "all") {
        plan.target_ids()
    } else {
        passes
            .iter()
            .map(|name| plan.target_named(name))
            .collect::<Result<_, _>>()
            .map_err(|e| {
                // The shadow terms are outputs too, planned only when named: listed as well.
                let mut with_terms = loaded.scene.clone();
                with_terms.quality.debug_shadow_terms = true;
                let available = PreparedFrame::new(&with_terms)
                    .map(|p| harness::names(&p.plan().target_ids()))
                    .unwrap_or(e.available);
                anyhow::anyhow!(
                    "scene `{}` has no pass output `{}` (its outputs: {available}, or `all`)",
                    e.scene,
                    e.name,
                )
            })?
    };
    check_out_path(out.as_deref(), &targets, plan)?;
    let mut backend = harness::faults::create_backend(kind)?;
    eprintln!(
        "rendering {} ({}x{}) on {kind} ...",
        scene.name, scene.quality.width, scene.quality.height
    );
    // Only the passes the asked-for outputs depend on run (`harness bench` times whole frames).
    let frame =
        engine::renderer::render_prepared(backend.as_mut(), &prepared, Readback::Needed(&targets))?;
    let default_dir = default_out_dir()
        .join("render")
        .join(&scene.name)
        .join(kind.name());
    for target in &targets {
        let image = &frame.outputs[target];
        let extension = if image.as_u8().is_some() {
            "png"
        } else {
            "exr"
        };
        let file = format!("{target}.{extension}");
        let path = match &out {
            Some(path) if targets.len() == 1 && names_a_file(path) => path.clone(),
            Some(dir) => dir.join(file),
            None => default_dir.join(file),
        };
        harness::images::write_image(image, &path, harness::images::FileCompression::Fast)?;
        println!("{:<17} -> {}", target.to_string(), path.display());
    }
    for pass in &plan.passes {
        if let Some(ns) = frame.timings.pass_time(pass.id) {
            eprintln!("  {:<20} {:8.3} ms GPU", pass.id.to_string(), ns / 1e6);
        }
    }
    Ok(ExitCode::SUCCESS)
}

/// Whether `--out` names an image file rather than a folder: it is no folder already, and its
/// extension is an image format's (a folder may have a dot in its name, `run.1`).
fn names_a_file(out: &std::path::Path) -> bool {
    const IMAGES: [&str; 10] = [
        "png", "exr", "jpg", "jpeg", "tga", "bmp", "hdr", "tif", "tiff", "webp",
    ];
    !out.is_dir()
        && out
            .extension()
            .and_then(|e| e.to_str())
            .is_some_and(|e| IMAGES.iter().any(|i| e.eq_ignore_ascii_case(i)))
}

/// Refuses, before anything is rendered, an `--out` that names an image file
/// ([`names_a_file`]) where several outputs are asked for (they go into a folder), or one it
/// cannot write: EXR holds a float output, PNG any (a float one clamped to 0..1).
fn check_out_path(
    out: Option<&std::path::Path>,
    targets: &[TargetId],
    plan: &engine::plan::RenderPlan,
) -> anyhow::Result<()> {
    use engine::backend::TextureFormat;
    // A folder on the way that is a file (`README.md/x.png`): refused before rendering, as a
    // missing one is made when the images are written (`out` itself too where it is a folder).
    let unwritable = out.and_then(|o| {
        if names_a_file(o) {
            super::preflight::file_problem("--out", o)
        } else {
            super::preflight::folder_problem("--out", o)
        }
    });
    if let Some(why) = unwritable {
        anyhow::bail!("{why}");
    }
    let Some(extension) = out.filter(|o| names_a_file(o)).and_then(|o| o.extension()) else {
        return Ok(());
    };
    let out = out.unwrap_or(std::path::Path::new("")).display();
    let [target] = targets else {
        anyhow::bail!(
            "--out {out} names a file, but {} outputs are asked for: give a folder",
            targets.len()
        );
    };
    let eight_bit = plan.target(*target).is_some_and(|t| {
        matches!(
            t.format,
            TextureFormat::Rgba8Unorm | TextureFormat::Rgba8UnormSrgb
        )
    });
    // PNG holds any output; EXR a float one.
    let writable = extension.eq_ignore_ascii_case("png")
        || (extension.eq_ignore_ascii_case("exr") && !eight_bit);
    if !writable {
        anyhow::bail!(
            "--out {out}: {target} is {}, written as {} (or give a folder)",
            if eight_bit { "8-bit" } else { "floating point" },
            if eight_bit {
                ".png"
            } else {
                ".exr, or .png clamped to 0..1"
            }
        );
    }
    Ok(())
}

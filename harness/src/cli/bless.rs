//! `harness bless`: rewrites the goldens that changed (or were named) after an intended change.

use std::process::ExitCode;

use engine::backend::BackendKind;

use super::load_cases;

/// Renders each scene asked for on `kind` and rewrites the passes outside tolerance, without a
/// golden, named with `--pass`, or all of them with `--every-pass` (nothing with `--dry-run`).
pub(crate) fn run(
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

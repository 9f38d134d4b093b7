//! `harness bless`: rewrites the goldens that changed (or were named) after an intended change.

use std::process::ExitCode;

use engine::backend::BackendKind;
use engine::plan::TargetId;
use engine::renderer::Readback;
use harness::golden::bless::{bless_pass, BlessOutcome, BlessRequest};

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
        // Names given on the command line (an edge), as the case's golden passes.
        let mut named: Vec<TargetId> = Vec::new();
        for name in passes {
            match name.parse().ok().filter(|p| case.passes.contains(p)) {
                Some(pass) => named.push(pass),
                None => anyhow::bail!(
                    "scene {} has no golden pass `{name}` (it has: {})",
                    case.name(),
                    harness::names(&case.passes)
                ),
            }
        }
        // In the case's order, each once.
        let wanted: Vec<TargetId> = case
            .passes
            .iter()
            .copied()
            .filter(|p| named.is_empty() || named.contains(p))
            .collect();
        eprintln!("rendering {} on {kind} ...", case.name());
        let frame = engine::renderer::render_prepared(
            backend.as_mut(),
            &case.frame,
            Readback::Only(&wanted),
        )?;
        let request = BlessRequest {
            named: &named,
            every_pass,
            dry_run,
        };
        let mut kept = 0;
        for pass in wanted {
            let blessed = bless_pass(
                &store,
                case,
                pass,
                &frame.outputs[&pass],
                (kind, &driver),
                request,
            )?;
            if blessed.outcome == BlessOutcome::Kept {
                kept += 1;
            }
            println!("{blessed}");
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

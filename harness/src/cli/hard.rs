//! `harness hard`: the numerical hard cases (far from the origin, tiny and huge scales) on every
//! backend, kept for the check report.

use std::path::Path;
use std::process::ExitCode;

use engine::backend::BackendKind;

/// Runs the hard cases on the backends asked for (every available one by default), keeps the
/// table in `out` (target/harness/ by default) and prints it; exits 1 when a case fails.
pub(crate) fn run(backends: &[BackendKind], out: &Path, json: bool) -> anyhow::Result<ExitCode> {
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
    let path = out.join(harness::measure::hard_cases::RESULTS_JSON);
    match std::fs::create_dir_all(out)
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

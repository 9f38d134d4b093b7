//! `harness selftest`: known small changes must fail where they originate, unchanged renders
//! must stay well within every limit.

use std::process::ExitCode;

use engine::backend::BackendKind;

use super::load_cases_isolated;

/// Runs the mutation self-test on every available backend and prints the margin and noise
/// tables (or JSON); exits 1 when a change goes unnoticed or an unchanged render is too noisy.
pub(crate) fn run(json: bool) -> anyhow::Result<ExitCode> {
    let store = harness::golden::GoldenStore::workspace();
    let model = harness::golden::noise::NoiseModel::load(&store)?;
    let (cases, broken) = load_cases_isolated(&[])?;
    let available: Vec<BackendKind> = BackendKind::ALL
        .into_iter()
        .filter(|&k| engine::backend::probe(k).available)
        .collect();
    if available.is_empty() {
        anyhow::bail!("no backend is available; run `harness backends` for the reasons");
    }
    eprintln!(
        "self-test: {} scenes x {} mutations and unchanged renders on {} ...",
        cases.len(),
        harness::golden::selftest::Mutation::ALL.len(),
        available
            .iter()
            .map(|k| k.name())
            .collect::<Vec<_>>()
            .join(", ")
    );
    let mut result = harness::golden::selftest::run(
        &cases,
        &store,
        &available,
        &model,
        harness::golden::selftest::MutationChecks::EveryPass,
    );
    result.errors.extend(
        broken
            .iter()
            .map(|b| format!("scene `{}` did not load: {}", b.scene, b.error)),
    );
    if json {
        println!("{}", serde_json::to_string_pretty(&result)?);
    } else {
        println!(
            "Known changes: value / limit in the pass where each originates (at least {} to pass)",
            harness::golden::noise::MIN_MUTATION_RATIO
        );
        print!("{}", result.margin_table());
        println!(
            "\nUnchanged renders: worst value / limit over every pass (at most {} to pass)",
            harness::golden::noise::MAX_NOISE_RATIO
        );
        print!("{}", result.noise_table());
        for m in result.weak_detections() {
            println!(
                "WEAK: `{}` on {} ({}): {} is {} of its limit, under {}",
                m.mutation.describe(),
                m.scene,
                m.backend,
                m.mutation.origin(),
                m.origin_ratio()
                    .map_or("not golden".to_owned(), |r| format!("{r:.2}x")),
                harness::golden::noise::MIN_MUTATION_RATIO
            );
        }
        for n in result.noisy() {
            println!(
                "NOISY: unchanged {} under {} on {}: {} at {:.2} of its limit",
                n.scene,
                n.source,
                n.backend.map_or("-", engine::backend::BackendKind::name),
                n.pass,
                n.ratio
            );
        }
        for e in &result.errors {
            println!("ERROR: {e}");
        }
    }
    Ok(if result.passed() {
        ExitCode::SUCCESS
    } else {
        ExitCode::FAILURE
    })
}

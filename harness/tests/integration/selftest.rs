//! The mutation self-test: every known change fails in the pass where it originates by at least
//! 3x its limit, on every available backend and every scene it applies to; every unchanged
//! render (every backend, synthetic rounding, and the sources recorded in golden/noise.toml)
//! stays at or below half of every limit. Prints the margin and noise tables.

use crate::common;
use harness::golden::noise::NoiseModel;
use harness::golden::selftest::{self, Mutation, MutationChecks};
use harness::golden::GoldenStore;

#[test]
fn every_mutation_fails_where_it_originates_and_no_noise_source_comes_near_a_limit() {
    let backends = common::available_backends();
    assert!(
        !backends.is_empty(),
        "no backend available: the self-test needs one (see `harness backends`)"
    );
    harness::use_ibl_cache();
    let store = GoldenStore::workspace();
    let model = NoiseModel::load(&store).unwrap();
    let cases = harness::golden::suite::canonical_cases().unwrap();
    // The verdict reads only the pass where each mutation originates, so only that is checked
    // (`harness selftest` checks every pass, to list where else a change shows).
    let result = selftest::run(&cases, &store, &backends, &model, MutationChecks::Origin);
    eprintln!("{}\n{}", result.margin_table(), result.noise_table());
    assert!(
        result.errors.is_empty(),
        "renders failed: {:?}",
        result.errors
    );
    let weak: Vec<String> = result
        .weak_detections()
        .iter()
        .map(|m| {
            format!(
                "{} on {} ({}): {:?}",
                m.mutation.describe(),
                m.scene,
                m.backend,
                m.origin_ratio()
            )
        })
        .collect();
    assert!(weak.is_empty(), "caught by less than 3x: {weak:?}");
    let noisy: Vec<String> = result
        .noisy()
        .iter()
        .map(|n| {
            format!(
                "{} {} {} {}: {:.2}",
                n.source,
                n.scene,
                n.backend.map_or("-", engine::backend::BackendKind::name),
                n.pass,
                n.ratio
            )
        })
        .collect();
    assert!(noisy.is_empty(), "unchanged renders above 0.5x: {noisy:?}");
    // Every mutation applies somewhere, and was rendered on every backend there.
    for mutation in Mutation::ALL {
        let applied: Vec<_> = result
            .mutations
            .iter()
            .filter(|m| m.mutation == mutation && m.applies)
            .collect();
        assert!(
            applied.len() >= backends.len(),
            "{} applies to no scene",
            mutation.describe()
        );
    }
    // The recorded sources were read: at least the CPU code paths and the second Mesa.
    for source in ["cpu-sse4.1", "cpu-avx", "threads-1"] {
        assert!(
            result.noise.iter().any(|n| n.source == source && !n.live),
            "golden/noise.toml has no figures for {source}"
        );
    }
}

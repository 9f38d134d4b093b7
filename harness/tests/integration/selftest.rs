//! The mutation self-test: every known change fails in the pass where it originates by at least
//! 3x its limit, on every available backend and every scene it applies to; every unchanged
//! render (every backend, synthetic rounding, and the sources recorded in golden/noise.toml)
//! stays at or below half of every limit. Prints the margin and noise tables.

use crate::common;
use engine::backend::BackendKind;
use engine::plan::TargetId;
use harness::golden::bless::{bless_pass, BlessOutcome, BlessRequest};
use harness::golden::noise::NoiseModel;
use harness::golden::selftest::{self, Mutation, MutationChecks};
use harness::golden::GoldenStore;

#[test]
fn every_mutation_fails_where_it_originates_and_no_noise_source_comes_near_a_limit() {
    harness::use_ibl_cache();
    let backends = common::available_backends();
    assert!(
        !backends.is_empty(),
        "no backend available: the self-test needs one (see `harness backends`)"
    );
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
    let misdiagnosed: Vec<String> = result
        .misdiagnosed()
        .iter()
        .map(|m| {
            format!(
                "{} on {} ({}): {:?}",
                m.mutation.describe(),
                m.scene,
                m.backend,
                m.diagnosed_origin
            )
        })
        .collect();
    assert!(
        misdiagnosed.is_empty(),
        "the verdict names another origin: {misdiagnosed:?}"
    );
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

/// The self-test reaches an extracted sun: a scene with `[quality.ibl] extract_sun` has the
/// sun's shadow map and shadow term among its golden passes, and the shadow-bias mutation,
/// applied to the scene as drawn, fails in the sun's `shadow_term_0` by the self-test's margin.
/// Its goldens are blessed here, into a temporary store, from the unchanged render on gl (a dry
/// run first says each would be written new, and writes nothing).
#[test]
fn a_mutation_of_an_extracted_suns_shadow_fails_in_its_shadow_term() {
    harness::use_ibl_cache();
    if !common::gl_available() {
        return;
    }
    let dir = tempfile::tempdir().unwrap();
    let path = common::ibl_with_extracted_sun(dir.path(), "ibl_sun");
    let case = harness::golden::suite::Case::load(path.to_str().unwrap()).unwrap();
    let term = TargetId::ShadowTerm { light: 0 };
    assert!(
        case.passes.contains(&TargetId::Shadow { light: 0 }) && case.passes.contains(&term),
        "{:?}",
        case.passes
    );
    let store = GoldenStore::new(dir.path().join("golden"));
    let frame = case.render(BackendKind::Gl).unwrap();
    let lock = store.lock_scene(case.name(), |_| {}).unwrap();
    for &pass in &case.passes {
        // A dry run first: a pass without a golden would be written new, and nothing is.
        let dry_run = BlessRequest {
            dry_run: true,
            ..BlessRequest::default()
        };
        let output = (BackendKind::Gl, "test");
        let image = &frame.outputs[&pass];
        let dry = bless_pass(&store, &lock, &case, pass, image, output, dry_run).unwrap();
        assert_eq!(dry.outcome, BlessOutcome::WouldWriteNew, "{dry}");
        assert!(
            dry.to_string()
                .ends_with(": new; would be written (dry run)"),
            "{dry}"
        );
        let eight_bit = harness::golden::is_eight_bit(image);
        assert!(store.load(case.name(), pass, eight_bit).unwrap().is_none());
        let request = BlessRequest::default();
        let blessed = bless_pass(
            &store,
            &lock,
            &case,
            pass,
            &frame.outputs[&pass],
            (BackendKind::Gl, "test"),
            request,
        )
        .unwrap();
        assert!(
            matches!(blessed.outcome, BlessOutcome::Written(_)),
            "{blessed}"
        );
    }
    let model = NoiseModel::load(&GoldenStore::workspace()).unwrap();
    let cases = [case];
    let result = selftest::run(
        &cases,
        &store,
        &[BackendKind::Gl],
        &model,
        MutationChecks::Origin,
    );
    assert!(result.errors.is_empty(), "{:?}", result.errors);
    let bias = result
        .mutations
        .iter()
        .find(|m| m.mutation == Mutation::ShadowBias)
        .unwrap();
    assert!(
        bias.applies,
        "the shadow bias did not reach the extracted sun"
    );
    let ratio = bias.ratios.get(&term).copied().unwrap_or_default();
    eprintln!("shadow bias x4 on the extracted sun: {ratio:.2} x the shadow term's limit");
    assert!(
        ratio >= harness::golden::noise::MIN_MUTATION_RATIO,
        "{ratio} in {term}: {:?}",
        bias.ratios
    );
}

/// `selftest --help` counts the mutations there are.
#[test]
fn the_help_counts_the_mutations() {
    let (code, stdout, _) = common::cli::harness(&["selftest", "--help"]);
    assert_eq!(code, 0);
    let count = format!("{} small known changes", Mutation::ALL.len());
    assert!(stdout.contains(&count), "{stdout}");
}

//! `harness selftest`: known small changes must fail where they originate, unchanged renders
//! must stay well within every limit.

use std::process::ExitCode;

use engine::backend::BackendKind;

use super::load_cases_isolated;

/// `harness selftest`: the mutation self-test, or with `speed` the speed self-test.
pub(crate) fn command(
    json: bool,
    speed: bool,
    scenes: &[String],
    backends: &[BackendKind],
) -> anyhow::Result<ExitCode> {
    if speed {
        self::speed(scenes, backends, json)
    } else {
        run(json)
    }
}

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
        for m in result.misdiagnosed() {
            println!(
                "MISDIAGNOSED: `{}` on {} ({}): the verdict names {} as where it starts, not {}",
                m.mutation.describe(),
                m.scene,
                m.backend,
                harness::names(&m.diagnosed_origin),
                harness::names(&m.origin_passes)
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

/// `harness selftest --speed`: slows each pass of each scene named (every canonical one by
/// default) down x1.5 and x2 in turn on every available backend (or those named) and prints
/// the margin table; exits 1 when an injection is missed where its pass is timed, or flagged
/// in another pass.
pub(crate) fn speed(
    scenes: &[String],
    backends: &[BackendKind],
    json: bool,
) -> anyhow::Result<ExitCode> {
    use harness::golden::speed::selftest;
    // Each scene that does not load is named once, then the command fails.
    let cases = super::load_cases(scenes)?;
    let store = harness::golden::GoldenStore::workspace();
    let available: Vec<(BackendKind, String)> = BackendKind::ALL
        .into_iter()
        .filter(|k| backends.is_empty() || backends.contains(k))
        .filter_map(|k| {
            let status = engine::backend::probe(k);
            status
                .info
                .filter(|_| status.available)
                .map(|info| (k, harness::golden::fingerprint(&info)))
        })
        .collect();
    if available.is_empty() {
        anyhow::bail!("no backend is available; run `harness backends` for the reasons");
    }
    // The passes with timing goldens, in plan order: those the speed checks time.
    let mut scenes: Vec<(String, String, Vec<engine::plan::PassId>)> = Vec::new();
    for c in &cases {
        let goldens = harness::golden::speed::TimingGoldens::load(store.root(), c.name())?;
        let timed = c.frame.plan().passes.iter().map(|p| p.id);
        let blessed =
            timed.filter(|id| goldens.backends.values().any(|b| b.passes.contains_key(id)));
        scenes.push((c.name().to_owned(), c.argument(), blessed.collect()));
    }
    let (injections, errors) = selftest::run(
        &std::env::current_exe()?,
        store.root(),
        &scenes,
        &available,
        &selftest::INJECTED,
        |what| eprintln!("speed self-test: {what} ..."),
    );
    if json {
        println!(
            "{}",
            serde_json::to_string_pretty(&serde_json::json!({
                "injections": injections, "errors": errors,
            }))?
        );
    } else {
        println!(
            "Injected slowdowns: the slowdown the copies delivered in the probe's own process \
             (the pass timed with and without them), the slowdown measured against the timing \
             golden (their quotient is how fast that process ran the unslowed pass against the \
             golden), value / limit in the pass slowed (above 1 is flagged), the smallest \
             slowdown each pass detects, and the worst other pass of the scene"
        );
        print!("{}", selftest::table(&injections));
        for e in &errors {
            println!("ERROR: {e}");
        }
    }
    let wrong = injections.iter().filter(|i| !i.correct()).count();
    Ok(if wrong == 0 && errors.is_empty() {
        ExitCode::SUCCESS
    } else {
        ExitCode::FAILURE
    })
}

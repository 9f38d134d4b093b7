//! `harness bless`: rewrites the goldens that changed (or were named) after an intended change.

use std::path::PathBuf;
use std::process::ExitCode;

use engine::backend::BackendKind;
use engine::plan::TargetId;
use engine::renderer::Readback;
use harness::golden::bless::{bless_pass, BlessOutcome, BlessRequest};

use super::bless_speed::{bless_speed, timed_passes};
use super::load_cases;

/// The command line of `harness bless`.
#[derive(clap::Args)]
pub(crate) struct BlessArgs {
    /// Only this scene: a name in scenes/ or a path to a scene file (repeatable).
    #[arg(long = "scene")]
    scenes: Vec<String>,
    /// Only this pass (repeatable); a pass named here is rewritten even within tolerance. With
    /// --speed-only, a timed pass as `check`'s speed table names it (lighting_pbr, mask, ...).
    #[arg(long = "pass")]
    passes: Vec<String>,
    /// Rewrite every pass considered, also those within tolerance (after a driver change).
    #[arg(long)]
    every_pass: bool,
    /// Backend to render the goldens with (default gl); with --from-last-check, whose outputs
    /// to accept (default: the reference among those the check checked, gl when it did); with
    /// --speed-only, the one backend whose timing goldens to bless (default: every available
    /// one).
    #[arg(long)]
    backend: Option<BackendKind>,
    /// Bless every canonical scene: the passes that moved beyond their limits or have no golden
    /// (required when no --scene is given; with --every-pass, every pass).
    #[arg(long, conflicts_with = "scenes")]
    all: bool,
    /// Show what would change without writing anything.
    #[arg(long)]
    dry_run: bool,
    /// Bless the timing goldens only (a deliberate slowdown or speed-up), not the images.
    #[arg(long, conflicts_with = "no_speed")]
    speed_only: bool,
    /// Bless the images only, not the timing goldens.
    #[arg(long)]
    no_speed: bool,
    /// Instead of blessing, remove what nothing produces or records any more: folders of
    /// scenes gone from scenes/ (a scene blessed from a file elsewhere keeps its folder while
    /// that file exists), goldens of passes gone, goldens blessed.toml does not
    /// record, records without a golden, stray files (every scene's, or the --scene ones';
    /// with --dry-run, only list them).
    #[arg(long, conflicts_with_all = ["speed_only", "every_pass", "passes"])]
    prune: bool,
    /// Instead of rendering, accept what the last `check` rendered: the outputs of its
    /// failing passes on --backend (of --scene and --pass, or all), kept under
    /// --out/failures/, blessed as a fresh render would be; and its speed checks that moved
    /// beyond their limits, as the timing goldens (--no-speed: images only; --speed-only:
    /// timings only).
    #[arg(long, conflicts_with_all = ["every_pass", "prune", "all"])]
    from_last_check: bool,
    /// With --from-last-check: the folder `check --out` wrote to.
    #[arg(long, default_value_os_t = crate::default_out_dir())]
    out: PathBuf,
    /// Write new image goldens without rendering them again on every backend and CPU code path
    /// first (the default refuses one that does not reproduce); blessed.toml records it.
    #[arg(long)]
    unverified: bool,
    /// Why the pictures or the timings changed (a sentence, as in a commit message): recorded as
    /// `reason` beside each golden written (in blessed.toml for an image, in timing.toml for a
    /// pass's speed ratio), so the golden says why it is what it is.
    #[arg(long, value_name = "TEXT", conflicts_with = "prune", value_parser = reason_text)]
    reason: Option<String>,
}

/// A `--reason` as recorded ([`harness::golden::bless::given_reason`]); an empty one refused.
fn reason_text(text: &str) -> Result<String, String> {
    harness::golden::bless::given_reason(text)
        .map(str::to_owned)
        .ok_or_else(|| "say why the goldens changed (the text is empty)".to_owned())
}

/// `harness bless`, by mode: prune, accept from the last check, or render and bless.
pub(crate) fn command(args: BlessArgs) -> anyhow::Result<ExitCode> {
    if args.prune {
        return prune(&args.scenes, args.dry_run);
    }
    if args.from_last_check {
        return from_last_check(
            &args.out,
            &args.scenes,
            &args.passes,
            args.backend,
            &Options {
                every_pass: false,
                dry_run: args.dry_run,
                images: !args.speed_only,
                speed: !args.no_speed,
                speed_backend: None,
                unverified: args.unverified,
                reason: args.reason.clone(),
            },
        );
    }
    run(
        &args.scenes,
        &args.passes,
        args.backend.unwrap_or(BackendKind::Gl),
        args.all,
        Options {
            every_pass: args.every_pass,
            dry_run: args.dry_run,
            images: !args.speed_only,
            speed: !args.no_speed,
            speed_backend: args.backend.filter(|_| args.speed_only),
            unverified: args.unverified,
            reason: args.reason,
        },
    )
}

/// What `bless` rewrites, beyond the scenes and passes named.
pub(crate) struct Options {
    /// Every pass considered, also those within tolerance.
    pub every_pass: bool,
    /// Decide and print; write nothing.
    pub dry_run: bool,
    /// Bless the images (on the one backend asked for).
    pub images: bool,
    /// Bless the timing goldens (on every available backend).
    pub speed: bool,
    /// With the timings alone, the one backend asked for (`--backend`); else every available.
    pub speed_backend: Option<BackendKind>,
    /// Write new image goldens without verifying that they reproduce.
    pub unverified: bool,
    /// Why the pictures or timings changed, recorded beside each golden written.
    pub reason: Option<String>,
}

/// Renders each scene asked for on `kind` and rewrites the passes outside tolerance, without a
/// golden, named with `--pass`, or all of them with `--every-pass` (nothing with `--dry-run`);
/// then probes every available backend and rewrites the timing goldens the same way.
pub(crate) fn run(
    scenes: &[String],
    passes: &[String],
    kind: BackendKind,
    all: bool,
    options: Options,
) -> anyhow::Result<ExitCode> {
    if scenes.is_empty() && !all {
        anyhow::bail!("name what to bless with --scene (and optionally --pass), or bless everything with --all");
    }
    let cases = load_cases(scenes)?;
    if let Some(why) = cases.iter().find_map(harness::golden::bless::refusal) {
        anyhow::bail!("{why}");
    }
    let store = harness::golden::GoldenStore::workspace();
    // Every scene's folder held for the whole run, images and timing goldens, taken in name
    // order (two runs over overlapping scenes cannot each wait for the other).
    let mut names: Vec<&str> = cases.iter().map(|c| c.name()).collect();
    names.sort_unstable();
    names.dedup();
    let mut locks = std::collections::BTreeMap::new();
    for name in names {
        locks.insert(name.to_owned(), scene_lock(&store, name, options.dry_run)?);
    }
    // Before anything is written: what would stop the bless half-way through a scene.
    for case in &cases {
        if options.images {
            harness::golden::bless::preflight(&store, case)?;
        }
        if options.speed {
            harness::golden::speed::TimingGoldens::load(store.root(), case.name())?;
        }
    }
    let mut refused = 0;
    if options.images {
        refused = bless_images(&cases, &store, &locks, passes, kind, &options)?;
    }
    if options.speed {
        // `--pass` names timed passes when the timings alone are blessed; with the images it
        // names image passes, and the timings are rewritten where they moved.
        let timed = if options.images {
            Vec::new()
        } else {
            timed_passes(&cases, &store, passes)?
        };
        let refused_timings = bless_speed(&cases, &store, &timed, &options)?;
        // Timings alone were asked for: a backend whose goldens another host blessed, kept,
        // or a pass asked for that could not be written, is a refusal (with images, keeping
        // them is what a bless elsewhere does).
        if refused_timings > 0 && !options.images {
            eprintln!(
                "error: {refused_timings} timing golden(s) asked for (a scene and backend, or a \
                 pass) were kept, not blessed (each line above says why and what to run)"
            );
            refused += refused_timings;
        }
    }
    Ok(if refused == 0 {
        ExitCode::SUCCESS
    } else {
        ExitCode::FAILURE
    })
}

/// The lock a bless of `scene` holds: waiting, saying so, while another bless holds it; none
/// at all for a dry run, which writes nothing (a lock would make the folder of a new scene).
fn scene_lock(
    store: &harness::golden::GoldenStore,
    scene: &str,
    dry_run: bool,
) -> anyhow::Result<harness::golden::SceneLock> {
    if dry_run {
        return Ok(store.dry_run_lock(scene));
    }
    Ok(store.lock_scene(scene, |path| {
        eprintln!(
            "waiting for another `harness bless` of {scene} to finish (it holds {})",
            path.display()
        );
    })?)
}

/// Whether `candidates`, the new goldens of `case`, reproduce under every verification source
/// (see [`harness::golden::verify`]); prints each disagreement as a refusal.
fn verified(
    store: &harness::golden::GoldenStore,
    case: &harness::golden::suite::Case,
    candidates: &[(TargetId, engine::Image)],
) -> anyhow::Result<bool> {
    let exe = std::env::current_exe()?;
    let disagreements = harness::golden::verify::verify(&exe, store, case, candidates, |source| {
        eprintln!("verifying {}'s new goldens under {source} ...", case.name());
    })
    .map_err(anyhow::Error::msg)?;
    print_disagreements(case, &disagreements);
    Ok(disagreements.is_empty())
}

/// Prints each place `case`'s new goldens did not reproduce as a refusal, and what to do.
fn print_disagreements(
    case: &harness::golden::suite::Case,
    disagreements: &[harness::golden::verify::Disagreement],
) {
    for d in disagreements {
        println!("REFUSED {}/{d}", case.name());
    }
    if !disagreements.is_empty() {
        println!(
            "{}: nothing written; the new goldens must reproduce on every backend and CPU code \
             path ({}); look at the disagreeing render, or bless with --unverified to record \
             them anyway",
            case.name(),
            harness::golden::verify::SOURCES.join(", ")
        );
    }
}

/// Renders each scene on `kind` and rewrites its image goldens as asked, once they are
/// verified (unless `--unverified`); the number of scenes refused.
fn bless_images(
    cases: &[harness::golden::suite::Case],
    store: &harness::golden::GoldenStore,
    locks: &std::collections::BTreeMap<String, harness::golden::SceneLock>,
    passes: &[String],
    kind: BackendKind,
    options: &Options,
) -> anyhow::Result<usize> {
    let mut refused = 0;
    let (every_pass, dry_run) = (options.every_pass, options.dry_run);
    let mut backend = harness::faults::create_backend(kind)?;
    let driver = harness::golden::fingerprint(backend.info());
    for case in cases {
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
            unverified: options.unverified,
            reason: options.reason.as_deref(),
        };
        let lock = &locks[case.name()];
        if !dry_run && !options.unverified {
            let mut candidates = Vec::new();
            for &pass in &wanted {
                let image = &frame.outputs[&pass];
                let decision = BlessRequest {
                    dry_run: true,
                    ..request
                };
                let blessed =
                    bless_pass(store, lock, case, pass, image, (kind, &driver), decision)?;
                if matches!(
                    blessed.outcome,
                    BlessOutcome::WouldWrite | BlessOutcome::WouldWriteNew
                ) {
                    candidates.push((pass, image.clone()));
                }
            }
            if !candidates.is_empty() && !verified(store, case, &candidates)? {
                refused += 1;
                continue;
            }
        }
        let (mut kept, mut written) = (0, 0);
        for pass in wanted {
            let blessed = bless_pass(
                store,
                lock,
                case,
                pass,
                &frame.outputs[&pass],
                (kind, &driver),
                request,
            )?;
            match blessed.outcome {
                BlessOutcome::Kept => kept += 1,
                BlessOutcome::Written(_) => written += 1,
                BlessOutcome::WouldWrite | BlessOutcome::WouldWriteNew => {}
            }
            println!("{blessed}");
        }
        if written > 0 {
            print_record_line(store, case.name(), request.reason.is_some());
        }
        if kept > 0 {
            println!(
                "{}: {kept} pass(es) within tolerance kept as they are (--every-pass rewrites them)",
                case.name()
            );
        }
        if !harness::golden::bless::is_canonical(case) {
            println!(
                "note: {} is not a canonical scene (a file directly in scenes/): `check` checks \
                 it only when named with --scene, and `bless --prune` keeps golden/{}/ while the \
                 file is there (put it directly in scenes/ to make it part of the suite)",
                case.loaded.path.display(),
                case.name()
            );
        }
    }
    Ok(refused)
}

/// After a scene's goldens were written (by a bless or an accept): where how each was blessed
/// is recorded (backend, driver, the old golden's metrics where there was one, and the reason).
fn print_record_line(store: &harness::golden::GoldenStore, scene: &str, reason: bool) {
    println!(
        "{scene}: recorded how each was blessed{} in {}",
        if reason { ", and why," } else { "" },
        store.record_path(scene).display()
    );
}

/// `harness bless --prune`: lists the orphans in golden/ (every scene's and golden/'s own, or
/// those of the scenes named) and removes them unless `dry_run`.
pub(crate) fn prune(scenes: &[String], dry_run: bool) -> anyhow::Result<ExitCode> {
    let cases = load_cases(scenes)?;
    // A scene copy named like a canonical scene would prune that scene's goldens by its own.
    if let Some(why) = cases.iter().find_map(harness::golden::bless::refusal) {
        anyhow::bail!("{why}");
    }
    let store = harness::golden::GoldenStore::workspace();
    let canonical = scenes
        .is_empty()
        .then(|| engine::scene_file::canonical_scenes(&harness::scenes_dir()));
    let orphans = harness::golden::orphans::find(&store, &cases, canonical.as_deref())?;
    if orphans.is_empty() {
        println!("no orphans in {}", store.root().display());
        return Ok(ExitCode::SUCCESS);
    }
    // What a prune keeps says so on its own line below.
    for orphan in orphans.iter().filter(|o| o.kind.prunable()) {
        println!("orphan: {orphan}");
    }
    let lines = harness::golden::orphans::prune(&store, &orphans, dry_run, |path| {
        eprintln!(
            "waiting for a `harness bless` to finish (it holds {})",
            path.display()
        );
    })?;
    for line in lines {
        println!("{line}");
    }
    Ok(ExitCode::SUCCESS)
}

/// `harness bless --from-last-check`: blesses the outputs the last `check` (under `out`) kept of
/// its failing passes on `backend`, of `scenes` and `passes` (all when empty), without rendering.
/// Exits 1 when a pass was refused.
pub(crate) fn from_last_check(
    out: &std::path::Path,
    scenes: &[String],
    passes: &[String],
    backend: Option<BackendKind>,
    options: &Options,
) -> anyhow::Result<ExitCode> {
    use harness::golden::accept;
    let (dry_run, unverified) = (options.dry_run, options.unverified);
    let candidates = if options.images {
        accept::candidates(out, backend, scenes, passes)?
    } else {
        Vec::new()
    };
    // A debug check's timings are never taken; its images are (the same picture).
    let (mut timings, checked) = if options.speed {
        match accept::speed_candidates(out, scenes, passes) {
            Err(e @ accept::AcceptError::DebugSlowdown) if options.images => {
                eprintln!("note: no timings accepted: {e}");
                Default::default()
            }
            other => other?,
        }
    } else {
        Default::default()
    };
    if let Some(backend) = backend {
        timings.retain(|c| c.backend == backend);
    }
    if candidates.is_empty() && timings.is_empty() {
        let on = backend.map_or("its reference backend".to_owned(), |b| b.to_string());
        println!(
            "nothing to accept: the last check ({}) has no failing pass on {on} and no speed \
             check beyond its limit{}",
            out.join(accept::LAST_CHECK).display(),
            if scenes.is_empty() && passes.is_empty() {
                ""
            } else {
                " among those named"
            }
        );
        return Ok(ExitCode::SUCCESS);
    }
    let mut arguments: Vec<String> = Vec::new();
    for c in &candidates {
        if !arguments.contains(&c.check.scene_argument) {
            arguments.push(c.check.scene_argument.clone());
        }
    }
    // No images to accept: no scene to load (an empty list would load them all).
    let cases = if arguments.is_empty() {
        Vec::new()
    } else {
        load_cases(&arguments)?
    };
    // Before anything is written: a scene copy named like a canonical scene blesses nothing.
    if let Some(why) = cases.iter().find_map(harness::golden::bless::refusal) {
        anyhow::bail!("{why}");
    }
    let store = harness::golden::GoldenStore::workspace();
    let exe = std::env::current_exe()?;
    let mut refused = 0;
    for case in &cases {
        let lock = scene_lock(&store, case.name(), dry_run)?;
        let mine: Vec<&accept::Candidate> = candidates
            .iter()
            .filter(|c| c.check.scene == case.name())
            .collect();
        let done = accept::accept_scene(
            &exe,
            &store,
            &lock,
            case,
            &mine,
            accept::AcceptOptions {
                dry_run,
                unverified,
                reason: options.reason.as_deref(),
                check_out: Some(out),
            },
            |source| eprintln!("verifying {}'s new goldens under {source} ...", case.name()),
        );
        // A scene refused whole (changed since the check, say) leaves the others to accept.
        let done = match done {
            Ok(done) => done,
            Err(why) => {
                println!("REFUSED {why}");
                refused += mine.len();
                continue;
            }
        };
        if done.verified_by_check {
            let outcome = if done.disagreements.is_empty() {
                "verified by the last check"
            } else {
                "refused by the last check's verification"
            };
            eprintln!(
                "{}: {outcome} (its inputs and kept outputs are unchanged); nothing rendered",
                case.name()
            );
        }
        print_disagreements(case, &done.disagreements);
        if !done.disagreements.is_empty() {
            refused += mine.len();
        }
        for (_, why) in &done.refused {
            refused += 1;
            println!("REFUSED {why}");
        }
        for blessed in &done.accepted {
            println!("{blessed}");
        }
        if done
            .accepted
            .iter()
            .any(|b| matches!(b.outcome, BlessOutcome::Written(_)))
        {
            print_record_line(&store, case.name(), options.reason.is_some());
        }
    }
    // The timing goldens, as the check measured them (a probe again would be a new measurement).
    let reason = options.reason.as_deref();
    let timed = accept::accept_all_timings(&store, &timings, &checked, dry_run, reason, |path| {
        eprintln!(
            "waiting for another `harness bless` to finish (it holds {})",
            path.display()
        );
    });
    // A timing kept out is a refusal where timings were all that was asked for or found
    // (--speed-only, or no image to accept), and a note beside the images otherwise (ratios
    // from a host that did not bless are common).
    let timings_asked = !options.images || candidates.is_empty();
    for (_, done) in timed {
        match done {
            Ok(done) => {
                done.written.iter().for_each(|line| println!("{line}"));
                for why in done.kept.iter().map(|k| &k.why) {
                    if timings_asked {
                        refused += 1;
                        println!("REFUSED {why}");
                    } else {
                        println!("note: {why}");
                    }
                }
            }
            Err(why) => {
                refused += 1;
                println!("REFUSED {why}");
            }
        }
    }
    Ok(if refused == 0 {
        ExitCode::SUCCESS
    } else {
        ExitCode::FAILURE
    })
}

//! `harness check`, the default command: every scene's passes against their goldens and the
//! backends against each other, as a table (or JSON) and the HTML report.

use std::path::{Path, PathBuf};
use std::process::ExitCode;

use engine::backend::BackendKind;

use harness::golden::check::CheckRun;
use harness::golden::speed::SpeedOutcome;
use harness::golden::suite::{Case, LimitSource};

use super::{default_out_dir, load_cases_isolated};

/// How `check` runs, beyond what it checks.
pub(crate) struct Options {
    /// Print JSON instead of the table.
    pub json: bool,
    /// Only these golden passes' image checks (all when empty), by name.
    pub passes: Vec<String>,
    /// Run the speed checks.
    pub speed: bool,
    /// Verify the outputs kept of failing passes (for accepting them without rendering).
    pub verify: bool,
    /// Debug: the lighting passes unspecialised, in the renders and the speed probes.
    pub unspecialised_lighting: bool,
    /// Where to write the results as JUnit XML.
    pub junit: Option<PathBuf>,
    /// Where to write the Markdown summary.
    pub summary: Option<PathBuf>,
}

/// Runs the check on the scenes and backends asked for (all by default), writes report.html
/// and the failure images under `out` and prints the results; exits 1 on any failure, and 2,
/// writing nothing, where a `--scene` names neither a file nor a scene in scenes/ (a typo must
/// not replace the last check that `harness review` and `bless --from-last-check` read).
pub(crate) fn run(
    out: &Path,
    scenes: &[String],
    backends: &[BackendKind],
    options: Options,
) -> anyhow::Result<ExitCode> {
    let (junit, summary) = (options.junit.as_deref(), options.summary.as_deref());
    let unwritable = super::preflight::report_problem(out, junit, summary);
    if let Some(why) = unwritable.or_else(|| super::preflight::no_scenes(scenes)) {
        eprintln!("error: {why}; nothing checked");
        return Ok(ExitCode::from(2));
    }
    for scene in scenes {
        if let Err(e @ engine::scene_file::SceneFileError::UnknownScene { .. }) =
            engine::scene_file::resolve(scene, &harness::scenes_dir())
        {
            eprintln!(
                "error: {e}; nothing checked, {} left as it was",
                out.display()
            );
            return Ok(ExitCode::from(2));
        }
    }
    let (mut cases, broken) = load_cases_isolated(scenes)?;
    // What each scene was loaded from, for the speed history (before `--pass` narrows).
    let input_digests = harness::golden::scene_inputs::digests(cases.iter().map(|c| &c.inputs));
    // Every scene's speed, before `--pass` narrows the image checks.
    let speed_scenes: Vec<(String, String)> = cases
        .iter()
        .map(|c| (c.name().to_owned(), c.argument()))
        .collect();
    narrow_passes(&mut cases, &options.passes)?;
    let variations = engine::renderer::Variations {
        unspecialised_lighting: options.unspecialised_lighting,
        ..Default::default()
    };
    if options.unspecialised_lighting {
        eprintln!(
            "debug: the lighting passes run unspecialised (--debug-unspecialised-lighting), in \
             the renders and the speed probes"
        );
        for case in &mut cases {
            case.frame = case.frame.clone().with_variations(variations);
        }
    }
    let store = harness::golden::GoldenStore::workspace();
    let exe = std::env::current_exe()?;
    // The speed probes' child starts now and prepares them (starting its backends, recording
    // and warming up the frames) on the core the image renders leave idle; their timed rounds
    // wait until the renders are done. None when no scene loaded (a child given no scene would
    // probe every canonical one).
    let speed = (options.speed && !speed_scenes.is_empty()).then(|| {
        harness::golden::speed::start_check(&exe, &speed_scenes, backends, variations, &[])
    });
    let bar = indicatif::ProgressBar::new(0).with_style(
        indicatif::ProgressStyle::with_template("{bar:30} {pos}/{len} renders  {msg}")
            .unwrap_or_else(|_| indicatif::ProgressStyle::default_bar()),
    );
    let failures = out.join("failures");
    let (run, outputs) =
        harness::golden::check::run(&cases, &store, backends, &failures, |done, total, what| {
            bar.set_length(total as u64);
            bar.set_position(done as u64);
            bar.set_message(what.to_owned());
        });
    let mut run = run;
    if !options.passes.is_empty() {
        // Where a change starts cannot be told from some passes only (the first one checked
        // would look like the origin).
        run.diagnoses.clear();
    }
    if options.verify {
        run.verifications =
            harness::golden::verify::verify_failing(&exe, &store, &cases, &run, &outputs, |what| {
                bar.set_message(what.to_owned())
            });
        harness::golden::diagnosis::after_verification(&mut run.diagnoses, &run.verifications);
    }
    if let Some(started) = speed {
        let available: Vec<(BackendKind, String)> = run
            .backends
            .iter()
            .filter(|b| b.unavailable.is_none())
            .map(|b| (b.backend, b.fingerprint.clone().unwrap_or_default()))
            .collect();
        run.speed = harness::golden::speed::check_scenes(
            started,
            store.root(),
            &speed_scenes,
            &available,
            |what| bar.set_message(what.to_owned()),
        );
        run.speed.unspecialised_lighting = options.unspecialised_lighting;
        // The history is the series of an unchanged build's ratios (drift, a host's record):
        // a run with the debug slowdown is not one.
        if !options.unspecialised_lighting {
            harness::golden::speed::append_history(out, &run.speed, &available, input_digests);
        }
    }
    bar.finish_and_clear();
    run.load_errors = broken;
    // With every scene checked, golden/'s folders too; otherwise the checked scenes' folders.
    // (With some passes only, the others' goldens would look orphaned: not looked for.)
    let canonical = scenes
        .is_empty()
        .then(|| engine::scene_file::canonical_scenes(&harness::scenes_dir()));
    if options.passes.is_empty() {
        match harness::golden::orphans::find(&store, &cases, canonical.as_deref()) {
            Ok(orphans) => run.orphans = orphans,
            Err(e) => eprintln!("note: cannot look for orphans in golden/: {e}"),
        }
    }
    for orphan in &run.orphans {
        if orphan.kind.prunable() {
            eprintln!("note: orphan: {orphan} (`harness bless --prune` removes it)");
        } else {
            eprintln!("note: {orphan}");
        }
    }
    for b in &run.backends {
        match &b.unavailable {
            Some(reason) if b.required => {
                eprintln!(
                    "error: {} was asked for but is unavailable: {reason}",
                    b.backend
                );
            }
            Some(reason) => eprintln!(
                "note: {} unavailable, not checked: {reason} (name it with --backend to make \
                 its absence fail the check)",
                b.backend
            ),
            None => {}
        }
    }
    // Nothing available and nothing asked for by name: no run to report. A backend asked for
    // and missing is reported as the run's failure (page, JUnit, summary).
    if run
        .backends
        .iter()
        .all(|b| b.unavailable.is_some() && !b.required)
    {
        anyhow::bail!("no backend is available; run `harness backends` for the reasons");
    }
    for note in &run.driver_notes {
        eprintln!("note: {note}");
    }
    note_borrowed_limits(&cases, &store);
    finish(
        &run,
        &outputs,
        &store,
        out,
        &failures.display().to_string(),
        &options,
    )
}

/// Keeps only the golden passes named in `passes` (all when empty) in each case, and the cases
/// left with any; a name that no case has is an error that lists the passes there are.
fn narrow_passes(cases: &mut Vec<Case>, passes: &[String]) -> anyhow::Result<()> {
    if passes.is_empty() {
        return Ok(());
    }
    for name in passes {
        if !cases
            .iter()
            .any(|c| c.passes.iter().any(|p| p.to_string() == *name))
        {
            let mut known: Vec<String> = cases
                .iter()
                .flat_map(|c| c.passes.iter().map(ToString::to_string))
                .collect();
            known.sort();
            known.dedup();
            // A plan pass (`lighting_pbr`) names a speed check, which --pass does not narrow.
            let timed = name.parse::<engine::plan::PassId>().is_ok();
            anyhow::bail!(
                "no scene checked has a golden pass `{name}` (they have: {}){}",
                known.join(", "),
                if timed {
                    "; `--pass` narrows the image checks, and the speed checks, which name the \
                     passes of the plan such as this one, are run whole (`--no-speed` skips them)"
                } else {
                    ""
                }
            );
        }
    }
    for case in cases.iter_mut() {
        case.passes.retain(|p| passes.contains(&p.to_string()));
    }
    cases.retain(|c| !c.passes.is_empty());
    Ok(())
}

/// Writes what a run leaves under `out` (the review page, last-check.json) and where `options`
/// asks (JUnit, summary), prints the table or the JSON, and says how the run went: `check`'s
/// last step, and `report --merge`'s.
pub(crate) fn finish(
    run: &CheckRun,
    outputs: &harness::golden::check::Outputs,
    store: &harness::golden::GoldenStore,
    out: &Path,
    failures: &str,
    options: &Options,
) -> anyhow::Result<ExitCode> {
    let html = harness::report::html(
        run,
        outputs,
        store,
        Some(out),
        &harness::measure::report_sections(),
    );
    let report = out.join("report.html");
    harness::images::write_atomically(&report, html.as_bytes())?;
    // What `bless --from-last-check` and `harness review` accept from: this run's results,
    // beside the failure images they point at.
    let record = serde_json::to_vec(run)?;
    harness::images::write_atomically(&out.join(harness::golden::accept::LAST_CHECK), &record)?;
    if let Some(path) = &options.junit {
        let xml = harness::ci_report::junit(run)
            .map_err(|e| anyhow::anyhow!("cannot write JUnit XML for {}: {e}", path.display()))?;
        harness::images::write_atomically(path, xml.as_bytes())?;
    }
    if let Some(path) = &options.summary {
        let markdown = harness::ci_report::summary(run, &report);
        harness::images::write_atomically(path, markdown.as_bytes())?;
    }
    if options.json {
        println!("{}", serde_json::to_string_pretty(run)?);
    } else {
        print_table(run, &report, failures);
    }
    Ok(if run.passed() {
        ExitCode::SUCCESS
    } else {
        ExitCode::FAILURE
    })
}

/// `harness report --merge DIR...`: the shards' runs joined into one, written under `out` like a
/// check's (page, last-check.json, and the JUnit and summary `options` asks for).
pub(crate) fn merge(shards: &[PathBuf], out: &Path, options: &Options) -> anyhow::Result<ExitCode> {
    let (junit, summary) = (options.junit.as_deref(), options.summary.as_deref());
    if let Some(why) = super::preflight::report_problem(out, junit, summary) {
        eprintln!("error: {why}; nothing joined");
        return Ok(ExitCode::from(2));
    }
    let (run, outputs) = match harness::golden::merge::merge(shards, out) {
        Err(e @ harness::golden::merge::MergeError::OutIsShard { .. }) => {
            eprintln!("error: {e}; nothing joined");
            return Ok(ExitCode::from(2));
        }
        other => other?,
    };
    let store = harness::golden::GoldenStore::workspace();
    let failures = out.join("failures");
    finish(
        &run,
        &outputs,
        &store,
        out,
        &failures.display().to_string(),
        options,
    )
}

/// Notes on stderr each scene whose limits are borrowed from the canonical scenes (or a
/// fallback) because golden/noise.toml has no figures for it, and how to measure its own; or,
/// where `store` has no noise.toml at all, that every limit is a fallback.
fn note_borrowed_limits(cases: &[Case], store: &harness::golden::GoldenStore) {
    let model = store.root().join(harness::golden::noise::NOISE_FILE);
    if !cases.is_empty() && !model.exists() {
        eprintln!(
            "note: {} does not exist, so no limit is a measured one: each is the built-in \
             fallback of its metric (measure the model with `{}`)",
            model.display(),
            harness::golden::command_line::harness_command("noise --write")
        );
        return;
    }
    for case in cases {
        let borrowed: Vec<String> = case
            .limit_sources
            .iter()
            .filter(|(_, s)| matches!(s, LimitSource::Borrowed | LimitSource::Fallback))
            .map(|(p, _)| p.to_string())
            .collect();
        if !borrowed.is_empty() {
            let measure = harness::golden::command_line::harness_command(&format!(
                "noise {} --write",
                harness::golden::command_line::scene_flag(&case.argument())
            ));
            eprintln!(
                "note: golden/noise.toml has no figures for {} ({}): its limits are the \
                 canonical scenes' largest; measure its own with `{measure}` (it needs the \
                 second Mesa: scripts/mesa-backports.sh)",
                case.name(),
                borrowed.join(", "),
            );
        }
    }
}

/// The results table on stdout: a line per scene, pass and backend, then the renders and
/// scenes that failed, the backends that disagree, a summary line, and on a failure where the
/// images are and what to do: the bless commands, and for the slower passes of a check with
/// `--debug-unspecialised-lighting`, that they are the debug setting's own and nothing is to
/// be blessed.
fn print_table(run: &CheckRun, report: &Path, failures: &str) {
    println!(
        "{:<8} {:<17} {:<12} {:<12} worst metric",
        "scene", "pass", "backend", "result"
    );
    for r in &run.results {
        let worst = r.worst();
        println!(
            "{:<8} {:<17} {:<12} {:<12} {worst}",
            r.scene,
            r.pass,
            r.backend,
            r.outcome.label()
        );
    }
    for (scene, backend, error) in &run.render_errors {
        println!(
            "{scene:<8} {:<17} {backend:<12} FAILED       render: {error}",
            "-"
        );
    }
    for b in &run.load_errors {
        println!(
            "{:<8} {:<17} {:<12} FAILED       load: {}",
            b.scene, "-", "-", b.error
        );
    }
    for b in run.backends.iter().filter(|b| b.missing()) {
        println!(
            "{:<8} {:<17} {:<12} FAILED       asked for (--backend) but unavailable: {}",
            "-",
            "-",
            b.backend,
            b.unavailable.as_deref().unwrap_or_default()
        );
    }
    let worst_cross = run
        .cross
        .iter()
        .filter(|c| !c.within_tolerance)
        .map(|c| format!("{}/{} {} vs {}", c.scene, c.pass, c.a, c.b))
        .collect::<Vec<_>>();
    if !worst_cross.is_empty() {
        println!(
            "backends disagree beyond tolerance on: {}",
            worst_cross.join(", ")
        );
    }
    print_diagnoses(run);
    if !run.verifications.is_empty() {
        println!("\nverified: the outputs kept of the failing passes, rendered again");
        for v in &run.verifications {
            println!("  {}", v.summary());
        }
        println!(
            "  to accept exactly these outputs (nothing rendered again; or the review page's \
             Accept): {}",
            accept_command(report.parent().unwrap_or(report))
        );
    }
    super::check_speed::print_speed(run);
    // Counted as the summary and the JUnit file count them: a scene that did not load, a
    // backend asked for and missing, a failed render or probe is one failed check each.
    let (total, failed) = harness::ci_report::counts(run);
    let mut unloaded = if run.load_errors.is_empty() {
        String::new()
    } else {
        format!(", {} scene(s) did not load", run.load_errors.len())
    };
    let missing = run.backends.iter().filter(|b| b.missing()).count();
    if missing > 0 {
        unloaded.push_str(&format!(", {missing} backend(s) asked for are unavailable"));
    }
    // Untimed speed checks pass (unless slower beyond even their wide limit): the summary says
    // how many, so that a run whose speed checks time little does not read as covered; counted
    // as the coverage below counts them, failed or not.
    let untimed = run.speed.checks.iter().filter(|c| c.untimed()).count();
    let untimed = match untimed {
        0 => String::new(),
        n => format!(", {n} untimed"),
    };
    println!(
        "{total} checks ({} of speed{untimed}), {failed} failed{unloaded}; report: {}",
        run.speed.checks.len(),
        report.display()
    );
    if failed > 0 {
        print_advice(run, report, failures);
    }
}

/// After a failing run: where its images are, and what to do (the bless commands, the accept,
/// or that nothing is to be blessed).
fn print_advice(run: &CheckRun, report: &Path, failures: &str) {
    if run.results.iter().any(|r| !r.outcome.passed()) {
        println!("failure images: {failures}");
    }
    // A debug check's slower passes are the setting's own: a golden taken from them would
    // hold the generic variant's cost, which no normal render has, and leave the lighting
    // passes unable to fail (the accept refuses them too). What else failed is advised on.
    let debug_slower = |c: &harness::golden::speed::SpeedCheck| run.speed.is_debug_slowdown(c);
    if run.speed.checks.iter().any(debug_slower) {
        println!(
            "the slower passes are --debug-unspecialised-lighting's own: the renderer is \
             unchanged and `check` without the setting passes them, so there is nothing to \
             bless or accept. A deliberate slowdown of your own is blessed after a check \
             without it (`harness bless --scene S --speed-only --reason \"why\"`)"
        );
        let others = run.results.iter().any(|r| !r.outcome.passed())
            || !run.speed.errors.is_empty()
            || run
                .speed
                .checks
                .iter()
                .any(|c| c.failed() && !debug_slower(c));
        if !others {
            return;
        }
    }
    let commands = run.bless_commands();
    // Slower passes whose timing goldens a bless from here writes: the check's own figures
    // can be accepted as they are, as its kept images can.
    let acceptable_timings = !run.speed.unspecialised_lighting
        && run
            .speed
            .checks
            .iter()
            .any(|c| c.outcome == SpeedOutcome::Slower && c.bless_writes_here());
    if commands.is_empty() && run.verifications.is_empty() && !acceptable_timings {
        // Only what no bless fixes failed: a scene that did not load, a backend asked for
        // and missing, a render or probe that failed (each said above).
        println!(
            "nothing here for a bless to take: fix what failed above (a scene that did not \
             load, a backend asked for and unavailable, a render or speed probe that failed)"
        );
        return;
    }
    let kept = match (run.verifications.is_empty(), acceptable_timings) {
        (true, false) => String::new(),
        (false, false) => "; or accept what this check kept, as above".to_owned(),
        // The accept takes the kept images and the measured timings both, unless told one.
        (true, true) => format!(
            "; or accept the timings this check measured, probing nothing again: `{} \
             --speed-only`",
            accept_command(report.parent().unwrap_or(report))
        ),
        (false, true) => format!(
            "; or accept what it kept and the timings it measured, rendering and probing \
             nothing again: `{}`",
            accept_command(report.parent().unwrap_or(report))
        ),
    };
    println!(
        "after reviewing the report, bless what changed on purpose (one command per \
         scene; it renders again and rewrites only the passes outside tolerance or without \
         a golden; add --reason \"why\" to record why{kept}).{}",
        harness::golden::command_line::moves_timings_note(&commands)
    );
    for command in commands {
        println!("  {command}");
    }
}

/// `bless --from-last-check` for a check that wrote to `out`, naming the folder unless it is
/// the default.
fn accept_command(out: &Path) -> String {
    harness::golden::command_line::accept_command(Some(out).filter(|dir| *dir != default_out_dir()))
}

/// Why the failing passes failed: per failing output where the change starts (or which
/// output it moved with), how the backends moved, and the advice, once per scene and output.
fn print_diagnoses(run: &CheckRun) {
    if run.diagnoses.is_empty() {
        return;
    }
    use harness::golden::diagnosis::Role;
    println!("\nwhy: where each change starts, and what to do");
    let mut seen: Vec<(&str, engine::plan::TargetId)> = Vec::new();
    let mut scenes: Vec<&str> = Vec::new();
    for d in &run.diagnoses {
        if seen.contains(&(d.scene.as_str(), d.pass)) {
            continue;
        }
        if !scenes.contains(&d.scene.as_str()) {
            scenes.push(&d.scene);
            print_load_warnings_of(run, &d.scene);
        }
        // A scene without goldens: one line for all its outputs, not a bless command each.
        let mut uncompared: Vec<engine::plan::TargetId> = Vec::new();
        if d.role == Role::NoComparison {
            for o in run.diagnoses.iter().filter(|o| o.scene == d.scene) {
                let new =
                    !seen.contains(&(d.scene.as_str(), o.pass)) && !uncompared.contains(&o.pass);
                if o.role == Role::NoComparison && new {
                    uncompared.push(o.pass);
                }
            }
        }
        if uncompared.len() > 1 {
            let folder = run
                .results
                .iter()
                .find(|r| r.scene == d.scene && r.pass == d.pass && r.backend == d.backend)
                .and_then(|r| r.artifacts.actual.as_deref()?.parent());
            println!(
                "  {}: nothing to compare with for {} outputs ({}); look at them{}; bless them \
                 if they are right: `{}`",
                d.scene,
                uncompared.len(),
                harness::names(&uncompared),
                folder.map_or(String::new(), |f| format!(" in {}", f.display())),
                harness::golden::command_line::bless_command(run.scene_argument(&d.scene))
            );
            seen.extend(uncompared.iter().map(|&p| (d.scene.as_str(), p)));
            continue;
        }
        seen.push((d.scene.as_str(), d.pass));
        println!("  {}/{}: {}; {}", d.scene, d.pass, d.headline(), d.advice);
    }
}

/// The most load warnings quoted under a failing scene.
const WARNINGS_QUOTED: usize = 5;

/// Under a failing scene that loaded with warnings, the warnings (the first
/// [`WARNINGS_QUOTED`]): a material library, material or map the scene lost changes its
/// picture, which a bless would make the golden, so they are read before blessing.
fn print_load_warnings_of(run: &CheckRun, scene: &str) {
    let Some(inputs) = run.inputs.iter().find(|i| i.scene == scene) else {
        return;
    };
    let warnings = &inputs.warnings;
    if warnings.is_empty() {
        return;
    }
    println!(
        "  {scene}: loaded with {} warning(s); one about a lost material library, material or \
         map, or data read differently, is a change to fix before blessing:",
        warnings.len()
    );
    for warning in warnings.iter().take(WARNINGS_QUOTED) {
        println!("    {warning}");
    }
    if warnings.len() > WARNINGS_QUOTED {
        println!(
            "    and {} more (`harness inspect` lists them)",
            warnings.len() - WARNINGS_QUOTED
        );
    }
}

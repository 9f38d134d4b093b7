//! `harness bless`'s timing part: probing the backends and rewriting the timing goldens that
//! moved (or the passes `--pass` names), through [`harness::golden::speed::bless_scenes`].

use engine::backend::BackendKind;
use engine::plan::PassId;

use super::bless::Options;

/// Probes every available backend (or the one asked for) and rewrites the timing goldens that
/// moved, or the `passes` named; returns how many it refused: scenes' backends kept whole as
/// another host's, and passes asked for that could not be written.
pub(super) fn bless_speed(
    cases: &[harness::golden::suite::Case],
    store: &harness::golden::GoldenStore,
    passes: &[PassId],
    options: &Options,
) -> anyhow::Result<usize> {
    let backends: Vec<(BackendKind, String)> = BackendKind::ALL
        .into_iter()
        .filter(|kind| options.speed_backend.is_none_or(|only| only == *kind))
        .filter_map(|kind| {
            let status = engine::backend::probe(kind);
            match (status.available, status.info) {
                (true, Some(info)) => Some((kind, harness::golden::fingerprint(&info))),
                _ => {
                    eprintln!("note: no timing goldens for {kind}: it is unavailable here");
                    None
                }
            }
        })
        .collect();
    let scenes: Vec<(String, String)> = cases
        .iter()
        .map(|c| (c.name().to_owned(), c.argument()))
        .collect();
    let lines = harness::golden::speed::bless_scenes(
        &std::env::current_exe()?,
        store.root(),
        &scenes,
        &backends,
        harness::golden::speed::TimingBless {
            every_pass: options.every_pass,
            // Another host's timing goldens move here only when timings alone were asked for.
            move_here: options.every_pass && !options.images,
            dry_run: options.dry_run,
            reason: options.reason.as_deref(),
            passes,
        },
        |what| eprintln!("{what} ..."),
    )?;
    for line in lines
        .iter()
        .filter(|l| l.fate != harness::golden::speed::bless::Fate::KeptAsAnotherHosts)
    {
        println!("{line}");
    }
    for line in harness::golden::speed::bless::another_hosts_lines(&lines, &scenes) {
        println!("{line}");
    }
    // Goldens moved here whose same-host figures this host has not measured (where it has,
    // from an earlier move, its checks read them at its own limits at once).
    let model = harness::golden::speed::TimingNoise::load(store.root())?;
    let unmeasured = harness::golden::speed::bless::moved_without_figures_here(
        &lines,
        &model,
        &backends,
        &harness::golden::speed::cpu_signature(),
    );
    if !unmeasured.is_empty() {
        let scenes: String = unmeasured
            .iter()
            .map(|n| format!(" {}", harness::golden::command_line::scene_flag(n)))
            .collect();
        let measure = harness::golden::command_line::harness_command(&format!(
            "noise --timing --write{scenes}"
        ));
        println!(
            "note: {} timing goldens are this host's now, but golden/timing-noise.toml's \
             same-host figures for them were measured on another host (or by a model that did \
             not yet record where), so until this host's are measured its checks read them at \
             the limits for any host. Measure them: `{measure}` (without the second Mesa: \
             `{measure} --source runs --source busy-neighbour`)",
            unmeasured.join(", ")
        );
    }
    let moved: std::collections::BTreeSet<&str> = lines
        .iter()
        .filter(|l| l.moved_here && l.fate.written())
        .map(|l| l.scene.as_str())
        .collect();
    if !moved.is_empty() {
        println!(
            "note: the recordings in golden/evidence/ were taken against the timing goldens of \
             {} that this bless replaced, and no longer apply to them",
            moved.into_iter().collect::<Vec<_>>().join(", ")
        );
    }
    // A scene whose timing goldens are new and that the model has no figures of: its checks
    // borrow every scene's until its own are measured.
    let mut new: Vec<&str> = lines
        .iter()
        .filter(|l| l.fate == harness::golden::speed::bless::Fate::Written)
        .map(|l| l.scene.as_str())
        .filter(|scene| !model.scenes.contains_key(*scene))
        .collect();
    new.sort_unstable();
    new.dedup();
    for scene in new {
        let measure = harness::golden::command_line::harness_command(&format!(
            "noise --timing --write {}",
            harness::golden::command_line::scene_flag(scene)
        ));
        println!(
            "note: {scene}'s timing goldens are new, and golden/timing-noise.toml has no figures \
             of it: its checks borrow every scene's until `{measure}` measures this host's (the \
             figures for other hosts stay at least the borrowed ones). Commit golden/{scene}/ \
             with the scene"
        );
    }
    Ok(lines.iter().filter(|l| l.refused).count())
}

/// The passes `--pass` names for a timing bless: each must have a timing golden (on some
/// backend) in every scene asked for, as `check`'s speed table names it.
pub(super) fn timed_passes(
    cases: &[harness::golden::suite::Case],
    store: &harness::golden::GoldenStore,
    names: &[String],
) -> anyhow::Result<Vec<PassId>> {
    let mut named = Vec::new();
    for case in cases {
        let goldens = harness::golden::speed::TimingGoldens::load(store.root(), case.name())?;
        let timed: std::collections::BTreeSet<PassId> = goldens
            .backends
            .values()
            .flat_map(|b| b.passes.keys().copied())
            .collect();
        for name in names {
            match name.parse::<PassId>().ok().filter(|p| timed.contains(p)) {
                Some(pass) if named.contains(&pass) => {}
                Some(pass) => named.push(pass),
                None => anyhow::bail!(
                    "scene {} has no timing golden of pass `{name}` (it has: {}; image passes, \
                     such as light and final, are timed as the passes that draw them)",
                    case.name(),
                    harness::names(&timed.iter().collect::<Vec<_>>())
                ),
            }
        }
    }
    Ok(named)
}

//! `check --summary FILE`: the run as Markdown for a CI job's page, failing checks first with
//! what to do about them, then a count of what passed per scene.

use std::fmt::Write as _;
use std::path::Path;

use super::{counts, speed_status, Status};
use crate::golden::check::CheckRun;

/// The run as Markdown; `report` is where its review page was written.
pub fn summary(run: &CheckRun, report: &Path) -> String {
    let (total, bad) = counts(run);
    let mut out = String::new();
    let verdict = if run.passed() { "passed" } else { "FAILED" };
    let _ = writeln!(out, "## Render check {verdict}\n");
    let _ = writeln!(
        out,
        "{bad} of {total} checks failed ({} image, {} speed); review page: `{}`\n",
        run.results.len(),
        run.speed.checks.len(),
        report.display()
    );
    let mut failing: Vec<[String; 5]> = Vec::new();
    for b in run.backends.iter().filter(|b| b.missing()) {
        let why = format!(
            "asked for (`--backend`) but unavailable: {}",
            b.unavailable.as_deref().unwrap_or_default()
        );
        failing.push(row("-", "-", b.backend.name(), "UNAVAILABLE", &why));
    }
    for b in &run.load_errors {
        failing.push(row(&b.scene, "-", "-", "LOAD", &b.error));
    }
    for (scene, backend, error) in &run.render_errors {
        failing.push(row(scene, "-", backend.name(), "RENDER", error));
    }
    for r in run.results.iter().filter(|r| !r.outcome.passed()) {
        let details =
            match crate::golden::diagnosis::find(&run.diagnoses, &r.scene, r.pass, r.backend) {
                Some(d) => format!("**{}**: {}. {}", d.headline(), d.advice, r.worst()),
                None => r.worst(),
            };
        failing.push(row(
            &r.scene,
            &r.pass.to_string(),
            r.backend.name(),
            r.outcome.label(),
            &details,
        ));
    }
    for c in run
        .speed
        .checks
        .iter()
        .filter(|c| speed_status(c) == Status::Failed)
    {
        let label = c.outcome.label();
        let pass = format!("speed {}", c.pass);
        failing.push(row(
            &c.scene,
            &pass,
            c.backend.name(),
            label,
            &c.measurement(),
        ));
    }
    for e in &run.speed.errors {
        failing.push(row("-", "speed probe", "-", "ERROR", e));
    }
    if !failing.is_empty() {
        let _ = writeln!(out, "### Failing\n");
        table(
            &mut out,
            &["scene", "pass", "backend", "result", "details"],
            &failing,
        );
        let commands = run.bless_commands();
        if !commands.is_empty() {
            let _ = writeln!(
                out,
                "\nAfter reviewing the page, bless what changed on purpose (each command \
                 rewrites only its scene's passes outside tolerance or without a golden).{}\n\n```sh",
                crate::golden::command_line::moves_timings_note(&commands)
            );
            for command in commands {
                let _ = writeln!(out, "{command}");
            }
            let _ = writeln!(out, "```");
        }
    }
    if !run.orphans.is_empty() {
        let _ = writeln!(
            out,
            "\n### Orphans in golden/\n\nNothing produces or records these any more \
             (`harness bless --prune --dry-run` lists what it would remove):\n"
        );
        for orphan in &run.orphans {
            let _ = writeln!(out, "- {}", cell(&orphan.to_string()));
        }
    }
    not_checked(&mut out, run);
    speed_coverage(&mut out, run);
    passing(&mut out, run);
    out
}

/// The backends this machine lacks that the check was not asked for by name: nothing of
/// theirs was checked, which a green run must not hide.
fn not_checked(out: &mut String, run: &CheckRun) {
    let absent: Vec<_> = run
        .backends
        .iter()
        .filter(|b| b.unavailable.is_some() && !b.required)
        .collect();
    if absent.is_empty() {
        return;
    }
    let _ = writeln!(
        out,
        "\n### Not checked\n\nUnavailable on this machine (name a backend with `--backend` to \
         make its absence fail the check):\n"
    );
    for b in absent {
        let _ = writeln!(
            out,
            "- `{}`: {}",
            b.backend.name(),
            cell(b.unavailable.as_deref().unwrap_or_default())
        );
    }
}

/// What the speed checks can catch on the host that ran them, per backend, and what to do
/// where the host neither blessed nor is recorded.
fn speed_coverage(out: &mut String, run: &CheckRun) {
    let coverage = crate::golden::speed::coverage(&run.speed.checks);
    if coverage.is_empty() {
        return;
    }
    let _ = writeln!(out, "\n### What the speed checks catch on this host\n");
    for c in &coverage {
        let _ = writeln!(out, "- `{}`: {}", c.backend.name(), cell(&c.describe()));
    }
    if let Some(advice) =
        crate::golden::speed::verdict::record_advice(&coverage, &run.speed.recorded_as)
    {
        let _ = writeln!(out, "\nNote: {advice}.");
    }
    for note in &run.speed.host_notes {
        let _ = writeln!(out, "\nNote: {}.", cell(note));
    }
}

/// A table row, each cell made safe for a Markdown table.
fn row(scene: &str, pass: &str, backend: &str, result: &str, details: &str) -> [String; 5] {
    [scene, pass, backend, result, details].map(cell)
}

/// `text` on one line, its pipes escaped.
fn cell(text: &str) -> String {
    text.replace('\n', " ").replace('|', "\\|")
}

/// A Markdown table.
fn table<const N: usize>(out: &mut String, header: &[&str; N], rows: &[[String; N]]) {
    let _ = writeln!(out, "| {} |", header.join(" | "));
    let _ = writeln!(out, "|{}", "---|".repeat(N));
    for r in rows {
        let _ = writeln!(out, "| {} |", r.join(" | "));
    }
}

/// Per scene, how many image and speed checks passed (untimed passes counted apart), folded.
fn passing(out: &mut String, run: &CheckRun) {
    let mut scenes: Vec<&str> = Vec::new();
    for scene in run
        .results
        .iter()
        .map(|r| r.scene.as_str())
        .chain(run.speed.checks.iter().map(|c| c.scene.as_str()))
    {
        if !scenes.contains(&scene) {
            scenes.push(scene);
        }
    }
    let rows: Vec<[String; 4]> = scenes
        .iter()
        .map(|scene| {
            let images = run.results.iter().filter(|r| r.scene == *scene);
            let speed = run.speed.checks.iter().filter(|c| c.scene == *scene);
            let passed = images.clone().filter(|r| r.outcome.passed()).count();
            let timed_passed = speed
                .clone()
                .filter(|c| speed_status(c) == Status::Passed)
                .count();
            let untimed = speed
                .clone()
                .filter(|c| speed_status(c) == Status::Skipped)
                .count();
            [
                (*scene).to_owned(),
                format!("{passed} of {}", images.count()),
                format!("{timed_passed} of {}", speed.count()),
                untimed.to_string(),
            ]
        })
        .collect();
    let _ = writeln!(out, "\n<details><summary>Passed, per scene</summary>\n");
    table(
        out,
        &["scene", "image checks", "speed checks", "untimed"],
        &rows,
    );
    let _ = writeln!(out, "\n</details>");
}

//! The HTML review page of a check run: one self-contained file built for finding what changed.
//!
//! - A summary table, failing checks first, each row linking to its case, with a failures-only
//!   filter and, per failing scene, the bless command ready to copy.
//! - Per failing pass: the golden and each backend's output at full resolution, embedded as
//!   zlib-compressed exact pixel data (8-bit, fp16 or fp32) that `review.js` draws side by side,
//!   as a swipe or a flicker, zoomable, with an exposure control for float passes, a
//!   false-colour difference in units of the pass's tolerance threshold, and a pixel inspector.
//! - Passing passes as small PNG thumbnails of the golden, so that the canonical run's page stays
//!   small (a few MB).
//! - Driver fingerprints, the cross-backend table, GPU time per pass, and the latest benchmark,
//!   sweep and hard-case results.
//!
//! The parts: `cases.rs` writes the failing passes' viewers and the passing passes' thumbnails,
//! `tables.rs` the summary and the backend tables, `pixels.rs` the embedded pixel data, and
//! `thumbnails.rs` the small PNG previews.

use engine::plan::TargetId;
use std::fmt::Write as _;
use std::path::Path;

use crate::golden::check::{CheckRun, Outputs};
use crate::golden::{GoldenStore, Outcome};
use crate::html::escape;

mod cases;
mod pixels;
mod tables;
mod thumbnails;

pub use thumbnails::preview;

use cases::cases;
use pixels::Blobs;
use tables::{details, summary};

/// The page's style sheet.
const STYLE: &str = include_str!("review.css");

/// The viewers, filter and copy buttons.
const SCRIPT: &str = include_str!("review.js");

/// A part of the review page contributed by something other than the golden check (the
/// benchmarks, the sweeps, the hard cases): HTML made from the results it kept in the page's
/// folder, empty when it kept none. The report knows nothing else of what made them.
pub trait Section {
    /// The section's HTML from the results kept in `dir`.
    fn html(&self, dir: &Path) -> String;
}

/// The anchor of a scene's pass on the page.
fn case_id(scene: &str, pass: TargetId) -> String {
    let clean = |s: &str| {
        s.chars()
            .map(|c| if c.is_ascii_alphanumeric() { c } else { '-' })
            .collect::<String>()
    };
    format!("case-{}-{}", clean(scene), clean(&pass.to_string()))
}

/// The checks of a result as text, worst first, with the largest difference.
fn metrics_text(outcome: &Outcome) -> String {
    match outcome {
        Outcome::Passed(v) | Outcome::Failed(v) => {
            let mut checks: Vec<_> = v.checks.iter().collect();
            checks.sort_by(|a, b| b.ratio().total_cmp(&a.ratio()));
            let mut lines: Vec<String> = checks.iter().map(ToString::to_string).collect();
            if v.non_finite > 0 {
                lines.insert(0, format!("{} NaN/Inf values in the output", v.non_finite));
            }
            if let Some(largest) = &v.largest_difference {
                lines.push(largest.to_string());
            }
            lines.join("\n")
        }
        Outcome::MissingGolden => "no golden yet".to_owned(),
        Outcome::Incomparable(why) => why.clone(),
    }
}

/// The result of a check as a word ([`Outcome::label`]).
fn result_label(outcome: &Outcome) -> &'static str {
    outcome.label()
}

/// A command as code, with a button that copies it.
fn bless_html(command: &str) -> String {
    format!(
        "<code>{}</code> <button type=\"button\" class=\"copy\" data-copy=\"{}\">copy</button>",
        escape(command),
        escape(command)
    )
}

/// Writes the report as one HTML string.
///
/// `page_dir` is where the page will be written (failure images under it are linked
/// relatively); with it, each of `sections` adds what it kept there (the latest bench results,
/// sweeps and hard cases: [`crate::measure::report_sections`]).
pub fn html(
    run: &CheckRun,
    outputs: &Outputs,
    store: &GoldenStore,
    page_dir: Option<&Path>,
    sections: &[&dyn Section],
) -> String {
    let failed = run.results.iter().filter(|r| !r.outcome.passed()).count();
    let mut out = String::new();
    let _ = write!(
        out,
        "<!doctype html><html><head><meta charset=\"utf-8\"><title>Render check: {}</title>\
         <style>{STYLE}</style></head><body>",
        if run.passed() { "passed" } else { "FAILED" }
    );
    let _ = write!(
        out,
        "<h1>Render check: {}</h1><p>{} checks, {} failed, {} render errors, {} scenes that did \
         not load; {} speed checks, {} failed.</p><div class=\"controls\"><label><input type=\"checkbox\" \
         id=\"failures-only\"> show failures only</label> · <a href=\"#summary\">summary</a> · \
         <a href=\"#failing\">failing passes</a> · <a href=\"#passing\">passing passes</a> · \
         <a href=\"#speed\">speed</a> · <a href=\"#backends\">backends</a></div>",
        if run.passed() {
            "<span class=\"pass\">passed</span>"
        } else {
            "<span class=\"fail\">FAILED</span>"
        },
        run.results.len(),
        failed,
        run.render_errors.len(),
        run.load_errors.len(),
        run.speed.checks.len(),
        run.speed.checks.iter().filter(|c| c.failed()).count() + run.speed.errors.len()
    );
    for broken in &run.load_errors {
        let _ = write!(
            out,
            "<p class=\"failed\">scene {} did not load: {}</p>",
            escape(&broken.scene),
            escape(&broken.error)
        );
    }
    for (scene, backend, error) in &run.render_errors {
        let _ = write!(
            out,
            "<p class=\"failed\">render of {} on {} failed: {}</p>",
            escape(scene),
            backend,
            escape(error)
        );
    }
    for b in &run.backends {
        let Some(reason) = &b.unavailable else {
            continue;
        };
        let (class, what) = if b.required {
            ("failed", "was asked for but is unavailable")
        } else {
            ("note", "is unavailable here, so nothing was checked on it")
        };
        let _ = write!(
            out,
            "<p class=\"{class}\">{} {what}: {}</p>",
            b.backend,
            escape(reason)
        );
    }
    // A failing speed check is as much a failure as a changed pixel: named here, above the
    // image tables, with a link to its row.
    for c in run.speed.checks.iter().filter(|c| c.failed()) {
        let _ = write!(
            out,
            "<p class=\"failed\"><a href=\"#speed\">speed</a> of {}/{} on {}: {}</p>",
            escape(&c.scene),
            c.pass,
            c.backend,
            escape(&c.describe())
        );
    }
    for e in &run.speed.errors {
        let _ = write!(
            out,
            "<p class=\"failed\">speed probe failed: {}</p>",
            escape(e)
        );
    }
    let commands = run.bless_commands();
    if !commands.is_empty() {
        let _ = write!(
            out,
            "<p>After reviewing, bless what changed on purpose (each command rewrites only its \
             scene's passes outside tolerance or without a golden).{}</p><ul>",
            escape(crate::golden::command_line::moves_timings_note(&commands))
        );
        for command in &commands {
            let _ = write!(out, "<li>{}</li>", bless_html(command));
        }
        out.push_str("</ul>");
    }
    summary(&mut out, run);
    let mut blobs = Blobs::default();
    cases(&mut out, run, outputs, store, page_dir, &mut blobs);
    tables::speed(&mut out, run);
    details(&mut out, run);
    if let Some(dir) = page_dir {
        for section in sections {
            out.push_str(&section.html(dir));
        }
    }
    out.push_str(&blobs.html());
    let _ = writeln!(out, "<script>{SCRIPT}</script></body></html>");
    out
}

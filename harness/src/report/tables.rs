//! The page's tables: the summary of every check (failing first), the speed checks, and the
//! backends, their cross-backend agreement and GPU times per pass.

use std::fmt::Write as _;

use super::{case_id, metrics_text, result_label};
use crate::golden::check::CheckRun;
use crate::golden::speed::verdict::noise_words;
use crate::html::escape;

/// The summary table: failing checks first, each row linking to its case.
pub(super) fn summary(out: &mut String, run: &CheckRun) {
    out.push_str(
        "<h2 id=\"summary\">Summary</h2><table class=\"summary\"><tr><th>scene</th><th>pass</th>\
         <th>backend</th><th>result</th><th>checks (worst first) and largest difference</th>\
         </tr>",
    );
    let mut rows: Vec<_> = run.results.iter().collect();
    rows.sort_by_key(|r| r.outcome.passed());
    for r in rows {
        let class = if r.outcome.passed() {
            "passed"
        } else {
            "failed"
        };
        // A failing check's verdict first: where the change starts and what to do.
        let verdict = crate::golden::diagnosis::find(&run.diagnoses, &r.scene, r.pass, r.backend)
            .map(|d| {
                format!(
                    "<div class=\"verdict\"><b>{}</b>: {}</div>",
                    escape(&d.headline()),
                    escape(&d.advice)
                )
            })
            .unwrap_or_default();
        let _ = write!(
            out,
            "<tr class=\"{class}\" data-scene=\"{}\" data-pass=\"{}\" data-backend=\"{}\"><td>{}</td>\
             <td><a href=\"#{}\">{}</a></td><td>{}</td><td class=\"result\">{}</td><td>{verdict}<code>{}</code></td></tr>",
            escape(&r.scene),
            r.pass,
            r.backend,
            escape(&r.scene),
            case_id(&r.scene, r.pass),
            r.pass,
            r.backend,
            result_label(&r.outcome),
            escape(&metrics_text(&r.outcome)).replace('\n', "<br>")
        );
    }
    out.push_str("</table>");
    for v in &run.verifications {
        let class = if v.verified() {
            "verified"
        } else {
            "not-verified"
        };
        let _ = write!(
            out,
            "<p class=\"{class}\" data-scene=\"{}\">{}</p>",
            escape(&v.scene),
            escape(&v.summary())
        );
    }
}

/// Backends, cross-backend agreement and GPU times.
pub(super) fn details(out: &mut String, run: &CheckRun) {
    out.push_str(
        "<h2 id=\"backends\">Backends</h2><table><tr><th>backend</th><th>driver fingerprint</th>\
         </tr>",
    );
    for b in &run.backends {
        let _ = write!(
            out,
            "<tr><td>{}</td><td>{}</td></tr>",
            b.backend,
            escape(
                b.fingerprint
                    .as_deref()
                    .or(b.unavailable.as_deref())
                    .unwrap_or("")
            )
        );
    }
    out.push_str("</table>");
    for note in &run.driver_notes {
        let _ = write!(out, "<p class=\"note\">Note: {}</p>", escape(note));
    }
    out.push_str(
        "<h2>Cross-backend agreement (largest disagreement per pass)</h2><table><tr>\
         <th>scene</th><th>pass</th><th>backends</th><th>max abs</th><th>fraction over</th>\
         <th>within tolerance</th></tr>",
    );
    for c in &run.cross {
        let _ = write!(
            out,
            "<tr class=\"{}\"><td>{}</td><td>{}</td><td>{} vs {}</td><td>{:.3e}</td><td>{:.3e}</td><td>{}</td></tr>",
            if c.within_tolerance { "passed" } else { "failed" },
            escape(&c.scene),
            c.pass,
            c.a,
            c.b,
            c.max_abs,
            c.fraction_over,
            if c.within_tolerance { "yes" } else { "NO" }
        );
    }
    out.push_str("</table>");
    out.push_str(
        "<h2>GPU time per pass (ms)</h2><p>Of the check's image renders: each is a fresh \
         backend's first frame, so the drivers' shader compiles are in it. The speed table's ms \
         are each pass's fastest of many submissions after a warm-up, what the speed checks \
         compare.</p><table><tr><th>scene</th><th>backend</th><th>pass</th><th>ms</th></tr>",
    );
    for t in &run.timings {
        let _ = write!(
            out,
            "<tr><td>{}</td><td>{}</td><td>{}</td><td>{}</td></tr>",
            escape(&t.scene),
            t.backend,
            t.pass,
            t.ms.map_or("-".to_owned(), |ms| format!("{ms:.3}"))
        );
    }
    out.push_str("</table>");
}

/// The speed checks: one row per scene, backend and pass, failing first, with the slowdown
/// against the golden, the limit and the value as a fraction of it, or why it is untimed.
pub(super) fn speed(out: &mut String, run: &CheckRun) {
    use crate::golden::speed::SpeedOutcome;
    if run.speed.checks.is_empty() && run.speed.errors.is_empty() {
        return;
    }
    // A timing bless writes on the host that blessed the goldens, or scaled from a recorded
    // one; elsewhere the command that moves them here is the one to offer.
    let elsewhere = run.speed.checks.iter().any(|c| !c.bless_writes_here());
    let bless = if elsewhere {
        "bless it with <code>harness bless --scene S --speed-only</code> if intended; where a \
         pass was read at the limits for any host, this host neither blessed its timing golden \
         nor holds a current recording of it: record it (<code>harness noise --timing \
         --record-host NAME</code>) first, or move the goldens here, every pass, with \
         <code>--speed-only --every-pass</code>"
    } else {
        "bless it with <code>harness bless --scene S --speed-only</code> if intended"
    };
    let _ = write!(
        out,
        "<h2 id=\"speed\">Speed</h2><p>Each pass submitted alone, its fastest time over its \
         floor's, against its timing golden (<code>golden/&lt;scene&gt;/timing.toml</code>; \
         limits from <code>golden/timing-noise.toml</code>). A slower pass beyond its limit \
         fails; a faster one is a note: {bless}.</p><table class=\"summary\"><tr><th>scene</th>\
         <th>pass</th><th>backend</th><th>result</th><th>against golden</th><th>limit</th>\
         <th>value / limit</th><th>ms</th><th>detail</th></tr>",
    );
    for e in &run.speed.errors {
        let _ = write!(
            out,
            "<tr class=\"failed\"><td colspan=\"9\">speed probe failed: {}</td></tr>",
            escape(e)
        );
    }
    let mut rows: Vec<_> = run.speed.checks.iter().collect();
    rows.sort_by_key(|c| !c.failed());
    for c in rows {
        let class = if c.failed() { "failed" } else { "passed" };
        let label = c.outcome.label();
        let factor = |v: Option<f64>| v.map_or("-".to_owned(), |v| format!("x{v:.3}"));
        let detail = match &c.outcome {
            SpeedOutcome::Untimed(why) | SpeedOutcome::TargetsChanged(why) => why.clone(),
            _ => c
                .noise
                .as_ref()
                .map(|(n, from)| noise_words(*n, from, c.borrowed))
                .unwrap_or_default(),
        };
        let _ = write!(
            out,
            "<tr class=\"{class}\" data-speed=\"1\" data-scene=\"{}\" data-pass=\"{}\" \
             data-backend=\"{}\"><td>{}</td><td>{}</td><td>{}</td><td class=\"result\">{label}</td>\
             <td>{}</td><td>{}</td><td>{}</td><td>{:.2}</td><td>{}</td></tr>",
            escape(&c.scene),
            c.pass,
            c.backend,
            escape(&c.scene),
            c.pass,
            c.backend,
            factor(c.slowdown()),
            factor(c.limit),
            c.score().map_or("-".to_owned(), |s| format!("{s:.2}")),
            c.ms,
            escape(&detail)
        );
    }
    out.push_str("</table>");
    let coverage = crate::golden::speed::coverage(&run.speed.checks);
    if !coverage.is_empty() {
        out.push_str("<p>What the speed checks catch on this host:</p><ul>");
        for c in &coverage {
            let _ = write!(out, "<li>{}: {}</li>", c.backend, escape(&c.describe()));
        }
        out.push_str("</ul>");
    }
    if let Some(advice) =
        crate::golden::speed::verdict::record_advice(&coverage, &run.speed.recorded_as)
    {
        let _ = write!(out, "<p class=\"note\">Note: {}.</p>", escape(&advice));
    }
    for note in &run.speed.host_notes {
        let _ = write!(out, "<p class=\"note\">Note: {}.</p>", escape(note));
    }
}

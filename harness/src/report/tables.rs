//! The page's tables: the summary of every check (failing first), and the backends, their
//! cross-backend agreement and GPU times per pass.

use std::fmt::Write as _;

use super::{case_id, metrics_text, result_label};
use crate::golden::check::CheckRun;
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
        let _ = write!(
            out,
            "<tr class=\"{class}\"><td>{}</td><td><a href=\"#{}\">{}</a></td><td>{}</td>\
             <td>{}</td><td><code>{}</code></td></tr>",
            escape(&r.scene),
            case_id(&r.scene, r.pass),
            r.pass,
            r.backend,
            result_label(&r.outcome),
            escape(&metrics_text(&r.outcome)).replace('\n', "<br>")
        );
    }
    out.push_str("</table>");
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
        "<h2>GPU time per pass (ms)</h2><table><tr><th>scene</th><th>backend</th><th>pass</th>\
         <th>ms</th></tr>",
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

//! The text tables of the sweeps: with times for `harness sweep`, and without times, rounded,
//! for the insta snapshots; and the IBL accuracy goal the IBL tables end with.

use super::{GbufferSweepRow, IblSweepRow, SweepRow};

/// The sweep as a table.
pub fn table(rows: &[SweepRow]) -> String {
    let mut out = format!(
        "{:<13} {:>6} {:>7} {:>11} {:>13} {:>14} {:>24}  {}\n",
        "filter",
        "map",
        "fetches",
        "shadow ms",
        "lighting ms",
        "misclassified",
        "vs soft ref mean/p99/max",
        "front"
    );
    let ms = |v: Option<f64>| v.map_or("-".to_owned(), |v| format!("{v:.2}"));
    for r in rows {
        out.push_str(&format!(
            "{:<13} {:>6} {:>7} {:>11} {:>13} {:>13.3}% {:>24}  {}{}\n",
            r.filter,
            r.map_size,
            r.fetches,
            ms(r.shadow_ms),
            ms(r.lighting_ms),
            r.misclassified * 100.0,
            r.error_vs_soft_reference
                .zip(r.soft_reference_p99_max)
                .map_or("-".to_owned(), |(mean, (p99, max))| format!(
                    "{mean:.4}/{p99:.3}/{max:.2}"
                )),
            if r.pareto { "*" } else { "" },
            if r.is_default { " (default)" } else { "" }
        ));
    }
    out.push_str("front: * = on the Pareto front of GPU time (shadow + lighting) against misclassification\n");
    out
}

/// The shadow sweep's errors without times (which vary run to run), rounded so that the text
/// is stable: the insta snapshot of the canonical scenes' sweep.
pub fn stable_table(rows: &[SweepRow]) -> String {
    let mut out = format!(
        "{:<13} {:>6} {:>7} {:>14} {:>12}\n",
        "filter", "map", "fetches", "misclassified", "vs soft ref"
    );
    for r in rows {
        out.push_str(&format!(
            "{:<13} {:>6} {:>7} {:>13.1}% {:>12}{}\n",
            r.filter,
            r.map_size,
            r.fetches,
            r.misclassified * 100.0,
            r.error_vs_soft_reference
                .map_or("-".to_owned(), |e| format!("{e:.3}")),
            if r.is_default { "  (default)" } else { "" }
        ));
    }
    out
}

/// The IBL sweep as a table: one line per setting, the mean relative error per roughness in
/// columns, then the reference's own noise.
pub fn ibl_table(rows: &[IblSweepRow]) -> String {
    let Some(first) = rows.first() else {
        return String::new();
    };
    // The setting column fits the longest name with its Pareto mark.
    let w = rows
        .iter()
        .map(|r| r.setting.len() + 2)
        .max()
        .unwrap_or(0)
        .max(15);
    let mut out = format!(
        "{:<w$} {:>13} {:>12} {:>9}",
        "setting", "precompute s", "lighting ms", "spec MiB"
    );
    for g in &first.by_roughness {
        out.push_str(&format!(" {:>7}", format!("r {:.1}", g.roughness)));
    }
    out.push_str(&format!(" {:>7} {:>7} {:>7}\n", "mean", "p99", "max"));
    for r in rows {
        out.push_str(&format!(
            "{:<w$} {:>13.3} {:>12} {:>9.2}",
            format!("{}{}", r.setting, if r.pareto { " *" } else { "" }),
            r.precompute_s,
            r.lighting_ms.map_or("-".to_owned(), |v| format!("{v:.1}")),
            r.specular_mib
        ));
        for g in &r.by_roughness {
            out.push_str(&format!(" {:>6.2}%", g.mean_relative * 100.0));
        }
        out.push_str(&format!(
            " {:>6.2}% {:>6.1}% {:>6.1}%\n",
            r.mean_relative * 100.0,
            r.p99_max_relative.0 * 100.0,
            r.p99_max_relative.1 * 100.0
        ));
        out.push_str(&format!(
            "{:<w$} {:>13} {:>12} {:>9}",
            "  (median)", "", "", ""
        ));
        for g in &r.by_roughness {
            out.push_str(&format!(" {:>6.2}%", g.median_relative * 100.0));
        }
        out.push('\n');
    }
    out.push_str(&format!(
        "{:<w$} {:>13} {:>12} {:>9}",
        "(ref. noise)", "", "", ""
    ));
    for g in &first.by_roughness {
        out.push_str(&format!(" {:>6.2}%", g.reference_noise * 100.0));
    }
    out.push('\n');
    out.push_str("* = on the Pareto front of precompute time, lighting time and mean error\n");
    for row in family_rows(rows) {
        out.push_str(&format!(
            "\n{}, relative error per material row (mean, p95, then the signed mean: + too bright):\n",
            row.setting
        ));
        for (family, cells) in &row.by_family {
            out.push_str(&format!("{family:<15} {:>13} {:>12}", "", "mean"));
            for cell in cells {
                out.push_str(&format!(" {:>6.2}%", cell.mean * 100.0));
            }
            out.push_str(&format!("\n{:<15} {:>13} {:>12}", "", "", "p95"));
            for cell in cells {
                out.push_str(&format!(" {:>6.2}%", cell.p95 * 100.0));
            }
            out.push_str(&format!("\n{:<15} {:>13} {:>12}", "", "", "bias"));
            for cell in cells {
                out.push_str(&format!(" {:>+6.1}%", cell.bias * 100.0));
            }
            out.push('\n');
        }
    }
    out.push_str(&format!("\n{}\n", ibl_goal_line(rows)));
    out.push_str(&format!("{}\n", ibl_default_goal_line(rows)));
    out
}

/// The bound for a default (issue 39): in every cell at most this mean relative error...
pub const IBL_DEFAULT_MEAN: f64 = 0.25;
/// ...for at most this many times the default setting's lighting time, measured in the same
/// sweep.
pub const IBL_DEFAULT_COST: f64 = 1.5;

/// One line: the settings within [`IBL_DEFAULT_MEAN`] in every cell at most
/// [`IBL_DEFAULT_COST`] times the default row's lighting time (a candidate for the default), or
/// the cheapest within the error bound and the most accurate within the cost bound.
pub fn ibl_default_goal_line(rows: &[IblSweepRow]) -> String {
    let goal = format!(
        "a default's bound: every cell within {:.0}% mean, lighting at most x{} the default's",
        IBL_DEFAULT_MEAN * 100.0,
        IBL_DEFAULT_COST
    );
    let Some(base) = rows
        .iter()
        .find(|r| r.is_default)
        .and_then(|r| r.lighting_ms)
    else {
        return format!("{goal}: no timed default row to compare with");
    };
    let cost = |r: &IblSweepRow| r.lighting_ms.map_or(f64::INFINITY, |ms| ms / base);
    let accurate = |r: &&IblSweepRow| worst_cells(r).0 <= IBL_DEFAULT_MEAN;
    let meeting: Vec<String> = rows
        .iter()
        .filter(|r| accurate(r) && cost(r) <= IBL_DEFAULT_COST)
        .map(|r| format!("{} (x{:.2})", r.setting, cost(r)))
        .collect();
    if !meeting.is_empty() {
        return format!("{goal}: met by {}", meeting.join(", "));
    }
    let cheapest = rows
        .iter()
        .filter(accurate)
        .min_by(|a, b| cost(a).total_cmp(&cost(b)))
        .map_or("none".to_owned(), |r| {
            format!("{} (x{:.2})", r.setting, cost(r))
        });
    let closest = rows
        .iter()
        .filter(|r| cost(r) <= IBL_DEFAULT_COST)
        .min_by(|a, b| worst_cells(a).0.total_cmp(&worst_cells(b).0))
        .map_or("none".to_owned(), |r| {
            format!("{} ({:.1}%)", r.setting, worst_cells(r).0 * 100.0)
        });
    format!(
        "{goal}: met by none; cheapest within the error: {cheapest}; most accurate within the cost: {closest}"
    )
}

/// The accuracy goal for IBL against the Monte Carlo reference: in every cell (material row x
/// roughness), at most this mean relative error...
pub const IBL_GOAL_MEAN: f64 = 0.05;
/// ...and at most this 95th-percentile relative error.
pub const IBL_GOAL_P95: f64 = 0.15;

/// A row's worst cell mean and worst cell p95 relative error over every material row and
/// roughness.
pub fn worst_cells(row: &IblSweepRow) -> (f64, f64) {
    row.by_family
        .iter()
        .flat_map(|(_, cells)| cells)
        .fold((0.0f64, 0.0f64), |(mean, p95), c| {
            (mean.max(c.mean), p95.max(c.p95))
        })
}

/// One line: the settings that meet the goal ([`IBL_GOAL_MEAN`], [`IBL_GOAL_P95`] in every
/// cell), or that none does and which comes closest.
pub fn ibl_goal_line(rows: &[IblSweepRow]) -> String {
    let meeting: Vec<&str> = rows
        .iter()
        .filter(|r| {
            let (mean, p95) = worst_cells(r);
            mean <= IBL_GOAL_MEAN && p95 <= IBL_GOAL_P95
        })
        .map(|r| r.setting.as_str())
        .collect();
    let goal = format!(
        "goal: every material row and roughness within {:.0}% mean and {:.0}% p95",
        IBL_GOAL_MEAN * 100.0,
        IBL_GOAL_P95 * 100.0
    );
    if !meeting.is_empty() {
        return format!("{goal}: met by {}", meeting.join(", "));
    }
    let closest = rows.iter().min_by(|a, b| {
        let score = |r: &IblSweepRow| {
            let (mean, p95) = worst_cells(r);
            (mean / IBL_GOAL_MEAN).max(p95 / IBL_GOAL_P95)
        };
        score(a).total_cmp(&score(b))
    });
    match closest {
        Some(r) => {
            let (mean, p95) = worst_cells(r);
            format!(
                "{goal}: met by none; closest {} (worst cell {:.1}% mean, {:.1}% p95)",
                r.setting,
                mean * 100.0,
                p95 * 100.0
            )
        }
        None => format!("{goal}: nothing swept"),
    }
}

/// The rows whose error per material row the tables show: the first (the defaults) and every
/// filtered-importance-sampling setting.
fn family_rows(rows: &[IblSweepRow]) -> impl Iterator<Item = &IblSweepRow> {
    rows.iter()
        .enumerate()
        .filter(|(i, r)| *i == 0 || r.settings.runtime_samples > 0 || r.settings.extract_sun)
        .map(|(_, r)| r)
}

/// The IBL sweep's errors without times, rounded so that the text is stable: the insta
/// snapshot of the canonical scenes' sweep.
pub fn stable_ibl_table(rows: &[IblSweepRow]) -> String {
    let Some(first) = rows.first() else {
        return String::new();
    };
    let mut out = format!("{:<15}", "setting");
    for g in &first.by_roughness {
        out.push_str(&format!(" {:>6}", format!("r {:.1}", g.roughness)));
    }
    out.push_str(&format!(" {:>6}\n", "mean"));
    for r in rows {
        out.push_str(&format!("{:<15}", r.setting));
        for g in &r.by_roughness {
            out.push_str(&format!(" {:>5.1}%", g.mean_relative * 100.0));
        }
        out.push_str(&format!(" {:>5.1}%\n", r.mean_relative * 100.0));
    }
    for row in family_rows(rows) {
        out.push_str(&format!(
            "\n{}, per material row (mean, p95):\n",
            row.setting
        ));
        for (family, cells) in &row.by_family {
            out.push_str(&format!("{family:<15}"));
            for cell in cells {
                out.push_str(&format!(" {:>5.1}%", cell.mean * 100.0));
            }
            out.push_str(&format!("\n{:<15}", ""));
            for cell in cells {
                out.push_str(&format!(" {:>5.1}%", cell.p95 * 100.0));
            }
            out.push('\n');
        }
    }
    out
}

/// The G-buffer sweep as a table.
pub fn gbuffer_table(rows: &[GbufferSweepRow]) -> String {
    let mut out = format!(
        "{:<28} {:>9} {:>14} {:>10} {:>10} {:>10}  {}\n",
        "storage (position/normal)",
        "distance",
        "geom+light ms",
        "mean rel",
        "p99 rel",
        "max rel",
        "front"
    );
    for r in rows {
        out.push_str(&format!(
            "{:<28} {:>9} {:>14} {:>10.2e} {:>10.2e} {:>10.2e}  {}{}\n",
            r.setting,
            r.distance,
            r.gpu_ms.map_or("-".to_owned(), |v| format!("{v:.2}")),
            r.mean_relative,
            r.p99_relative,
            r.max_relative,
            if r.pareto { "*" } else { "" },
            if r.is_default { " (default)" } else { "" }
        ));
    }
    out.push_str("front: * = on the Pareto front of GPU time against p99 error at that distance\n");
    out
}

/// The G-buffer sweep's p99 errors without times, as power-of-ten bands so that the text is
/// stable: the insta snapshot of the canonical scene's sweep.
pub fn stable_gbuffer_table(rows: &[GbufferSweepRow]) -> String {
    let band = |e: f64| {
        if e <= 0.0 {
            "0".to_owned()
        } else {
            format!("1e{}", e.log10().ceil() as i32)
        }
    };
    let mut out = format!(
        "{:<28} {:>9} {:>10}\n",
        "storage (position/normal)", "distance", "p99 <="
    );
    for r in rows {
        out.push_str(&format!(
            "{:<28} {:>9} {:>10}{}\n",
            r.setting,
            r.distance,
            band(r.p99_relative),
            if r.is_default { "  (default)" } else { "" }
        ));
    }
    out
}

//! The review page's sweep section: the result files `harness sweep` keeps in the output
//! folder, read back as a Pareto plot and a table per sweep.

use super::pareto_svg;

/// File name of a sweep's results in the output folder (read by the check report).
pub fn result_file(scene: &str, knob: &str) -> String {
    format!("sweep_{scene}_{knob}.json")
}

/// HTML sections for the check report from the sweeps kept in `dir` (`harness sweep` writes
/// them): per sweep, its table and a Pareto plot of error against cost. Empty without any.
pub fn report_sections(dir: &std::path::Path) -> String {
    let mut files: Vec<std::path::PathBuf> = std::fs::read_dir(dir)
        .into_iter()
        .flatten()
        .flatten()
        .map(|e| e.path())
        .filter(|p| {
            p.file_name()
                .and_then(|n| n.to_str())
                .is_some_and(|n| n.starts_with("sweep_") && n.ends_with(".json"))
        })
        .collect();
    files.sort();
    let mut out = String::new();
    for path in files {
        let Some(bytes) = std::fs::read(&path).ok() else {
            continue;
        };
        let name = path
            .file_stem()
            .and_then(|n| n.to_str())
            .unwrap_or("sweep")
            .to_owned();
        if let Ok(rows) = serde_json::from_slice::<Vec<serde_json::Value>>(&bytes) {
            let is_ibl = rows
                .first()
                .is_some_and(|r| r.get("precompute_s").is_some());
            let is_gbuffer = rows
                .first()
                .is_some_and(|r| r.get("p99_relative").is_some());
            let points: Vec<(String, f64, f64, bool, bool)> = rows
                .iter()
                .map(|r| {
                    let label = if is_gbuffer {
                        format!(
                            "{} at {}",
                            r["setting"].as_str().unwrap_or("?"),
                            r["distance"].as_f64().unwrap_or(0.0)
                        )
                    } else if is_ibl {
                        r["setting"].as_str().unwrap_or("?").to_owned()
                    } else {
                        format!(
                            "{} {}",
                            r["filter"].as_str().unwrap_or("?"),
                            r["map_size"].as_u64().unwrap_or(0)
                        )
                    };
                    let (cost, error) = if is_gbuffer {
                        (
                            r["gpu_ms"].as_f64().unwrap_or(0.0),
                            r["p99_relative"].as_f64().unwrap_or(0.0),
                        )
                    } else if is_ibl {
                        (
                            r["precompute_s"].as_f64().unwrap_or(0.0),
                            r["mean_relative"].as_f64().unwrap_or(0.0),
                        )
                    } else {
                        (
                            r["shadow_ms"].as_f64().unwrap_or(0.0)
                                + r["lighting_ms"].as_f64().unwrap_or(0.0),
                            r["misclassified"].as_f64().unwrap_or(0.0),
                        )
                    };
                    (
                        label,
                        cost,
                        error,
                        r["pareto"].as_bool().unwrap_or(false),
                        r["is_default"].as_bool().unwrap_or(false),
                    )
                })
                .collect();
            // The G-buffer sweep's front is per distance: plot the farthest distance only.
            let farthest = rows
                .iter()
                .filter_map(|r| r["distance"].as_f64())
                .fold(0.0, f64::max);
            let plotted: Vec<(String, f64, f64, bool, bool)> = points
                .iter()
                .zip(&rows)
                .filter(|(_, r)| !is_gbuffer || r["distance"].as_f64() == Some(farthest))
                .map(|(p, _)| p.clone())
                .collect();
            let (x_label, y_label) = if is_gbuffer {
                (
                    "geometry + lighting GPU ms",
                    "p99 relative error of the light buffer",
                )
            } else if is_ibl {
                ("precompute s", "mean relative error")
            } else {
                ("shadow + lighting GPU ms", "misclassified fraction")
            };
            out.push_str(&format!(
                "<h2>Speed against error: <code>{name}</code> (latest <code>harness sweep</code>)</h2>\
                 <p>{y_label} against {x_label}; green: Pareto front, ringed: the default.</p>{}<table>\
                 <tr><th>setting</th><th>{x_label}</th><th>{y_label}</th><th>front</th></tr>",
                pareto_svg(
                    &if is_gbuffer {
                        format!("{name} at distance {farthest}")
                    } else {
                        name.clone()
                    },
                    x_label,
                    y_label,
                    &plotted
                )
            ));
            for (label, cost, error, front, default) in &points {
                out.push_str(&format!(
                    "<tr><td>{label}{}</td><td>{cost:.3}</td><td>{error:.4}</td><td>{}</td></tr>",
                    if *default { " (default)" } else { "" },
                    if *front { "*" } else { "" }
                ));
            }
            out.push_str("</table>");
        }
    }
    out
}

//! The review page's bench section: the result files `harness bench` keeps in the output
//! folder, read back as a table of pass times against floors and SVG plots of the series.

use super::SeriesPoint;

/// File name of `harness bench`'s results in the output folder (read by the check report).
pub const BENCH_JSON: &str = "bench.json";
/// File name of `harness bench --series`'s results in the output folder.
pub const SERIES_JSON: &str = "bench_series.json";

/// A small SVG line chart of a series' pass time against its value (log2 x axis).
pub fn series_svg(points: &[SeriesPoint]) -> String {
    let (w, h, left, bottom, top, right) = (380.0, 200.0, 50.0, 30.0, 20.0, 35.0);
    let data: Vec<(f64, f64)> = points
        .iter()
        .filter_map(|p| p.pass_ms.map(|ms| ((p.value.max(1) as f64).log2(), ms)))
        .collect();
    let Some(first) = points.first() else {
        return String::new();
    };
    let mut svg = format!(
        "<svg xmlns=\"http://www.w3.org/2000/svg\" width=\"{w}\" height=\"{h}\" \
         style=\"background:#fff;border:1px solid #ccc\">\
         <text x=\"{left}\" y=\"14\" font-size=\"12\">{} ms against {}</text>",
        crate::html::escape(&first.pass.to_string()),
        crate::html::escape(first.series.name())
    );
    if data.is_empty() {
        svg.push_str("<text x=\"60\" y=\"100\" font-size=\"12\">no timestamps</text></svg>");
        return svg;
    }
    let (x0, x1) = data.iter().fold((f64::MAX, f64::MIN), |(a, b), (x, _)| {
        (a.min(*x), b.max(*x))
    });
    let y1 = data.iter().map(|(_, y)| *y).fold(0.0, f64::max).max(1e-9);
    let sx = |x: f64| left + (x - x0) / (x1 - x0).max(1e-9) * (w - left - right);
    let sy = |y: f64| h - bottom - y / y1 * (h - bottom - top);
    svg.push_str(&format!(
        "<line x1=\"{left}\" y1=\"{0}\" x2=\"{1}\" y2=\"{0}\" stroke=\"#888\"/>\
         <line x1=\"{left}\" y1=\"{top}\" x2=\"{left}\" y2=\"{0}\" stroke=\"#888\"/>\
         <text x=\"4\" y=\"{2}\" font-size=\"10\">{y1:.1}</text>\
         <text x=\"4\" y=\"{0}\" font-size=\"10\">0</text>",
        h - bottom,
        w - right,
        top + 4.0
    ));
    let line: Vec<String> = data
        .iter()
        .map(|(x, y)| format!("{:.1},{:.1}", sx(*x), sy(*y)))
        .collect();
    svg.push_str(&format!(
        "<polyline fill=\"none\" stroke=\"#2a6\" stroke-width=\"2\" points=\"{}\"/>",
        line.join(" ")
    ));
    for (p, (x, y)) in points.iter().filter(|p| p.pass_ms.is_some()).zip(&data) {
        svg.push_str(&format!(
            "<circle cx=\"{:.1}\" cy=\"{:.1}\" r=\"3\" fill=\"#2a6\"/>\
             <text x=\"{:.1}\" y=\"{}\" font-size=\"10\" text-anchor=\"middle\">{}</text>",
            sx(*x),
            sy(*y),
            sx(*x),
            h - bottom + 14.0,
            p.value
        ));
    }
    svg.push_str("</svg>");
    svg
}

/// HTML sections for the check report from the latest `harness bench` results in `dir`
/// (per-pass times against floors, scaling series plots); empty when there are none.
pub fn report_sections(dir: &std::path::Path) -> String {
    let mut out = String::new();
    let bench = std::fs::read(dir.join(BENCH_JSON))
        .ok()
        .and_then(|b| serde_json::from_slice::<serde_json::Value>(&b).ok());
    if let Some((benches, injected)) = bench.as_ref().and_then(|v| {
        let injected = v["injected"].as_str().map(crate::html::escape);
        Some((v["scenes"].as_array()?.clone(), injected))
    }) {
        out.push_str("<h2>Pass time against floor (latest <code>harness bench</code>)</h2>");
        if let Some(injected) = injected {
            out.push_str(&format!(
                "<p class=\"note\">With an injected slowdown: {injected}. Not this build's \
                 timings.</p>"
            ));
        }
        out.push_str(
            "<table><tr><th>scene</th><th>backend</th><th>pass</th><th>ms</th><th>floor ms</th>\
             <th>ratio</th></tr>",
        );
        let cell = |v: &serde_json::Value, digits: usize| {
            v.as_f64()
                .map_or("-".to_owned(), |x| format!("{x:.digits$}"))
        };
        for b in &benches {
            let scene = crate::html::escape(b["scene"].as_str().unwrap_or("?"));
            let backend = crate::html::escape(b["backend"].as_str().unwrap_or("?"));
            for p in b["passes"].as_array().into_iter().flatten() {
                out.push_str(&format!(
                    "<tr><td>{scene}</td><td>{backend}</td><td>{}</td><td>{}</td><td>{}</td><td>{}</td></tr>",
                    crate::html::escape(p["pass"].as_str().unwrap_or("?")),
                    cell(&p["median_ms"], 2),
                    cell(&p["floor_ms"], 2),
                    cell(&p["ratio"], 1)
                ));
            }
            out.push_str(&format!(
                "<tr><td>{scene}</td><td>{backend}</td><td><b>frame</b> (floor: G-buffer once)</td>\
                 <td>{}</td><td>{}</td><td>{}</td></tr>",
                cell(&b["frame_ms"], 2),
                cell(&b["gbuffer_floor_ms"], 2),
                cell(&b["frame_to_gbuffer_floor"], 1)
            ));
        }
        out.push_str("</table>");
    }
    if let Some(series) = std::fs::read(dir.join(SERIES_JSON))
        .ok()
        .and_then(|b| serde_json::from_slice::<Vec<serde_json::Value>>(&b).ok())
    {
        out.push_str("<h2>How cost grows (latest <code>harness bench --series</code>)</h2>");
        for s in &series {
            let points: Vec<SeriesPoint> =
                serde_json::from_value(s["points"].clone()).unwrap_or_default();
            out.push_str(&format!(
                "<figure>{}<figcaption>{}</figcaption></figure>",
                series_svg(&points),
                crate::html::escape(s["backend"].as_str().unwrap_or("?"))
            ));
        }
    }
    out
}

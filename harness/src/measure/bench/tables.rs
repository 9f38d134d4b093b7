//! The text tables `harness bench` prints: a scene's passes against their floors, a lighting
//! pass's breakdown, and a scaling series.

use super::{PassBreakdown, SceneBench, SeriesPoint};

/// A pass breakdown as a table.
pub fn breakdown_table(b: &PassBreakdown) -> String {
    let ms = |v: Option<f64>| v.map_or("-".to_owned(), |v| format!("{v:.2}"));
    let share = |v: Option<f64>| {
        v.zip(b.total_ms)
            .map_or(String::new(), |(v, t)| format!("{:.0}%", 100.0 * v / t))
    };
    let mut out = format!(
        "{} {} on {} (GPU ms, lower quartile of {} frames; each part: what the pass loses \
         without it)\n",
        b.scene, b.pass, b.backend, b.frames
    );
    for row in &b.rows {
        out.push_str(&format!(
            "  {:<44} {:>8} {:>6}\n",
            row.what,
            ms(row.ms),
            share(row.ms)
        ));
    }
    out.push_str(&format!(
        "  {:<44} {:>8} {:>6}\n  {:<44} {:>8}\n",
        "sum of the parts",
        ms(b.sum_ms),
        share(b.sum_ms),
        "pass as it is",
        ms(b.total_ms)
    ));
    out
}

/// One scene's timings as a table.
pub fn table(bench: &SceneBench) -> String {
    let ms = |v: Option<f64>| v.map_or("-".to_owned(), |v| format!("{v:.2}"));
    let ratio = |v: Option<f64>| v.map_or("-".to_owned(), |v| format!("{v:.1}x"));
    let mut out = format!(
        "{} on {} ({}x{}, {} frames: median GPU ms; ratio: lower quartile of per-frame pass / floor)\n{:<22} {:>9} {:>9} {:>8} {:>12} {:>8}\n",
        bench.scene,
        bench.backend,
        bench.width,
        bench.height,
        bench.frames,
        "pass",
        "time",
        "floor",
        "ratio",
        "input floor",
        "ratio"
    );
    for p in &bench.passes {
        let (input, input_ratio) = if p.input_floor_ms.is_some() {
            (ms(p.input_floor_ms), ratio(p.input_ratio))
        } else {
            (String::new(), String::new())
        };
        out.push_str(&format!(
            "{:<22} {:>9} {:>9} {:>8} {:>12} {:>8}\n",
            p.pass,
            ms(p.median_ms),
            ms(p.floor_ms),
            ratio(p.ratio),
            input,
            input_ratio
        ));
    }
    out.push_str(&format!(
        "{:<22} {:>9} {:>9} {:>8}   (floor: writing the G-buffer once)\n",
        "frame",
        ms(bench.frame_ms),
        ms(bench.gbuffer_floor_ms),
        ratio(bench.frame_to_gbuffer_floor)
    ));
    out.push_str(&format!(
        "{:<22} {:>9.2}   wall time of a whole render\n",
        "render (wall)", bench.wall_ms
    ));
    out
}

/// A series as a table, with each point's growth against the previous one.
pub fn series_table(points: &[SeriesPoint]) -> String {
    let ms = |v: Option<f64>| v.map_or("-".to_owned(), |v| format!("{v:.2}"));
    let mut out = String::new();
    if let Some(first) = points.first() {
        out.push_str(&format!(
            "{:<12} {:>10} {:>14} {:>10} {:>10} {:>12}\n",
            "series",
            "value",
            format!("{} ms", first.pass),
            "x value",
            "x time",
            "frame ms"
        ));
    }
    for (i, p) in points.iter().enumerate() {
        let (value_growth, time_growth) = match i.checked_sub(1).map(|j| &points[j]) {
            Some(prev) => (
                format!("{:.1}", p.value as f64 / prev.value as f64),
                p.pass_ms
                    .zip(prev.pass_ms)
                    .map_or("-".to_owned(), |(a, b)| format!("{:.2}", a / b)),
            ),
            None => ("-".to_owned(), "-".to_owned()),
        };
        out.push_str(&format!(
            "{:<12} {:>10} {:>14} {:>10} {:>10} {:>12}\n",
            p.series.name(),
            p.value,
            ms(p.pass_ms),
            value_growth,
            time_growth,
            ms(p.frame_ms)
        ));
    }
    out
}

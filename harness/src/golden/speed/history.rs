//! The speed history: each `check` and `bench` appends its per-pass ratios, with the commit and
//! the hosts, as one JSON line to `<out>/speed-history.jsonl`, so that a slow drift shows
//! before it crosses a limit (the review page plots it).

use std::collections::BTreeMap;
use std::io::Write;
use std::path::Path;

use engine::backend::BackendKind;
use engine::plan::PassId;

/// The history's file name in the output folder.
pub const HISTORY_FILE: &str = "speed-history.jsonl";

/// One pass's ratio in a history entry.
#[derive(Clone, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct HistoryRatio {
    /// Scene.
    pub scene: String,
    /// Backend.
    pub backend: BackendKind,
    /// Pass.
    pub pass: PassId,
    /// Its ratio (the speed probe's for `check`, the interleaved frames' for `bench`).
    pub ratio: f64,
    /// Its time, ms.
    pub ms: f64,
}

/// One line of the history.
#[derive(Clone, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct HistoryEntry {
    /// UTC time (RFC 3339).
    pub time: String,
    /// `check` or `bench` (their ratios are measured differently: compare like with like).
    pub command: String,
    /// `git rev-parse HEAD` of the workspace, when it is a git tree.
    pub commit: Option<String>,
    /// Each backend's host fingerprint.
    pub hosts: BTreeMap<BackendKind, String>,
    /// The ratios.
    pub ratios: Vec<HistoryRatio>,
    /// Per scene, what it was loaded from
    /// ([`SceneInputs::digest`](crate::golden::scene_inputs::SceneInputs::digest); `check`'s
    /// entries): a scene edited between two runs of one commit is another scene's series.
    #[serde(default, skip_serializing_if = "BTreeMap::is_empty")]
    pub inputs: BTreeMap<String, String>,
    /// The harness executable that measured ([`build`]): an uncommitted change to the engine
    /// is another build of the same commit.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub build: Option<String>,
}

/// This harness executable's identity: a digest of its size and modification time (None where
/// they cannot be read). Two builds of the same commit with edits between them differ.
pub fn build() -> Option<String> {
    use sha2::Digest as _;
    let meta = std::env::current_exe().and_then(std::fs::metadata).ok()?;
    let modified = meta
        .modified()
        .ok()?
        .duration_since(std::time::UNIX_EPOCH)
        .ok()?;
    let identity = format!("{} {}", meta.len(), modified.as_nanos());
    let digest = sha2::Sha256::digest(identity.as_bytes());
    Some(digest.iter().take(8).map(|b| format!("{b:02x}")).collect())
}

/// Of `entries`, what an unchanged build measured: the `check` entries of this executable
/// ([`build`]), each keeping only the ratios of scenes loaded from the bytes `inputs` names
/// (scene to [`SceneInputs::digest`](crate::golden::scene_inputs::SceneInputs::digest)); with
/// how many `check` entries were left out whole (another build, or every scene edited).
pub fn of_this_build(
    entries: &[HistoryEntry],
    inputs: &BTreeMap<String, String>,
) -> (Vec<HistoryEntry>, usize) {
    let this = build();
    let mut kept = Vec::new();
    let mut left_out = 0;
    for entry in entries.iter().filter(|e| e.command == "check") {
        let mut entry = entry.clone();
        if this.is_none() || entry.build != this {
            entry.ratios.clear();
        }
        entry.ratios.retain(|r| {
            inputs
                .get(&r.scene)
                .is_some_and(|d| entry.inputs.get(&r.scene) == Some(d))
        });
        if entry.ratios.is_empty() {
            left_out += 1;
        } else {
            kept.push(entry);
        }
    }
    (kept, left_out)
}

/// The workspace's commit, when it is a git tree and git is there.
pub fn commit() -> Option<String> {
    let output = std::process::Command::new("git")
        .args(["rev-parse", "HEAD"])
        .current_dir(crate::workspace_root())
        .output()
        .ok()?;
    output
        .status
        .success()
        .then(|| String::from_utf8_lossy(&output.stdout).trim().to_owned())
        .filter(|c| !c.is_empty())
}

/// Appends `entry` to the history in `out` (creating both); a failure is a warning on stderr,
/// never a failed run.
pub fn append(out: &Path, entry: &HistoryEntry) {
    let path = out.join(HISTORY_FILE);
    let result = std::fs::create_dir_all(out).and_then(|()| {
        let mut file = std::fs::OpenOptions::new()
            .create(true)
            .append(true)
            .open(&path)?;
        let line = serde_json::to_string(entry).map_err(std::io::Error::other)?;
        // One write per line: concurrent appenders do not interleave within a line.
        file.write_all(format!("{line}\n").as_bytes())
    });
    if let Err(e) = result {
        eprintln!("warning: could not append to {}: {e}", path.display());
    }
}

/// Appends one entry of `command` (`check` or `bench`) to the history in `out`, stamped with
/// the time, the commit and the build: `hosts` by backend, `ratios` as measured, `inputs` the
/// scenes' digests. Nothing when there are no ratios.
pub fn record(
    out: &Path,
    command: &str,
    hosts: BTreeMap<BackendKind, String>,
    ratios: Vec<HistoryRatio>,
    inputs: BTreeMap<String, String>,
) {
    if ratios.is_empty() {
        return;
    }
    append(
        out,
        &HistoryEntry {
            time: humantime::format_rfc3339_seconds(std::time::SystemTime::now()).to_string(),
            command: command.to_owned(),
            commit: commit(),
            hosts,
            ratios,
            inputs,
            build: build(),
        },
    );
}

/// Reads the history in `out`: its entries in order, skipping lines that do not parse (a
/// line cut short by a crash), with how many were skipped.
pub fn read(out: &Path) -> (Vec<HistoryEntry>, usize) {
    let Ok(text) = std::fs::read_to_string(out.join(HISTORY_FILE)) else {
        return (Vec::new(), 0);
    };
    let mut skipped = 0;
    let entries = text
        .lines()
        .filter(|l| !l.trim().is_empty())
        .filter_map(|l| {
            let entry = serde_json::from_str(l).ok();
            skipped += usize::from(entry.is_none());
            entry
        })
        .collect();
    (entries, skipped)
}

/// The review page's plots of the history in `dir`: per scene and backend, each pass's speed
/// ratio over the `check` runs recorded, as a factor of its first value there (a slow drift
/// shows as a line climbing before it crosses a limit). Empty with fewer than two runs.
pub fn report_section(dir: &Path) -> String {
    let (entries, skipped) = read(dir);
    let checks: Vec<&HistoryEntry> = entries.iter().filter(|e| e.command == "check").collect();
    if checks.len() < 2 {
        return String::new();
    }
    let mut series: BTreeMap<(String, BackendKind), PassSeries> = BTreeMap::new();
    for (index, entry) in checks.iter().enumerate() {
        for r in &entry.ratios {
            series
                .entry((r.scene.clone(), r.backend))
                .or_default()
                .entry(r.pass)
                .or_default()
                .push((index, r.ratio));
        }
    }
    let mut out = format!(
        "<h2 id=\"speed-history\">Speed history</h2><p>Each pass's speed ratio over the last {} \
         <code>check</code> runs in <code>{HISTORY_FILE}</code> (first {}, last {}), as a \
         factor of its first value there.{}</p>",
        checks.len(),
        crate::html::escape(&checks[0].time),
        crate::html::escape(&checks[checks.len() - 1].time),
        if skipped > 0 {
            format!(" {skipped} line(s) that did not parse were skipped.")
        } else {
            String::new()
        }
    );
    for ((scene, backend), passes) in &series {
        out.push_str(&format!(
            "<figure>{}</figure>",
            history_svg(&format!("{scene} on {backend}"), passes, checks.len())
        ));
    }
    out
}

/// Each pass's (run index, ratio) points.
type PassSeries = BTreeMap<PassId, Vec<(usize, f64)>>;

/// One plot (plotters): a line per pass, its ratios over runs divided by its first.
fn history_svg(title: &str, passes: &PassSeries, runs: usize) -> String {
    use plotters::prelude::*;
    let lines: Vec<(String, Vec<(f64, f64)>)> = passes
        .iter()
        .filter_map(|(pass, points)| {
            let first = points.first()?.1;
            (first > 0.0).then(|| {
                let line = points.iter().map(|&(i, r)| (i as f64, r / first)).collect();
                (pass.to_string(), line)
            })
        })
        .collect();
    let (lo, hi) = lines
        .iter()
        .flat_map(|(_, l)| l.iter().map(|p| p.1))
        .fold((0.9f64, 1.1f64), |(a, b), y| (a.min(y), b.max(y)));
    let mut svg = String::new();
    let drawn = (|| -> Result<(), Box<dyn std::error::Error>> {
        let root = SVGBackend::with_string(&mut svg, (480, 240)).into_drawing_area();
        root.fill(&WHITE)?;
        let mut chart = ChartBuilder::on(&root)
            .caption(title, ("sans-serif", 14))
            .margin(10)
            .x_label_area_size(28)
            .y_label_area_size(44)
            .build_cartesian_2d(0.0..(runs.max(2) - 1) as f64, (lo * 0.98)..(hi * 1.02))?;
        // Whole runs on the x axis (numbered from 1), and a mark on each point, so that a pass
        // seen in one run only still shows.
        chart
            .configure_mesh()
            .x_desc("check run")
            .y_desc("ratio / first")
            .x_labels(runs.clamp(2, 11))
            .x_label_formatter(&|x| format!("{:.0}", x + 1.0))
            .label_style(("sans-serif", 10))
            .draw()?;
        for (index, (name, line)) in lines.iter().enumerate() {
            let color = Palette99::pick(index).to_rgba();
            chart
                .draw_series(LineSeries::new(line.clone(), color.stroke_width(2)))?
                .label(name.clone())
                .legend(move |(x, y)| PathElement::new(vec![(x, y), (x + 14, y)], color));
            chart.draw_series(
                line.iter()
                    .map(|&point| Circle::new(point, 2, color.filled())),
            )?;
        }
        chart
            .configure_series_labels()
            .background_style(WHITE.mix(0.8))
            .border_style(BLACK)
            .label_font(("sans-serif", 10))
            .draw()?;
        root.present()?;
        Ok(())
    })();
    match drawn {
        Ok(()) => svg,
        Err(e) => format!("<p>plot failed: {e}</p>"),
    }
}

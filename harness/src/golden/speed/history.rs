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

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn entries_append_and_read_back_and_a_cut_line_is_skipped() {
        let dir = tempfile::tempdir().unwrap();
        let entry = |ratio| HistoryEntry {
            time: "t".to_owned(),
            command: "check".to_owned(),
            commit: Some("abc".to_owned()),
            hosts: BTreeMap::from([(BackendKind::Gl, "host".to_owned())]),
            ratios: vec![HistoryRatio {
                scene: "chess".to_owned(),
                backend: BackendKind::Gl,
                pass: PassId::ToneMap,
                ratio,
                ms: 1.0,
            }],
        };
        append(dir.path(), &entry(2.0));
        std::fs::OpenOptions::new()
            .append(true)
            .open(dir.path().join(HISTORY_FILE))
            .unwrap()
            .write_all(b"{\"time\": \"cut")
            .unwrap();
        std::fs::OpenOptions::new()
            .append(true)
            .open(dir.path().join(HISTORY_FILE))
            .unwrap()
            .write_all(b"\n")
            .unwrap();
        append(dir.path(), &entry(3.0));
        let (entries, skipped) = read(dir.path());
        assert_eq!(entries, vec![entry(2.0), entry(3.0)]);
        assert_eq!(skipped, 1);
    }
}

//! Tests of `harness::golden::speed::history`.

use engine::backend::BackendKind;
use engine::plan::PassId;
use harness::golden::speed::history::*;
use std::collections::BTreeMap;
use std::io::Write;

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
        inputs: BTreeMap::new(),
        build: None,
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
    let section = report_section(dir.path());
    assert!(
        section.contains("<svg") && section.contains("chess on gl"),
        "{section}"
    );
    assert!(
        section.contains("tonemap") && section.contains("1 line(s)"),
        "{section}"
    );
}

/// A recording pools only an unchanged build's checks: this executable's, and of each scene
/// only the runs loaded from the bytes it is now (a check of an edited scene under the same
/// commit measured another scene); bench entries never.
#[test]
fn only_this_builds_checks_of_unedited_scenes_are_pooled() {
    let ratio = |scene: &str| HistoryRatio {
        scene: scene.to_owned(),
        backend: BackendKind::Gl,
        pass: PassId::ToneMap,
        ratio: 2.0,
        ms: 1.0,
    };
    let entry = |command: &str, build_id: Option<String>, chess: &str| HistoryEntry {
        time: "t".to_owned(),
        command: command.to_owned(),
        commit: Some("abc".to_owned()),
        hosts: BTreeMap::new(),
        ratios: vec![ratio("chess"), ratio("ibl")],
        inputs: BTreeMap::from([
            ("chess".to_owned(), chess.to_owned()),
            ("ibl".to_owned(), "ibl-now".to_owned()),
        ]),
        build: build_id,
    };
    let this = build();
    assert!(this.is_some(), "the test executable has an identity");
    let now = BTreeMap::from([
        ("chess".to_owned(), "chess-now".to_owned()),
        ("ibl".to_owned(), "ibl-now".to_owned()),
    ]);
    let entries = [
        entry("check", this.clone(), "chess-now"),
        entry("check", this.clone(), "chess-edited"),
        entry("check", Some("another build".to_owned()), "chess-now"),
        entry("check", None, "chess-now"),
        entry("bench", this.clone(), "chess-now"),
    ];
    let (kept, left_out) = of_this_build(&entries, &now);
    let scenes: Vec<Vec<&str>> = kept
        .iter()
        .map(|e| e.ratios.iter().map(|r| r.scene.as_str()).collect())
        .collect();
    assert_eq!(scenes, [vec!["chess", "ibl"], vec!["ibl"]]);
    assert_eq!(left_out, 2);
}

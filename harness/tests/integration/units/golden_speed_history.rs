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

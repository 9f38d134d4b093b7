//! Tests of `harness::golden::portability::sources`.

use harness::golden::portability::sources::*;
use harness::golden::GoldenStore;

#[test]
fn sources_are_selected_by_name_or_as_the_cheap_ones() {
    let store = GoldenStore::new(std::env::temp_dir().join("no-such-golden-folder"));
    let (all, missing) = sources(&store);
    let names = |picked: Vec<Source>| picked.into_iter().map(|s| s.name).collect::<Vec<_>>();
    assert_eq!(names(select(&all, &missing, &[]).unwrap()).len(), all.len());
    let cheap = names(select(&all, &missing, &["cheap".to_owned()]).unwrap());
    assert_eq!(
        cheap,
        ["drivers", "cpu-sse4.1", "cpu-avx", "synthetic-rounding"]
    );
    let one = select(
        &all,
        &missing,
        &["threads-1".to_owned(), "drivers".to_owned()],
    );
    assert_eq!(names(one.unwrap()), ["drivers", "threads-1"]);
    let err = select(&all, &missing, &["nope".to_owned()]).unwrap_err();
    assert!(err.contains("unknown source `nope`"), "{err}");
}

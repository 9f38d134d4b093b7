//! Tests of `harness::golden::bless`.

use harness::golden::bless::refusal_for;

/// A scene named like a canonical scene is blessed only from the canonical file: a bare name is
/// that file; a path elsewhere, or one that no longer resolves (a copy deleted or read from
/// another folder), is refused (fail closed); a name of its own has nothing to overwrite.
#[test]
fn only_the_canonical_file_blesses_a_canonical_name() {
    let canonical = harness::scenes_dir().join("arrow.toml");
    assert_eq!(refusal_for("arrow", "arrow"), None);
    assert_eq!(refusal_for("arrow", &canonical.to_string_lossy()), None);
    let why = refusal_for("arrow", "/nonexistent/arrow.toml").expect("refused");
    assert!(
        why.contains("shares its name with the canonical scene") && why.contains("golden/arrow/"),
        "{why}"
    );
    assert_eq!(refusal_for("my_scene", "/nonexistent/my_scene.toml"), None);
}

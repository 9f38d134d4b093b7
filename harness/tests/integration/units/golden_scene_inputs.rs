//! Tests of `harness::golden::scene_inputs`.

use harness::golden::scene_inputs::SceneInputs;

/// Inputs of `files`, each `(name, digest)`.
fn inputs(files: &[(&str, Option<&str>)]) -> SceneInputs {
    SceneInputs {
        scene: "pyramid".to_owned(),
        files: files
            .iter()
            .map(|(f, d)| (f.into(), d.map(str::to_owned)))
            .collect(),
        warnings: Vec::new(),
    }
}

/// A file changed, gone, newly read or unreadable is a change; the same files with the same
/// bytes are not, and then nothing is refused.
#[test]
fn a_scene_changed_since_the_check_names_its_files() {
    let then = inputs(&[
        ("s.toml", Some("1")),
        ("m.obj", Some("2")),
        ("m.mtl", Some("3")),
        ("t.png", None),
    ]);
    assert_eq!(
        then.changed(&inputs(&[
            ("s.toml", Some("1")),
            ("m.obj", Some("9")),
            ("t.png", None),
            ("u.png", Some("4")),
        ])),
        ["m.obj", "m.mtl", "t.png", "u.png"].map(std::path::PathBuf::from)
    );
    let same = inputs(&[("s.toml", Some("1")), ("m.obj", Some("2"))]);
    assert!(same.changed(&same.clone()).is_empty());
    assert_eq!(same.refusal(&[], "pyramid", None), None);
    let changed = same.changed(&inputs(&[("s.toml", Some("5")), ("m.obj", Some("2"))]));
    let out = std::path::Path::new("ci out");
    let why = same.refusal(&changed, "p/pyramid.toml", Some(out)).unwrap();
    // The check to run again writes where the accept reads.
    assert!(
        why.starts_with("pyramid changed since the check (s.toml): ")
            && why.contains(" check --scene p/pyramid.toml --out 'ci out'`), then accept"),
        "{why}"
    );
}

/// A file digest is SHA-256 of its bytes (the same on every machine and Rust release, so a CI
/// job's check compares with a local checkout), and a recorded file changed on disk is seen.
#[test]
fn digests_travel_and_changes_on_disk_are_seen() {
    use harness::golden::scene_inputs::{file_digest, input_name};
    let dir = tempfile::tempdir().unwrap();
    let file = dir.path().join("a.toml");
    std::fs::write(&file, "abc").unwrap();
    assert_eq!(
        file_digest(&file).as_deref(),
        Some("ba7816bf8f01cfea414140de5dae2223b00361a396177a9cb410ff61f20015ad")
    );
    assert_eq!(file_digest(&dir.path().join("gone")), None);
    // Inside the workspace, a name relative to it (`..` resolved); outside, absolute.
    let inner = dir.path().join("x/../a.toml");
    assert_eq!(
        input_name(&inner, dir.path()),
        std::path::PathBuf::from("a.toml")
    );
    let elsewhere = tempfile::tempdir().unwrap();
    assert!(input_name(&file, elsewhere.path()).is_absolute());
    // What a timing accept asks: the recorded files' bytes now, without loading the scene.
    let recorded = SceneInputs {
        scene: "a".to_owned(),
        files: vec![("a.toml".into(), file_digest(&file))],
        warnings: Vec::new(),
    };
    assert!(recorded.changed_on_disk(dir.path()).is_empty());
    std::fs::write(&file, "abd").unwrap();
    assert_eq!(
        recorded.changed_on_disk(dir.path()),
        [std::path::PathBuf::from("a.toml")]
    );
    std::fs::remove_file(&file).unwrap();
    assert_eq!(recorded.changed_on_disk(dir.path()).len(), 1);
}

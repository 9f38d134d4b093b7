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
    assert_eq!(same.refusal(&same.clone(), "pyramid"), None);
    let why = same
        .refusal(
            &inputs(&[("s.toml", Some("5")), ("m.obj", Some("2"))]),
            "p/pyramid.toml",
        )
        .unwrap();
    assert!(
        why.starts_with("pyramid changed since the check (s.toml): ")
            && why.contains(" check --scene p/pyramid.toml`), then accept"),
        "{why}"
    );
}

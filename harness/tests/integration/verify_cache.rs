//! Kept verifications (`HARNESS_VERIFY_CACHE`): the key changes with everything a
//! verification's child checks read, and the tests' runs reuse what they verified.

use engine::backend;
use engine::plan::TargetId;
use harness::golden::suite::Case;
use harness::golden::verify_cache::key;
use harness::golden::GoldenStore;

use crate::common;

/// The candidates, the passes verified and the scene's assets (a material library its OBJ
/// names, which the scene file does not) each change the key; nothing else does. A file edited
/// since the scene was loaded gives no key: the children would render the edited scene.
#[test]
fn a_kept_verification_is_keyed_by_everything_its_checks_read() {
    // The key names the drivers this process has loaded: load them, as a check has.
    let Some(kind) = common::available_backends().into_iter().next() else {
        return;
    };
    let _backend = backend::create(kind).unwrap();
    let root = common::temp_workspace();
    let scene = root.path().join("scenes/chess.toml");
    let case = Case::load(scene.to_str().unwrap()).unwrap();
    let golden = tempfile::tempdir().unwrap();
    let candidate = golden.path().join("chess/light.exr");
    std::fs::create_dir_all(candidate.parent().unwrap()).unwrap();
    std::fs::write(&candidate, b"candidate").unwrap();
    let passes = [TargetId::Light, TargetId::Final];
    let inputs = harness::golden::verify::inputs_digest(&GoldenStore::new(golden.path()), &case);
    let key_now =
        || key(&inputs, &case, golden.path(), &passes).expect("a key where drivers are loaded");

    let first = key_now();
    assert_eq!(key_now(), first, "the same inputs give the same key");

    std::fs::write(&candidate, b"another candidate").unwrap();
    let other_candidate = key_now();
    assert_ne!(other_candidate, first, "a changed candidate");

    assert_ne!(
        key(&inputs, &case, golden.path(), &passes[..1]).unwrap(),
        other_candidate,
        "other passes"
    );

    let mtl = root.path().join("scenes/assets/board.mtl");
    let text = std::fs::read_to_string(&mtl).unwrap();
    std::fs::write(&mtl, format!("{text}\n# edited\n")).unwrap();
    assert_eq!(
        key(&inputs, &case, golden.path(), &passes),
        None,
        "a material library edited since the load"
    );
    let reloaded = Case::load(scene.to_str().unwrap()).unwrap();
    let inputs =
        harness::golden::verify::inputs_digest(&GoldenStore::new(golden.path()), &reloaded);
    let edited = key(&inputs, &reloaded, golden.path(), &passes).expect("a key after the reload");
    assert_ne!(edited, other_candidate, "an edited material library");
}

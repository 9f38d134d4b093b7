//! Issue 8: the speed-against-error sweeps of the canonical scenes, as insta snapshots of their
//! errors (times vary run to run and are left out; errors are rounded so the text is stable).
//! Run on `gl` (the snapshots are that driver's numbers); skipped with a note where it is
//! missing, unless `REQUIRE_BACKENDS` names it.

mod common;

use engine::BackendKind;

fn gl_available() -> bool {
    common::available_backends().contains(&BackendKind::Gl)
}

#[test]
fn chess_shadow_sweep() {
    if !gl_available() {
        return;
    }
    let scene = harness::load_scene("chess").unwrap().scene;
    let rows = harness::sweep::shadow_sweep(&scene, BackendKind::Gl, 1, |_| {}).unwrap();
    assert!(
        rows.iter().any(|r| r.is_default),
        "the default setting is swept"
    );
    insta::assert_snapshot!(harness::sweep::stable_table(&rows));
}

#[test]
fn ibl_sweep() {
    if !gl_available() {
        return;
    }
    let scene = harness::load_scene("ibl").unwrap().scene;
    let rows = harness::sweep::ibl_sweep(&scene, BackendKind::Gl, 1, |_| {}).unwrap();
    assert!(
        rows.iter().any(|r| r.is_default),
        "the default setting is swept"
    );
    insta::assert_snapshot!(harness::sweep::stable_ibl_table(&rows));
}

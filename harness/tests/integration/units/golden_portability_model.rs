//! Tests of `harness::golden::portability::model`.

use engine::backend::BackendKind;
use harness::golden::noise::NoiseModel;
use harness::golden::portability::measuring::Missed;
use harness::golden::portability::model::*;
use harness::golden::suite::Case;
use std::collections::BTreeMap;

/// `harness noise --scene S --write` measures one scene: the other scenes' figures and
/// known crashes stay as they were, the measured scene's crashes are this run's.
#[test]
fn unmeasured_scenes_keep_their_known_crashes() {
    let why = |text: &str| text.to_owned();
    let previous = NoiseModel {
        known_crashes: BTreeMap::from([
            ("vector-128/wgpu-vulkan/chess".to_owned(), why("old")),
            ("vector-128/wgpu-vulkan/arrow".to_owned(), why("old")),
        ]),
        ..NoiseModel::default()
    };
    let missed = [Missed {
        source: "vector-128".to_owned(),
        backend: BackendKind::WgpuVulkan,
        scene: "ibl".to_owned(),
        error: why("new"),
        known: true,
    }];
    // No case measured (as with `--scene ibl`, ibl's case adds its own figures): nothing
    // of the previous model is lost, and the run's crash is added.
    let model = build_model(&[], &[], 3.0, BTreeMap::new(), &missed, &previous);
    assert_eq!(
        model.known_crashes,
        BTreeMap::from([
            ("vector-128/wgpu-vulkan/arrow".to_owned(), why("old")),
            ("vector-128/wgpu-vulkan/chess".to_owned(), why("old")),
            ("vector-128/wgpu-vulkan/ibl".to_owned(), why("new")),
        ])
    );
    // Chess measured, and it did not crash this time: its old record goes, arrow's stays.
    // The IBL maps of chess from the workspace's disk cache, as the CLI reads them (a
    // precompute here cost this test 3 CPU-s).
    harness::use_ibl_cache();
    let noise = NoiseModel::load(&harness::golden::store::GoldenStore::workspace()).unwrap();
    let chess = vec![Case::load_with("chess", &noise).unwrap()];
    let model = build_model(&chess, &[], 3.0, BTreeMap::new(), &[], &previous);
    assert_eq!(
        model.known_crashes,
        BTreeMap::from([("vector-128/wgpu-vulkan/arrow".to_owned(), why("old"))])
    );
}

//! Tests of `harness::golden::store`.

use engine::backend::BackendKind;
use engine::backend::TextureFormat;
use engine::plan::TargetId;
use engine::{Image, ImageData};
use harness::golden::store::*;

fn temp_store(name: &str) -> GoldenStore {
    let dir = std::env::temp_dir().join(format!("golden-{name}-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    GoldenStore::new(dir)
}

/// A golden is decoded once while its file is unchanged, also for a clone of the store
/// (which shares the decoded goldens), and again once rewritten.
#[test]
fn a_rewritten_golden_is_decoded_again() {
    let store = temp_store("decoded");
    let image = |value: f32| Image {
        width: 1,
        height: 1,
        format: TextureFormat::Rgba16Float,
        data: ImageData::F32(vec![value, 0.0, 0.0, 1.0]),
    };
    let bless = |store: &GoldenStore, value: f32| {
        let lock = store.lock_scene("s", |_| {}).unwrap();
        let provenance = Provenance {
            backend: BackendKind::Gl,
            driver: "llvmpipe",
            previous: "new",
            unverified: false,
            reason: None,
            scene_file: None,
        };
        store
            .bless(&lock, TargetId::Light, &image(value), provenance)
            .unwrap();
    };
    bless(&store, 1.0);
    let clone = store.clone();
    let load = |store: &GoldenStore| store.load("s", TargetId::Light, false).unwrap().unwrap();
    let decodes = || store.decodes();
    assert_eq!(load(&store).data, image(1.0).data);
    assert_eq!(load(&store).data, image(1.0).data);
    assert_eq!(load(&clone).data, image(1.0).data);
    assert_eq!(decodes(), 1);
    bless(&clone, 2.0);
    assert_eq!(load(&store).data, image(2.0).data);
    assert_eq!(load(&clone).data, image(2.0).data);
    assert_eq!(decodes(), 2);
    let _ = std::fs::remove_dir_all(store.root());
}

#[test]
fn bless_writes_the_golden_and_the_record_and_refuses_nan() {
    let store = temp_store("bless");
    let image = Image {
        width: 1,
        height: 1,
        format: TextureFormat::Rgba16Float,
        data: ImageData::F32(vec![1.0, 2.0, 3.0, 1.0]),
    };
    let lock = store.lock_scene("s", |_| {}).unwrap();
    let path = store
        .bless(
            &lock,
            TargetId::Light,
            &image,
            Provenance {
                backend: BackendKind::Gl,
                driver: "llvmpipe",
                previous: "new",
                unverified: false,
                reason: Some("the sky's \"atan2\" changed"),
                scene_file: None,
            },
        )
        .unwrap();
    assert!(path.ends_with("s/light.exr"));
    assert_eq!(
        store
            .load("s", TargetId::Light, false)
            .unwrap()
            .unwrap()
            .data,
        image.data
    );
    let records = store.records("s").unwrap();
    assert_eq!(records["light"].backend, BackendKind::Gl);
    assert_eq!(
        records["light"].reason.as_deref(),
        Some("the sky's \"atan2\" changed")
    );
    let bad = Image {
        data: ImageData::F32(vec![f32::NAN, 0.0, 0.0, 1.0]),
        ..image.clone()
    };
    let err = store
        .bless(
            &lock,
            TargetId::Light,
            &bad,
            Provenance {
                backend: BackendKind::Gl,
                driver: "llvmpipe",
                previous: "new",
                unverified: false,
                reason: None,
                scene_file: None,
            },
        )
        .unwrap_err();
    assert!(err.to_string().contains("NaN/Inf"), "{err}");
    // The refused bless left the old golden untouched.
    assert_eq!(
        store
            .load("s", TargetId::Light, false)
            .unwrap()
            .unwrap()
            .data,
        image.data
    );
    // A golden that holds NaN anyway (written around the bless) is named as corrupt when
    // read, not compared (a check would blame the renderer).
    harness::images::write_image(&bad, &path, harness::images::FileCompression::Fast).unwrap();
    let err = store.load("s", TargetId::Light, false).unwrap_err();
    assert!(
        matches!(err, GoldenError::CorruptGolden { count: 1, .. })
            && err.to_string().contains("light.exr")
            && err.to_string().contains("corrupt"),
        "{err}"
    );
    let _ = std::fs::remove_dir_all(store.root());
}

/// A scene blessed from a file outside scenes/ records that file in blessed.toml (relative to
/// the workspace), a forgotten record keeps it, and its folder is no orphan while the file
/// exists; once the file is gone, the folder is a scene gone. Blessed as a scene of scenes/
/// (no file to record), the record goes.
#[test]
fn a_scene_file_elsewhere_keeps_its_golden_folder() {
    use harness::golden::orphans::{find, OrphanKind};
    let workspace = tempfile::tempdir().unwrap();
    let store = GoldenStore::new(workspace.path().join("golden"));
    let scene_file = workspace.path().join("mine/pyramid.toml");
    std::fs::create_dir_all(scene_file.parent().unwrap()).unwrap();
    std::fs::write(&scene_file, "").unwrap();
    let image = Image {
        width: 1,
        height: 1,
        format: TextureFormat::Rgba8Unorm,
        data: ImageData::U8(vec![1, 2, 3, 255]),
    };
    let lock = store.lock_scene("pyramid", |_| {}).unwrap();
    let bless = |lock: &SceneLock, pass, scene_file| {
        let provenance = Provenance {
            backend: BackendKind::Gl,
            driver: "llvmpipe",
            previous: "new",
            unverified: false,
            reason: None,
            scene_file,
        };
        store.bless(lock, pass, &image, provenance).unwrap();
    };
    bless(&lock, TargetId::Final, Some(scene_file.as_path()));
    bless(&lock, TargetId::Mask(0), Some(scene_file.as_path()));
    store.forget(&lock, "mask").unwrap();
    let text = std::fs::read_to_string(store.root().join("pyramid/blessed.toml")).unwrap();
    assert!(
        text.contains("scene_file = \"mine/pyramid.toml\""),
        "{text}"
    );
    let recorded = store.scene_file("pyramid").unwrap().unwrap();
    assert_eq!(
        recorded.canonicalize().unwrap(),
        scene_file.canonicalize().unwrap()
    );
    drop(lock);
    let orphans = || find(&store, &[], Some(&[])).unwrap();
    assert!(orphans().is_empty(), "{:?}", orphans());
    std::fs::remove_file(&scene_file).unwrap();
    let gone = orphans();
    assert!(
        gone.len() == 1 && gone[0].kind == OrphanKind::SceneGone,
        "{gone:?}"
    );
    let lock = store.lock_scene("pyramid", |_| {}).unwrap();
    bless(&lock, TargetId::Final, None);
    assert_eq!(store.scene_file("pyramid").unwrap(), None);
}

/// A scene folder whose blessed.toml is missing or empty lost its records, not its goldens: the
/// orphans say so once (with how to restore them), and a prune keeps every golden.
#[test]
fn a_prune_keeps_goldens_whose_records_were_lost() {
    use harness::golden::orphans::{find, prune, OrphanKind};
    use harness::golden::suite::Case;
    let workspace = tempfile::tempdir().unwrap();
    let store = GoldenStore::new(workspace.path().join("golden"));
    let from = harness::golden::GoldenStore::workspace()
        .root()
        .join("arrow");
    let dir = store.root().join("arrow");
    std::fs::create_dir_all(&dir).unwrap();
    let mut goldens = 0;
    for entry in std::fs::read_dir(&from).unwrap() {
        let path = entry.unwrap().path();
        if path.extension().is_some_and(|x| x == "png" || x == "exr") {
            std::fs::copy(&path, dir.join(path.file_name().unwrap())).unwrap();
            goldens += 1;
        }
    }
    let case = Case::load("arrow").unwrap();
    for records in [None, Some("")] {
        if let Some(text) = records {
            std::fs::write(dir.join("blessed.toml"), text).unwrap();
        }
        let orphans = find(&store, std::slice::from_ref(&case), None).unwrap();
        assert!(
            orphans.len() == 1
                && orphans[0].kind == OrphanKind::RecordsLost { goldens }
                && !orphans[0].kind.prunable(),
            "{orphans:?}"
        );
        let text = orphans[0].to_string();
        assert!(
            text.contains("git checkout -- ") && text.contains("bless --scene arrow --every-pass"),
            "{text}"
        );
        let lines = prune(&store, &orphans, false, |_| {}).unwrap();
        assert!(
            lines.len() == 1 && lines[0].starts_with("kept: "),
            "{lines:?}"
        );
        let left = std::fs::read_dir(&dir)
            .unwrap()
            .filter(|e| {
                let path = e.as_ref().unwrap().path();
                path.extension().is_some_and(|x| x == "png" || x == "exr")
            })
            .count();
        assert_eq!(left, goldens);
    }
}

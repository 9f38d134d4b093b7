//! The hard numerical cases ([`harness::measure::hard_cases`]: `scenes/hard/*.toml`, and the chess scene
//! moved and scaled), each with its invariant, on every available backend: no NaN/Inf in any
//! pass, the light buffer within fp16's safe range, and the case's own check (the lighting pass
//! against the f64 reference at p99.9 <= 2e-3 where that is defined).

use crate::common;
use engine::plan::{GBufferTarget, TargetId};
use harness::measure::hard_cases;

/// Every hard case holds its invariants on every available backend.
#[test]
fn every_hard_case_holds_on_every_backend() {
    harness::use_ibl_cache();
    let mut failures = Vec::new();
    for kind in common::available_backends() {
        let rows = hard_cases::run(kind, |_| {}).unwrap_or_else(|e| panic!("{kind}: {e}"));
        assert_eq!(rows.len(), hard_cases::SCENE_CASES.len() + 4);
        eprint!("{}", hard_cases::table(&rows));
        failures.extend(rows.iter().filter(|r| !r.passed).map(|r| format!("{r:?}")));
    }
    assert!(failures.is_empty(), "{}", failures.join("\n"));
}

/// Every scene file in scenes/hard/ is one of the cases (a new case cannot be forgotten).
#[test]
fn every_hard_scene_file_is_tested() {
    let dir = harness::workspace_root().join("scenes/hard");
    let mut files: Vec<String> = std::fs::read_dir(&dir)
        .unwrap()
        .filter_map(|e| {
            let path = e.unwrap().path();
            (path.extension()? == "toml").then(|| path.file_stem()?.to_str().map(str::to_owned))?
        })
        .collect();
    files.sort();
    assert_eq!(files, hard_cases::SCENE_CASES.to_vec());
}

/// The grazing case really reaches N.V ~ 1e-6 (measured on the read-back G-buffer).
#[test]
fn grazing_case_reaches_a_millionth() {
    let scene = hard_cases::scene("grazing").unwrap();
    for kind in common::available_backends() {
        let mut backend = engine::backend::create(kind).unwrap();
        let frame =
            engine::renderer::render(backend.as_mut(), &scene, engine::renderer::Readback::All)
                .unwrap();
        let get = |g| frame.output(TargetId::GBuffer(g)).unwrap();
        let (p, n) = (
            get(GBufferTarget::Position).as_f32().unwrap(),
            get(GBufferTarget::Normal).as_f32().unwrap(),
        );
        let mask = frame.output(TargetId::Mask(0)).unwrap().as_u8().unwrap();
        let min = (0..p.len() / 4)
            .filter(|i| mask[i * 4..i * 4 + 4].iter().any(|&m| m > 127))
            .map(|i| {
                let position =
                    glam::DVec3::new(p[i * 4].into(), p[i * 4 + 1].into(), p[i * 4 + 2].into());
                let normal =
                    glam::DVec3::new(n[i * 4].into(), n[i * 4 + 1].into(), n[i * 4 + 2].into());
                normal.normalize().dot(-position.normalize())
            })
            .filter(|d| *d > 0.0)
            .fold(1.0, f64::min);
        eprintln!("grazing on {kind}: smallest N.V {min:e}");
        assert!(min < 2e-6, "{kind}: smallest N.V {min}");
    }
}

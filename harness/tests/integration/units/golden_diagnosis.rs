//! Tests of `harness::golden::diagnosis`.

use engine::backend::BackendKind;
use engine::plan::PassSpec;
use engine::plan::{PassId, RenderPlan, TargetId};
use harness::golden::diagnosis::*;
use harness::golden::suite::PassCheck;
use std::collections::BTreeMap;

fn plan_of_grid() -> RenderPlan {
    let scene = harness::test_scenes::material_grid(16);
    engine::renderer::PreparedFrame::new(&scene)
        .unwrap()
        .plan()
        .clone()
}

fn pass(id: PassId, reads: &[TargetId], writes: &[TargetId]) -> PassSpec {
    PassSpec {
        id,
        reads: reads.to_vec(),
        writes: writes.to_vec(),
        detail: String::new(),
    }
}

#[test]
fn the_origin_is_where_the_earliest_moved_output_is_written() {
    use engine::plan::GBufferTarget;
    use engine::scene::LightingModel;
    let albedo = TargetId::GBuffer(GBufferTarget::Albedo);
    let mut plan = plan_of_grid();
    plan.passes = vec![
        pass(PassId::Geometry, &[], &[albedo, TargetId::Depth]),
        pass(
            PassId::Lighting(LightingModel::Pbr),
            &[albedo, TargetId::Depth],
            &[TargetId::Light],
        ),
        pass(PassId::ToneMap, &[TargetId::Light], &[TargetId::Final]),
    ];
    assert_eq!(
        upstream(&plan, TargetId::Final),
        [TargetId::Light, albedo, TargetId::Depth]
    );
    assert_eq!(upstream(&plan, TargetId::Depth), []);
    let failing = [TargetId::Light, TargetId::Final];
    assert_eq!(
        origins(&plan, &failing, &failing),
        [PassId::Lighting(LightingModel::Pbr)]
    );
    let failing = [TargetId::Final, TargetId::Depth, albedo];
    assert_eq!(origins(&plan, &failing, &failing), [PassId::Geometry]);
    assert_eq!(
        origins(&plan, &[TargetId::Final], &[TargetId::Final]),
        [PassId::ToneMap]
    );
    // The final image fails, the light buffer moved within its tolerance: it starts there.
    assert_eq!(
        origins(
            &plan,
            &[TargetId::Final],
            &[TargetId::Final, TargetId::Light]
        ),
        [PassId::Lighting(LightingModel::Pbr)]
    );
}

fn check(pass: TargetId, backend: BackendKind, passed: bool) -> PassCheck {
    use harness::golden::tolerance::Verdict;
    use harness::golden::Outcome;
    let verdict = Verdict {
        passed,
        ratio: if passed { 0.1 } else { 9.0 },
        non_finite: 0,
        checks: vec![],
        largest_difference: None,
    };
    PassCheck {
        scene: "grid".to_owned(),
        scene_argument: "grid".to_owned(),
        pass,
        backend,
        outcome: if passed {
            Outcome::Passed(verdict)
        } else {
            Outcome::Failed(verdict)
        },
        golden_path: Default::default(),
        artifacts: Default::default(),
        criterion: None,
        golden_digest: None,
    }
}

#[test]
fn backends_that_moved_alike_point_at_the_renderer_and_one_alone_at_its_driver() {
    use BackendKind::{Gl, WgpuVulkan};
    let plans = BTreeMap::from([("grid".to_owned(), plan_of_grid())]);
    // Light and final fail on both backends: light is the origin, final follows it.
    let results = [
        check(TargetId::Depth, Gl, true),
        check(TargetId::Light, Gl, false),
        check(TargetId::Final, Gl, false),
        check(TargetId::Depth, WgpuVulkan, true),
        check(TargetId::Light, WgpuVulkan, false),
        check(TargetId::Final, WgpuVulkan, false),
    ];
    let verdicts = diagnose(&plans, &results, &[]);
    assert_eq!(verdicts.len(), 4);
    let light = find(&verdicts, "grid", TargetId::Light, Gl).unwrap();
    assert!(
        matches!(&light.role, Role::Origin { passes } if passes.iter().all(|p| matches!(p, PassId::Lighting(_))))
    );
    assert_eq!(light.agreement, Agreement::AllBackends);
    assert!(
        light.advice.contains("bless --scene grid"),
        "{}",
        light.advice
    );
    let last = find(&verdicts, "grid", TargetId::Final, WgpuVulkan).unwrap();
    assert_eq!(
        last.role,
        Role::Downstream {
            of: vec![TargetId::Light]
        }
    );
    assert_eq!(last.headline(), "moved because light moved");

    // Depth moves on gl alone: gl or its driver; everything after it follows.
    let results = [
        check(TargetId::Depth, Gl, false),
        check(TargetId::Light, Gl, false),
        check(TargetId::Depth, WgpuVulkan, true),
        check(TargetId::Light, WgpuVulkan, true),
    ];
    let verdicts = diagnose(&plans, &results, &[]);
    let depth = find(&verdicts, "grid", TargetId::Depth, Gl).unwrap();
    assert_eq!(
        depth.agreement,
        Agreement::Only {
            moved: vec![Gl],
            held: vec![WgpuVulkan]
        }
    );
    assert_eq!(
        depth.headline(),
        "origin: the geometry pass, gl alone (wgpu-vulkan held)"
    );
    assert!(depth.advice.contains("driver"), "{}", depth.advice);
    let light = find(&verdicts, "grid", TargetId::Light, Gl).unwrap();
    assert_eq!(
        light.role,
        Role::Downstream {
            of: vec![TargetId::Depth]
        }
    );
}

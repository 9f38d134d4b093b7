//! The render plan of every canonical scene and test scene, as insta snapshots: a change in what
//! a scene needs (passes, targets, formats, mask channels, draw counts) shows up in review.
//! After an intended change: `INSTA_UPDATE=always cargo test -p harness --test integration
//! plans::` (or `cargo insta review`), then read the diff.

use engine::plan::{PassId, RenderPlan, TargetId};
use engine::renderer::PreparedFrame;
use engine::scene::{LightingModel, Scene};
use harness::test_scenes;

/// The plan of `scene` as drawn.
fn plan_of(scene: &Scene) -> RenderPlan {
    PreparedFrame::new(scene)
        .unwrap_or_else(|e| panic!("{e}"))
        .plan()
        .clone()
}

#[test]
fn canonical_scene_plans() {
    harness::use_ibl_cache();
    for name in ["chess", "arrow", "ibl", "corner"] {
        let loaded = harness::load_scene(name).unwrap_or_else(|e| panic!("{e}"));
        insta::assert_snapshot!(format!("plan_{name}"), plan_of(&loaded.scene).to_string());
    }
}

#[test]
fn test_scene_plans() {
    for scene in [
        test_scenes::material_grid(256),
        test_scenes::white_furnace(128, 1.0),
        test_scenes::five_models(160),
        test_scenes::many_point_lights(128, 64),
    ] {
        insta::assert_snapshot!(format!("plan_{}", scene.name), plan_of(&scene).to_string());
    }
}

/// What a plan leaves out: no skybox without an environment, no second mask target up to four
/// models, no lighting pass for an unused model, no gizmos unless asked.
#[test]
fn plans_contain_only_what_the_scene_needs() {
    let grid = plan_of(&test_scenes::material_grid(64));
    let passes: Vec<PassId> = grid.passes.iter().map(|p| p.id).collect();
    assert_eq!(
        passes,
        [
            PassId::Geometry,
            PassId::ShaderMask,
            PassId::Lighting(LightingModel::Pbr),
            PassId::Lighting(LightingModel::BlinnPhong),
            PassId::ToneMap
        ]
    );
    assert!(grid.target(TargetId::Mask(1)).is_none());
    let five = plan_of(&test_scenes::five_models(64));
    assert!(five.target(TargetId::Mask(1)).is_some());
    assert_eq!(five.mask_channels.len(), 5);
}

/// Shadow variants: chess's sun with variance shadow maps (moments target, two blur passes) and
/// arrow's point light drawn in one pass through the geometry shader.
#[test]
fn shadow_variant_plans() {
    harness::use_ibl_cache();
    let mut chess = harness::load_scene("chess").unwrap().scene;
    for light in &mut chess.lights {
        if let engine::scene::Light::Directional {
            shadow: Some(s), ..
        } = light
        {
            s.filter = engine::scene::ShadowFilter::Vsm;
        }
    }
    insta::assert_snapshot!("plan_chess_vsm", plan_of(&chess).to_string());
    let mut arrow = harness::load_scene("arrow").unwrap().scene;
    arrow.quality.point_shadows = engine::scene::PointShadowPass::GeometryShader;
    insta::assert_snapshot!("plan_arrow_geometry_shader", plan_of(&arrow).to_string());
}

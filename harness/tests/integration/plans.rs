//! The render plan of every canonical scene and test scene, as insta snapshots: a change in what
//! a scene needs (passes, targets, formats, mask channels, draw counts) shows up in review.
//! After an intended change: `INSTA_UPDATE=always cargo test -p harness --test integration
//! plans::` (or `cargo insta review`), then read the diff.

use engine::plan::RenderPlan;
use harness::test_scenes;

#[test]
fn canonical_scene_plans() {
    for name in ["chess", "arrow", "ibl"] {
        let loaded = harness::load_scene(name).unwrap_or_else(|e| panic!("{e}"));
        insta::assert_snapshot!(
            format!("plan_{name}"),
            RenderPlan::new(&loaded.scene).to_string()
        );
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
        insta::assert_snapshot!(
            format!("plan_{}", scene.name),
            RenderPlan::new(&scene).to_string()
        );
    }
}

/// What a plan leaves out: no skybox without an environment, no second mask target up to four
/// models, no lighting pass for an unused model, no gizmos unless asked.
#[test]
fn plans_contain_only_what_the_scene_needs() {
    let grid = RenderPlan::new(&test_scenes::material_grid(64));
    let names: Vec<&str> = grid.passes.iter().map(|p| p.name.as_str()).collect();
    assert_eq!(
        names,
        [
            "geometry",
            "mask",
            "lighting_pbr",
            "lighting_blinn_phong",
            "tonemap"
        ]
    );
    assert!(grid.target("mask_1").is_none());
    let five = RenderPlan::new(&test_scenes::five_models(64));
    assert!(five.target("mask_1").is_some());
    assert_eq!(five.mask_channels.len(), 5);
}

/// Shadow variants: chess's sun with variance shadow maps (moments target, two blur passes) and
/// arrow's point light drawn in one pass through the geometry shader.
#[test]
fn shadow_variant_plans() {
    let mut chess = harness::load_scene("chess").unwrap().scene;
    for light in &mut chess.lights {
        if let engine::scene::Light::Directional {
            shadow: Some(s), ..
        } = light
        {
            s.filter = engine::scene::ShadowFilter::Vsm;
        }
    }
    insta::assert_snapshot!("plan_chess_vsm", RenderPlan::new(&chess).to_string());
    let mut arrow = harness::load_scene("arrow").unwrap().scene;
    arrow.quality.point_shadows = engine::scene::PointShadowPass::GeometryShader;
    insta::assert_snapshot!(
        "plan_arrow_geometry_shader",
        RenderPlan::new(&arrow).to_string()
    );
}

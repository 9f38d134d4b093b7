//! The deferred renderer on every available backend, against the f64 reference and the
//! renderer's invariants: white furnace, 10 km from the origin, five lighting models, 64 lights.

use crate::common;
use engine::plan::{GBufferTarget, PassId, TargetId};
use engine::renderer::{self, Frame, PreparedFrame, Readback};
use engine::scene::Scene;
use engine::{Backend, Image};
use glam::DVec3;
use harness::golden::metrics::bitwise_equal;
use harness::{reference, test_scenes};

fn render(backend: &mut dyn Backend, scene: &Scene) -> Frame {
    renderer::render(backend, scene, Readback::All)
        .unwrap_or_else(|e| panic!("{} on {}: {e}", scene.name, backend.kind()))
}

fn save(name: &str, image: &Image) {
    let out = std::path::Path::new(env!("CARGO_TARGET_TMPDIR")).join("renderer");
    std::fs::create_dir_all(&out).unwrap();
    let path = out.join(format!("{name}.png"));
    harness::images::write_image(image, &path, harness::images::FileCompression::Fast).unwrap();
}

/// The lighting pass against the f64 reference on the same G-buffer, 99.9th-percentile
/// relative error <= 2e-3 and no NaN/Inf, on a grid covering roughness 0..1, metallic 0/1,
/// clearcoat 0/1, anisotropy -1..1, Blinn-Phong exponents 1..256 and grazing silhouettes.
#[test]
fn lighting_pass_matches_the_f64_reference() {
    let scene = test_scenes::material_grid(256);
    for kind in common::available_backends() {
        let mut backend = engine::backend::create(kind).unwrap();
        let frame = render(backend.as_mut(), &scene);
        save(
            &format!("grid_{kind}"),
            frame.output(TargetId::Final).unwrap(),
        );
        let error = reference::lighting_error(&scene, &frame).unwrap();
        eprintln!("{kind}: {error:?}");
        assert!(
            error.pixels > 20_000,
            "{kind}: only {} pixels",
            error.pixels
        );
        assert_eq!(error.non_finite, 0, "{kind}: NaN/Inf in the light buffer");
        assert!(
            error.p999_relative <= 2e-3,
            "{kind}: 99.9th percentile relative error {:.3e} > 2e-3 (worst {:.3e} at {:?})",
            error.p999_relative,
            error.max_relative,
            error.worst_pixel
        );
    }
}

/// The reference derives the lights from the scene itself: a renderer whose light uniforms carry
/// a radiance 1% off fails it (99.9th-percentile error far over 2e-3), while the same render
/// without the fault passes.
#[test]
fn a_wrong_light_radiance_in_the_uniforms_fails_the_reference() {
    let scene = test_scenes::material_grid(128);
    let Some(&kind) = common::available_backends().first() else {
        return;
    };
    let mut backend = engine::backend::create(kind).unwrap();
    let faulty = PreparedFrame::new(&scene)
        .unwrap()
        .with_variations(renderer::Variations {
            light_radiance_scale: Some(1.01),
            ..Default::default()
        });
    let frame = renderer::render_prepared(backend.as_mut(), &faulty, Readback::All).unwrap();
    let wrong = reference::lighting_error(&scene, &frame).unwrap();
    let frame = render(backend.as_mut(), &scene);
    let right = reference::lighting_error(&scene, &frame).unwrap();
    eprintln!("{kind}: with the fault {wrong:?}, without {right:?}");
    assert!(right.p999_relative <= 2e-3, "{right:?}");
    assert!(
        wrong.p999_relative > 5e-3,
        "a 1% radiance error in the uniforms passes the reference: {wrong:?}"
    );
}

/// A white dielectric Lambert surface under uniform unit radiance returns its albedo within 1%.
#[test]
fn white_furnace_returns_the_albedo() {
    for kind in common::available_backends() {
        let mut backend = engine::backend::create(kind).unwrap();
        for albedo in [1.0f32, 0.5] {
            let scene = test_scenes::white_furnace(128, albedo);
            let frame = render(backend.as_mut(), &scene);
            let light = frame.output(TargetId::Light).unwrap().as_f32().unwrap();
            let mask = frame.output(TargetId::Mask(0)).unwrap().as_u8().unwrap();
            let mut covered = 0;
            for (texel, m) in light.chunks_exact(4).zip(mask.chunks_exact(4)) {
                if m[0] == 0 {
                    continue;
                }
                covered += 1;
                for &c in &texel[..3] {
                    assert!(
                        (c - albedo).abs() <= 0.01 * albedo,
                        "{kind}: furnace pixel {c} for albedo {albedo}"
                    );
                }
            }
            assert!(
                covered > 5000,
                "{kind}: sphere covers only {covered} pixels"
            );
        }
    }
}

/// The same scene 10 km from the origin (camera too) renders within the final-image tolerance
/// (>= 99.9% of pixels within 1/255) of the scene at the origin.
#[test]
fn scene_far_from_the_origin_matches_the_scene_at_the_origin() {
    let near = test_scenes::material_grid(192);
    let far = near.translated(DVec3::new(10_000.0, 0.0, -10_000.0));
    for kind in common::available_backends() {
        let mut backend = engine::backend::create(kind).unwrap();
        let a = render(backend.as_mut(), &near);
        let b = render(backend.as_mut(), &far);
        let diff = harness::golden::metrics::compare::u8_difference(
            a.output(TargetId::Final).unwrap(),
            b.output(TargetId::Final).unwrap(),
            1,
        )
        .unwrap();
        eprintln!("{kind}: {diff:?}");
        assert!(
            diff.fraction_within >= 0.999,
            "{kind}: only {:.4}% of pixels within 1/255 at 10 km",
            diff.fraction_within * 100.0
        );
    }
}

/// Five lighting models in one frame: two mask targets, and every covered pixel flagged for
/// exactly one model; background pixels for none.
#[test]
fn five_models_route_every_pixel_to_exactly_one_model() {
    let scene = test_scenes::five_models(160);
    for kind in common::available_backends() {
        let mut backend = engine::backend::create(kind).unwrap();
        let frame = render(backend.as_mut(), &scene);
        save(
            &format!("five_models_{kind}"),
            frame.output(TargetId::Final).unwrap(),
        );
        assert_eq!(frame.plan.mask_channels.len(), 5);
        let mask0 = frame.output(TargetId::Mask(0)).unwrap().as_u8().unwrap();
        let mask1 = frame.output(TargetId::Mask(1)).unwrap().as_u8().unwrap();
        let depth = frame.output(TargetId::Depth).unwrap().as_f32().unwrap();
        let mut per_model = [0usize; 5];
        for i in 0..depth.len() {
            let flags: Vec<usize> = frame
                .plan
                .mask_channels
                .iter()
                .enumerate()
                .filter(|(_, c)| {
                    let m = if c.target == 0 { mask0 } else { mask1 };
                    m[i * 4 + c.channel] > 127
                })
                .map(|(n, _)| n)
                .collect();
            let covered = depth[i] < 1.0;
            assert_eq!(
                flags.len(),
                usize::from(covered),
                "{kind}: pixel {i} (depth {}) has models {flags:?}",
                depth[i]
            );
            if let Some(&n) = flags.first() {
                per_model[n] += 1;
            }
        }
        assert!(
            per_model.iter().all(|&n| n > 100),
            "{kind}: a model has almost no pixels: {per_model:?}"
        );
        let error = reference::lighting_error(&scene, &frame).unwrap();
        assert!(error.p999_relative <= 2e-3, "{kind}: {error:?}");
    }
}

/// 64 point lights (four lighting draws of 16) light the floor as the reference says.
#[test]
fn sixty_four_point_lights() {
    let scene = test_scenes::many_point_lights(128, 64);
    for kind in common::available_backends() {
        let mut backend = engine::backend::create(kind).unwrap();
        let frame = render(backend.as_mut(), &scene);
        save(
            &format!("lights64_{kind}"),
            frame.output(TargetId::Final).unwrap(),
        );
        let error = reference::lighting_error(&scene, &frame).unwrap();
        eprintln!("{kind}: {error:?}");
        assert!(error.p999_relative <= 2e-3, "{kind}: {error:?}");
        let light = frame.output(TargetId::Light).unwrap().as_f32().unwrap();
        let lit = light
            .chunks_exact(4)
            .filter(|t| t[0] + t[1] + t[2] > 0.05)
            .count();
        assert!(lit > light.len() / 4 / 4, "{kind}: only {lit} lit pixels");
    }
}

/// Lights too bright for fp16, in more than one draw (17 lights: 16 to a draw): each draw
/// clamps its output to its share of the fp16-safe maximum, so their sum in the light buffer
/// stays at most 65000. With each draw clamping at 65000 the sum went past it: llvmpipe's blend
/// saturated at 65504, fp16's largest value; IEEE rounding of the sum gives infinity.
#[test]
fn additive_draws_of_overbright_lights_stay_finite() {
    let mut scene = test_scenes::many_point_lights(64, 17);
    for light in &mut scene.lights {
        if let engine::scene::Light::Point { intensity, .. } = light {
            *intensity = 1e9;
        }
    }
    let prepared = PreparedFrame::new(&scene).unwrap();
    let draws = prepared
        .plan()
        .lighting_draws(engine::scene::LightingModel::Pbr);
    assert_eq!(draws.len(), 2);
    assert!(draws.iter().all(|d| d.variant.draws == 2));
    for kind in common::available_backends() {
        let mut backend = engine::backend::create(kind).unwrap();
        let frame = renderer::render(backend.as_mut(), &scene, Readback::Only(&[TargetId::Light]))
            .unwrap_or_else(|e| panic!("{kind}: {e}"));
        let light = frame.output(TargetId::Light).unwrap().as_f32().unwrap();
        let largest = light
            .iter()
            .fold(0.0f32, |m, &v| if v > m || v.is_nan() { v } else { m });
        assert!(
            largest.is_finite() && largest <= 65000.0,
            "{kind}: {largest}"
        );
        // Both draws reached their cap somewhere: the sum is at the fp16-safe maximum.
        assert!(largest >= 64000.0, "{kind}: {largest}");
    }
}

/// Same scene, same backend: identical outputs, every target.
#[test]
fn renders_are_deterministic() {
    let scene = test_scenes::five_models(96);
    for kind in common::available_backends() {
        let mut backend = engine::backend::create(kind).unwrap();
        let a = render(backend.as_mut(), &scene);
        let b = render(backend.as_mut(), &scene);
        for (name, image) in &a.outputs {
            assert!(
                image.data == b.outputs[name].data,
                "{kind}: `{name}` differs between two renders"
            );
        }
    }
}

/// Normal mapping through the TBN and maps replacing scalars: a plane facing +Y (tangent +X,
/// bitangent along +v = -Z) with a constant normal map tilting towards +u, then towards +v; a
/// roughness map replaces the scalar, and without it the scalar is written.
#[test]
fn normal_and_parameter_maps_reach_the_gbuffer() {
    use engine::scene::{Material, TextureImage};
    use std::sync::Arc;

    let texture = |rgba: [u8; 4], srgb: bool| {
        Arc::new(TextureImage {
            label: format!("{rgba:?}"),
            srgb,
            width: 2,
            height: 2,
            format: engine::assets::TexelFormat::Rgba8,
            mips: vec![rgba.repeat(4), rgba.to_vec()],
        })
    };
    // Tangent-space normals (0.6, 0, 0.8) and (0, 0.6, 0.8), encoded n * 0.5 + 0.5.
    let cases = [
        ([204u8, 128, 230, 255], [0.6f32, 0.8, 0.0]),
        ([128u8, 204, 230, 255], [0.0f32, 0.8, -0.6]),
    ];
    for kind in common::available_backends() {
        let mut backend = engine::backend::create(kind).unwrap();
        for (encoded, expected) in cases {
            let mut scene = test_scenes::many_point_lights(64, 1);
            scene.camera.position = glam::DVec3::new(0.0, 5.0, 0.01);
            scene.textures = vec![texture(encoded, false), texture([51, 0, 0, 255], false)];
            scene.objects[0].material = Material {
                normal_map: Some(0),
                roughness_map: Some(1),
                roughness: 0.9,
                ..Material::default()
            };
            let frame = render(backend.as_mut(), &scene);
            let normal = frame
                .output(TargetId::GBuffer(GBufferTarget::Normal))
                .unwrap()
                .pixel(32, 32);
            let position = frame
                .output(TargetId::GBuffer(GBufferTarget::Position))
                .unwrap()
                .pixel(32, 32);
            for i in 0..3 {
                assert!(
                    (normal[i] - expected[i]).abs() < 0.01,
                    "{kind}: normal {normal:?}, expected {expected:?}"
                );
            }
            assert!(
                (position[3] - 0.2).abs() < 0.002,
                "{kind}: roughness {}",
                position[3]
            );

            scene.objects[0].material.roughness_map = None;
            let frame = render(backend.as_mut(), &scene);
            let position = frame
                .output(TargetId::GBuffer(GBufferTarget::Position))
                .unwrap()
                .pixel(32, 32);
            assert!(
                (position[3] - 0.9).abs() < 0.001,
                "{kind}: scalar roughness {}",
                position[3]
            );
        }
    }
}

/// Gizmos are off by default and, when on, add a pass that draws over the final image only.
#[test]
fn gizmos_are_optional_and_only_touch_the_final_image() {
    let mut scene = test_scenes::five_models(96);
    assert!(!scene.quality.gizmos);
    for kind in common::available_backends() {
        let mut backend = engine::backend::create(kind).unwrap();
        scene.quality.gizmos = false;
        let plain = render(backend.as_mut(), &scene);
        scene.quality.gizmos = true;
        let with = render(backend.as_mut(), &scene);
        assert!(plain.plan.pass(PassId::Gizmos).is_none());
        assert!(with.plan.pass(PassId::Gizmos).is_some());
        assert_eq!(
            plain.outputs[&TargetId::Light],
            with.outputs[&TargetId::Light],
            "{kind}"
        );
        let changed = harness::golden::metrics::compare::u8_difference(
            &plain.outputs[&TargetId::Final],
            &with.outputs[&TargetId::Final],
            0,
        )
        .unwrap()
        .pixels_over;
        assert!(changed > 50, "{kind}: gizmos changed only {changed} pixels");
    }
}

/// Specialisation: scenes with different features get different lighting pipelines (their
/// variants differ, and rendering the second compiles new pipelines), and rendering a scene
/// again compiles nothing new (every backend caches pipelines by shader, state and constants).
#[test]
fn lighting_variants_follow_the_scene_and_are_compiled_once() {
    harness::use_ibl_cache();
    let chess = harness::load_scene("chess").unwrap().scene;
    let ibl = harness::load_scene("ibl").unwrap().scene;
    let variants = |scene: &Scene| {
        let prepared = PreparedFrame::new(scene).unwrap();
        prepared
            .plan()
            .lighting
            .iter()
            .flat_map(|pass| pass.draws.iter().map(|d| d.variant))
            .collect::<Vec<_>>()
    };
    let (chess_variants, ibl_variants) = (variants(&chess), variants(&ibl));
    // chess: a shadowed directional sun and a point light, clearcoat, no anisotropy; ibl: no
    // lights, IBL, clearcoat and anisotropy.
    assert!(chess_variants
        .iter()
        .any(|v| v.shadow.is_some() && v.lights == 1));
    assert!(chess_variants.iter().all(|v| v.clearcoat && !v.anisotropy));
    assert!(ibl_variants
        .iter()
        .all(|v| v.ibl && v.anisotropy && v.lights == 0));
    assert!(chess_variants.iter().all(|v| !ibl_variants.contains(v)));
    for kind in common::available_backends() {
        let mut backend = engine::backend::create(kind).unwrap();
        let before = backend.pipelines_compiled();
        renderer::render(backend.as_mut(), &chess, Readback::Only(&[])).unwrap();
        let after_chess = backend.pipelines_compiled();
        assert!(after_chess > before, "{kind}: nothing compiled");
        renderer::render(backend.as_mut(), &chess, Readback::Only(&[])).unwrap();
        assert_eq!(
            backend.pipelines_compiled(),
            after_chess,
            "{kind}: rendering chess again compiled pipelines"
        );
        renderer::render(backend.as_mut(), &ibl, Readback::Only(&[])).unwrap();
        assert!(
            backend.pipelines_compiled() > after_chess,
            "{kind}: ibl's lighting variants came from chess's pipelines"
        );
    }
}

/// A scene with an environment and no objects renders the sky in every pixel (it panicked
/// indexing the shader mask, which such a scene does not have), the same sky as where the ibl
/// scene's objects leave it visible.
#[test]
fn an_environment_without_objects_renders_the_sky_everywhere() {
    harness::use_ibl_cache();
    let with_objects = harness::load_scene("ibl").unwrap().scene;
    let mut empty = with_objects.clone();
    empty.objects.clear();
    for kind in common::available_backends() {
        let mut backend = engine::backend::create(kind).unwrap();
        let sky = renderer::render(backend.as_mut(), &empty, Readback::Only(&[TargetId::Light]))
            .unwrap_or_else(|e| panic!("{kind}: {e}"));
        let sky = sky.output(TargetId::Light).unwrap().as_f32().unwrap();
        assert!(
            sky.chunks_exact(4)
                .all(|p| p[..3].iter().all(|v| v.is_finite() && *v > 0.0)),
            "{kind}: a pixel without sky"
        );
        let full = render(backend.as_mut(), &with_objects);
        let light = full.output(TargetId::Light).unwrap().as_f32().unwrap();
        let mask = full.output(TargetId::Mask(0)).unwrap().as_u8().unwrap();
        let mut compared = 0;
        for (i, (a, b)) in sky.chunks_exact(4).zip(light.chunks_exact(4)).enumerate() {
            if mask[i * 4..i * 4 + 4].iter().all(|&m| m == 0) {
                assert_eq!(a[..3], b[..3], "{kind}: pixel {i}");
                compared += 1;
            }
        }
        assert!(compared > 1000, "{kind}: {compared} sky pixels compared");
    }
}

/// Culling: a render that asks only for some targets ([`Readback::Needed`]) runs only the passes
/// they depend on, and gives the same targets, bit for bit, as the whole frame: the G-buffer
/// alone (geometry and mask only), the shadow terms (no lighting, no tone mapping), the light
/// buffer (no tone mapping), on every backend; and each target of the plan alone (the mask
/// alone needs the depth its pass tests against), on the first. On chess (shadowed sun and point
/// light, environment) and arrow (two lighting models), at 128 x 128 (culling works on the
/// recorded passes, whatever their size).
#[test]
fn culled_renders_give_the_whole_frame_s_targets() {
    harness::use_ibl_cache();
    let scenes: Vec<Scene> = ["chess", "arrow"]
        .map(|name| {
            let mut scene = harness::load_scene(name).unwrap().scene;
            scene.quality.debug_shadow_terms = true;
            (scene.quality.width, scene.quality.height) = (128, 128);
            scene
        })
        .into();
    for (index, kind) in common::available_backends().into_iter().enumerate() {
        let first = index == 0;
        let mut backend = engine::backend::create(kind).unwrap();
        for scene in &scenes {
            let name = &scene.name;
            let prepared = PreparedFrame::new(scene).unwrap();
            let plan = prepared.plan();
            let terms: Vec<TargetId> = plan
                .target_ids()
                .into_iter()
                .filter(|t| matches!(t, TargetId::ShadowTerm { .. }))
                .collect();
            assert!(!terms.is_empty(), "{name} has no shadow term");
            let mut gbuffer = TargetId::GBUFFER.to_vec();
            gbuffer.extend([TargetId::Depth, TargetId::Mask(0)]);
            // Each wanted set, and the passes that must not run for it.
            type Culled = fn(PassId) -> bool;
            let mut cases: Vec<(Vec<TargetId>, Culled)> = vec![
                (gbuffer, |p| {
                    matches!(
                        p,
                        PassId::Shadow { .. }
                            | PassId::ShadowBlur { .. }
                            | PassId::ShadowTerm { .. }
                            | PassId::Skybox
                            | PassId::Lighting(_)
                            | PassId::ToneMap
                    )
                }),
                (terms, |p| {
                    matches!(p, PassId::Skybox | PassId::Lighting(_) | PassId::ToneMap)
                }),
                (vec![TargetId::Light], |p| {
                    matches!(p, PassId::ShadowTerm { .. } | PassId::ToneMap)
                }),
            ];
            if first {
                let nothing: Culled = |_| false;
                cases.extend(plan.target_ids().into_iter().map(|t| (vec![t], nothing)));
            }
            let whole = render(backend.as_mut(), scene);
            for (wanted, culled) in &cases {
                let wanted = wanted.as_slice();
                let frame = renderer::render(backend.as_mut(), scene, Readback::Needed(wanted))
                    .unwrap_or_else(|e| panic!("{name} on {kind}: {e}"));
                for target in wanted {
                    assert!(
                        bitwise_equal(&frame.outputs[target], &whole.outputs[target]),
                        "{name} on {kind}: {target} differs when only {wanted:?} are rendered"
                    );
                }
                let ran: Vec<PassId> = frame.timings.owners.clone();
                assert!(
                    ran.iter().all(|&pass| !culled(pass)),
                    "{name} on {kind}: for {wanted:?}, {ran:?} ran"
                );
            }
        }
    }
}

/// An object mirrored by a negative scale is drawn from outside, its bumps the right way up: its
/// triangles are wound the other way round on screen, so the renderer culls its front faces
/// instead of its back faces, and its tangent frames change handedness. Corner's sphere mirrored
/// across its own centre is the same sphere (only its quads' diagonals swap): the final image
/// matches the unmirrored one within the final image's tolerance; culled as before, the sphere
/// showed its inside. A mirrored floor's normal map bends the normal as the mirror image of the
/// unmirrored floor's.
#[test]
fn a_mirrored_object_is_drawn_from_outside_with_its_bumps_mirrored() {
    use engine::scene::{Material, TextureImage};
    use std::sync::Arc;

    let corner = engine::scene_file::load(&harness::scenes_dir().join("corner.toml"))
        .unwrap()
        .scene;
    let mut mirrored = corner.clone();
    let sphere = mirrored
        .objects
        .iter_mut()
        .find(|o| o.name == "sphere")
        .expect("corner's sphere");
    sphere.transform.scale.x = -sphere.transform.scale.x;
    assert!(sphere.transform.mirrors());
    // Tangent-space normals (0.6, 0, 0.8) and (0, 0.6, 0.8), encoded n * 0.5 + 0.5, on a floor
    // seen from above, its tangent along +x (mirrored: -x) and its bitangent along -z.
    let cases = [
        ([204u8, 128, 230, 255], [-0.6f32, 0.8, 0.0]),
        ([128u8, 204, 230, 255], [0.0f32, 0.8, -0.6]),
    ];
    for kind in common::available_backends() {
        let mut backend = engine::backend::create(kind).unwrap();
        let a = render(backend.as_mut(), &corner);
        let b = render(backend.as_mut(), &mirrored);
        let diff = harness::golden::metrics::compare::u8_difference(
            a.output(TargetId::Final).unwrap(),
            b.output(TargetId::Final).unwrap(),
            1,
        )
        .unwrap();
        eprintln!("{kind}: mirrored sphere {diff:?}");
        assert!(
            diff.fraction_within >= 0.999,
            "{kind}: only {:.3}% of pixels within 1/255 with the sphere mirrored",
            diff.fraction_within * 100.0
        );
        for (encoded, expected) in cases {
            let mut scene = test_scenes::many_point_lights(64, 1);
            scene.camera.position = DVec3::new(0.0, 5.0, 0.01);
            scene.textures = vec![Arc::new(TextureImage {
                label: format!("{encoded:?}"),
                srgb: false,
                width: 2,
                height: 2,
                format: engine::assets::TexelFormat::Rgba8,
                mips: vec![encoded.repeat(4), encoded.to_vec()],
            })];
            scene.objects[0].material = Material {
                normal_map: Some(0),
                ..Material::default()
            };
            scene.objects[0].transform.scale.x = -1.0;
            let frame = render(backend.as_mut(), &scene);
            let normal = frame
                .output(TargetId::GBuffer(GBufferTarget::Normal))
                .unwrap()
                .pixel(32, 32);
            for i in 0..3 {
                assert!(
                    (normal[i] - expected[i]).abs() < 0.01,
                    "{kind}: mirrored floor's normal {normal:?}, expected {expected:?}"
                );
            }
        }
    }
}

//! Shadow maps: no acne on an open plane at any sun elevation, for every filter and both light
//! types, on every available backend.

use crate::common;
use engine::plan::{GBufferTarget, PassId, TargetId};
use std::sync::Arc;

use engine::mesh;
use engine::renderer::{self, Readback};
use engine::scene::*;
use glam::DVec3;

/// A 4 m ground plane (the only shadow caster, so nothing can occlude it) under one light.
fn plane_scene(light: Light) -> Scene {
    Scene {
        name: "acne".to_owned(),
        camera: Camera {
            position: DVec3::new(0.0, 2.5, 3.0),
            target: DVec3::ZERO,
            up: DVec3::Y,
            fov_y_degrees: 50.0,
            near: 0.05,
            far: 50.0,
        },
        objects: vec![Object {
            name: "ground".to_owned(),
            mesh: Arc::new(mesh::plane(4.0, 4.0)),
            transform: Transform::default(),
            material: Material::default(),
            lighting: LightingModel::Pbr,
            casts_shadows: true,
        }],
        lights: vec![light],
        ambient: [0.0; 3],
        environment: None,
        textures: vec![],
        quality: Quality {
            width: 256,
            height: 256,
            ..Quality::default()
        },
    }
}

/// The targets the ray-cast comparison reads for `light` in `scene`.
fn visibility_targets(scene: &engine::scene::Scene, light: usize) -> Vec<TargetId> {
    let prepared = engine::renderer::PreparedFrame::new(scene).unwrap();
    harness::reference::shadows::visibility_targets(prepared.plan(), light)
}

/// Renders the open plane under `light`: its light buffer and mask.
fn render_plane(backend: &mut dyn engine::Backend, light: Light) -> renderer::Frame {
    renderer::render(
        backend,
        &plane_scene(light),
        Readback::Needed(&[TargetId::Light, TargetId::Mask(0)]),
    )
    .unwrap()
}

/// The fraction of covered pixels whose light-buffer value is unchanged by the shadow map (shadow
/// term exactly 1): `shadowed` against `plain`, the same light without a shadow.
fn fully_lit_fraction(shadowed: &renderer::Frame, plain: &renderer::Frame) -> f64 {
    assert!(shadowed
        .plan
        .target(TargetId::Shadow { light: 0 })
        .is_some());
    let mask = plain.outputs[&TargetId::Mask(0)].as_u8().unwrap();
    let a = shadowed.outputs[&TargetId::Light].as_f32().unwrap();
    let b = plain.outputs[&TargetId::Light].as_f32().unwrap();
    let (mut covered, mut same) = (0usize, 0usize);
    for i in 0..mask.len() / 4 {
        if mask[i * 4] == 0 {
            continue;
        }
        covered += 1;
        if a[i * 4..i * 4 + 3] == b[i * 4..i * 4 + 3] {
            same += 1;
        }
    }
    assert!(covered > 10_000, "plane covers only {covered} pixels");
    same as f64 / covered as f64
}

/// A light of the acne test, given its shadow settings.
type LightWithShadow<'a> = dyn Fn(Option<ShadowSettings>) -> Light + 'a;

/// Every shadow filter under a directional light at 5, 15, 45 and 90 degrees and a point light
/// at matching heights leaves at least 99.99% of an open plane fully lit (no acne). Each
/// light's unshadowed render serves all the filters.
#[test]
fn open_plane_has_no_shadow_acne() {
    let filters = [
        ShadowFilter::Hard,
        ShadowFilter::Pcf3,
        ShadowFilter::Bilinear,
        ShadowFilter::Pcf3Bilinear,
        ShadowFilter::Soft,
        ShadowFilter::Vsm,
    ];
    for kind in common::available_backends() {
        let mut backend = engine::backend::create(kind).unwrap();
        for elevation in [5.0f64, 15.0, 45.0, 90.0] {
            let e = elevation.to_radians();
            let azimuth = 0.6f64;
            let direction = DVec3::new(e.cos() * azimuth.cos(), e.sin(), e.cos() * azimuth.sin());
            let height = 1.5 * e.sin().max(0.05);
            let directional = |shadow| Light::Directional {
                direction,
                color: [1.0; 3],
                intensity: 3.0,
                angular_radius: 0.0,
                shadow,
            };
            let point = |shadow| Light::Point {
                position: DVec3::new(0.3, height, 0.2),
                color: [1.0; 3],
                intensity: 3.0,
                radius: 6.0,
                falloff: 1.0,
                shadow,
            };
            let lights: [(&str, &LightWithShadow); 2] =
                [("directional", &directional), ("point", &point)];
            for (what, light) in lights {
                let plain = render_plane(backend.as_mut(), light(None));
                for filter in filters {
                    if filter == ShadowFilter::Vsm && what == "point" {
                        continue; // directional lights only
                    }
                    let shadow = Some(ShadowSettings {
                        filter,
                        ..ShadowSettings::default()
                    });
                    let shadowed = render_plane(backend.as_mut(), light(shadow));
                    let fraction = fully_lit_fraction(&shadowed, &plain);
                    eprintln!(
                        "{kind} {filter:?} {what} at {elevation} deg (point height {height:.3}): \
                         {fraction:.6} fully lit"
                    );
                    assert!(
                        fraction >= 0.9999,
                        "{kind}: {filter:?} {what} light at {elevation} deg (point height \
                         {height:.3}): only {:.4}% fully lit",
                        fraction * 100.0
                    );
                }
            }
        }
    }
}

/// Hard-shadow visibility from the GPU (the lighting pass's own lookup, read back through the
/// `shadow_term_<light>` debug output) against exact ray casting from each G-buffer position to
/// the light: chess's sun (directional), chess's point light (given default shadow settings)
/// and arrow's point light at default bias, misclassified on at most 0.5% of the lit-surface
/// pixels.
#[test]
fn hard_shadows_match_the_ray_cast_reference() {
    // chess's sunset maps come from the IBL caches: the precompute is not under test here.
    harness::use_ibl_cache();
    for (scene_name, light) in [("chess", 0usize), ("chess", 1), ("arrow", 0)] {
        let mut scene = harness::load_scene(scene_name).unwrap().scene;
        scene.quality.debug_shadow_terms = true;
        if let Light::Point {
            shadow, position, ..
        } = &mut scene.lights[light]
        {
            if shadow.is_none() {
                // Chess's point light sits beside the camera, so its shadows hide behind the
                // checkers; from behind them, they fall towards the camera.
                *position = DVec3::new(0.09, 0.07, -0.09);
                *shadow = Some(ShadowSettings::default());
            }
        }
        for l in &mut scene.lights {
            if let Light::Directional {
                shadow: Some(s), ..
            }
            | Light::Point {
                shadow: Some(s), ..
            } = l
            {
                s.filter = ShadowFilter::Hard;
            }
        }
        let wanted = visibility_targets(&scene, light);
        for kind in common::available_backends() {
            let mut backend = engine::backend::create(kind).unwrap();
            let frame =
                renderer::render(backend.as_mut(), &scene, Readback::Needed(&wanted)).unwrap();
            let error =
                harness::reference::shadows::visibility_error(&scene, &frame, light, 1e-4).unwrap();
            eprintln!("{scene_name} light {light} on {kind}: {error:?}");
            assert!(
                error.shadowed_by_reference > 1000,
                "{scene_name}: the reference finds only {} shadowed pixels",
                error.shadowed_by_reference
            );
            assert!(
                error.fraction <= 0.005,
                "{scene_name} on {kind}: {:.3}% of lit-surface pixels misclassified",
                error.fraction * 100.0
            );
        }
    }
}

/// A 0.4 m box standing on a plane under a 30-degree sun, hard filter, default bias: in the
/// contact zone (plane points whose ray to the sun enters the box within 10 texels of its base),
/// the points the GPU lights although the box shadows them (peter-panning) lie at most two
/// shadow-map texels (plus one pixel's footprint) from the box's base.
#[test]
fn box_on_a_plane_shows_at_most_a_two_texel_contact_gap() {
    let elevation = 30f64.to_radians();
    let azimuth = 0.6f64;
    let direction = DVec3::new(
        elevation.cos() * azimuth.cos(),
        elevation.sin(),
        elevation.cos() * azimuth.sin(),
    );
    let mut scene = plane_scene(Light::Directional {
        direction,
        color: [1.0; 3],
        intensity: 3.0,
        angular_radius: 0.0,
        shadow: Some(ShadowSettings {
            filter: ShadowFilter::Hard,
            ..ShadowSettings::default()
        }),
    });
    scene.objects.push(Object {
        name: "box".to_owned(),
        mesh: Arc::new(mesh::cube()),
        transform: Transform {
            translation: DVec3::new(0.0, 0.2, 0.0),
            scale: DVec3::splat(0.2),
            ..Transform::default()
        },
        material: Material::default(),
        lighting: LightingModel::Pbr,
        casts_shadows: true,
    });
    // Look down at the shadowed side of the box, close enough for ~1.5 mm pixels.
    scene.camera.position = DVec3::new(-0.9, 1.1, -0.7);
    scene.camera.target = DVec3::new(-0.3, 0.0, -0.25);
    scene.quality.width = 512;
    scene.quality.height = 512;
    scene.quality.debug_shadow_terms = true;
    let texel = renderer::shadows::shadow_views(&scene)[0].texel_world;
    for kind in common::available_backends() {
        let mut backend = engine::backend::create(kind).unwrap();
        let wanted = [
            TargetId::ShadowTerm { light: 0 },
            TargetId::GBuffer(GBufferTarget::Position),
            TargetId::Depth,
        ];
        let frame = renderer::render(backend.as_mut(), &scene, Readback::Needed(&wanted)).unwrap();
        let term = frame.outputs[&TargetId::ShadowTerm { light: 0 }]
            .as_f32()
            .unwrap();
        let position = frame.outputs[&TargetId::GBuffer(GBufferTarget::Position)]
            .as_f32()
            .unwrap();
        let depth = frame.outputs[&TargetId::Depth].as_f32().unwrap();
        let (mut gap, mut shadowed, mut pixel, mut contact) = (0.0f64, 0usize, 0.0f64, 0usize);
        for i in 0..depth.len() {
            if depth[i] >= 1.0 {
                continue;
            }
            let p = DVec3::new(
                position[i * 4] as f64,
                position[i * 4 + 1] as f64,
                position[i * 4 + 2] as f64,
            ) + scene.camera.position;
            if p.y.abs() > 1e-3 {
                continue; // on the box, not the plane
            }
            if p.x.abs() < 0.3 && p.z.abs() < 0.3 && i + 1 < depth.len() && depth[i + 1] < 1.0 {
                // Pixel footprint near the box.
                let q = DVec3::new(
                    position[i * 4 + 4] as f64,
                    position[i * 4 + 5] as f64,
                    position[i * 4 + 6] as f64,
                ) + scene.camera.position;
                if q.y.abs() < 1e-3 {
                    pixel = pixel.max((q - p).length());
                }
            }
            // Where does the ray to the light enter the box (slab test)?
            let d = direction.normalize();
            let (lo, hi) = (DVec3::new(-0.2, 0.0, -0.2), DVec3::new(0.2, 0.4, 0.2));
            let t0 = (lo - p) / d;
            let t1 = (hi - p) / d;
            let near = t0.min(t1).max_element();
            let far = t0.max(t1).min_element();
            if near > far || far <= 0.0 {
                continue; // not in the box's shadow
            }
            shadowed += 1;
            let entry = p + d * near.max(0.0);
            // The contact zone: points whose shadow comes from the bottom 10 texels of a side
            // face, away from its vertical edges (there a shadow edge runs past, not a contact).
            let lateral = if (entry.x.abs() - 0.2).abs() < 1e-9 {
                0.2 - entry.z.abs()
            } else {
                0.2 - entry.x.abs()
            };
            if entry.y > 10.0 * texel || lateral < 2.0 * texel {
                continue;
            }
            contact += 1;
            if term[i * 4] > 0.5 {
                let dx = (p.x.abs() - 0.2).max(0.0);
                let dz = (p.z.abs() - 0.2).max(0.0);
                gap = gap.max((dx * dx + dz * dz).sqrt());
            }
        }
        eprintln!(
            "{kind}: contact gap {:.2} mm = {:.2} texels (texel {:.2} mm, pixel {:.2} mm), {shadowed} shadowed plane pixels, {contact} in the contact zone",
            gap * 1e3,
            gap / texel,
            texel * 1e3,
            pixel * 1e3
        );
        assert!(
            shadowed > 5000,
            "{kind}: only {shadowed} shadowed plane pixels in view"
        );
        assert!(
            contact > 500,
            "{kind}: only {contact} pixels in the contact zone"
        );
        assert!(
            gap <= 2.0 * texel + pixel,
            "{kind}: contact gap {:.2} mm > 2 texels ({:.2} mm) + 1 pixel ({:.2} mm)",
            gap * 1e3,
            2.0 * texel * 1e3,
            pixel * 1e3
        );
    }
}

/// Stratified soft shadows: with the outer-ring early-out, the shadow term equals the full
/// 16-sample kernel on every pixel outside the penumbrae (where the full kernel is exactly 0 or
/// 1), and the penumbrae are really soft (fractional terms exist): chess's sun, and arrow's point
/// light, whose taps offset the lookup direction across cube faces.
#[test]
fn soft_shadow_early_out_matches_the_full_kernel_outside_penumbrae() {
    // chess's sunset maps come from the IBL caches: the precompute is not under test here.
    harness::use_ibl_cache();
    let term = |backend: &mut dyn engine::Backend, scene_name: &str, filter: ShadowFilter| {
        let mut scene = harness::load_scene(scene_name).unwrap().scene;
        scene.quality.debug_shadow_terms = true;
        for l in &mut scene.lights {
            if let Light::Directional {
                shadow: Some(s), ..
            }
            | Light::Point {
                shadow: Some(s), ..
            } = l
            {
                s.filter = filter;
            }
        }
        let frame = renderer::render(
            backend,
            &scene,
            Readback::Needed(&[TargetId::ShadowTerm { light: 0 }]),
        )
        .unwrap();
        frame.outputs[&TargetId::ShadowTerm { light: 0 }]
            .as_f32()
            .unwrap()
            .to_vec()
    };
    for kind in common::available_backends() {
        let mut backend = engine::backend::create(kind).unwrap();
        for scene_name in ["chess", "arrow"] {
            let early = term(backend.as_mut(), scene_name, ShadowFilter::Soft);
            let full = term(backend.as_mut(), scene_name, ShadowFilter::SoftFull);
            let (mut outside, mut penumbra) = (0usize, 0usize);
            for (i, (e, f)) in early.iter().zip(&full).enumerate().step_by(4) {
                if *f == 0.0 || *f == 1.0 {
                    outside += 1;
                    assert_eq!(
                        e,
                        f,
                        "{kind} {scene_name}: pixel {} differs outside the penumbra",
                        i / 4
                    );
                } else {
                    penumbra += 1;
                }
            }
            eprintln!(
                "{kind} {scene_name}: {outside} pixels outside penumbrae agree; {penumbra} penumbra pixels"
            );
            assert!(
                penumbra > 500,
                "{kind} {scene_name}: only {penumbra} penumbra pixels: not soft"
            );
        }
    }
}

/// Variance shadow maps on chess's sun: every shadow term finite and within 0..1, penumbrae soft,
/// and on the right side of 0.5 against exact ray casting on nearly every lit-surface pixel
/// (VSM's light bleeding and blur make it less exact than PCF; the sweep reports the figure).
#[test]
fn variance_shadow_maps_agree_with_the_ray_cast_reference() {
    // chess's sunset maps come from the IBL caches: the precompute is not under test here.
    harness::use_ibl_cache();
    let mut scene = harness::load_scene("chess").unwrap().scene;
    scene.quality.debug_shadow_terms = true;
    if let Light::Directional {
        shadow: Some(s), ..
    } = &mut scene.lights[0]
    {
        s.filter = ShadowFilter::Vsm;
    }
    assert!(scene.lights[0].casts_shadows());
    let wanted = visibility_targets(&scene, 0);
    for kind in common::available_backends() {
        let mut backend = engine::backend::create(kind).unwrap();
        let frame = renderer::render(backend.as_mut(), &scene, Readback::Needed(&wanted)).unwrap();
        let term = frame.outputs[&TargetId::ShadowTerm { light: 0 }]
            .as_f32()
            .unwrap();
        assert!(
            term.iter()
                .all(|t| t.is_finite() && (0.0..=1.0).contains(t)),
            "{kind}: VSM term outside 0..1"
        );
        let fractional = term
            .iter()
            .step_by(4)
            .filter(|t| **t > 0.0 && **t < 1.0)
            .count();
        let error = harness::reference::shadows::visibility_error(&scene, &frame, 0, 1e-4).unwrap();
        eprintln!("chess VSM on {kind}: {error:?}, {fractional} fractional terms");
        assert!(
            fractional > 500,
            "{kind}: only {fractional} penumbra pixels"
        );
        assert!(
            error.fraction <= 0.005,
            "{kind}: VSM misclassifies {:.3}% of lit-surface pixels",
            error.fraction * 100.0
        );
    }
}

/// VSM is for directional lights: asking for it on a point light is an error naming the light.
#[test]
fn variance_shadow_maps_on_a_point_light_are_refused() {
    let mut scene = plane_scene(Light::Point {
        position: DVec3::new(0.0, 1.0, 0.0),
        color: [1.0; 3],
        intensity: 1.0,
        radius: 5.0,
        falloff: 1.0,
        shadow: Some(ShadowSettings {
            filter: ShadowFilter::Vsm,
            ..ShadowSettings::default()
        }),
    });
    scene.name = "vsm-point".to_owned();
    let error = renderer::validate(&scene).unwrap_err().to_string();
    assert!(
        error.contains("light 0") && error.contains("vsm") && error.contains("directional"),
        "{error}"
    );
}

/// The Quarantamaula engine's single-pass point shadow (its Listing 2: a geometry shader routing each triangle to its face's
/// viewport; gl only) fills the atlas with the same depth as six passes, bit for bit, and so
/// gives the same light buffer; a backend without geometry shaders refuses it with an error
/// instead of silently drawing six passes.
#[test]
fn geometry_shader_point_shadows_equal_six_passes() {
    let six_passes = harness::load_scene("arrow").unwrap().scene;
    assert!(six_passes.lights[0].casts_shadows());
    let mut single_pass = six_passes.clone();
    single_pass.quality.point_shadows = PointShadowPass::GeometryShader;
    let wanted = [TargetId::Shadow { light: 0 }, TargetId::Light];
    for kind in common::available_backends() {
        let mut backend = engine::backend::create(kind).unwrap();
        if !backend.features().geometry_shaders {
            let error = renderer::render(backend.as_mut(), &single_pass, Readback::Only(&wanted))
                .err()
                .expect("a backend without geometry shaders must refuse the single-pass path");
            assert!(error.to_string().contains("geometry"), "{kind}: {error}");
            continue;
        }
        let a = renderer::render(backend.as_mut(), &six_passes, Readback::Only(&wanted)).unwrap();
        let b = renderer::render(backend.as_mut(), &single_pass, Readback::Only(&wanted)).unwrap();
        let shadow_passes = |frame: &renderer::Frame| {
            let owners = frame.timings.owners.iter();
            owners
                .filter(|o| **o == PassId::Shadow { light: 0 })
                .count()
        };
        assert_eq!((shadow_passes(&a), shadow_passes(&b)), (6, 1), "{kind}");
        for name in wanted {
            assert!(
                a.outputs[&name].as_f32().unwrap() == b.outputs[&name].as_f32().unwrap(),
                "{kind}: `{name}` differs between six passes and the geometry shader"
            );
        }
    }
}

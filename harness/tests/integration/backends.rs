//! Foundation acceptance on real drivers: the first scene agrees across backends, renders are
//! deterministic, readback orientation is pinned, and `harness backends --json` tells the truth.

use crate::common;
use engine::backend::*;
use engine::shaders;
use harness::first_scene;

#[test]
fn first_scene_agrees_across_backends() {
    let kinds = common::available_backends();
    assert!(!kinds.is_empty(), "no backend available at all");
    let renders: Vec<_> = kinds
        .iter()
        .map(|&k| {
            (
                k,
                first_scene::render(k).unwrap_or_else(|e| panic!("{k}: {e}")),
            )
        })
        .collect();
    let (reference, reference_images) = &renders[0];
    for (kind, images) in &renders[1..] {
        let a = first_scene::agreement(*kind, images, *reference, reference_images).unwrap();
        eprintln!("{a:?}");
        assert!(
            a.ldr.fraction_within >= first_scene::LDR_MIN_FRACTION,
            "{kind} vs {reference}: RGBA8 only {:.4}% of pixels within 1/255",
            a.ldr.fraction_within * 100.0
        );
        assert!(!a.hdr.non_finite, "{kind}: NaN or Inf in the HDR image");
        assert!(
            a.hdr.fraction_within >= first_scene::HDR_MIN_FRACTION,
            "{kind} vs {reference}: RGBA16F only {:.4}% of pixels within relative 1e-3",
            a.hdr.fraction_within * 100.0
        );
        assert!(
            a.hdr.max_abs <= first_scene::HDR_MAX_ABS,
            "{kind} vs {reference}: RGBA16F absolute difference {} at {:?}",
            a.hdr.max_abs,
            a.hdr.worst_pixel
        );
        assert!(
            a.depth.max_relative <= 1e-5,
            "{kind}: depth differs by {}",
            a.depth.max_relative
        );
    }
}

#[test]
fn first_scene_is_lit_and_covers_the_middle() {
    for kind in common::available_backends() {
        let images = first_scene::render(kind).unwrap();
        let centre = images
            .hdr
            .pixel(first_scene::SIZE / 2, first_scene::SIZE / 2);
        assert!(
            centre[..3].iter().any(|&c| c > 0.1),
            "{kind}: centre is unlit: {centre:?}"
        );
        let corner = images.depth.pixel(0, 0);
        assert_eq!(
            corner[0], 1.0,
            "{kind}: the corner should be background (depth 1)"
        );
        let middle = images
            .depth
            .pixel(first_scene::SIZE / 2, first_scene::SIZE / 2)[0];
        assert!(
            middle > 0.0 && middle < 1.0,
            "{kind}: centre depth {middle}"
        );
        let hdr_max = images
            .hdr
            .as_f32()
            .unwrap()
            .iter()
            .cloned()
            .fold(0.0f32, f32::max);
        assert!(
            hdr_max > 1.0,
            "{kind}: the HDR target should hold values above 1, max {hdr_max}"
        );
    }
}

#[test]
fn rendering_twice_gives_identical_bits() {
    for kind in common::available_backends() {
        let mut backend = create(kind).unwrap();
        let first = engine::lit_cube::render(backend.as_mut(), 64).unwrap();
        let second = engine::lit_cube::render(backend.as_mut(), 64).unwrap();
        assert_eq!(
            first.hdr, second.hdr,
            "{kind}: HDR differs between two renders"
        );
        assert_eq!(
            first.ldr, second.ldr,
            "{kind}: LDR differs between two renders"
        );
        assert_eq!(
            first.depth, second.depth,
            "{kind}: depth differs between two renders"
        );
        let fresh = first_scene::render(kind).unwrap();
        let again = first_scene::render(kind).unwrap();
        assert_eq!(
            fresh.ldr, again.ldr,
            "{kind}: LDR differs between two backends instances"
        );
        assert_eq!(
            backend.live_resources(),
            0,
            "{kind}: lit_cube::render leaked resources"
        );
    }
}

const PROBE: u32 = 16;

fn solid_target(backend: &mut dyn Backend, label: &str) -> Handle<Texture> {
    backend
        .create_texture(&TextureDesc::d2(
            label,
            PROBE,
            PROBE,
            TextureFormat::Rgba8Unorm,
        ))
        .unwrap()
}

fn probe_pipeline(
    backend: &mut dyn Backend,
    shader: Handle<Shader>,
    vs: &str,
    fs: &str,
    bindings: Vec<BindingLayout>,
) -> Handle<Pipeline> {
    backend
        .create_pipeline(&PipelineDesc {
            label: format!("orientation {fs}"),
            shader,
            vertex_entry: vs.to_owned(),
            fragment_entry: Some(fs.to_owned()),
            vertex_buffers: vec![],
            bindings,
            color_targets: vec![ColorTarget {
                format: TextureFormat::Rgba8Unorm,
                blend: None,
            }],
            depth: None,
            topology: Topology::TriangleList,
            cull: CullMode::Back,
            geometry: None,
            constants: vec![],
        })
        .unwrap()
}

fn pass(name: &str, target: Handle<Texture>, draw: Draw) -> RenderPass {
    RenderPass {
        name: name.to_owned(),
        color_attachments: vec![ColorAttachment {
            texture: target,
            subresource: Subresource::default(),
            load: LoadOp::Clear([0.0, 0.0, 0.0, 1.0]),
        }],
        depth_attachment: None,
        viewports: vec![],
        draws: vec![draw],
    }
}

/// An asymmetric image keeps its top-left marker top-left: through upload and readback, through
/// a texel-for-texel copy pass, and for a counter-clockwise triangle placed top-left in
/// normalized device coordinates with back-face culling on.
#[test]
fn readback_orientation_is_top_row_first_on_every_backend() {
    const RED: [u8; 4] = [255, 0, 0, 255];
    const BLUE: [u8; 4] = [0, 0, 255, 255];
    const BLACK: [u8; 4] = [0, 0, 0, 255];
    const GREEN: [u8; 4] = [0, 255, 0, 255];
    let mut marker = Vec::new();
    for y in 0..PROBE {
        for x in 0..PROBE {
            marker.extend_from_slice(match (x < 4, x >= PROBE - 4, y < 4) {
                (true, _, true) => &RED,
                (_, true, true) => &BLUE,
                _ => &BLACK,
            });
        }
    }
    let at = |image: &engine::Image, x: u32, y: u32| -> [u8; 4] {
        let p = image.pixel(x, y);
        [p[0] as u8, p[1] as u8, p[2] as u8, p[3] as u8]
    };
    for kind in common::available_backends() {
        let mut backend = create(kind).unwrap();
        let backend = backend.as_mut();
        let texture = solid_target(backend, "marker");
        backend
            .write_texture(texture, Subresource::default(), &marker)
            .unwrap();
        let round_trip = backend
            .read_texture(texture, Subresource::default())
            .unwrap();
        assert_eq!(
            round_trip.as_u8().unwrap(),
            &marker[..],
            "{kind}: upload/readback changed the image"
        );

        let shader = backend
            .create_shader(&ShaderDesc {
                name: shaders::ORIENTATION.name.to_owned(),
                wgsl: shaders::ORIENTATION.wgsl.to_owned(),
            })
            .unwrap();
        let copy = probe_pipeline(
            backend,
            shader,
            "vs_fullscreen",
            "fs_marker",
            vec![BindingLayout {
                binding: 0,
                kind: BindingKind::Texture {
                    sample_type: TextureSampleType::UnfilterableFloat,
                    view: TextureViewKind::D2,
                },
            }],
        );
        let corner = probe_pipeline(backend, shader, "vs_corner", "fs_solid", vec![]);
        let copied = solid_target(backend, "copied");
        let triangle = solid_target(backend, "triangle");
        let draw = |pipeline, bindings| Draw {
            pipeline,
            bindings,
            vertex_buffers: vec![],
            index_buffer: None,
            count: 3,
        };
        backend
            .submit(&[
                pass(
                    "copy",
                    copied,
                    draw(
                        copy,
                        vec![Binding {
                            binding: 0,
                            resource: BindingResource::Texture(texture),
                        }],
                    ),
                ),
                pass("corner", triangle, draw(corner, vec![])),
            ])
            .unwrap();
        let copied = backend
            .read_texture(copied, Subresource::default())
            .unwrap();
        assert_eq!(
            at(&copied, 1, 1),
            RED,
            "{kind}: copy pass: top-left marker moved"
        );
        assert_eq!(
            at(&copied, PROBE - 2, 1),
            BLUE,
            "{kind}: copy pass: top-right marker moved"
        );
        assert_eq!(
            at(&copied, 1, PROBE - 2),
            BLACK,
            "{kind}: copy pass: flipped vertically"
        );
        let triangle = backend
            .read_texture(triangle, Subresource::default())
            .unwrap();
        assert_eq!(
            at(&triangle, 1, 1),
            GREEN,
            "{kind}: CCW triangle culled or not top-left"
        );
        assert_eq!(
            at(&triangle, 1, PROBE - 2),
            BLACK,
            "{kind}: triangle drawn bottom-left"
        );
        assert_eq!(
            at(&triangle, PROBE - 2, 1),
            BLACK,
            "{kind}: triangle drawn top-right"
        );
    }
}

fn harness_backends_json(envs: &[(&str, &str)]) -> Vec<serde_json::Value> {
    let mut command = common::harness_command();
    command.args(["backends", "--json"]);
    for (k, v) in envs {
        command.env(k, v);
    }
    let output = command.output().expect("run harness");
    assert!(
        output.status.success(),
        "harness backends failed: {}",
        String::from_utf8_lossy(&output.stderr)
    );
    serde_json::from_slice(&output.stdout).expect("backends --json prints JSON")
}

#[test]
fn probing_the_backends_logs_no_error_where_every_backend_is_available() {
    // wgpu's GL backend logs an error for each EGL display it tries and cannot use before it
    // finds llvmpipe's; the harness leaves those out unless RUST_LOG asks for them.
    let available = common::available_backends();
    let output = common::harness_command()
        .arg("backends")
        .env_remove("RUST_LOG")
        .output()
        .expect("run harness");
    assert!(output.status.success());
    let stderr = String::from_utf8_lossy(&output.stderr);
    let errors: Vec<&str> = stderr.lines().filter(|l| l.contains(" ERROR ")).collect();
    if available.len() == BackendKind::ALL.len() {
        assert!(errors.is_empty(), "errors logged: {errors:?}");
    }
}

#[test]
fn backends_json_reports_every_backend_with_fingerprints() {
    let available = common::available_backends();
    let statuses = harness_backends_json(&[]);
    let names: Vec<&str> = statuses
        .iter()
        .map(|s| s["name"].as_str().unwrap())
        .collect();
    assert_eq!(names, ["gl", "wgpu-vulkan", "wgpu-gl"]);
    for status in &statuses {
        let name = status["name"].as_str().unwrap();
        let kind: BackendKind = name.parse().unwrap();
        assert_eq!(
            status["available"].as_bool().unwrap(),
            available.contains(&kind),
            "{name}"
        );
        if available.contains(&kind) {
            let info = &status["info"];
            assert!(
                !info["renderer"].as_str().unwrap().is_empty(),
                "{name}: no renderer"
            );
            assert!(info["env"].is_object(), "{name}: no env");
        } else {
            assert!(
                !status["reason"].as_str().unwrap().is_empty(),
                "{name}: no reason"
            );
            assert!(
                !status["fix"].as_str().unwrap().is_empty(),
                "{name}: no fix"
            );
        }
    }
    if available.contains(&BackendKind::Gl) {
        let gl = &statuses[0]["info"];
        let version = gl["api_version"].as_str().unwrap();
        let number = version.split_whitespace().next().unwrap_or_default();
        let mut parts = number.split('.').map(|n| n.parse::<u32>().unwrap_or(0));
        let (major, minor) = (parts.next().unwrap_or(0), parts.next().unwrap_or(0));
        assert!(
            (major, minor) >= (4, 5),
            "gl context {version} is older than 4.5"
        );
        assert!(
            version.contains("Core Profile") || !version.contains("Mesa"),
            "gl: {version} is not a core context"
        );
    }
}

/// With the Vulkan driver hidden, `wgpu-vulkan` is reported unavailable with a reason and a fix,
/// and the other backends are unaffected.
#[test]
fn a_missing_vulkan_driver_is_reported_not_fatal() {
    let available = common::available_backends();
    let statuses = harness_backends_json(&[
        ("VK_ICD_FILENAMES", "/nonexistent/icd.json"),
        ("VK_DRIVER_FILES", "/nonexistent/icd.json"),
    ]);
    let vulkan = &statuses[1];
    assert_eq!(vulkan["name"], "wgpu-vulkan");
    assert_eq!(vulkan["available"], false, "{vulkan}");
    assert!(
        vulkan["reason"].as_str().unwrap().contains("Vulkan"),
        "{vulkan}"
    );
    assert!(
        vulkan["fix"]
            .as_str()
            .unwrap()
            .contains("mesa-vulkan-drivers"),
        "{vulkan}"
    );
    assert_eq!(
        statuses[0]["available"].as_bool().unwrap(),
        available.contains(&BackendKind::Gl)
    );
}

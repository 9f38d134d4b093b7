//! No GPU object leaks: creating and dropping a backend with resources 50 times keeps process
//! memory flat, and (ignored by default: minutes) 500 renders of chess on one backend keep it
//! within 10% of its value after the first 20. Its own test binary, so no other test's
//! allocations disturb the measurement.

mod common;

use engine::backend::*;

/// Resident set size of this process, in bytes.
fn resident_bytes() -> u64 {
    let status = std::fs::read_to_string("/proc/self/status").expect("/proc/self/status");
    let kib: u64 = status
        .lines()
        .find_map(|l| l.strip_prefix("VmRSS:"))
        .and_then(|v| v.split_whitespace().next())
        .and_then(|v| v.parse().ok())
        .expect("VmRSS in /proc/self/status");
    kib * 1024
}

/// One cycle: a backend, a full render (which frees its own resources), and resources left
/// alive for the backend's Drop to free.
fn cycle(kind: BackendKind) {
    let mut backend = create(kind).unwrap();
    engine::lit_cube::render(backend.as_mut(), 64).unwrap();
    let texture = backend
        .create_texture(&TextureDesc::d2(
            "left alive",
            256,
            256,
            TextureFormat::Rgba16Float,
        ))
        .unwrap();
    backend
        .write_texture(texture, Subresource::default(), &vec![0u8; 256 * 256 * 8])
        .unwrap();
    backend
        .create_buffer(&BufferDesc {
            label: "left alive".into(),
            size: 1 << 20,
            usage: BufferUsage::Vertex,
        })
        .unwrap();
}

#[test]
fn creating_and_dropping_backends_keeps_memory_flat() {
    const WARM_UP: usize = 10;
    const CYCLES: usize = 50;
    /// Allowed growth over 50 cycles. One leaked cycle holds at least 1.5 MiB (the texture and
    /// buffer above), so a per-cycle leak shows up as 75 MiB or more.
    const BOUND: u64 = 24 << 20;
    for kind in common::available_backends() {
        for _ in 0..WARM_UP {
            cycle(kind);
        }
        let before = resident_bytes();
        for _ in 0..CYCLES {
            cycle(kind);
        }
        let after = resident_bytes();
        let growth = after.saturating_sub(before);
        eprintln!(
            "{kind}: RSS {} KiB -> {} KiB over {CYCLES} cycles (+{} KiB)",
            before >> 10,
            after >> 10,
            growth >> 10
        );
        assert!(
            growth <= BOUND,
            "{kind}: memory grew by {} KiB over {CYCLES} create/drop cycles",
            growth >> 10
        );
    }
}

/// Renders create their shaders and pipelines every frame: creating and destroying the same
/// pipeline 200 times on one backend keeps memory flat. (On wgpu's Vulkan path with lavapipe
/// each cycle kept ~450 KiB before the wgpu backend cached compiled pipelines.)
#[test]
fn recreating_a_pipeline_keeps_memory_flat() {
    const CYCLES: usize = 200;
    const BOUND: u64 = 16 << 20;
    let source = engine::shaders::TONEMAP;
    for kind in common::available_backends() {
        let mut backend = create(kind).unwrap();
        let mut cycle = || {
            let shader = backend
                .create_shader(&ShaderDesc {
                    name: source.name.into(),
                    wgsl: source.wgsl.into(),
                })
                .unwrap();
            let pipeline = backend
                .create_pipeline(&PipelineDesc {
                    label: "tonemap".into(),
                    shader,
                    vertex_entry: "vs_fullscreen".into(),
                    fragment_entry: Some("fs_tonemap".into()),
                    vertex_buffers: vec![],
                    bindings: vec![
                        BindingLayout {
                            binding: 0,
                            kind: BindingKind::UniformBuffer,
                        },
                        BindingLayout {
                            binding: 1,
                            kind: BindingKind::Texture {
                                sample_type: TextureSampleType::UnfilterableFloat,
                                view: TextureViewKind::D2,
                            },
                        },
                    ],
                    color_targets: vec![ColorTarget {
                        format: TextureFormat::Rgba8UnormSrgb,
                        blend: None,
                    }],
                    depth: None,
                    topology: Topology::TriangleList,
                    cull: CullMode::None,
                    geometry: None,
                    constants: vec![],
                })
                .unwrap();
            backend.destroy_pipeline(pipeline).unwrap();
            backend.destroy_shader(shader).unwrap();
        };
        for _ in 0..10 {
            cycle();
        }
        let before = resident_bytes();
        for _ in 0..CYCLES {
            cycle();
        }
        let growth = resident_bytes().saturating_sub(before);
        eprintln!(
            "{kind}: +{} KiB over {CYCLES} pipeline cycles",
            growth >> 10
        );
        assert!(
            growth <= BOUND,
            "{kind}: memory grew by {} KiB over {CYCLES} pipeline create/destroy cycles",
            growth >> 10
        );
    }
}

/// The soak test: 500 consecutive renders of chess on each backend (one backend each, as a
/// long-running check would use it); resident memory after them stays within 10% of its value
/// after the first 20. `cargo test --release --test leaks -- --ignored` (several minutes).
#[test]
#[ignore = "soak: 500 renders per backend, several minutes"]
fn five_hundred_chess_renders_keep_memory_within_ten_percent() {
    const WARM_UP: usize = 20;
    const RENDERS: usize = 500;
    let scene = harness::load_scene("chess").unwrap().scene;
    let mut failures = Vec::new();
    for kind in common::available_backends() {
        let mut backend = create(kind).unwrap();
        let mut after_warm_up = 0;
        for i in 0..RENDERS {
            engine::renderer::render(
                backend.as_mut(),
                &scene,
                engine::renderer::Readback::Only(&["final"]),
            )
            .unwrap();
            if i + 1 == WARM_UP {
                after_warm_up = resident_bytes();
            }
        }
        let after = resident_bytes();
        let growth = after as f64 / after_warm_up as f64 - 1.0;
        eprintln!(
            "{kind}: RSS {} KiB after {WARM_UP} renders, {} KiB after {RENDERS} ({:+.2}%)",
            after_warm_up >> 10,
            after >> 10,
            growth * 100.0
        );
        if growth > 0.10 {
            failures.push(format!(
                "{kind}: memory grew {:.1}% over {RENDERS} renders",
                growth * 100.0
            ));
        }
    }
    assert!(failures.is_empty(), "{}", failures.join("; "));
}

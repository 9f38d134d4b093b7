//! No GPU object leaks: creating and dropping a backend with resources 50 times keeps process
//! memory flat (and a backend leaked on purpose shows the bound would catch a leak by 3x or
//! more), and (ignored by default: minutes) 500 renders of chess on one backend keep it
//! within 10% of its value after the first 20. Each test runs in a child process of its own
//! (rusty-fork re-runs this binary for just that test), so no other test's allocations disturb
//! the measurement, while the other tests run beside it.

use crate::common;
use engine::backend::*;
use engine::plan::TargetId;
use rusty_fork::rusty_fork_test;

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

/// Bytes of the texture and of the buffer each cycle leaves alive for the backend's Drop: both
/// written, so that a leak of them is resident memory.
const TEXTURE_SIZE: u32 = 512;
const BUFFER_BYTES: usize = 2 << 20;

/// One cycle: a backend, a full render (which frees its own resources), and a texture and a
/// buffer left alive for the backend's Drop to free. Returns the backend, for the caller to drop
/// (or, to show what a leak looks like, to forget).
fn cycle(kind: BackendKind) -> Box<dyn Backend> {
    let mut backend = create(kind).unwrap();
    engine::lit_cube::render(backend.as_mut(), 64).unwrap();
    let texture = backend
        .create_texture(&TextureDesc::d2(
            "left alive",
            TEXTURE_SIZE,
            TEXTURE_SIZE,
            TextureFormat::Rgba16Float,
        ))
        .unwrap();
    // Non-zero data: zero pages could be shared copy-on-write and not count as resident.
    let texels = vec![0x3cu8; (TEXTURE_SIZE * TEXTURE_SIZE * 8) as usize];
    backend
        .write_texture(texture, Subresource::default(), &texels)
        .unwrap();
    let buffer = backend
        .create_buffer(&BufferDesc {
            label: "left alive".into(),
            size: BUFFER_BYTES as u64,
            usage: BufferUsage::Vertex,
        })
        .unwrap();
    backend
        .write_buffer(buffer, 0, &vec![0x5au8; BUFFER_BYTES])
        .unwrap();
    backend
}

/// Resident growth over `cycles` cycles, dropping each backend (or forgetting it: a leak).
fn growth_over(kind: BackendKind, cycles: usize, leak: bool) -> u64 {
    let before = resident_bytes();
    for _ in 0..cycles {
        let backend = cycle(kind);
        if leak {
            std::mem::forget(backend);
        }
    }
    resident_bytes().saturating_sub(before)
}

rusty_fork_test! {
    #[test]
    fn creating_and_dropping_backends_keeps_memory_flat() {
        const WARM_UP: usize = 10;
        const CYCLES: usize = 50;
        /// Allowed growth over 50 cycles: the measured no-leak growth is a few MiB (see the note
        /// printed), and the leak measured below must exceed this at least 3x.
        const BOUND: u64 = 24 << 20;
        /// Cycles leaked on purpose to measure what a per-cycle leak costs.
        const LEAKED: usize = 4;
        for kind in common::available_backends() {
            for _ in 0..WARM_UP {
                drop(cycle(kind));
            }
            let growth = growth_over(kind, CYCLES, false);
            // What the bound is for: a backend (with its texture and buffer) that is never freed.
            let leak_per_cycle = growth_over(kind, LEAKED, true) / LEAKED as u64;
            let leak_over_cycles = leak_per_cycle * CYCLES as u64;
            eprintln!(
                "{kind}: +{} KiB over {CYCLES} create/drop cycles (bound {} KiB); a leaked cycle \
                 holds {} KiB, {} KiB over {CYCLES} cycles ({:.1}x the bound)",
                growth >> 10,
                BOUND >> 10,
                leak_per_cycle >> 10,
                leak_over_cycles >> 10,
                leak_over_cycles as f64 / BOUND as f64
            );
            assert!(
                growth <= BOUND,
                "{kind}: memory grew by {} KiB over {CYCLES} create/drop cycles",
                growth >> 10
            );
            assert!(
                leak_over_cycles >= 3 * BOUND,
                "{kind}: a leaked cycle holds only {} KiB: the bound of {} KiB over {CYCLES} \
                 cycles would not catch it by 3x",
                leak_per_cycle >> 10,
                BOUND >> 10
            );
        }
    }
}

rusty_fork_test! {
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
}

rusty_fork_test! {
    /// The soak test: 500 consecutive renders of chess on each backend (one backend each, as a
    /// long-running check would use it); resident memory after them stays within 10% of its value
    /// after the first 20. `cargo test --release --test integration leaks:: -- --ignored` (several minutes).
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
                    engine::renderer::Readback::Only(&[TargetId::Final]),
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
}

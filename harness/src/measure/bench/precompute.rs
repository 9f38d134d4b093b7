//! Work done once per process rather than per frame (the shadow jitter texture, the IBL maps
//! and their caches), timed apart from frames.

use std::time::Instant;

use engine::stats::median;

/// Work done once, not per frame, timed apart from frames.
#[derive(Clone, Debug, serde::Serialize)]
pub struct Precompute {
    /// What is computed.
    pub what: String,
    /// Where it runs.
    pub on: String,
    /// Median time of a few runs, ms.
    pub ms: f64,
}

/// The precomputation the renderer does once per process, timed (median of 5 runs): the
/// stratified soft filter's jitter texture (CPU). The IBL maps join this list when they exist.
pub fn precompute() -> Vec<Precompute> {
    let runs: Vec<f64> = (0..5)
        .map(|_| {
            let start = Instant::now();
            std::hint::black_box(engine::renderer::shadows::compute_jitter_texels());
            start.elapsed().as_secs_f64() * 1e3
        })
        .collect();
    let mut out = vec![Precompute {
        what: "shadow jitter texture (32x32x8 RGBA16F)".to_owned(),
        on: "CPU, once per process".to_owned(),
        ms: median(runs).unwrap_or(0.0),
    }];
    out.extend(ibl_precompute());
    out
}

/// The IBL maps of the canonical environments at default settings: built from scratch (the DFG
/// table apart, as it is computed once per process), read back from a disk cache, and found in
/// memory (a second render in the same process). A build (about a second or two) and the DFG
/// table are timed once; the cache reads, median of 3.
fn ibl_precompute() -> Vec<Precompute> {
    use engine::ibl;
    let mut out = Vec::new();
    let start = Instant::now();
    std::hint::black_box(ibl::dfg::table(ibl::dfg::SIZE, ibl::dfg::SAMPLES));
    out.push(Precompute {
        what: format!(
            "IBL DFG table ({}x{}, {} samples)",
            ibl::dfg::SIZE,
            ibl::dfg::SIZE,
            ibl::dfg::SAMPLES
        ),
        on: "CPU, once per process".to_owned(),
        ms: start.elapsed().as_secs_f64() * 1e3,
    });
    ibl::dfg_table();
    let settings = ibl::IblSettings::default();
    let Ok(cache) = tempfile::tempdir() else {
        return out;
    };
    for name in ["sunset.exr", "interior.exr"] {
        let path = crate::scenes_dir().join("assets").join(name);
        let Ok(env) = engine::assets::load_environment(&path) else {
            continue;
        };
        let image = engine::scene::EnvironmentImage {
            label: name.to_owned(),
            width: env.width,
            height: env.height,
            texels: env.texels,
        };
        let timed = |f: &mut dyn FnMut()| {
            median(
                (0..3)
                    .map(|_| {
                        let start = Instant::now();
                        f();
                        start.elapsed().as_secs_f64() * 1e3
                    })
                    .collect(),
            )
            .unwrap_or(0.0)
        };
        let start = Instant::now();
        let maps = ibl::build(&image, &settings);
        out.push(Precompute {
            what: format!("IBL maps of {name}: {}", settings.describe()),
            on: "CPU, built".to_owned(),
            ms: start.elapsed().as_secs_f64() * 1e3,
        });
        let key = ibl::cache::key(&image, &settings);
        if ibl::cache::write(cache.path(), &key, &maps).is_ok() {
            let read = timed(&mut || {
                let key = ibl::cache::key(&image, &settings);
                std::hint::black_box(ibl::cache::read(cache.path(), &key));
            });
            out.push(Precompute {
                what: format!(
                    "IBL maps of {name}, from the disk cache (hash texels, read, verify)"
                ),
                on: "CPU, new process".to_owned(),
                ms: read,
            });
            let shared = std::sync::Arc::new(image);
            let previous = ibl::cache::directory();
            ibl::cache::set_directory(Some(cache.path().to_path_buf()));
            ibl::prepare(&shared, &settings);
            let again = timed(&mut || {
                std::hint::black_box(ibl::prepare(&shared, &settings));
            });
            ibl::cache::set_directory(previous);
            out.push(Precompute {
                what: format!("IBL maps of {name}, next frame of the same scene"),
                on: "CPU, in memory".to_owned(),
                ms: again,
            });
        }
    }
    out
}

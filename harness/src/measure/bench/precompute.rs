//! Work done once per process rather than per frame (the shadow jitter texture, the IBL maps
//! and their caches), timed apart from frames.

use std::time::Instant;

use engine::scene::Scene;
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

/// The precomputation the renderer does once per process for `scenes`, timed apart from frames:
/// the stratified soft filter's jitter texture (CPU, median of 5 runs), and with an environment
/// the DFG table and each distinct environment's IBL maps at its scene's settings.
pub fn precompute(scenes: &[Scene]) -> Vec<Precompute> {
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
    out.extend(ibl_precompute(scenes));
    out
}

/// The IBL maps of each distinct environment of `scenes` at its scene's settings: built from
/// scratch (the DFG table apart, as it is computed once per process), read back from a disk
/// cache, and found in memory (a second render in the same process). A build (about a second
/// or two) and the DFG table are timed once; the cache reads, median of 3. Nothing without an
/// environment.
fn ibl_precompute(scenes: &[Scene]) -> Vec<Precompute> {
    use engine::ibl;
    type Shared = std::sync::Arc<engine::scene::EnvironmentImage>;
    let mut environments: Vec<(&Shared, &ibl::IblSettings)> = Vec::new();
    for scene in scenes {
        if let Some(environment) = &scene.environment {
            let seen = environments.iter().any(|(image, settings)| {
                image.label == environment.image.label && **settings == scene.quality.ibl
            });
            if !seen {
                environments.push((&environment.image, &scene.quality.ibl));
            }
        }
    }
    let mut out = Vec::new();
    if environments.is_empty() {
        return out;
    }
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
    let Ok(cache) = tempfile::tempdir() else {
        return out;
    };
    for (image, settings) in environments {
        let name = std::path::Path::new(&image.label)
            .file_name()
            .map_or_else(|| image.label.clone(), |n| n.to_string_lossy().into_owned());
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
        let maps = ibl::build(image, settings);
        out.push(Precompute {
            what: format!("IBL maps of {name}: {}", settings.describe()),
            on: "CPU, built".to_owned(),
            ms: start.elapsed().as_secs_f64() * 1e3,
        });
        let key = ibl::cache::key(image, settings);
        if ibl::cache::write(cache.path(), &key, &maps).is_ok() {
            let read = timed(&mut || {
                let key = ibl::cache::key(image, settings);
                std::hint::black_box(ibl::cache::read(cache.path(), &key));
            });
            out.push(Precompute {
                what: format!(
                    "IBL maps of {name}, from the disk cache (hash texels, read, verify)"
                ),
                on: "CPU, new process".to_owned(),
                ms: read,
            });
            let previous = ibl::cache::directory();
            ibl::cache::set_directory(Some(cache.path().to_path_buf()));
            ibl::prepare(image, settings);
            let again = timed(&mut || {
                std::hint::black_box(ibl::prepare(image, settings));
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

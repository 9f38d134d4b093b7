//! Image-based lighting, precomputed on the CPU: the split-sum model's three maps, built from
//! an equirectangular environment.
//!
//! - [`CubeMap`] `specular`: the environment prefiltered with the GGX lobe, one roughness per
//!   mip ([`specular`] documents the roughness-to-mip mapping and the filtered importance
//!   sampling that keeps a bright sun from leaving fireflies).
//! - `irradiance`: diffuse irradiance / pi as a small cube, by exact convolution (default) or
//!   SH9 ([`irradiance`] says why).
//! - `dfg`: the DFG lookup table of the split sum ([`dfg`]).
//! - `radiance`: the environment cube itself with a box-filtered mip chain, which the lighting
//!   pass's filtered importance samples read (`[quality.ibl] runtime_samples`,
//!   `anisotropic_samples`): a sample reads the level whose texels cover `runtime_footprint`
//!   times its solid angle, so its footprint is blurred once, by the box filter, instead of by
//!   the GGX prefilter of the specular cube as well.
//!
//! Why the CPU: the maps are a pure function of the image and [`IblSettings`], so computing
//! them once, identically for every backend, keeps driver differences out of them (one golden
//! serves all backends), and the result can be cached on disk ([`cache`]) keyed by a hash of the
//! image and settings. The work is split over threads by texel, and every texel is computed
//! alone, so the maps are bit-identical whatever the thread count. Rotation and intensity are
//! applied when the lighting pass samples the maps, so changing them needs no precompute.

pub mod cache;
pub mod cube;
pub mod dfg;
pub mod irradiance;
pub mod specular;
pub mod sun;

use std::sync::Arc;
use std::time::Instant;

use glam::Vec3;
use serde::Serialize;

pub use cube::{CubeLevel, CubeMap};

use crate::scene::EnvironmentImage;

pub use crate::scene::{
    AnisotropicLookup, DominantDirection, Footprint, IblSettings, IrradianceMethod,
};

/// The settings' line in plans and reports (it names the precompute's own constants).
impl IblSettings {
    /// One line for plans and reports.
    pub fn describe(&self) -> String {
        format!(
            "specular {} x {} mips, {} GGX samples from a {} cube; irradiance {} {}; DFG {}x{}",
            self.specular_size,
            specular::level_count(self.specular_size),
            self.specular_samples,
            self.source_size,
            self.irradiance.name(),
            self.irradiance_size,
            dfg::SIZE,
            dfg::SIZE,
        ) + &if self.seed != 0 {
            format!(", seed {}", self.seed)
        } else {
            String::new()
        } + &if self.extract_sun && self.extracted_lights > 1 {
            format!(
                "; up to {} suns extracted into directional lights",
                self.extracted_lights
            )
        } else if self.extract_sun {
            "; sun extracted into a directional light".to_owned()
        } else {
            String::new()
        } + &if self.runtime_samples != 0 {
            format!(
                "; specular by {} filtered importance samples per pixel",
                self.runtime_samples
            )
        } else if self.anisotropic_samples != 0 {
            format!(
                "; specular by {} filtered importance samples on anisotropic pixels",
                self.anisotropic_samples
            )
        } else {
            String::new()
        } + &if self.runtime_footprint != Footprint::ONE {
            format!(", each reading {}x its solid angle", self.runtime_footprint)
        } else {
            String::new()
        } + if self.dominant_direction == DominantDirection::Frostbite {
            "; Frostbite's dominant direction"
        } else {
            ""
        } + if self.anisotropic_lookup == AnisotropicLookup::Taps {
            "; anisotropic pixels by taps"
        } else {
            ""
        }
    }
}

/// The precomputed maps of one environment.
#[derive(Clone, Debug, PartialEq)]
pub struct IblMaps {
    /// Prefiltered specular radiance; level `m` holds roughness `m / (levels - 1)`.
    pub specular: CubeMap,
    /// Irradiance / pi.
    pub irradiance: CubeLevel,
    /// DFG table (`scale`, `bias`), [`dfg::SIZE`] square, `NoV` across, roughness down.
    pub dfg: Vec<[f32; 2]>,
    /// The environment cube the prefilter reads (`source_size` faces), box-filtered down to
    /// 1 x 1: what filtered importance samples read.
    pub radiance: CubeMap,
    /// With `extract_sun`: the suns cut out of the maps (at most `extracted_lights`, in the
    /// order they were cut out), each to be lit as a directional light.
    pub suns: Vec<sun::Sun>,
}

impl IblMaps {
    /// Whether every value of the maps is finite: an environment bright enough to overflow
    /// the precompute's 32-bit sums (a texel near 3e38) leaves NaN or infinity in them.
    pub fn is_finite(&self) -> bool {
        let level = |l: &CubeLevel| l.texels.iter().flatten().all(|v| v.is_finite());
        let cube = |c: &CubeMap| c.levels.iter().all(level);
        cube(&self.specular)
            && cube(&self.radiance)
            && level(&self.irradiance)
            && self.dfg.iter().flatten().all(|v| v.is_finite())
            && self
                .suns
                .iter()
                .all(|s| s.direction.is_finite() && s.irradiance.iter().all(|v| v.is_finite()))
    }
}

/// Builds the maps (the whole precompute, no caches).
pub fn build(image: &EnvironmentImage, settings: &IblSettings) -> IblMaps {
    let (residual, suns) = if settings.extract_sun {
        sun::extract(image, settings.extracted_lights)
            .map_or((None, Vec::new()), |(residual, suns)| {
                (Some(residual), suns)
            })
    } else {
        (None, Vec::new())
    };
    let base = cube::cube_from_equirect(residual.as_ref().unwrap_or(image), settings.source_size);
    let source = CubeMap::with_mips(base, 1);
    IblMaps {
        specular: specular::prefilter(&source, settings),
        irradiance: irradiance::irradiance(&source, settings.irradiance_size, settings.irradiance),
        dfg: dfg_table().as_ref().clone(),
        radiance: source,
        suns,
    }
}

/// [`build`], timed, and the result kept in this process's memory cache, so that the next
/// [`prepare`] of the same image and settings (a render) reuses it: what a sweep that times the
/// precompute and then renders needs, without building twice.
pub fn build_timed(image: &Arc<EnvironmentImage>, settings: &IblSettings) -> (Arc<IblMaps>, f64) {
    let start = Instant::now();
    let maps = Arc::new(build(image, settings));
    let seconds = start.elapsed().as_secs_f64();
    cache::memory_put(cache::key_of_shared(image, settings), maps.clone());
    (maps, seconds)
}

/// The DFG table, computed once per process (it depends on nothing).
pub fn dfg_table() -> Arc<Vec<[f32; 2]>> {
    static TABLE: std::sync::OnceLock<Arc<Vec<[f32; 2]>>> = std::sync::OnceLock::new();
    TABLE
        .get_or_init(|| Arc::new(dfg::table(dfg::SIZE, dfg::SAMPLES)))
        .clone()
}

/// Where a frame's maps came from.
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
#[serde(rename_all = "kebab-case", tag = "from")]
pub enum MapsSource {
    /// Computed now, taking this long.
    Built {
        /// Seconds of CPU precompute.
        seconds: f64,
    },
    /// Read from the disk cache.
    Disk {
        /// Seconds to read and verify.
        seconds: f64,
    },
    /// Already in this process.
    Memory,
}

/// Told before maps are built (not found in memory or the disk cache): what is built. A program
/// that can take a while to answer says so with it (`harness` prints it); none by default.
static BUILD_NOTICE: std::sync::RwLock<Option<fn(&str)>> = std::sync::RwLock::new(None);

/// Sets what [`prepare`] tells before it builds maps (None: nothing).
pub fn set_build_notice(notice: Option<fn(&str)>) {
    *BUILD_NOTICE.write().unwrap_or_else(|e| e.into_inner()) = notice;
}

/// The maps for an environment and settings: from this process's memory, else from the disk
/// cache set with [`cache::set_directory`], else built (and then stored in both). A disk cache
/// that cannot be written (full disk, read-only folder) is a warning naming the file, not an
/// error: the frame renders with the maps just built, and no partial entry is left. Threads
/// asking for the same maps at once share one build: the others wait for it.
pub fn prepare(
    image: &Arc<EnvironmentImage>,
    settings: &IblSettings,
) -> (Arc<IblMaps>, MapsSource) {
    let key = cache::key_of_shared(image, settings);
    if let Some(maps) = cache::memory_get(&key) {
        return (maps, MapsSource::Memory);
    }
    let lock = cache::preparing(&key);
    let _preparing = lock.lock().unwrap_or_else(|e| e.into_inner());
    if let Some(maps) = cache::memory_get(&key) {
        return (maps, MapsSource::Memory); // prepared by another thread while this one waited
    }
    let start = Instant::now();
    let directory = cache::directory();
    if let Some(dir) = &directory {
        if let Some(maps) = cache::read(dir, &key) {
            let maps = Arc::new(maps);
            cache::memory_put(key, maps.clone());
            return (
                maps,
                MapsSource::Disk {
                    seconds: start.elapsed().as_secs_f64(),
                },
            );
        }
    }
    if let Some(notice) = *BUILD_NOTICE.read().unwrap_or_else(|e| e.into_inner()) {
        notice(&format!(
            "precomputing the IBL maps of {} ({}x{}; specular {}x{} from {} samples per texel; \
             not cached yet)",
            image.label,
            image.width,
            image.height,
            settings.specular_size,
            settings.specular_size,
            settings.specular_samples
        ));
    }
    let maps = Arc::new(build(image, settings));
    let seconds = start.elapsed().as_secs_f64();
    // Maps that overflowed are not kept (the render refuses them; see `PreparedFrame::new`).
    if let Some(dir) = directory.as_ref().filter(|_| maps.is_finite()) {
        if let Err(e) = cache::write(dir, &key, &maps) {
            log::warn!("{e}; continuing without caching these IBL maps");
        }
    }
    cache::memory_put(key, maps.clone());
    (maps, MapsSource::Built { seconds })
}

/// `f(i)` for `i` in `0..count`, split over the available cores. Each element is computed on
/// its own, so the result does not depend on the thread count.
pub(crate) fn parallel_map<T: Send>(count: usize, f: impl Fn(usize) -> T + Sync) -> Vec<T> {
    let threads = std::thread::available_parallelism()
        .map_or(1, |n| n.get())
        .min(16);
    if threads <= 1 || count < 256 {
        return (0..count).map(f).collect();
    }
    let chunk = count.div_ceil(threads);
    let f = &f;
    std::thread::scope(|scope| {
        let handles: Vec<_> = (0..threads)
            .map(|t| {
                let range = (t * chunk).min(count)..((t + 1) * chunk).min(count);
                scope.spawn(move || range.map(f).collect::<Vec<T>>())
            })
            .collect();
        handles
            .into_iter()
            .flat_map(|h| h.join().expect("IBL worker thread panicked"))
            .collect()
    })
}

/// SplitMix64's output function: a fixed, well-mixed 64-bit hash of `z` (no global state), for
/// seeded patterns that must be the same on every run and machine.
pub fn splitmix64(z: u64) -> u64 {
    let mut z = z.wrapping_add(0x9e37_79b9_7f4a_7c15);
    z = (z ^ (z >> 30)).wrapping_mul(0xbf58_476d_1ce4_e5b9);
    z = (z ^ (z >> 27)).wrapping_mul(0x94d0_49bb_1331_11eb);
    z ^ (z >> 31)
}

/// Point `i` of `n` of the Hammersley set, optionally rotated (Cranley-Patterson) by offsets
/// derived from `seed`.
pub fn hammersley(i: u32, n: u32, seed: u32) -> (f32, f32) {
    let u1 = i as f32 / n as f32;
    let u2 = i.reverse_bits() as f32 * (1.0 / 4_294_967_296.0);
    if seed == 0 {
        return (u1, u2);
    }
    let offset =
        |salt: u64| (splitmix64(u64::from(seed) << 32 | salt) >> 40) as f32 / (1u64 << 24) as f32;
    ((u1 + offset(1)).fract(), (u2 + offset(2)).fract())
}

/// A GGX-distributed half vector around +Z for uniform `(u1, u2)`.
pub fn ggx_half_vector(u1: f32, u2: f32, alpha: f32) -> Vec3 {
    let a2 = alpha * alpha;
    let cos_theta = ((1.0 - u1) / (1.0 + (a2 - 1.0) * u1)).max(0.0).sqrt();
    let sin_theta = (1.0 - cos_theta * cos_theta).max(0.0).sqrt();
    let phi = std::f32::consts::TAU * u2;
    Vec3::new(sin_theta * phi.cos(), sin_theta * phi.sin(), cos_theta)
}

/// GGX normal distribution (Filament's form).
pub fn d_ggx(n_dot_h: f32, alpha: f32) -> f32 {
    let a = n_dot_h * alpha;
    let k = alpha / (1.0 - n_dot_h * n_dot_h + a * a);
    k * k / std::f32::consts::PI
}

/// Two unit vectors completing `n` to an orthonormal basis (Duff et al. 2017).
pub fn tangent_frame(n: Vec3) -> (Vec3, Vec3) {
    let sign = 1.0f32.copysign(n.z);
    let a = -1.0 / (sign + n.z);
    let b = n.x * n.y * a;
    (
        Vec3::new(1.0 + sign * n.x * n.x * a, sign * b, -sign * n.x),
        Vec3::new(b, sign + n.y * n.y * a, -n.y),
    )
}

//! The mutation self-test: proof of the golden tolerances from both sides.
//!
//! - Tight enough: each small known change ([`Mutation`]: a light 2% brighter, a material
//!   parameter moved by 0.05, the camera turned a quarter degree, an injected fault in one pass,
//!   ...) must fail in the pass where it originates ([`Mutation::origin`]: light changes in the
//!   light buffer, material changes in the G-buffer target holding them, shadow bias in the
//!   shadow term, geometry in depth, tone mapping in the final image) by at least
//!   [`MIN_MUTATION_RATIO`] times its limit, on every backend and in every scene it applies to.
//!   A suite whose only working rule were on the final image would tell the user *that*
//!   something changed, not *where*.
//! - Loose enough: an unchanged render under every noise source must stay at or below
//!   [`MAX_NOISE_RATIO`] of every limit: each backend and synthetic rounding, rendered by this
//!   run, and the sources `harness noise` recorded in golden/noise.toml (llvmpipe's CPU code
//!   paths, another Mesa, renders from other hosts).
//!
//! Faults that no scene parameter can express are injected through
//! [`engine::renderer::Variations`].
//!
//! The parts: `mutations.rs` defines the known changes and applies them to a scene, `run.rs`
//! renders them and the unchanged scenes, and `tables.rs` prints the findings.

use std::collections::BTreeMap;

use engine::backend::BackendKind;
use engine::plan::{PassId, TargetId};

use crate::golden::noise::{MAX_NOISE_RATIO, MIN_MUTATION_RATIO};

mod mutations;
mod run;
mod tables;

pub use mutations::Mutation;
pub use run::run;

/// Which golden passes of a mutated render the self-test checks.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum MutationChecks {
    /// Every golden pass: [`MutationResult::also_failing`] then lists where else a change
    /// shows (what `harness selftest` prints).
    EveryPass,
    /// Only the passes where each mutation originates, which is all the verdict reads
    /// ([`SelfTest::weak_detections`]); the render runs only the passes they depend on, so a
    /// material change costs a G-buffer pass, not a frame. The unchanged renders are checked
    /// in every pass either way.
    Origin,
}

/// One mutation rendered on one scene and backend.
#[derive(Clone, Debug, serde::Serialize)]
pub struct MutationResult {
    /// Scene.
    pub scene: String,
    /// Mutation.
    pub mutation: Mutation,
    /// Backend.
    pub backend: BackendKind,
    /// Whether the mutation applies to the scene (if not, nothing was rendered).
    pub applies: bool,
    /// `value / limit` of every checked golden pass's rule (see
    /// [`crate::golden::tolerance::Verdict::ratio`] and [`MutationChecks`]).
    pub ratios: BTreeMap<TargetId, f64>,
    /// Why the render failed, if it did.
    pub error: Option<String>,
    /// The plan passes `check`'s verdict names as where the change starts, from the outputs
    /// that failed ([`crate::golden::diagnosis::origins`]).
    pub diagnosed_origin: Vec<PassId>,
    /// The plan passes that write the outputs the mutation reaches directly
    /// ([`Mutation::starts_in`]): where the verdict may say it starts.
    pub origin_passes: Vec<PassId>,
}

impl MutationResult {
    /// The ratio in the pass where the mutation originates (the largest, for the shadow bias
    /// over the scene's shadow terms); `None` when that pass is not among the scene's goldens.
    pub fn origin_ratio(&self) -> Option<f64> {
        self.ratios
            .iter()
            .filter(|(pass, _)| self.mutation.is_origin(**pass))
            .map(|(_, &r)| r)
            .fold(None, |m: Option<f64>, r| Some(m.map_or(r, |m| m.max(r))))
    }

    /// Whether the verdict names where the mutation starts: some origin, and each a pass that
    /// writes an output the mutation reaches directly.
    pub fn origin_named(&self) -> bool {
        !self.diagnosed_origin.is_empty()
            && self
                .diagnosed_origin
                .iter()
                .all(|p| self.origin_passes.contains(p))
    }

    /// Other passes that failed (ratio above 1).
    pub fn also_failing(&self) -> Vec<TargetId> {
        self.ratios
            .iter()
            .filter(|(pass, &r)| r > 1.0 && !self.mutation.is_origin(**pass))
            .map(|(pass, _)| *pass)
            .collect()
    }
}

/// An unchanged render under one noise source, against the limits.
#[derive(Clone, Debug, serde::Serialize)]
pub struct NoiseResult {
    /// Source (`drivers`, `synthetic-rounding`, or one recorded in golden/noise.toml).
    pub source: String,
    /// Scene.
    pub scene: String,
    /// Backend (none where the source has none; `-` in JSON).
    #[serde(serialize_with = "crate::backend_or_dash")]
    pub backend: Option<BackendKind>,
    /// Pass.
    pub pass: TargetId,
    /// `value / limit` of the pass's rule (for recorded figures, the worst check's).
    pub ratio: f64,
    /// Rendered by this run (rather than read from golden/noise.toml).
    pub live: bool,
}

/// The self-test's findings.
#[derive(Clone, Debug, serde::Serialize)]
pub struct SelfTest {
    /// Every mutation on every scene and backend.
    pub mutations: Vec<MutationResult>,
    /// Every unchanged render (live, and recorded in the noise model) against every limit.
    pub noise: Vec<NoiseResult>,
    /// Renders that failed.
    pub errors: Vec<String>,
}

impl SelfTest {
    /// Applicable mutations that do not fail in their originating pass by
    /// [`MIN_MUTATION_RATIO`] (or whose origin has no golden).
    pub fn weak_detections(&self) -> Vec<&MutationResult> {
        self.mutations
            .iter()
            .filter(|m| m.applies && m.origin_ratio().is_none_or(|r| r < MIN_MUTATION_RATIO))
            .collect()
    }

    /// Applicable mutations caught in their origin whose verdict names another origin.
    pub fn misdiagnosed(&self) -> Vec<&MutationResult> {
        self.mutations
            .iter()
            .filter(|m| m.applies && m.error.is_none() && !m.origin_named())
            .filter(|m| m.origin_ratio().is_some_and(|r| r >= MIN_MUTATION_RATIO))
            .collect()
    }

    /// Unchanged renders above [`MAX_NOISE_RATIO`] of a limit.
    pub fn noisy(&self) -> Vec<&NoiseResult> {
        self.noise
            .iter()
            .filter(|n| n.ratio > MAX_NOISE_RATIO)
            .collect()
    }

    /// Every mutation caught where it originates with its margin and its verdict naming that
    /// origin, every noise source within its
    /// bound, no failed render.
    pub fn passed(&self) -> bool {
        self.weak_detections().is_empty()
            && self.misdiagnosed().is_empty()
            && self.noisy().is_empty()
            && self.errors.is_empty()
    }
}

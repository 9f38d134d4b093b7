//! CPU references the renders are checked against, in f64 and sharing no code with the
//! renderer: the analytic lights' BRDF evaluation ([`lighting`], re-exported here), shadow
//! visibility by ray casting ([`shadows`]), image-based lighting by Monte Carlo
//! integration ([`ibl`]), and the ambient occlusion of two planes in a corner against the exact
//! geometry and a closed form ([`ambient_occlusion`], which shares only the kernel's points, its
//! input, with the renderer).

pub mod ambient_occlusion;
pub mod ibl;
pub mod lighting;
pub mod shadows;

pub use lighting::*;

/// Why a comparison with a reference could not run.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
pub enum ReferenceError {
    /// The frame lacks an output the reference reads, or holds it in another storage.
    #[error("reference comparison: frame has no {storage} output `{target}`")]
    MissingOutput {
        /// The target.
        target: engine::plan::TargetId,
        /// The storage the reference reads ("float", "8-bit").
        storage: &'static str,
    },
    /// The scene lacks what the reference compares.
    #[error("reference comparison: scene `{scene}` has no {what}")]
    SceneLacks {
        /// Scene name.
        scene: String,
        /// What it lacks ("environment", "light 3", "[quality.ssao]").
        what: String,
    },
    /// Nothing in the frame to compare.
    #[error("reference comparison: no {0} in the frame")]
    NoPixels(&'static str),
    /// An output and the reference cover different pixels.
    #[error("reference comparison: `{target}` has {output} pixels, the reference {reference}")]
    SizeMismatch {
        /// The target.
        target: engine::plan::TargetId,
        /// Its pixels.
        output: usize,
        /// The reference's.
        reference: usize,
    },
}

impl ReferenceError {
    /// `target` is missing as a float image.
    pub fn no_float(target: engine::plan::TargetId) -> Self {
        ReferenceError::MissingOutput {
            target,
            storage: "float",
        }
    }
}

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

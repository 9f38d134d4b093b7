//! CPU references the renders are checked against, in f64 and sharing no code with the
//! renderer: the analytic lights' BRDF evaluation ([`lighting`], re-exported here), shadow
//! visibility by ray casting ([`shadows`]) and image-based lighting by Monte Carlo
//! integration ([`ibl`]).

pub mod ibl;
pub mod lighting;
pub mod shadows;

pub use lighting::*;

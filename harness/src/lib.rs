//! The harness library: image comparison, cross-backend checks, and (growing) goldens, bless and
//! reports. The `harness` binary is a thin command line over it.

pub mod compare;
pub mod first_scene;
pub mod images;
pub mod metrics;
pub mod reference;
pub mod test_scenes;
pub mod tolerance;

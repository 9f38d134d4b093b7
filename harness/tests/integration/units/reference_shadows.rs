//! Tests of `harness::reference::shadows`.

use glam::DVec3;
use harness::reference::shadows::*;

#[test]
fn ray_hits_a_triangle_in_front_and_not_behind() {
    let t = Triangle {
        a: DVec3::new(-1.0, -1.0, 1.0),
        b: DVec3::new(1.0, -1.0, 1.0),
        c: DVec3::new(0.0, 1.0, 1.0),
    };
    assert!(intersect(&t, DVec3::ZERO, DVec3::Z, 10.0));
    assert!(!intersect(&t, DVec3::ZERO, DVec3::Z, 0.5));
    assert!(!intersect(&t, DVec3::ZERO, DVec3::NEG_Z, 10.0));
    assert!(!intersect(&t, DVec3::new(5.0, 0.0, 0.0), DVec3::Z, 10.0));
}

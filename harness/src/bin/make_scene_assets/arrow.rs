//! The arrow mesh: a shaft and a cone head along +X.

use crate::lathe::{flat, lathe, Ring, Section, UvMap};
use crate::math::normalize;
use crate::obj_writer::{Group, Mesh};

/// An arrow along +X with its back at the origin: shaft radius 0.006 m, length 0.12 m; cone head
/// radius 0.015 m, length 0.04 m; closed by a disc at the back and an annulus behind the head.
pub(crate) fn arrow_mesh() -> Mesh {
    let (shaft_r, shaft_len, head_r, head_len) = (0.006, 0.12, 0.015, 0.04);
    let length = shaft_len + head_len;
    let back = UvMap::PlanarBottom(head_r);
    let cone_n = normalize([head_len, head_r, 0.0]);
    let mut shaft = vec![
        Ring::new(shaft_r, 0.0, 1.0, 0.0),
        Ring::new(shaft_r, shaft_len, 1.0, 0.0),
    ];
    let mut cone = vec![
        Ring::new(head_r, shaft_len, cone_n[0], cone_n[1]),
        Ring::new(0.0, length, cone_n[0], cone_n[1]),
    ];
    for ring in shaft.iter_mut().chain(cone.iter_mut()) {
        ring.v = ring.y / length;
    }
    let sections = [
        Section {
            rings: flat(0.0, shaft_r, 0.0, -1.0),
            uv: back,
        },
        Section {
            rings: shaft,
            uv: UvMap::Cylindrical,
        },
        Section {
            rings: flat(shaft_r, head_r, shaft_len, -1.0),
            uv: back,
        },
        Section {
            rings: cone,
            uv: UvMap::Cylindrical,
        },
    ];
    let mut group = Group::new("arrow", "arrow");
    lathe(&mut group, &sections, 32, None);
    // Lay the +Y axis along +X: a proper rotation (x, y, z) -> (y, -x, z) keeps the winding.
    for v in &mut group.vertices {
        v.p = [v.p[1], -v.p[0], v.p[2]];
        v.n = [v.n[1], -v.n[0], v.n[2]];
    }
    Mesh {
        name: "arrow",
        description: "Arrow along +X from the origin, 0.16 m long",
        groups: vec![group],
    }
}

//! The unit UV sphere mesh.

use std::f64::consts::PI;

use crate::lathe::{lathe, Ring, Section, UvMap};
use crate::obj_writer::{Group, Mesh};

/// A UV sphere of radius 1: 64 segments by 32 rings, u = longitude (0 at +X, growing
/// counter-clockwise seen from above), v = latitude (0 south pole, 1 north pole). The seam column
/// is duplicated; each pole has one vertex per segment at the segment's middle longitude, so no
/// triangle is degenerate, in position or in texture space.
pub(crate) fn sphere_mesh() -> Mesh {
    let rings = 32u32;
    let profile = (0..=rings)
        .map(|i| {
            let a = PI * f64::from(i) / f64::from(rings);
            let (s, c) = a.sin_cos();
            let (r, y) = match i {
                0 => (0.0, -1.0),
                i if i == rings => (0.0, 1.0),
                _ => (s, -c),
            };
            Ring {
                v: f64::from(i) / f64::from(rings),
                ..Ring::new(r, y, r, y)
            }
        })
        .collect();
    let mut group = Group::new("sphere", "sphere");
    lathe(
        &mut group,
        &[Section {
            rings: profile,
            uv: UvMap::Cylindrical,
        }],
        64,
        None,
    );
    Mesh {
        name: "sphere",
        description: "UV sphere, radius 1, 64 segments x 32 rings",
        groups: vec![group],
    }
}

//! The workspace's `[f64; 3]` helpers (`plane-geom`), and the corners of a triangle.

pub(crate) use plane_geom::vec3::{Vec3, add, cross, dot, scale, sub, unit};

/// The corners of triangle `t`.
#[inline]
pub(crate) fn corners(vertices: &[Vec3], t: [u32; 3]) -> [Vec3; 3] {
    [
        vertices[t[0] as usize],
        vertices[t[1] as usize],
        vertices[t[2] as usize],
    ]
}

//! Small helpers on `[f64; 3]` vectors and `[f64; 2]` points.

pub(crate) type V3 = [f64; 3];
pub(crate) type V2 = [f64; 2];

/// `a / |a|`, or `None` when `|a|` is zero, not finite or too small to invert.
pub(crate) use plane_geom::vec3::unit as normalize;
pub(crate) use plane_geom::vec3::{add, cross, dot, norm, scale, sub};

/// `a + s b`.
#[inline]
pub(crate) fn axpy(a: V3, s: f64, b: V3) -> V3 {
    [a[0] + s * b[0], a[1] + s * b[1], a[2] + s * b[2]]
}

/// Twice the signed area of the 2D triangle `(a, b, c)`; positive when counter-clockwise.
#[inline]
pub(crate) fn orient2(a: V2, b: V2, c: V2) -> f64 {
    (b[0] - a[0]) * (c[1] - a[1]) - (b[1] - a[1]) * (c[0] - a[0])
}

/// Signed area of a 2D ring (shoelace); positive when counter-clockwise.
pub(crate) fn ring_area(ring: &[V2]) -> f64 {
    let n = ring.len();
    let mut s = 0.0;
    for i in 0..n {
        let a = ring[i];
        let b = ring[(i + 1) % n];
        s += a[0] * b[1] - b[0] * a[1];
    }
    0.5 * s
}

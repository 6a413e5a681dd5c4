//! Small 3-vector helpers, written out component by component so that hot loops
//! inline them fully.

pub(crate) type Vec3 = [f64; 3];

#[inline]
pub(crate) fn add(a: Vec3, b: Vec3) -> Vec3 {
    [a[0] + b[0], a[1] + b[1], a[2] + b[2]]
}

#[inline]
pub(crate) fn sub(a: Vec3, b: Vec3) -> Vec3 {
    [a[0] - b[0], a[1] - b[1], a[2] - b[2]]
}

#[inline]
pub(crate) fn scale(a: Vec3, s: f64) -> Vec3 {
    [a[0] * s, a[1] * s, a[2] * s]
}

#[inline]
pub(crate) fn dot(a: Vec3, b: Vec3) -> f64 {
    a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
}

#[inline]
pub(crate) fn cross(a: Vec3, b: Vec3) -> Vec3 {
    [
        a[1] * b[2] - a[2] * b[1],
        a[2] * b[0] - a[0] * b[2],
        a[0] * b[1] - a[1] * b[0],
    ]
}

/// The corners of triangle `t`.
#[inline]
pub(crate) fn corners(vertices: &[Vec3], t: [u32; 3]) -> [Vec3; 3] {
    [
        vertices[t[0] as usize],
        vertices[t[1] as usize],
        vertices[t[2] as usize],
    ]
}

/// `v / |v|`, or `None` for a zero or non-finite length.
pub(crate) fn unit(v: Vec3) -> Option<Vec3> {
    let len = dot(v, v).sqrt();
    (len > 0.0 && len.is_finite()).then(|| scale(v, 1.0 / len))
}

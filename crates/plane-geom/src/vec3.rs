//! Helpers on `[f64; 3]` vectors, written out component by component so that hot loops
//! inline them fully. Every crate of the workspace that works on 3D points uses these, so
//! that a dot product is the same sum of products, in the same order, everywhere.

/// A 3D vector or point.
pub type Vec3 = [f64; 3];

/// `a + b`.
///
/// ```
/// assert_eq!(plane_geom::vec3::add([1.0, 2.0, 3.0], [1.0, 1.0, 1.0]), [2.0, 3.0, 4.0]);
/// ```
#[inline]
pub fn add(a: Vec3, b: Vec3) -> Vec3 {
    [a[0] + b[0], a[1] + b[1], a[2] + b[2]]
}

/// `a − b`.
///
/// ```
/// assert_eq!(plane_geom::vec3::sub([1.0, 2.0, 3.0], [1.0, 1.0, 1.0]), [0.0, 1.0, 2.0]);
/// ```
#[inline]
pub fn sub(a: Vec3, b: Vec3) -> Vec3 {
    [a[0] - b[0], a[1] - b[1], a[2] - b[2]]
}

/// `s · a`.
///
/// ```
/// assert_eq!(plane_geom::vec3::scale([1.0, -2.0, 3.0], 2.0), [2.0, -4.0, 6.0]);
/// ```
#[inline]
pub fn scale(a: Vec3, s: f64) -> Vec3 {
    [a[0] * s, a[1] * s, a[2] * s]
}

/// `a · b`, summed as `(a₀b₀ + a₁b₁) + a₂b₂`.
///
/// ```
/// assert_eq!(plane_geom::vec3::dot([1.0, 2.0, 3.0], [4.0, 5.0, 6.0]), 32.0);
/// ```
#[inline]
pub fn dot(a: Vec3, b: Vec3) -> f64 {
    a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
}

/// `a × b` (right-handed).
///
/// ```
/// assert_eq!(plane_geom::vec3::cross([1.0, 0.0, 0.0], [0.0, 1.0, 0.0]), [0.0, 0.0, 1.0]);
/// ```
#[inline]
pub fn cross(a: Vec3, b: Vec3) -> Vec3 {
    [
        a[1] * b[2] - a[2] * b[1],
        a[2] * b[0] - a[0] * b[2],
        a[0] * b[1] - a[1] * b[0],
    ]
}

/// The Euclidean length `√(a · a)`.
///
/// ```
/// assert_eq!(plane_geom::vec3::norm([3.0, 0.0, 4.0]), 5.0);
/// ```
#[inline]
pub fn norm(a: Vec3) -> f64 {
    dot(a, a).sqrt()
}

/// `a / |a|` (computed as `a · (1 / |a|)`), or `None` when `|a|` is zero or not finite,
/// or so small that its reciprocal overflows: the result, when there is one, is finite.
///
/// ```
/// use plane_geom::vec3::unit;
/// assert_eq!(unit([0.0, -2.0, 0.0]), Some([0.0, -1.0, 0.0]));
/// assert_eq!(unit([0.0; 3]), None);
/// assert_eq!(unit([f64::NAN, 0.0, 1.0]), None);
/// ```
#[inline]
pub fn unit(a: Vec3) -> Option<Vec3> {
    let len = norm(a);
    let inv = 1.0 / len;
    (len > 0.0 && len.is_finite() && inv.is_finite()).then(|| scale(a, inv))
}

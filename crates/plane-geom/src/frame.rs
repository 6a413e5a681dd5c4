//! The orthonormal frame of a plane: 3D points to 2D coordinates in the plane and back.

use crate::vec3::{Vec3, cross, dot, norm, scale, sub, unit};

/// A right-handed orthonormal frame `(e1, e2, normal)` with an `origin` on the plane.
///
/// **The convention** (one for the whole workspace, from [`PlaneFrame::from_unit_normal`]):
/// `e1` starts from the coordinate axis least aligned with the normal (x, then y, then z
/// on ties), loses its normal component and is normalised (`e1 · (1 / |e1|)`); then
/// `e2 = normal × e1`. For `normal = +z` this is exactly `e1 = +x`, `e2 = +y`, so a 2.5D
/// computation looking down `+z` works on plain `(x, y)`. Counter-clockwise in 2D is
/// counter-clockwise seen from the side `normal` points to.
///
/// [`PlaneFrame::project`] maps `p` to `((p − origin) · e1, (p − origin) · e2)` (the
/// orthogonal projection's coordinates); [`PlaneFrame::lift`] maps `(a, b)` to
/// `origin + a e1 + b e2`. With the default origin (zero) `p − origin` is `p` exactly.
///
/// ```
/// use plane_geom::PlaneFrame;
///
/// let frame = PlaneFrame::new([0.0, 0.0, 2.0]).ok_or("zero normal")?;
/// assert_eq!(frame.project([3.0, 4.0, 5.0]), [3.0, 4.0]);
///
/// let tilted = PlaneFrame::new([1.0, 1.0, 1.0]).ok_or("zero normal")?.with_origin([0.0, 0.0, 1.0]);
/// let q = tilted.project([1.0, 2.0, 3.0]);
/// let p = tilted.lift(q); // the orthogonal projection of (1, 2, 3) onto the plane
/// assert!(tilted.signed_distance(p).abs() < 1e-12);
/// # Ok::<(), &str>(())
/// ```
#[derive(Debug, Clone, Copy, PartialEq)]
#[non_exhaustive]
pub struct PlaneFrame {
    /// Origin of the 2D coordinates (a point on the plane).
    pub origin: Vec3,
    /// First in-plane unit axis.
    pub e1: Vec3,
    /// Second in-plane unit axis, `normal × e1`.
    pub e2: Vec3,
    /// The plane's unit normal, `e1 × e2`.
    pub normal: Vec3,
}

impl PlaneFrame {
    /// The frame of the direction `normal` (normalised here), origin at zero; `None` when
    /// `normal` is zero or not finite.
    #[inline]
    pub fn new(normal: Vec3) -> Option<Self> {
        unit(normal).map(Self::from_unit_normal)
    }

    /// The frame of the unit vector `normal` (trusted to be unit; see [`Self::new`]),
    /// origin at zero, built by the convention in the type's documentation.
    #[inline]
    pub fn from_unit_normal(normal: Vec3) -> Self {
        let n = normal;
        let axis = if n[0].abs() <= n[1].abs() && n[0].abs() <= n[2].abs() {
            [1.0, 0.0, 0.0]
        } else if n[1].abs() <= n[2].abs() {
            [0.0, 1.0, 0.0]
        } else {
            [0.0, 0.0, 1.0]
        };
        let e1 = sub(axis, scale(n, dot(axis, n)));
        let e1 = scale(e1, 1.0 / norm(e1));
        let e2 = cross(n, e1);
        Self {
            origin: [0.0; 3],
            e1,
            e2,
            normal: n,
        }
    }

    /// The frame at `origin` with the in-plane axis `e1` and the `normal`, both unit and
    /// orthogonal (trusted); `e2 = normal × e1`, normalised. For frames whose in-plane
    /// axes mean something, such as a fitted plane's direction of largest spread, instead
    /// of following the convention above.
    ///
    /// ```
    /// use plane_geom::PlaneFrame;
    ///
    /// let frame = PlaneFrame::from_unit_axes([0.0, 0.0, 1.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]);
    /// assert_eq!(frame.e2, [-1.0, 0.0, 0.0]);
    /// assert_eq!(frame.project([2.0, 3.0, 1.0]), [3.0, -2.0]);
    /// ```
    #[inline]
    pub fn from_unit_axes(origin: Vec3, e1: Vec3, normal: Vec3) -> Self {
        let e2 = cross(normal, e1);
        let length = norm(e2);
        Self {
            origin,
            e1,
            e2: e2.map(|v| v / length),
            normal,
        }
    }

    /// The frame seen from the other side: `e2` and `normal` reversed (still
    /// right-handed), so 2D coordinates are mirrored in their second axis and a
    /// clockwise ring becomes counter-clockwise.
    #[inline]
    #[must_use]
    pub fn flipped(self) -> Self {
        Self {
            e2: scale(self.e2, -1.0),
            normal: scale(self.normal, -1.0),
            ..self
        }
    }

    /// The same axes with 2D coordinates measured from `origin` (a point on the plane;
    /// near the data keeps the coordinates small and precise).
    #[inline]
    #[must_use]
    pub fn with_origin(self, origin: Vec3) -> Self {
        Self { origin, ..self }
    }

    /// The 2D coordinates of `p`'s orthogonal projection onto the plane.
    #[inline]
    pub fn project(&self, p: Vec3) -> [f64; 2] {
        let d = sub(p, self.origin);
        [dot(d, self.e1), dot(d, self.e2)]
    }

    /// The 3D point on the plane at 2D coordinates `q`.
    #[inline]
    pub fn lift(&self, q: [f64; 2]) -> Vec3 {
        [
            self.origin[0] + q[0] * self.e1[0] + q[1] * self.e2[0],
            self.origin[1] + q[0] * self.e1[1] + q[1] * self.e2[1],
            self.origin[2] + q[0] * self.e1[2] + q[1] * self.e2[2],
        ]
    }

    /// Signed distance of `p` from the plane through `origin`, positive on the side
    /// `normal` points to.
    #[inline]
    pub fn signed_distance(&self, p: Vec3) -> f64 {
        dot(sub(p, self.origin), self.normal)
    }
}

#[cfg(test)]
mod tests {
    #![allow(clippy::unwrap_used)]
    use super::*;

    #[test]
    fn axis_normals_give_axis_frames_exactly() {
        let f = PlaneFrame::new([0.0, 0.0, 2.0]).unwrap();
        assert_eq!((f.e1, f.e2), ([1.0, 0.0, 0.0], [0.0, 1.0, 0.0]));
        let f = PlaneFrame::new([3.0, 0.0, 0.0]).unwrap();
        assert_eq!((f.e1, f.e2), ([0.0, 1.0, 0.0], [0.0, 0.0, 1.0]));
        let f = PlaneFrame::new([0.0, -1.0, 0.0]).unwrap();
        assert_eq!((f.e1, f.e2), ([1.0, 0.0, 0.0], [0.0, 0.0, 1.0]));
    }

    #[test]
    fn bad_normals_have_no_frame() {
        for n in [[0.0; 3], [f64::NAN, 0.0, 1.0], [f64::INFINITY, 0.0, 0.0]] {
            assert_eq!(PlaneFrame::new(n), None, "{n:?}");
        }
    }
}

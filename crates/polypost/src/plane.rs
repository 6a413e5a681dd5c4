//! Planes in Hessian normal form and the orthonormal 2D frame post-processing works in.

use crate::PostError;

/// An oriented plane `normal · x + offset = 0` with a unit `normal`.
///
/// `centroid` is a point on the plane (for a fitted plane, the mean of the fitted
/// points); it is the origin of the plane's 2D [`PlaneFrame`], which keeps projected
/// coordinates small and therefore precise.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Plane {
    /// Unit normal.
    pub normal: [f64; 3],
    /// Offset `d` in `normal · x + d = 0`, in metres (minus the distance of the plane
    /// from the origin along `normal`).
    pub offset: f64,
    /// A point on the plane, the origin of [`Plane::frame`].
    pub centroid: [f64; 3],
}

impl Plane {
    /// Builds the plane through `point` with normal direction `normal` (normalised here).
    ///
    /// # Errors
    /// [`PostError::BadNormal`] if `normal` is zero or not finite,
    /// [`PostError::BadPlanePoint`] if `point` is not finite.
    pub fn from_normal_and_point(normal: [f64; 3], point: [f64; 3]) -> Result<Self, PostError> {
        if !point.iter().all(|c| c.is_finite()) {
            return Err(PostError::BadPlanePoint { point });
        }
        let len = norm(normal);
        if !len.is_finite() || len == 0.0 {
            return Err(PostError::BadNormal { normal });
        }
        let n = scale(normal, 1.0 / len);
        Ok(Self {
            normal: n,
            offset: -dot(n, point),
            centroid: point,
        })
    }

    /// Signed distance of `p` from the plane, positive on the side `normal` points to.
    pub fn signed_distance(&self, p: [f64; 3]) -> f64 {
        dot(self.normal, p) + self.offset
    }

    /// Orthogonal projection of `p` onto the plane.
    pub fn project(&self, p: [f64; 3]) -> [f64; 3] {
        let s = self.signed_distance(p);
        sub(p, scale(self.normal, s))
    }

    /// The same plane with the opposite orientation.
    pub fn flipped(&self) -> Self {
        Self {
            normal: scale(self.normal, -1.0),
            offset: -self.offset,
            centroid: self.centroid,
        }
    }

    /// The same plane, oriented so that `normal · hint >= 0` (e.g. a hint pointing
    /// towards the sensor). A hint orthogonal to the normal leaves it unchanged.
    pub fn oriented_toward(&self, hint: [f64; 3]) -> Self {
        if dot(self.normal, hint) < 0.0 {
            self.flipped()
        } else {
            *self
        }
    }

    /// The plane's 2D frame; see [`PlaneFrame`] for how it is built.
    pub fn frame(&self) -> PlaneFrame {
        let n = self.normal;
        // The coordinate axis least aligned with the normal (first one on ties).
        let abs = [n[0].abs(), n[1].abs(), n[2].abs()];
        let k = if abs[0] <= abs[1] && abs[0] <= abs[2] {
            0
        } else if abs[1] <= abs[2] {
            1
        } else {
            2
        };
        let mut axis = [0.0; 3];
        axis[k] = 1.0;
        let u_raw = sub(axis, scale(n, n[k]));
        let u = scale(u_raw, 1.0 / norm(u_raw));
        let v = cross(n, u);
        PlaneFrame {
            origin: self.project(self.centroid),
            u,
            v,
            normal: n,
        }
    }
}

/// A right-handed orthonormal frame `(u, v, normal)` on a plane.
///
/// Built by [`Plane::frame`]: `origin` is the plane's centroid projected onto the plane;
/// `u` is the coordinate axis least aligned with the normal (x, then y, then z on ties)
/// with its normal component removed and normalised; `v = normal × u`. A point `p` has 2D
/// coordinates `((p − origin)·u, (p − origin)·v)`; 2D coordinates `(a, b)` lift to
/// `origin + a·u + b·v`, which lies on the plane up to rounding (≈ 1e-16 relative).
/// Counter-clockwise in 2D is counter-clockwise seen from the side `normal` points to.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PlaneFrame {
    /// Origin of the 2D coordinates, on the plane.
    pub origin: [f64; 3],
    /// First in-plane unit axis.
    pub u: [f64; 3],
    /// Second in-plane unit axis, `normal × u`.
    pub v: [f64; 3],
    /// The plane's unit normal.
    pub normal: [f64; 3],
}

impl PlaneFrame {
    /// 2D coordinates of the orthogonal projection of `p`.
    pub fn to_2d(&self, p: [f64; 3]) -> [f64; 2] {
        let d = sub(p, self.origin);
        [dot(d, self.u), dot(d, self.v)]
    }

    /// The 3D point on the plane with 2D coordinates `q`.
    pub fn to_3d(&self, q: [f64; 2]) -> [f64; 3] {
        [
            self.origin[0] + q[0] * self.u[0] + q[1] * self.v[0],
            self.origin[1] + q[0] * self.u[1] + q[1] * self.v[1],
            self.origin[2] + q[0] * self.u[2] + q[1] * self.v[2],
        ]
    }
}

pub(crate) fn dot(a: [f64; 3], b: [f64; 3]) -> f64 {
    a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
}

pub(crate) fn sub(a: [f64; 3], b: [f64; 3]) -> [f64; 3] {
    [a[0] - b[0], a[1] - b[1], a[2] - b[2]]
}

pub(crate) fn add(a: [f64; 3], b: [f64; 3]) -> [f64; 3] {
    [a[0] + b[0], a[1] + b[1], a[2] + b[2]]
}

pub(crate) fn scale(a: [f64; 3], s: f64) -> [f64; 3] {
    [a[0] * s, a[1] * s, a[2] * s]
}

pub(crate) fn cross(a: [f64; 3], b: [f64; 3]) -> [f64; 3] {
    [
        a[1] * b[2] - a[2] * b[1],
        a[2] * b[0] - a[0] * b[2],
        a[0] * b[1] - a[1] * b[0],
    ]
}

pub(crate) fn norm(a: [f64; 3]) -> f64 {
    dot(a, a).sqrt()
}

#[cfg(test)]
mod tests {
    use super::*;

    fn close(a: f64, b: f64) -> bool {
        (a - b).abs() < 1e-12
    }

    #[test]
    fn frame_is_orthonormal_and_right_handed() {
        for normal in [
            [0.0, 0.0, 1.0],
            [1.0, 0.0, 0.0],
            [0.3, -0.4, 0.8],
            [-1.0, -1.0, -1.0],
        ] {
            let plane = Plane::from_normal_and_point(normal, [1.0, 2.0, 3.0]).unwrap();
            let f = plane.frame();
            assert!(close(dot(f.u, f.u), 1.0));
            assert!(close(dot(f.v, f.v), 1.0));
            assert!(close(dot(f.u, f.v), 0.0));
            assert!(close(dot(f.u, f.normal), 0.0));
            let c = cross(f.u, f.v);
            assert!(close(dot(c, f.normal), 1.0), "right-handed");
        }
    }

    #[test]
    fn round_trip_through_frame() {
        let plane = Plane::from_normal_and_point([0.2, 0.5, -0.7], [4.0, -1.0, 2.0]).unwrap();
        let f = plane.frame();
        let p = plane.project([7.0, 3.0, -2.0]);
        let q = f.to_2d(p);
        let back = f.to_3d(q);
        for k in 0..3 {
            assert!((back[k] - p[k]).abs() < 1e-12);
        }
        assert!(plane.signed_distance(f.to_3d([12.5, -3.25])).abs() < 1e-12);
    }

    #[test]
    fn orientation_and_errors() {
        let plane = Plane::from_normal_and_point([0.0, 0.0, 2.0], [0.0, 0.0, 1.0]).unwrap();
        assert_eq!(plane.normal, [0.0, 0.0, 1.0]);
        assert_eq!(plane.offset, -1.0);
        assert!(close(plane.signed_distance([5.0, 5.0, 3.0]), 2.0));
        let down = plane.oriented_toward([0.0, 0.0, -1.0]);
        assert_eq!(down.normal, [-0.0, -0.0, -1.0]);
        assert!(close(down.signed_distance([5.0, 5.0, 3.0]), -2.0));
        assert!(matches!(
            Plane::from_normal_and_point([0.0; 3], [0.0; 3]),
            Err(PostError::BadNormal { .. })
        ));
        assert!(matches!(
            Plane::from_normal_and_point([0.0, 0.0, 1.0], [f64::NAN, 0.0, 0.0]),
            Err(PostError::BadPlanePoint { .. })
        ));
    }
}

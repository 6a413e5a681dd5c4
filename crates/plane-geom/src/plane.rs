//! Planes in Hessian normal form.

use crate::PlaneError;
use crate::frame::PlaneFrame;
use crate::vec3::{Vec3, dot, scale, sub, unit};

/// An oriented plane `normal · x + offset = 0` with a unit `normal`, and a point on it.
///
/// `centroid` is a point on the plane (for a fitted plane, the mean of the fitted
/// points); [`Plane::frame`] puts its 2D origin there, which keeps projected coordinates
/// small and therefore precise.
///
/// ```
/// use plane_geom::Plane;
///
/// let floor = Plane::from_normal_and_point([0.0, 0.0, 2.0], [0.0, 0.0, 1.0])?;
/// assert_eq!(floor.normal, [0.0, 0.0, 1.0]);
/// assert_eq!(floor.signed_distance([5.0, 5.0, 3.0]), 2.0);
/// assert_eq!(floor.project([5.0, 5.0, 3.0]), [5.0, 5.0, 1.0]);
/// # Ok::<(), plane_geom::PlaneError>(())
/// ```
///
/// Not `#[non_exhaustive]`: like a `geo-types` coordinate, the three fields are the
/// definition, and code that writes a plane as a literal keeps compiling.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Plane {
    /// Unit normal.
    pub normal: Vec3,
    /// Offset `d` in `normal · x + d = 0`, in the unit of the coordinates (minus the
    /// distance of the plane from the origin along `normal`).
    pub offset: f64,
    /// A point on the plane, the origin of [`Plane::frame`].
    pub centroid: Vec3,
}

impl Plane {
    /// The plane through `point` with normal direction `normal` (normalised here).
    ///
    /// # Errors
    /// [`PlaneError::BadPoint`] if `point` is not finite, [`PlaneError::BadNormal`] if
    /// `normal` is zero or not finite.
    #[inline]
    pub fn from_normal_and_point(normal: Vec3, point: Vec3) -> Result<Self, PlaneError> {
        if !point.iter().all(|c| c.is_finite()) {
            return Err(PlaneError::BadPoint { point });
        }
        let n = unit(normal).ok_or(PlaneError::BadNormal { normal })?;
        Ok(Self::from_unit_normal(n, point))
    }

    /// The plane through `point` with the unit normal `normal`, taken as given (not
    /// checked nor normalised; see [`Self::from_normal_and_point`]).
    #[inline]
    pub fn from_unit_normal(normal: Vec3, point: Vec3) -> Self {
        Self {
            normal,
            offset: -dot(normal, point),
            centroid: point,
        }
    }

    /// Signed distance of `p` from the plane, positive on the side `normal` points to.
    #[inline]
    pub fn signed_distance(&self, p: Vec3) -> f64 {
        dot(self.normal, p) + self.offset
    }

    /// Orthogonal projection of `p` onto the plane.
    #[inline]
    pub fn project(&self, p: Vec3) -> Vec3 {
        sub(p, scale(self.normal, self.signed_distance(p)))
    }

    /// The same plane with the opposite orientation.
    #[inline]
    #[must_use]
    pub fn flipped(&self) -> Self {
        Self {
            normal: scale(self.normal, -1.0),
            offset: -self.offset,
            centroid: self.centroid,
        }
    }

    /// The same plane, oriented so that `normal · hint >= 0` (e.g. a hint pointing
    /// towards the sensor). A hint orthogonal to the normal leaves it unchanged.
    #[inline]
    #[must_use]
    pub fn oriented_toward(&self, hint: Vec3) -> Self {
        if dot(self.normal, hint) < 0.0 {
            self.flipped()
        } else {
            *self
        }
    }

    /// The plane's [`PlaneFrame`] (the workspace convention for its axes), with the
    /// 2D origin at the centroid projected onto the plane.
    #[inline]
    pub fn frame(&self) -> PlaneFrame {
        PlaneFrame::from_unit_normal(self.normal).with_origin(self.project(self.centroid))
    }
}

#[cfg(test)]
mod tests {
    #![allow(clippy::unwrap_used)]
    use super::*;

    #[test]
    fn orientation_and_errors() {
        let plane = Plane::from_normal_and_point([0.0, 0.0, 2.0], [0.0, 0.0, 1.0]).unwrap();
        assert_eq!(plane.offset, -1.0);
        let down = plane.oriented_toward([0.0, 0.0, -1.0]);
        assert_eq!(down.normal, [-0.0, -0.0, -1.0]);
        assert_eq!(down.signed_distance([5.0, 5.0, 3.0]), -2.0);
        assert_eq!(plane.oriented_toward([1.0, 0.0, 0.0]), plane);
        assert!(matches!(
            Plane::from_normal_and_point([0.0; 3], [0.0; 3]),
            Err(PlaneError::BadNormal { .. })
        ));
        assert!(matches!(
            Plane::from_normal_and_point([0.0, 0.0, 1.0], [f64::NAN, 0.0, 0.0]),
            Err(PlaneError::BadPoint { .. })
        ));
    }
}

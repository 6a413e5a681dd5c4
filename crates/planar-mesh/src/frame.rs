//! Preprocessing (§IV-A1): the least-squares plane of a segment (PCA) and the rigid
//! transform into its x-y frame.

use nalgebra::{Matrix3, SymmetricEigen, Vector3};

use plane_geom::vec3::dot;

use crate::MeshError;

/// A plane with an orthonormal frame: `origin + x · axis_x + y · axis_y` is the point at
/// plane coordinates `(x, y)`; `normal = axis_x × axis_y`.
///
/// Unlike `plane_geom::PlaneFrame`, whose axes are a function of the normal alone, this
/// frame is fitted: `axis_x` is the direction of the points' largest spread (PCA), so it
/// is its own type and keeps its own eigen decomposition order (largest spread first).
///
/// ```
/// use planar_mesh::PlaneFrame;
///
/// let points = [[0.0, 0.0, 2.0], [1.0, 0.0, 2.0], [0.0, 1.0, 2.0], [1.0, 1.0, 2.0]];
/// let frame = PlaneFrame::fit(&points)?;
/// assert!((frame.normal[2].abs() - 1.0).abs() < 1e-12);
/// let [x, y] = frame.to_plane([1.0, 1.0, 2.5]);
/// let back = frame.to_world([x, y]);
/// assert!((back[2] - 2.0).abs() < 1e-12); // projected onto the plane
/// # Ok::<(), planar_mesh::MeshError>(())
/// ```
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PlaneFrame {
    /// A point on the plane: the centroid of the fitted points.
    pub origin: [f64; 3],
    /// First in-plane axis (unit): the direction of largest spread.
    pub axis_x: [f64; 3],
    /// Second in-plane axis (unit).
    pub axis_y: [f64; 3],
    /// Unit normal, `axis_x × axis_y`.
    pub normal: [f64; 3],
}

impl PlaneFrame {
    /// The least-squares plane of `points` by principal component analysis: the normal is
    /// the eigenvector of the covariance with the smallest eigenvalue, `axis_x` the one
    /// with the largest.
    ///
    /// # Errors
    /// [`MeshError::TooFewPoints`] below 3 points, [`MeshError::NonFinite`] for a NaN or
    /// infinite coordinate, [`MeshError::Degenerate`] when the points span no plane.
    pub fn fit(points: &[[f64; 3]]) -> Result<Self, MeshError> {
        if points.len() < 3 {
            return Err(MeshError::TooFewPoints(points.len()));
        }
        if let Some(index) = points.iter().position(|p| !p.iter().all(|v| v.is_finite())) {
            return Err(MeshError::NonFinite {
                what: "point",
                index,
                value: points[index],
            });
        }
        let n = points.len() as f64;
        let mut mean = Vector3::zeros();
        for p in points {
            mean += Vector3::from(*p);
        }
        mean /= n;
        // The six distinct entries of the symmetric covariance, summed in point order.
        let mut sums = [0.0f64; 6];
        for p in points {
            let d = Vector3::from(*p) - mean;
            let (x, y, z) = (d[0], d[1], d[2]);
            for (s, v) in sums
                .iter_mut()
                .zip([x * x, x * y, x * z, y * y, y * z, z * z])
            {
                *s += v;
            }
        }
        let [xx, xy, xz, yy, yz, zz] = sums;
        let cov = Matrix3::new(xx, xy, xz, xy, yy, yz, xz, yz, zz) / n;
        let eigen = SymmetricEigen::new(cov);
        let mut order = [0usize, 1, 2];
        order.sort_by(|&a, &b| eigen.eigenvalues[b].total_cmp(&eigen.eigenvalues[a]));
        let largest = eigen.eigenvalues[order[0]];
        let middle = eigen.eigenvalues[order[1]];
        if largest.is_nan() || largest <= 0.0 || middle <= largest * 1e-18 {
            return Err(MeshError::Degenerate);
        }
        let axis_x = eigen.eigenvectors.column(order[0]).normalize();
        let normal = eigen.eigenvectors.column(order[2]).normalize();
        let axis_y = normal.cross(&axis_x).normalize();
        Ok(Self {
            origin: mean.into(),
            axis_x: axis_x.into(),
            axis_y: axis_y.into(),
            normal: normal.into(),
        })
    }

    /// The same plane seen from the other side: `axis_y` and `normal` negated.
    pub fn flipped(&self) -> Self {
        Self {
            axis_y: self.axis_y.map(|v| -v),
            normal: self.normal.map(|v| -v),
            ..*self
        }
    }

    /// Plane coordinates of `p` (its orthogonal projection onto the plane).
    #[inline]
    pub fn to_plane(&self, p: [f64; 3]) -> [f64; 2] {
        let d = [
            p[0] - self.origin[0],
            p[1] - self.origin[1],
            p[2] - self.origin[2],
        ];
        [dot(d, self.axis_x), dot(d, self.axis_y)]
    }

    /// The 3D point at plane coordinates `q`.
    #[inline]
    pub fn to_world(&self, q: [f64; 2]) -> [f64; 3] {
        std::array::from_fn(|k| self.origin[k] + q[0] * self.axis_x[k] + q[1] * self.axis_y[k])
    }

    /// Signed distance of `p` from the plane, positive on the normal's side.
    #[inline]
    pub fn distance(&self, p: [f64; 3]) -> f64 {
        dot(
            [
                p[0] - self.origin[0],
                p[1] - self.origin[1],
                p[2] - self.origin[2],
            ],
            self.normal,
        )
    }
}

#[cfg(test)]
mod tests {
    #![allow(clippy::unwrap_used)]
    use super::*;

    #[test]
    fn fit_recovers_a_tilted_plane() {
        // Points on the plane z = 0.5 x - 0.25 y + 3 with alternating offsets ±e along the
        // normal: the least-squares plane is the plane itself.
        let n = Vector3::new(-0.5, 0.25, 1.0).normalize();
        let mut points = Vec::new();
        for i in 0..20 {
            for j in 0..15 {
                let (x, y) = (f64::from(i) * 0.1, f64::from(j) * 0.1);
                let e = if (i + j) % 2 == 0 { 1e-3 } else { -1e-3 };
                let p = Vector3::new(x, y, 0.5 * x - 0.25 * y + 3.0) + n * e;
                points.push([p.x, p.y, p.z]);
            }
        }
        let frame = PlaneFrame::fit(&points).unwrap();
        let found = Vector3::from(frame.normal);
        assert!(found.dot(&n).abs() > 1.0 - 1e-6);
        let (ax, ay) = (Vector3::from(frame.axis_x), Vector3::from(frame.axis_y));
        assert!((ax.cross(&ay) - found).norm() < 1e-12);
        for p in &points {
            let back = frame.to_world(frame.to_plane(*p));
            assert!(frame.distance(back).abs() < 1e-12);
            assert!(frame.distance(*p).abs() < 1.1e-3);
        }
    }

    #[test]
    fn bad_input_is_named() {
        assert_eq!(
            PlaneFrame::fit(&[[0.0; 3]; 2]),
            Err(MeshError::TooFewPoints(2))
        );
        let line: Vec<[f64; 3]> = (0..5).map(|i| [f64::from(i), 0.0, 0.0]).collect();
        assert_eq!(PlaneFrame::fit(&line), Err(MeshError::Degenerate));
        let nan = [[0.0; 3], [1.0, 0.0, 0.0], [0.0, f64::NAN, 0.0]];
        assert!(matches!(
            PlaneFrame::fit(&nan),
            Err(MeshError::NonFinite { index: 2, .. })
        ));
    }
}

//! Least-squares plane fitting by the smallest eigenvector of the scatter matrix.
//!
//! Written here on purpose rather than taken from `plane-geom` (the workspace's shared
//! plane, frame and eigen routines): this fit is the independent oracle the scores
//! judge a segmentation by, so it shares no code with the pipeline it scores.

/// A least-squares plane through a set of points.
///
/// The plane passes through `centroid` with unit `normal` and minimises the sum of squared
/// orthogonal distances of the points to it.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct LeastSquaresPlane {
    /// Unit normal: the eigenvector of the smallest eigenvalue of the scatter matrix. Its
    /// sign is arbitrary; for fewer than three points, or collinear points, any unit vector
    /// orthogonal to the points' span may come back.
    pub normal: [f64; 3],
    /// Mean of the points; the plane passes through it.
    pub centroid: [f64; 3],
    /// Root mean square orthogonal distance of the points to the plane, in the points'
    /// unit: `sqrt(λ_min / n)` with `λ_min` the smallest eigenvalue of the scatter matrix.
    pub rmse: f64,
    /// Number of points fitted.
    pub points: usize,
}

/// Fits a plane to `points` by least squares (orthogonal distances).
///
/// The centroid comes first, then the scatter matrix `S = Σ (p − c)(p − c)ᵀ` is built around
/// it (two passes, so large coordinate offsets such as UTM eastings cost no precision), and
/// a cyclic Jacobi eigen-decomposition of the 3 × 3 symmetric `S` gives the normal (the
/// eigenvector of the smallest eigenvalue `λ_min`) and the residual sum of squares
/// `λ_min = min_{‖n‖=1} Σ (n · (p − c))²`.
///
/// Returns `None` for an empty slice or when any coordinate is NaN or infinite. One or two
/// points, or collinear points, fit exactly (`rmse == 0`).
///
/// ```
/// use seg_metrics::fit_plane;
///
/// let fit = fit_plane(&[[0.0, 0.0, 1.0], [1.0, 0.0, 1.0], [0.0, 1.0, 1.0], [1.0, 1.0, 1.0]])
///     .expect("finite points");
/// assert!(fit.rmse < 1e-12);
/// assert!((fit.normal[2].abs() - 1.0).abs() < 1e-12);
/// assert_eq!(fit.centroid, [0.5, 0.5, 1.0]);
/// ```
pub fn fit_plane(points: &[[f64; 3]]) -> Option<LeastSquaresPlane> {
    if points.is_empty() || !points.iter().all(is_finite) {
        return None;
    }
    let n = points.len() as f64;
    let mut sum = [0.0; 3];
    for p in points {
        for a in 0..3 {
            sum[a] += p[a];
        }
    }
    let centroid = sum.map(|s| s / n);
    let scatter = Scatter::of(points, &centroid);
    let (lambda, normal) = smallest_eigen(&scatter.matrix());
    Some(LeastSquaresPlane {
        normal,
        centroid,
        rmse: (lambda.max(0.0) / n).sqrt(),
        points: points.len(),
    })
}

/// Root mean square orthogonal distance of `points` to their least-squares plane (see
/// [`fit_plane`]); `None` for an empty slice or non-finite coordinates.
///
/// ```
/// use seg_metrics::fit_plane_rmse;
///
/// // The corners of a 10 × 10 × 2 box: the best plane lies half-way between the two
/// // large faces, 1 from every point.
/// let rmse = fit_plane_rmse(&[
///     [0.0, 0.0, 0.0], [10.0, 0.0, 0.0], [0.0, 10.0, 0.0], [10.0, 10.0, 0.0],
///     [0.0, 0.0, 2.0], [10.0, 0.0, 2.0], [0.0, 10.0, 2.0], [10.0, 10.0, 2.0],
/// ]);
/// assert!((rmse.unwrap() - 1.0).abs() < 1e-12);
/// assert_eq!(fit_plane_rmse(&[]), None);
/// ```
pub fn fit_plane_rmse(points: &[[f64; 3]]) -> Option<f64> {
    fit_plane(points).map(|fit| fit.rmse)
}

pub(crate) fn is_finite(p: &[f64; 3]) -> bool {
    p[0].is_finite() && p[1].is_finite() && p[2].is_finite()
}

/// The six distinct entries of a symmetric 3 × 3 scatter matrix, accumulated around a
/// given centre.
#[derive(Debug, Clone, Copy, Default)]
pub(crate) struct Scatter {
    xx: f64,
    xy: f64,
    xz: f64,
    yy: f64,
    yz: f64,
    zz: f64,
}

impl Scatter {
    #[inline]
    pub(crate) fn add(&mut self, p: &[f64; 3], centre: &[f64; 3]) {
        let (x, y, z) = (p[0] - centre[0], p[1] - centre[1], p[2] - centre[2]);
        self.xx += x * x;
        self.xy += x * y;
        self.xz += x * z;
        self.yy += y * y;
        self.yz += y * z;
        self.zz += z * z;
    }

    /// The scatter of `points` around `centre`.
    pub(crate) fn of(points: &[[f64; 3]], centre: &[f64; 3]) -> Self {
        let mut scatter = Self::default();
        for p in points {
            scatter.add(p, centre);
        }
        scatter
    }

    #[inline]
    pub(crate) fn merge(&mut self, other: &Scatter) {
        self.xx += other.xx;
        self.xy += other.xy;
        self.xz += other.xz;
        self.yy += other.yy;
        self.yz += other.yz;
        self.zz += other.zz;
    }

    pub(crate) fn matrix(&self) -> [[f64; 3]; 3] {
        [
            [self.xx, self.xy, self.xz],
            [self.xy, self.yy, self.yz],
            [self.xz, self.yz, self.zz],
        ]
    }

    /// Smallest eigenvalue, clamped at zero: the residual sum of squares of the
    /// least-squares plane.
    pub(crate) fn residual_sum_of_squares(&self) -> f64 {
        smallest_eigen(&self.matrix()).0.max(0.0)
    }
}

/// Smallest eigenvalue of a symmetric 3 × 3 matrix and a unit eigenvector for it, by cyclic
/// Jacobi rotations (accurate also for eigenvalues many orders of magnitude below the
/// largest, which is exactly the thin-plane case).
pub(crate) fn smallest_eigen(m: &[[f64; 3]; 3]) -> (f64, [f64; 3]) {
    let mut a = *m;
    // Columns of `v` are the eigenvectors.
    let mut v = [[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]];
    let frobenius2: f64 = a.iter().flatten().map(|x| x * x).sum();
    for _sweep in 0..64 {
        let off = a[0][1] * a[0][1] + a[0][2] * a[0][2] + a[1][2] * a[1][2];
        if off == 0.0 || off <= 1e-40 * frobenius2 {
            break;
        }
        for (p, q) in [(0, 1), (0, 2), (1, 2)] {
            let apq = a[p][q];
            if apq == 0.0 {
                continue;
            }
            // Rotation angle φ with tan φ = t zeroing a[p][q]: t² + 2θt − 1 = 0, smaller root.
            let theta = (a[q][q] - a[p][p]) / (2.0 * apq);
            let t = if theta.abs() > 1e150 {
                0.5 / theta
            } else {
                theta.signum() / (theta.abs() + (theta * theta + 1.0).sqrt())
            };
            let c = 1.0 / (t * t + 1.0).sqrt();
            let s = t * c;
            // a ← Jᵀ a J with J = identity except J[p][p] = J[q][q] = c, J[p][q] = s,
            // J[q][p] = −s. Columns first (a J), then rows (Jᵀ ·).
            for row in &mut a {
                let (rp, rq) = (row[p], row[q]);
                row[p] = c * rp - s * rq;
                row[q] = s * rp + c * rq;
            }
            let (row_p, row_q) = (a[p], a[q]);
            for k in 0..3 {
                a[p][k] = c * row_p[k] - s * row_q[k];
                a[q][k] = s * row_p[k] + c * row_q[k];
            }
            a[p][q] = 0.0;
            a[q][p] = 0.0;
            for row in &mut v {
                let (rp, rq) = (row[p], row[q]);
                row[p] = c * rp - s * rq;
                row[q] = s * rp + c * rq;
            }
        }
    }
    let mut k = 0;
    for i in 1..3 {
        if a[i][i] < a[k][k] {
            k = i;
        }
    }
    let vector = [v[0][k], v[1][k], v[2][k]];
    let norm = (vector[0] * vector[0] + vector[1] * vector[1] + vector[2] * vector[2]).sqrt();
    (a[k][k], vector.map(|x| x / norm))
}

#[cfg(test)]
mod tests {
    use super::*;

    fn mul(m: &[[f64; 3]; 3], x: &[f64; 3]) -> [f64; 3] {
        [0, 1, 2].map(|r| m[r][0] * x[0] + m[r][1] * x[1] + m[r][2] * x[2])
    }

    #[test]
    fn jacobi_finds_the_smallest_eigenpair() {
        let m = [[4.0, 1.0, -2.0], [1.0, 3.0, 0.5], [-2.0, 0.5, 5.0]];
        let (lambda, x) = smallest_eigen(&m);
        let mx = mul(&m, &x);
        for a in 0..3 {
            assert!(
                (mx[a] - lambda * x[a]).abs() < 1e-12,
                "{mx:?} vs {lambda} {x:?}"
            );
        }
        // The trace is the sum of eigenvalues; the smallest is below a third of it.
        assert!(lambda < 12.0 / 3.0);
        assert!(lambda > 0.0);
    }

    #[test]
    fn diagonal_and_zero_matrices() {
        let (lambda, x) = smallest_eigen(&[[3.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 2.0]]);
        assert_eq!(lambda, 1.0);
        assert_eq!(x, [0.0, 1.0, 0.0]);
        let (lambda, x) = smallest_eigen(&[[0.0; 3]; 3]);
        assert_eq!(lambda, 0.0);
        assert!((x.iter().map(|c| c * c).sum::<f64>() - 1.0).abs() < 1e-15);
    }

    #[test]
    fn tiny_eigenvalue_keeps_relative_accuracy() {
        // A thin slab: extents 10 and 5 along tilted axes, thickness 1e-4.
        let (u, w) = ([0.6, 0.8, 0.0], [0.0, 0.0, 1.0]);
        let n = [0.8, -0.6, 0.0];
        let d = [100.0, 25.0, 1e-8];
        let mut m = [[0.0; 3]; 3];
        for (axis, dd) in [u, w, n].iter().zip(d) {
            for r in 0..3 {
                for c in 0..3 {
                    m[r][c] += dd * axis[r] * axis[c];
                }
            }
        }
        let (lambda, x) = smallest_eigen(&m);
        assert!((lambda - 1e-8).abs() < 1e-8 * 1e-6, "{lambda}");
        assert!((x[0] * n[0] + x[1] * n[1]).abs() > 1.0 - 1e-12);
    }

    #[test]
    fn fit_rejects_empty_and_non_finite() {
        assert_eq!(fit_plane(&[]), None);
        assert_eq!(fit_plane(&[[0.0, f64::NAN, 0.0]]), None);
        assert_eq!(fit_plane(&[[0.0, 0.0, f64::INFINITY]]), None);
        let one = fit_plane(&[[1.0, 2.0, 3.0]]).unwrap();
        assert_eq!(one.rmse, 0.0);
        assert_eq!(one.centroid, [1.0, 2.0, 3.0]);
    }

    #[test]
    fn large_offsets_cost_no_precision() {
        // A tilted plane near UTM-like coordinates with ±1 mm alternating offsets.
        let origin = [500_000.0, 5_400_000.0, 300.0];
        let pts: Vec<[f64; 3]> = (0..400)
            .map(|i| {
                let (u, v) = ((i % 20) as f64, (i / 20) as f64);
                let e = if i % 2 == 0 { 1e-3 } else { -1e-3 };
                [
                    origin[0] + u,
                    origin[1] + v,
                    origin[2] + 0.1 * u + 0.2 * v + e,
                ]
            })
            .collect();
        let rmse = fit_plane_rmse(&pts).unwrap();
        // Distances along the normal are e / sqrt(1 + 0.01 + 0.04) (up to the small tilt
        // the alternating pattern induces).
        let expected = 1e-3 / (1.05f64).sqrt();
        assert!((rmse - expected).abs() < 1e-5, "{rmse} vs {expected}");
    }
}

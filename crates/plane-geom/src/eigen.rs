//! The eigen decomposition of symmetric 3 × 3 matrices (covariances of point sets).

use nalgebra::{Matrix3, SymmetricEigen};

use crate::vec3::{Vec3, cross, dot};

/// The most implicit QR steps [`symmetric_eigen`] runs before giving up; a finite 3 × 3 matrix
/// converges in a few dozen, so the cap only turns a would-be hang into `None`.
const MAX_SWEEPS: usize = 10_000;

/// Eigenvalues and unit eigenvectors of a symmetric 3 × 3 matrix, eigenvalues ascending.
///
/// `vectors[i]` is the eigenvector of `values[i]`. For a covariance of points,
/// `vectors[0]` is the least-squares plane's normal (its sign is whatever the solver
/// gives, deterministic for a given matrix) and `values[0]` the mean squared distance
/// to that plane.
#[derive(Debug, Clone, Copy, PartialEq)]
#[non_exhaustive]
pub struct Eigen3 {
    /// The eigenvalues, ascending; equal ones keep the solver's order.
    pub values: [f64; 3],
    /// The unit eigenvectors, `vectors[i]` for `values[i]`.
    pub vectors: [Vec3; 3],
}

/// The eigen decomposition of the symmetric matrix `m` (rows; it must be symmetric) by
/// nalgebra's [`SymmetricEigen`], sorted ascending; `None` when an entry is not finite
/// (or, which a finite matrix does not do, the solver does not converge).
///
/// ```
/// use plane_geom::symmetric_eigen;
///
/// // [[2, 1, 0], [1, 2, 0], [0, 0, 5]] has eigenvalues 1, 3, 5.
/// let e = symmetric_eigen([[2.0, 1.0, 0.0], [1.0, 2.0, 0.0], [0.0, 0.0, 5.0]]).ok_or("not finite")?;
/// for (got, want) in e.values.iter().zip([1.0, 3.0, 5.0]) {
///     assert!((got - want).abs() < 1e-12);
/// }
/// let v = e.vectors[0]; // ±(1, −1, 0)/√2
/// assert!((v[0] + v[1]).abs() < 1e-12 && v[2].abs() < 1e-12);
/// # Ok::<(), &str>(())
/// ```
pub fn symmetric_eigen(m: [[f64; 3]; 3]) -> Option<Eigen3> {
    if !m.iter().flatten().all(|v| v.is_finite()) {
        return None;
    }
    let matrix = Matrix3::new(
        m[0][0], m[0][1], m[0][2], m[1][0], m[1][1], m[1][2], m[2][0], m[2][1], m[2][2],
    );
    // `SymmetricEigen::new` is this with no cap on the steps.
    let eigen = SymmetricEigen::try_new(matrix, f64::EPSILON, MAX_SWEEPS)?;
    let mut order = [0usize, 1, 2];
    order.sort_by(|&a, &b| eigen.eigenvalues[a].total_cmp(&eigen.eigenvalues[b]));
    Some(Eigen3 {
        values: order.map(|i| eigen.eigenvalues[i]),
        vectors: order.map(|i| {
            let c = eigen.eigenvectors.column(i);
            [c[0], c[1], c[2]]
        }),
    })
}

/// The eigenvalues, ascending, of the symmetric matrix given by its entries
/// `[xx, yy, zz, xy, xz, yz]`, in closed form (the trigonometric solution of the
/// characteristic cubic); all three equal the mean of the diagonal when the matrix is a
/// multiple of the identity or an entry is NaN.
///
/// This is the values-only fast path for hot loops that need no eigenvectors (the noise
/// estimate fits one 3 × 3 neighbourhood per pixel): it costs a fraction of
/// [`symmetric_eigen`] (see the crate README) and agrees with it to rounding.
///
/// ```
/// use plane_geom::symmetric_eigenvalues;
///
/// let e = symmetric_eigenvalues([2.0, 2.0, 5.0, 1.0, 0.0, 0.0]);
/// for (got, want) in e.iter().zip([1.0, 3.0, 5.0]) {
///     assert!((got - want).abs() < 1e-12);
/// }
/// ```
pub fn symmetric_eigenvalues(a: [f64; 6]) -> [f64; 3] {
    let [xx, yy, zz, xy, xz, yz] = a;
    let off = xy * xy + xz * xz + yz * yz;
    let q = (xx + yy + zz) / 3.0;
    let (dx, dy, dz) = (xx - q, yy - q, zz - q);
    let p2 = dx * dx + dy * dy + dz * dz + 2.0 * off;
    if p2.is_nan() || p2 <= 0.0 {
        return [q; 3];
    }
    let p = (p2 / 6.0).sqrt();
    // det((A − qI) / p) / 2, clamped into [−1, 1] against rounding.
    let (bx, by, bz, bxy, bxz, byz) = (dx / p, dy / p, dz / p, xy / p, xz / p, yz / p);
    let det =
        bx * (by * bz - byz * byz) - bxy * (bxy * bz - byz * bxz) + bxz * (bxy * byz - by * bxz);
    let half = (det / 2.0).clamp(-1.0, 1.0);
    let phi = half.acos() / 3.0;
    let largest = q + 2.0 * p * phi.cos();
    let smallest = q + 2.0 * p * (phi + 2.0 * std::f64::consts::FRAC_PI_3).cos();
    let middle = 3.0 * q - largest - smallest;
    [smallest, middle, largest]
}

/// The unit eigenvector of the smallest eigenvalue of the symmetric matrix given by its
/// entries `c = [xx, yy, zz, xy, xz, yz]`, and that eigenvalue over the trace; `None` when
/// it is not unique (the two smallest eigenvalues equal: a line, a spot) or the matrix is
/// not finite. The closed form of [`symmetric_eigenvalues`] for the value, the largest
/// cross product of two rows of `A − λI` for the vector: the fast path for a normal per
/// point (PCA normals of unorganized clouds).
///
/// ```
/// use plane_geom::smallest_eigenvector;
///
/// // The covariance of points spread in x and y: the normal is ±z.
/// let (normal, ratio) = smallest_eigenvector([2.0, 1.0, 0.0, 0.0, 0.0, 0.0]).ok_or("not unique")?;
/// assert!((normal[2].abs() - 1.0).abs() < 1e-12);
/// assert!(ratio < 1e-12);
/// # Ok::<(), &str>(())
/// ```
#[inline]
pub fn smallest_eigenvector(c: [f64; 6]) -> Option<([f64; 3], f64)> {
    let [xx, yy, zz, xy, xz, yz] = c;
    let trace = xx + yy + zz;
    if !(trace.is_finite() && trace > 0.0) {
        return None;
    }
    // Scale to unit trace so that the tolerances below are relative.
    let s = 1.0 / trace;
    let (xx, xy, xz, yy, yz, zz) = (xx * s, xy * s, xz * s, yy * s, yz * s, zz * s);
    let q = 1.0 / 3.0;
    let off = xy * xy + xz * xz + yz * yz;
    let p2 = (xx - q).powi(2) + (yy - q).powi(2) + (zz - q).powi(2) + 2.0 * off;
    let p = (p2 / 6.0).sqrt();
    if p < 1e-12 {
        return None;
    }
    // B = (A − qI) / p; r = det(B) / 2 ∈ [−1, 1]; eigenvalues q + 2p cos(φ + 2πj/3).
    let (b00, b11, b22) = ((xx - q) / p, (yy - q) / p, (zz - q) / p);
    let (b01, b02, b12) = (xy / p, xz / p, yz / p);
    let det = b00 * (b11 * b22 - b12 * b12) - b01 * (b01 * b22 - b12 * b02)
        + b02 * (b01 * b12 - b11 * b02);
    let phi = (det / 2.0).clamp(-1.0, 1.0).acos() / 3.0;
    let smallest = q + 2.0 * p * (phi + 2.0 * std::f64::consts::PI / 3.0).cos();
    let middle = q + 2.0 * p * (phi + 4.0 * std::f64::consts::PI / 3.0).cos();
    if middle - smallest < 1e-6 {
        return None;
    }
    // The eigenvector is orthogonal to every row of A − λI: the largest cross product of
    // two rows.
    let r0 = [xx - smallest, xy, xz];
    let r1 = [xy, yy - smallest, yz];
    let r2 = [xz, yz, zz - smallest];
    let norm2 = |a: [f64; 3]| dot(a, a);
    let best = [cross(r0, r1), cross(r0, r2), cross(r1, r2)]
        .into_iter()
        .max_by(|a, b| norm2(*a).total_cmp(&norm2(*b)))?;
    let len = norm2(best).sqrt();
    if !(len.is_finite() && len > 0.0) {
        return None;
    }
    Some((best.map(|v| v / len), smallest.max(0.0)))
}

/// The centroid of the points `points()` yields and their covariance matrix about it, in
/// two passes (the mean first, then the products of the centred offsets, which keeps the
/// precision of coordinates far from zero without a reference point): the input of a
/// least-squares plane fit by [`symmetric_eigen`]. `None` without points or when a
/// coordinate is not finite.
///
/// ```
/// use plane_geom::centroid_and_covariance;
///
/// let points = [[10.0, 0.0, 5.0], [12.0, 0.0, 5.0]];
/// let (centroid, c) = centroid_and_covariance(|| points.into_iter()).unwrap();
/// assert_eq!(centroid, [11.0, 0.0, 5.0]);
/// assert_eq!(c, [[1.0, 0.0, 0.0], [0.0, 0.0, 0.0], [0.0, 0.0, 0.0]]);
/// assert!(centroid_and_covariance(|| [[f64::NAN, 0.0, 0.0]].into_iter()).is_none());
/// assert!(centroid_and_covariance(|| std::iter::empty()).is_none());
/// ```
pub fn centroid_and_covariance<I>(points: impl Fn() -> I) -> Option<(Vec3, [[f64; 3]; 3])>
where
    I: Iterator<Item = Vec3>,
{
    let mut count = 0usize;
    let mut sum = [0.0f64; 3];
    for p in points() {
        if !(p[0].is_finite() && p[1].is_finite() && p[2].is_finite()) {
            return None;
        }
        count += 1;
        for k in 0..3 {
            sum[k] += p[k];
        }
    }
    if count == 0 {
        return None;
    }
    let inv = 1.0 / count as f64;
    let mean = sum.map(|s| s * inv);
    // xx xy xz yy yz zz
    let mut c = [0.0f64; 6];
    for p in points() {
        let d = [p[0] - mean[0], p[1] - mean[1], p[2] - mean[2]];
        c[0] += d[0] * d[0];
        c[1] += d[0] * d[1];
        c[2] += d[0] * d[2];
        c[3] += d[1] * d[1];
        c[4] += d[1] * d[2];
        c[5] += d[2] * d[2];
    }
    let [xx, xy, xz, yy, yz, zz] = c.map(|v| v * inv);
    Some((mean, [[xx, xy, xz], [xy, yy, yz], [xz, yz, zz]]))
}

/// The covariance of `points` as `[xx, yy, zz, xy, xz, yz]` (the entries
/// [`symmetric_eigenvalues`] and [`smallest_eigenvector`] take), accumulated in one pass as
/// offsets from `origin`, a point near them, so that coordinates far from zero keep their
/// precision; `None` without points or when an offset is not finite.
///
/// ```
/// use plane_geom::covariance;
///
/// let points = [[10.0, 0.0, 5.0], [12.0, 0.0, 5.0]];
/// assert_eq!(covariance(points[0], points), Some([1.0, 0.0, 0.0, 0.0, 0.0, 0.0]));
/// assert_eq!(covariance([0.0; 3], []), None);
/// ```
pub fn covariance(origin: Vec3, points: impl IntoIterator<Item = Vec3>) -> Option<[f64; 6]> {
    let mut n = 0usize;
    let mut sum = [0.0f64; 3];
    // xx, yy, zz, xy, xz, yz of the offsets.
    let mut sq = [0.0f64; 6];
    for p in points {
        let d = [p[0] - origin[0], p[1] - origin[1], p[2] - origin[2]];
        if !(d[0].is_finite() && d[1].is_finite() && d[2].is_finite()) {
            return None;
        }
        n += 1;
        for a in 0..3 {
            sum[a] += d[a];
        }
        sq[0] += d[0] * d[0];
        sq[1] += d[1] * d[1];
        sq[2] += d[2] * d[2];
        sq[3] += d[0] * d[1];
        sq[4] += d[0] * d[2];
        sq[5] += d[1] * d[2];
    }
    if n == 0 {
        return None;
    }
    let n = n as f64;
    let m = sum.map(|s| s / n);
    Some([
        sq[0] / n - m[0] * m[0],
        sq[1] / n - m[1] * m[1],
        sq[2] / n - m[2] * m[2],
        sq[3] / n - m[0] * m[1],
        sq[4] / n - m[0] * m[2],
        sq[5] / n - m[1] * m[2],
    ])
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn diagonal_and_rotated_matrices_have_known_eigenvalues() {
        let e = symmetric_eigenvalues([3.0, 1.0, 2.0, 0.0, 0.0, 0.0]);
        for (got, want) in e.iter().zip([1.0, 2.0, 3.0]) {
            assert!((got - want).abs() < 1e-12, "{e:?}");
        }
        let e = symmetric_eigen([[3.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 2.0]]);
        assert_eq!(e.map(|e| e.values), Some([1.0, 2.0, 3.0]));
        assert_eq!(e.map(|e| e.vectors[0].map(f64::abs)), Some([0.0, 1.0, 0.0]));
    }

    /// The closed-form smallest eigenvector against nalgebra's decomposition, on
    /// covariances `M Mᵀ` of a grid of matrices with a clear smallest eigenvalue.
    #[test]
    fn smallest_eigenvector_matches_the_full_decomposition() {
        let mut checked = 0;
        for k in 0..500 {
            let t = f64::from(k);
            let m = [
                [(t * 0.37).sin(), (t * 0.11).cos(), 0.3],
                [(t * 0.73).cos(), 0.5, (t * 0.29).sin()],
                [0.1 * (t * 0.53).sin(), (t * 0.17).sin(), (t * 0.91).cos()],
            ];
            let a: [[f64; 3]; 3] =
                std::array::from_fn(|i| std::array::from_fn(|j| dot(m[i], m[j])));
            let full = symmetric_eigen(a).unwrap();
            let trace = a[0][0] + a[1][1] + a[2][2];
            if full.values[1] - full.values[0] < 1e-3 * trace {
                continue;
            }
            let c = [a[0][0], a[1][1], a[2][2], a[0][1], a[0][2], a[1][2]];
            let (v, ratio) = smallest_eigenvector(c).unwrap();
            assert!(
                dot(v, full.vectors[0]).abs() > 1.0 - 1e-9,
                "{k}: {v:?} {:?}",
                full.vectors[0]
            );
            assert!(
                (ratio - full.values[0].max(0.0) / trace).abs() < 1e-9,
                "{k}"
            );
            checked += 1;
        }
        assert!(checked > 300, "{checked}");
    }

    #[test]
    fn non_finite_matrices_have_no_decomposition() {
        let mut m = [[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]];
        m[1][2] = f64::NAN;
        assert_eq!(symmetric_eigen(m), None);
        m[1][2] = f64::INFINITY;
        assert_eq!(symmetric_eigen(m), None);
        assert!(symmetric_eigenvalues([f64::NAN, 1.0, 1.0, 0.0, 0.0, 0.0])[0].is_nan());
    }
}

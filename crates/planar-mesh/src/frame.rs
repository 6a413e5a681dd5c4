//! Preprocessing (§IV-A1): the least-squares plane of a segment (PCA) and the rigid
//! transform into its x-y frame.

use plane_geom::vec3::norm;
use plane_geom::{PlaneFrame, centroid_and_covariance, symmetric_eigen};

use crate::PlanarMeshError;

/// The least-squares plane of `points` by principal component analysis, as a frame:
/// the normal is the eigenvector of the covariance with the smallest eigenvalue, `e1`
/// the one with the largest (the direction of the points' largest spread, so that a
/// texture laid along it wastes least), the origin the centroid.
///
/// ```
/// use planar_mesh::fit_frame;
///
/// let points = [[0.0, 0.0, 2.0], [1.0, 0.0, 2.0], [0.0, 1.0, 2.0], [1.0, 1.0, 2.0]];
/// let frame = fit_frame(&points)?;
/// assert!((frame.normal[2].abs() - 1.0).abs() < 1e-12);
/// let back = frame.lift(frame.project([1.0, 1.0, 2.5]));
/// assert!((back[2] - 2.0).abs() < 1e-12); // projected onto the plane
/// # Ok::<(), planar_mesh::PlanarMeshError>(())
/// ```
///
/// # Errors
/// [`PlanarMeshError::TooFewPoints`] below 3 points, [`PlanarMeshError::NonFinite`] for a NaN or
/// infinite coordinate, [`PlanarMeshError::Degenerate`] when the points are collinear or
/// coincide.
pub fn fit_frame(points: &[[f64; 3]]) -> Result<PlaneFrame, PlanarMeshError> {
    if points.len() < 3 {
        return Err(PlanarMeshError::TooFewPoints(points.len()));
    }
    let Some((mean, covariance)) = centroid_and_covariance(|| points.iter().copied()) else {
        let index = points
            .iter()
            .position(|p| !p.iter().all(|v| v.is_finite()))
            .unwrap_or(0);
        return Err(PlanarMeshError::NonFinite {
            what: "point",
            index,
            value: points[index],
        });
    };
    let eigen = symmetric_eigen(covariance).ok_or(PlanarMeshError::Degenerate)?;
    let [_, middle, largest] = eigen.values;
    if largest <= 0.0 || middle <= largest * 1e-18 {
        return Err(PlanarMeshError::Degenerate);
    }
    // The solver's eigenvectors are unit to rounding; they are normalised once more, by
    // division.
    let unit = |v: [f64; 3]| v.map(|x| x / norm(v));
    Ok(PlaneFrame::from_unit_axes(
        mean,
        unit(eigen.vectors[2]),
        unit(eigen.vectors[0]),
    ))
}

#[cfg(test)]
mod tests {
    #![allow(clippy::unwrap_used)]
    use nalgebra::Vector3;

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
        let frame = fit_frame(&points).unwrap();
        let found = Vector3::from(frame.normal);
        assert!(found.dot(&n).abs() > 1.0 - 1e-6);
        let (ax, ay) = (Vector3::from(frame.e1), Vector3::from(frame.e2));
        assert!((ax.cross(&ay) - found).norm() < 1e-12);
        for p in &points {
            let back = frame.lift(frame.project(*p));
            assert!(frame.signed_distance(back).abs() < 1e-12);
            assert!(frame.signed_distance(*p).abs() < 1.1e-3);
        }
    }

    #[test]
    fn bad_input_is_named() {
        assert_eq!(
            fit_frame(&[[0.0; 3]; 2]),
            Err(PlanarMeshError::TooFewPoints(2))
        );
        let line: Vec<[f64; 3]> = (0..5).map(|i| [f64::from(i), 0.0, 0.0]).collect();
        assert_eq!(fit_frame(&line), Err(PlanarMeshError::Degenerate));
        let nan = [[0.0; 3], [1.0, 0.0, 0.0], [0.0, f64::NAN, 0.0]];
        assert!(matches!(
            fit_frame(&nan),
            Err(PlanarMeshError::NonFinite { index: 2, .. })
        ));
    }
}

//! Delaunay triangulation of 2D point sets and of 3D clouds projected on a plane (2.5D).

use plane_geom::PlaneFrame;

use crate::{HalfEdgeMesh, MeshError, sweep};

/// Summary of a triangulation: points left out because they coincide with another.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub struct DelaunayReport {
    /// Input points left out because an equal point (same coordinates) is in the
    /// triangulation; of each group of equal points the first one is kept.
    pub duplicate_points: usize,
}

impl HalfEdgeMesh {
    /// Delaunay triangulation of a 2D point set (sweep-hull, exact orientation and in-circle
    /// tests). Vertices are the input points with `z = 0`, in input order; every triangle
    /// normal is `+z`.
    ///
    /// Coincident points are triangulated once; the others stay as unused vertices.
    ///
    /// ```
    /// use halfedge_mesh::HalfEdgeMesh;
    /// let mesh = HalfEdgeMesh::delaunay_2d(&[[0.0, 0.0], [2.0, 0.0], [1.0, 1.5], [1.0, -1.5]])?;
    /// assert_eq!(mesh.num_triangles(), 2);
    /// assert_eq!(mesh.triangle_normals().unwrap()[0], [0.0, 0.0, 1.0]);
    /// # Ok::<(), halfedge_mesh::MeshError>(())
    /// ```
    ///
    /// # Errors
    /// [`MeshError::TooFewPoints`], [`MeshError::NonFinitePoint`], [`MeshError::Collinear`],
    /// [`MeshError::TooLarge`].
    pub fn delaunay_2d(points: &[[f64; 2]]) -> Result<Self, MeshError> {
        Self::delaunay_2d_with_report(points).map(|(mesh, _)| mesh)
    }

    /// [`Self::delaunay_2d`], also returning how many duplicate points were merged.
    ///
    /// # Errors
    /// As [`Self::delaunay_2d`].
    pub fn delaunay_2d_with_report(
        points: &[[f64; 2]],
    ) -> Result<(Self, DelaunayReport), MeshError> {
        let (triangles, halfedges, report) = triangulate(points.len(), |i| points[i])?;
        let vertices = points.iter().map(|p| [p[0], p[1], 0.0]).collect();
        let normals = vec![[0.0, 0.0, 1.0]; triangles.len()];
        Ok((
            Self::from_parts_trusted(vertices, triangles, halfedges, normals),
            report,
        ))
    }

    /// 2.5D Delaunay triangulation of a 3D cloud: triangulates the points projected on the
    /// plane orthogonal to `up` (the xy plane for `up = [0, 0, 1]`), keeps the 3D points as
    /// vertices and computes 3D triangle normals, which all point to the `up` side.
    ///
    /// ```
    /// use halfedge_mesh::HalfEdgeMesh;
    /// let cloud = [[0.0, 0.0, 1.0], [1.0, 0.0, 1.0], [0.0, 1.0, 1.0], [1.0, 1.0, 1.0]];
    /// let mesh = HalfEdgeMesh::delaunay_25d(&cloud, [0.0, 0.0, 1.0])?;
    /// assert_eq!(mesh.num_triangles(), 2);
    /// # Ok::<(), halfedge_mesh::MeshError>(())
    /// ```
    ///
    /// # Errors
    /// As [`Self::delaunay_2d`], plus [`MeshError::BadUpVector`].
    pub fn delaunay_25d(points: &[[f64; 3]], up: [f64; 3]) -> Result<Self, MeshError> {
        Self::delaunay_25d_with_report(points, up).map(|(mesh, _)| mesh)
    }

    /// [`Self::delaunay_25d`], also returning how many duplicate points were merged.
    ///
    /// # Errors
    /// As [`Self::delaunay_25d`].
    pub fn delaunay_25d_with_report(
        points: &[[f64; 3]],
        up: [f64; 3],
    ) -> Result<(Self, DelaunayReport), MeshError> {
        // Projecting on the frame's (e1, e2) looks down `up`; for up = +z it is (x, y).
        let frame = PlaneFrame::new(up).ok_or(MeshError::BadUpVector { up })?;
        let (triangles, halfedges, report) =
            triangulate(points.len(), |i| frame.project(points[i]))?;
        let mut mesh = Self::from_parts_trusted(points.to_vec(), triangles, halfedges, Vec::new());
        mesh.compute_triangle_normals();
        Ok((mesh, report))
    }
}

/// The largest coordinate magnitude accepted: the in-circle test raises coordinate
/// differences to the fourth power, which must stay finite.
pub const MAX_COORDINATE: f64 = 1e60;

/// Counter-clockwise triangles, their twin array and the duplicates report.
type Triangulated = (Vec<[u32; 3]>, Vec<u32>, DelaunayReport);

/// Triangulates `n` points given by `point(i)` and returns counter-clockwise triangles
/// (indices into the caller's array) and their twin array.
///
/// Our sweep-hull triangulation with exact orientation and in-circle tests
/// (`crate::sweep`); cocircular ties are broken by point index, so the result is unique.
fn triangulate(n: usize, point: impl Fn(usize) -> [f64; 2]) -> Result<Triangulated, MeshError> {
    check_count(n)?;
    let mut input = Vec::with_capacity(n);
    for i in 0..n {
        let p = point(i);
        check_point(i, p)?;
        input.push(p);
    }
    let result = sweep::triangulate(&input, None).map_err(|_| MeshError::Collinear { count: n })?;
    let report = DelaunayReport {
        duplicate_points: result.duplicates as usize,
    };
    Ok((result.caller_triangles(), result.halfedges, report))
}

/// The point count a triangulation accepts: at least 3, and few enough that the `6n`
/// half-edge indices of up to `2n` triangles fit in `u32`.
pub(crate) fn check_count(n: usize) -> Result<(), MeshError> {
    if n < 3 {
        return Err(MeshError::TooFewPoints { found: n });
    }
    if n > (u32::MAX / 6) as usize {
        return Err(MeshError::TooLarge {
            what: "points",
            count: n,
        });
    }
    Ok(())
}

/// Point `index` must be finite and within [`MAX_COORDINATE`].
#[inline]
pub(crate) fn check_point(index: usize, [x, y]: [f64; 2]) -> Result<(), MeshError> {
    if !(x.is_finite() && y.is_finite()) {
        return Err(MeshError::NonFinitePoint { index });
    }
    if x.abs().max(y.abs()) > MAX_COORDINATE {
        return Err(MeshError::CoordinateTooLarge {
            index,
            value: if x.abs() > y.abs() { x } else { y },
            max: MAX_COORDINATE,
        });
    }
    Ok(())
}

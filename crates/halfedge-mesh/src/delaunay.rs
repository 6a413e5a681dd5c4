//! Delaunay triangulation of 2D point sets and of 3D clouds projected on a plane (2.5D).

use crate::mesh::NO_TWIN;
use crate::{HalfEdgeMesh, MeshError};

/// Summary of a triangulation: points left out because they coincide with another.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub struct DelaunayReport {
    /// Input points left out because an equal (or, within 2^-51 in both coordinates,
    /// nearly equal) point was already in the triangulation.
    pub duplicate_points: usize,
}

impl HalfEdgeMesh {
    /// Delaunay triangulation of a 2D point set (sweep-hull, exact orientation tests). Vertices are the
    /// input points with `z = 0`, in input order; every triangle normal is `+z`.
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
        let frame = PlaneFrame::new(up)?;
        let (triangles, halfedges, report) =
            triangulate(points.len(), |i| frame.project(points[i]))?;
        let mut mesh = Self::from_parts_trusted(points.to_vec(), triangles, halfedges, Vec::new());
        mesh.compute_triangle_normals();
        Ok((mesh, report))
    }
}

/// An orthonormal frame `(e1, e2, up)`: projecting on `(e1, e2)` looks down `up`.
#[derive(Debug, Clone, Copy)]
struct PlaneFrame {
    e1: [f64; 3],
    e2: [f64; 3],
}

impl PlaneFrame {
    fn new(up: [f64; 3]) -> Result<Self, MeshError> {
        let len = (up[0] * up[0] + up[1] * up[1] + up[2] * up[2]).sqrt();
        if !len.is_finite() || len == 0.0 {
            return Err(MeshError::BadUpVector { up });
        }
        let n = up.map(|c| c / len);
        // Pick the world axis least aligned with n to start e1 (Gram–Schmidt).
        let axis = if n[0].abs() <= n[1].abs() && n[0].abs() <= n[2].abs() {
            [1.0, 0.0, 0.0]
        } else if n[1].abs() <= n[2].abs() {
            [0.0, 1.0, 0.0]
        } else {
            [0.0, 0.0, 1.0]
        };
        let d = axis[0] * n[0] + axis[1] * n[1] + axis[2] * n[2];
        let e1 = [axis[0] - d * n[0], axis[1] - d * n[1], axis[2] - d * n[2]];
        let l1 = (e1[0] * e1[0] + e1[1] * e1[1] + e1[2] * e1[2]).sqrt();
        let e1 = e1.map(|c| c / l1);
        let e2 = [
            n[1] * e1[2] - n[2] * e1[1],
            n[2] * e1[0] - n[0] * e1[2],
            n[0] * e1[1] - n[1] * e1[0],
        ];
        // For up = +z keep the identity so that 2.5D on xy is exactly the xy triangulation.
        if n == [0.0, 0.0, 1.0] {
            return Ok(Self {
                e1: [1.0, 0.0, 0.0],
                e2: [0.0, 1.0, 0.0],
            });
        }
        Ok(Self { e1, e2 })
    }

    #[inline]
    fn project(&self, p: [f64; 3]) -> [f64; 2] {
        [
            p[0] * self.e1[0] + p[1] * self.e1[1] + p[2] * self.e1[2],
            p[0] * self.e2[0] + p[1] * self.e2[1] + p[2] * self.e2[2],
        ]
    }
}

/// The largest coordinate magnitude accepted: the in-circle test raises coordinate
/// differences to the fourth power, which must stay finite.
pub const MAX_COORDINATE: f64 = 1e60;

/// Triangulates `n` points given by `point(i)` and returns counter-clockwise triangles
/// (indices into the caller's array) and their twin array.
///
/// Uses delaunator (sweep-hull with exact orientation tests); its triangles run clockwise
/// in a y-up frame, so each is reversed here and the twin array remapped.
fn triangulate(
    n: usize,
    point: impl Fn(usize) -> [f64; 2],
) -> Result<(Vec<[u32; 3]>, Vec<u32>, DelaunayReport), MeshError> {
    if n < 3 {
        return Err(MeshError::TooFewPoints { found: n });
    }
    if n > u32::MAX as usize {
        return Err(MeshError::TooLarge {
            what: "points",
            count: n,
        });
    }
    let mut input = Vec::with_capacity(n);
    for i in 0..n {
        let [x, y] = point(i);
        if !(x.is_finite() && y.is_finite()) {
            return Err(MeshError::NonFinitePoint { index: i });
        }
        if x.abs().max(y.abs()) > MAX_COORDINATE {
            return Err(MeshError::CoordinateTooLarge {
                index: i,
                value: if x.abs() > y.abs() { x } else { y },
                max: MAX_COORDINATE,
            });
        }
        input.push(delaunator::Point { x, y });
    }
    let result = delaunator::triangulate(&input);
    let num_triangles = result.triangles.len() / 3;
    if num_triangles == 0 {
        return Err(MeshError::Collinear { count: n });
    }
    if result.triangles.len() >= u32::MAX as usize {
        return Err(MeshError::TooLarge {
            what: "triangles",
            count: num_triangles,
        });
    }
    // Reversing [a, b, c] into [a, c, b] turns old half-edge j into new half-edge 2 − j.
    let flip = |h: usize| (h - h % 3 + 2 - h % 3) as u32;
    let triangles: Vec<[u32; 3]> = result
        .triangles
        .chunks_exact(3)
        .map(|t| [t[0] as u32, t[2] as u32, t[1] as u32])
        .collect();
    let mut halfedges = vec![NO_TWIN; result.halfedges.len()];
    for (h, &twin) in result.halfedges.iter().enumerate() {
        if twin != delaunator::EMPTY {
            halfedges[flip(h) as usize] = flip(twin);
        }
    }
    let mut used = vec![false; n];
    for &v in &result.triangles {
        used[v] = true;
    }
    let report = DelaunayReport {
        duplicate_points: used.iter().filter(|u| !**u).count(),
    };
    Ok((triangles, halfedges, report))
}

//! Delaunay triangulation of 2D point sets and of 3D clouds projected on a plane (2.5D).

use spade::handles::FixedVertexHandle;
use spade::{DelaunayTriangulation, HasPosition, InsertionError, Point2, Triangulation};

use crate::mesh::NO_TWIN;
use crate::{HalfEdgeMesh, MeshError};

/// A point handed to spade, remembering its index in the caller's array.
#[derive(Debug, Clone, Copy)]
struct Indexed {
    position: Point2<f64>,
    index: u32,
}

impl HasPosition for Indexed {
    type Scalar = f64;
    fn position(&self) -> Point2<f64> {
        self.position
    }
}

/// Summary of a triangulation: points merged because they coincide with another.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub struct DelaunayReport {
    /// Input points left out because an equal point was already in the triangulation.
    pub duplicate_points: usize,
}

impl HalfEdgeMesh {
    /// Delaunay triangulation of a 2D point set (spade, exact predicates). Vertices are the
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

/// Triangulates `n` points given by `point(i)` and returns counter-clockwise triangles
/// (indices into the caller's array) and their twin array.
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
        let p = point(i);
        if !(p[0].is_finite() && p[1].is_finite()) {
            return Err(MeshError::NonFinitePoint { index: i });
        }
        input.push(Indexed {
            position: Point2::new(p[0], p[1]),
            index: i as u32,
        });
    }
    let tri = DelaunayTriangulation::<Indexed>::bulk_load(input).map_err(|e| match e {
        // Finite values spade cannot represent exactly (|x| > 2^201 or subnormal-small).
        InsertionError::NAN | InsertionError::TooLarge | InsertionError::TooSmall => {
            MeshError::NonFinitePoint {
                index: first_unrepresentable(n, &point),
            }
        }
    })?;
    if tri.num_inner_faces() == 0 {
        return Err(MeshError::Collinear { count: n });
    }
    if 3 * tri.num_inner_faces() >= u32::MAX as usize {
        return Err(MeshError::TooLarge {
            what: "triangles",
            count: tri.num_inner_faces(),
        });
    }
    let report = DelaunayReport {
        duplicate_points: n - tri.num_vertices(),
    };
    let vertex_index = |v: FixedVertexHandle| tri.vertex(v).data().index;

    // Half-edge 3t + i is the i-th directed edge of inner face t walked from the face's
    // adjacent edge; spade's directed edge indices map back to it without hashing.
    let mut he_of_edge = vec![NO_TWIN; tri.num_directed_edges()];
    let mut triangles = Vec::with_capacity(tri.num_inner_faces());
    for (t, face) in tri.inner_faces().enumerate() {
        let e0 = face.adjacent_edge();
        let edges = [e0, e0.next(), e0.prev()];
        triangles.push(edges.map(|e| vertex_index(e.from().fix())));
        for (i, e) in edges.iter().enumerate() {
            he_of_edge[e.fix().index()] = (3 * t + i) as u32;
        }
    }
    let mut halfedges = vec![NO_TWIN; 3 * triangles.len()];
    for (t, face) in tri.inner_faces().enumerate() {
        let e0 = face.adjacent_edge();
        for (i, e) in [e0, e0.next(), e0.prev()].iter().enumerate() {
            halfedges[3 * t + i] = he_of_edge[e.rev().fix().index()];
        }
    }
    Ok((triangles, halfedges, report))
}

/// The first point spade refuses (too large or too small in magnitude to be exact).
fn first_unrepresentable(n: usize, point: &impl Fn(usize) -> [f64; 2]) -> usize {
    (0..n)
        .find(|&i| {
            point(i)
                .iter()
                .any(|c| spade::validate_coordinate(*c).is_err())
        })
        .unwrap_or(0)
}

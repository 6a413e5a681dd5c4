//! The [`HalfEdgeMesh`] type, its accessors and triangle normals.

use rayon::prelude::*;

use crate::MeshError;

/// Sentinel stored in the twin array for a half-edge without a twin (a border edge).
pub const NO_TWIN: u32 = u32::MAX;

/// Triangles in parallel loops are handed out in chunks of this size.
const PAR_CHUNK: usize = 4096;

/// A triangle mesh with twin half-edges.
///
/// * `vertices` are `f64` points; vertices no triangle uses may be NaN (an organized point
///   cloud keeps its invalid pixels as vertices so that point indices stay pixel indices).
/// * `triangles[t] = [a, b, c]` lists vertex indices counter-clockwise seen from the
///   triangle's normal side.
/// * Half-edge `h = 3 t + i` runs from `triangles[t][i]` to `triangles[t][(i + 1) % 3]`, so
///   half-edge `h` belongs to triangle `h / 3`.
/// * `halfedges[h]` is the twin of `h` (the same edge in the neighbouring triangle, running
///   the other way) or [`NO_TWIN`].
/// * `triangle_normals`, when present, has one unit normal per triangle.
///
/// The default is the empty mesh.
///
/// # Example
/// ```
/// use halfedge_mesh::{HalfEdgeMesh, NO_TWIN};
///
/// // Two triangles sharing the diagonal of the unit square.
/// let mesh = HalfEdgeMesh::delaunay_2d(&[[0.0, 0.0], [1.0, 0.0], [1.0, 1.0], [0.0, 1.0]])?;
/// assert_eq!(mesh.num_triangles(), 2);
/// let shared = (0..6).filter(|&h| mesh.twin(h).is_some()).count();
/// assert_eq!(shared, 2);
/// mesh.sanity_check()?;
/// # Ok::<(), halfedge_mesh::MeshError>(())
/// ```
#[derive(Debug, Clone, Default, PartialEq)]
pub struct HalfEdgeMesh {
    pub(crate) vertices: Vec<[f64; 3]>,
    pub(crate) triangles: Vec<[u32; 3]>,
    pub(crate) halfedges: Vec<u32>,
    pub(crate) triangle_normals: Vec<[f64; 3]>,
}

impl HalfEdgeMesh {
    /// Assembles a mesh from its arrays and checks every invariant ([`Self::sanity_check`]).
    ///
    /// Pass an empty `triangle_normals` to build a mesh without normals.
    ///
    /// # Errors
    /// Any broken invariant, as a [`MeshError`].
    pub fn from_parts(
        vertices: Vec<[f64; 3]>,
        triangles: Vec<[u32; 3]>,
        halfedges: Vec<u32>,
        triangle_normals: Vec<[f64; 3]>,
    ) -> Result<Self, MeshError> {
        let mesh = Self {
            vertices,
            triangles,
            halfedges,
            triangle_normals,
        };
        mesh.sanity_check()?;
        Ok(mesh)
    }

    /// Assembles a mesh from arrays the caller has built correctly (for example a mesher
    /// that derives twins from a grid). Only the array lengths are checked here, in debug
    /// builds; use [`Self::from_parts`] for untrusted data.
    pub fn from_parts_trusted(
        vertices: Vec<[f64; 3]>,
        triangles: Vec<[u32; 3]>,
        halfedges: Vec<u32>,
        triangle_normals: Vec<[f64; 3]>,
    ) -> Self {
        debug_assert_eq!(halfedges.len(), 3 * triangles.len());
        debug_assert!(triangle_normals.is_empty() || triangle_normals.len() == triangles.len());
        Self {
            vertices,
            triangles,
            halfedges,
            triangle_normals,
        }
    }

    /// Splits the mesh into its arrays: vertices, triangles, twins, normals.
    pub fn into_parts(self) -> MeshParts {
        (
            self.vertices,
            self.triangles,
            self.halfedges,
            self.triangle_normals,
        )
    }

    /// All vertices (unused ones may be NaN).
    #[inline]
    pub fn vertices(&self) -> &[[f64; 3]] {
        &self.vertices
    }

    /// Triangles as vertex-index triples, counter-clockwise about their normal.
    #[inline]
    pub fn triangles(&self) -> &[[u32; 3]] {
        &self.triangles
    }

    /// The twin array: `halfedges()[h]` is the twin of half-edge `h` or [`NO_TWIN`].
    #[inline]
    pub fn halfedges(&self) -> &[u32] {
        &self.halfedges
    }

    /// Unit triangle normals, if computed.
    #[inline]
    pub fn triangle_normals(&self) -> Option<&[[f64; 3]]> {
        (!self.triangle_normals.is_empty() || self.triangles.is_empty())
            .then_some(self.triangle_normals.as_slice())
    }

    /// Number of vertices.
    #[inline]
    pub fn num_vertices(&self) -> usize {
        self.vertices.len()
    }

    /// Number of triangles.
    #[inline]
    pub fn num_triangles(&self) -> usize {
        self.triangles.len()
    }

    /// The twin of half-edge `h`, or `None` on a border edge.
    #[inline]
    pub fn twin(&self, h: u32) -> Option<u32> {
        let t = self.halfedges[h as usize];
        (t != NO_TWIN).then_some(t)
    }

    /// The vertex half-edge `h` starts at.
    #[inline]
    pub fn origin(&self, h: u32) -> u32 {
        self.triangles[(h / 3) as usize][(h % 3) as usize]
    }

    /// The vertex half-edge `h` ends at.
    #[inline]
    pub fn destination(&self, h: u32) -> u32 {
        self.origin(next_halfedge(h))
    }

    /// Replaces the triangle normals (for example with filtered ones).
    ///
    /// # Errors
    /// [`MeshError::LengthMismatch`] unless there is one normal per triangle.
    pub fn set_triangle_normals(&mut self, normals: Vec<[f64; 3]>) -> Result<(), MeshError> {
        if normals.len() != self.triangles.len() {
            return Err(MeshError::LengthMismatch {
                what: "triangle normals",
                found: normals.len(),
                expected: self.triangles.len(),
            });
        }
        self.triangle_normals = normals;
        Ok(())
    }

    /// Takes the triangle normals out, leaving the mesh without normals. A mesh built
    /// without normals still hands over the allocation of the normals of the mesh its
    /// arrays were recycled from, for [`Self::set_triangle_normals`] to refill.
    ///
    /// ```
    /// use halfedge_mesh::HalfEdgeMesh;
    ///
    /// let vertices = vec![[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]];
    /// let mut mesh = HalfEdgeMesh::from_parts(vertices, vec![[0, 1, 2]], vec![u32::MAX; 3], vec![])?;
    /// mesh.compute_triangle_normals();
    /// let mut normals = mesh.take_triangle_normals();
    /// assert_eq!((normals.as_slice(), mesh.triangle_normals()), (&[[0.0, 0.0, 1.0]][..], None));
    /// normals[0] = [0.0, 0.0, -1.0];
    /// mesh.set_triangle_normals(normals)?;
    /// assert_eq!(mesh.triangle_normals(), Some(&[[0.0, 0.0, -1.0]][..]));
    /// # Ok::<(), halfedge_mesh::MeshError>(())
    /// ```
    pub fn take_triangle_normals(&mut self) -> Vec<[f64; 3]> {
        std::mem::take(&mut self.triangle_normals)
    }

    /// Replaces the vertices (for example with smoothed ones) keeping the connectivity,
    /// and recomputes triangle normals if the mesh had them.
    ///
    /// # Errors
    /// [`MeshError::LengthMismatch`] unless the vertex count is unchanged.
    pub fn set_vertices(&mut self, vertices: Vec<[f64; 3]>) -> Result<(), MeshError> {
        if vertices.len() != self.vertices.len() {
            return Err(MeshError::LengthMismatch {
                what: "vertices",
                found: vertices.len(),
                expected: self.vertices.len(),
            });
        }
        self.vertices = vertices;
        if !self.triangle_normals.is_empty() {
            self.compute_triangle_normals();
        }
        Ok(())
    }

    /// Computes (or recomputes) unit triangle normals, in parallel for large meshes.
    ///
    /// A triangle of zero area gets the normal `[0, 0, 0]`; meshes built by this crate
    /// contain none.
    pub fn compute_triangle_normals(&mut self) {
        let vertices = &self.vertices;
        let mut normals = vec![[0.0; 3]; self.triangles.len()];
        normals
            .par_chunks_mut(PAR_CHUNK)
            .zip(self.triangles.par_chunks(PAR_CHUNK))
            .for_each(|(normals, triangles)| {
                for (n, tri) in normals.iter_mut().zip(triangles) {
                    *n = unit_normal(vertices, *tri);
                }
            });
        self.triangle_normals = normals;
    }

    /// Checks every invariant of the mesh and names the first one broken.
    ///
    /// * `halfedges` has `3 × triangles` entries, normals are absent or one per triangle;
    /// * vertex indices are in range, the vertices used are finite, no triangle repeats a
    ///   vertex;
    /// * twins are mutual (`twin(twin(h)) == h`), never inside one triangle, and join the
    ///   same two vertices in opposite directions;
    /// * normals, if present, are finite unit vectors.
    ///
    /// Runs in linear time; tests and fuzzers call it on every mesh they build.
    ///
    /// # Errors
    /// The first broken invariant.
    pub fn sanity_check(&self) -> Result<(), MeshError> {
        let nt = self.triangles.len();
        if self.halfedges.len() != 3 * nt {
            return Err(MeshError::LengthMismatch {
                what: "halfedges",
                found: self.halfedges.len(),
                expected: 3 * nt,
            });
        }
        if !self.triangle_normals.is_empty() && self.triangle_normals.len() != nt {
            return Err(MeshError::LengthMismatch {
                what: "triangle normals",
                found: self.triangle_normals.len(),
                expected: nt,
            });
        }
        let nv = self.vertices.len();
        for (t, tri) in self.triangles.iter().enumerate() {
            for &v in tri {
                let Some(p) = self.vertices.get(v as usize) else {
                    return Err(MeshError::IndexOutOfRange {
                        triangle: t,
                        vertex: v,
                        num_vertices: nv,
                    });
                };
                if !p.iter().all(|c| c.is_finite()) {
                    return Err(MeshError::NonFiniteVertex {
                        vertex: v,
                        triangle: t,
                    });
                }
            }
            if tri[0] == tri[1] || tri[1] == tri[2] || tri[0] == tri[2] {
                return Err(MeshError::DegenerateTriangle {
                    triangle: t,
                    vertices: *tri,
                    reason: "repeated vertex",
                });
            }
        }
        for (h, &twin) in self.halfedges.iter().enumerate() {
            if twin == NO_TWIN {
                continue;
            }
            let h = h as u32;
            let bad = |reason| {
                Err(MeshError::BadTwin {
                    halfedge: h,
                    reason,
                })
            };
            if twin as usize >= self.halfedges.len() {
                return bad("twin index out of range");
            }
            if twin / 3 == h / 3 {
                return bad("twin lies in the same triangle");
            }
            if self.halfedges[twin as usize] != h {
                return bad("twin link is not mutual");
            }
            if self.origin(h) != self.destination(twin) || self.destination(h) != self.origin(twin)
            {
                return bad("twin does not join the same vertices in the opposite direction");
            }
        }
        for (t, n) in self.triangle_normals.iter().enumerate() {
            let len2 = n[0] * n[0] + n[1] * n[1] + n[2] * n[2];
            if !len2.is_finite() || (len2 - 1.0).abs() > 1e-6 {
                return Err(MeshError::BadNormal { triangle: t });
            }
        }
        Ok(())
    }
}

/// The next half-edge in the same triangle (counter-clockwise).
#[inline]
pub fn next_halfedge(h: u32) -> u32 {
    if h % 3 == 2 { h - 2 } else { h + 1 }
}

/// The arrays of a [`HalfEdgeMesh`] ([`HalfEdgeMesh::into_parts`]): vertices, triangles,
/// twins, triangle normals.
pub type MeshParts = (Vec<[f64; 3]>, Vec<[u32; 3]>, Vec<u32>, Vec<[f64; 3]>);

/// The previous half-edge in the same triangle.
#[inline]
pub fn prev_halfedge(h: u32) -> u32 {
    if h.is_multiple_of(3) { h + 2 } else { h - 1 }
}

/// The unnormalised normal `(b − a) × (c − a)` of a triangle; its length is twice the area.
#[inline]
pub fn cross_normal(a: [f64; 3], b: [f64; 3], c: [f64; 3]) -> [f64; 3] {
    let u = [b[0] - a[0], b[1] - a[1], b[2] - a[2]];
    let v = [c[0] - a[0], c[1] - a[1], c[2] - a[2]];
    [
        u[1] * v[2] - u[2] * v[1],
        u[2] * v[0] - u[0] * v[2],
        u[0] * v[1] - u[1] * v[0],
    ]
}

/// The unit normal of triangle `tri`, or zero for a zero-area triangle.
#[inline]
pub(crate) fn unit_normal(vertices: &[[f64; 3]], tri: [u32; 3]) -> [f64; 3] {
    let n = cross_normal(
        vertices[tri[0] as usize],
        vertices[tri[1] as usize],
        vertices[tri[2] as usize],
    );
    let len = (n[0] * n[0] + n[1] * n[1] + n[2] * n[2]).sqrt();
    if len > 0.0 {
        [n[0] / len, n[1] / len, n[2] / len]
    } else {
        [0.0; 3]
    }
}

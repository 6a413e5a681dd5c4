//! The public face of right-cut meshing: options, the result type and the entry points on
//! [`OrganizedPointCloud`] and [`OrganizedPointCloudView`]; the passes live in
//! [`crate::rightcut`].

use halfedge_mesh::HalfEdgeMesh;

use crate::rightcut::{Buffers, mesh_grid, unflatten};
use crate::triangle_map::TriangleMap;
use crate::{OpcError, OrganizedPointCloud, OrganizedPointCloudView};

/// Options of right-cut meshing ([`OrganizedPointCloudView::mesh`]).
///
/// ```
/// use opc_mesh::OpcMeshOptions;
/// let options = OpcMeshOptions::new().with_compute_normals(false).with_parallel(false);
/// assert!(!options.compute_normals);
/// ```
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
#[non_exhaustive]
pub struct OpcMeshOptions {
    /// Compute unit triangle normals in the same pass. Default `true`.
    pub compute_normals: bool,
    /// Spread the work over the current rayon thread pool (install a pool of your own to
    /// choose the thread count); `false` runs on the calling thread only. The result is
    /// the same either way. Default `true`.
    pub parallel: bool,
}

impl Default for OpcMeshOptions {
    fn default() -> Self {
        Self {
            compute_normals: true,
            parallel: true,
        }
    }
}

impl OpcMeshOptions {
    /// The defaults: normals computed, parallel.
    pub fn new() -> Self {
        Self::default()
    }

    /// Sets whether triangle normals are computed.
    pub fn with_compute_normals(mut self, compute_normals: bool) -> Self {
        self.compute_normals = compute_normals;
        self
    }

    /// Sets whether the work runs in parallel.
    pub fn with_parallel(mut self, parallel: bool) -> Self {
        self.parallel = parallel;
        self
    }
}

/// A meshed organized point cloud: the half-edge mesh and the map from the implicit
/// right-cut mesh's global triangle ids to its triangles.
///
/// The mesh's vertices are all the cloud's points, NaN included, so vertex `r · cols + c`
/// is pixel `(r, c)`.
#[derive(Debug, Clone, PartialEq)]
pub struct OpcMesh {
    /// The triangles, twins and (if asked for) unit normals.
    pub mesh: HalfEdgeMesh,
    /// Cell triangle (GID) → mesh triangle.
    pub triangle_map: TriangleMap,
}

impl OrganizedPointCloudView<'_> {
    /// Meshes the cloud with right-cut triangles (Polylidar3D §4.2, Alg. 1–2).
    ///
    /// Every cell, from pixel `(r, c)` to pixel `(r + 1, c + 1)`, is split along that
    /// diagonal into a [`First`](crate::CellTriangle::First) (upper-right) and a
    /// [`Second`](crate::CellTriangle::Second) (lower-left) triangle, as in the original.
    /// A triangle is created where its three points are valid (finite) and its normal is
    /// well defined (the squared length of the edge cross product is a positive normal
    /// `f64`: this drops only triangles of repeated or exactly collinear points, such as
    /// sensors reporting `(0, 0, 0)` for no return). Triangles are numbered in GID order.
    ///
    /// **Orientation.** Triangles are `[p(r+1, c+1), p(r, c+1), p(r, c)]` and
    /// `[p(r, c), p(r+1, c), p(r+1, c+1)]` (the original's order). For a camera frame with
    /// `x` growing with the column, `y` with the row and `z` forward, as
    /// [`OrganizedPointCloud::from_depth_image`] builds it, normals point back toward the
    /// sensor (negative `z` for a surface facing the camera). A cloud whose columns or
    /// rows run the other way gets normals pointing away.
    ///
    /// The points are copied into the mesh's vertex array; see
    /// [`OrganizedPointCloud::into_mesh`] to move them instead.
    ///
    /// # Performance
    /// O(rows · cols) time and memory, two passes parallel over rows.
    ///
    /// # Errors
    /// [`OpcError::NoTriangles`] if no triangle can be formed (e.g. an all-NaN cloud),
    /// [`OpcError::TooLarge`] if the half-edges would overflow `u32` indices.
    pub fn mesh(&self, options: &OpcMeshOptions) -> Result<OpcMesh, OpcError> {
        self.mesh_with_buffers(
            options,
            Buffers {
                vertices: Some(Vec::new()),
                ..Buffers::default()
            },
        )
    }

    /// Meshes the cloud like [`Self::mesh`], writing over the arrays of `previous` (for
    /// example the mesh of the previous frame of a stream) instead of allocating new
    /// ones. The result is the same as [`Self::mesh`]'s; the difference is speed: fresh
    /// arrays cost the kernel a page fault and zeroing per 4 KiB page on first touch (most
    /// of the time of meshing a 500 × 500 cloud), reused ones cost nothing.
    ///
    /// ```
    /// use opc_mesh::{OpcMeshOptions, OrganizedPointCloud};
    /// let options = OpcMeshOptions::default();
    /// let frame = |z: f64| {
    ///     let points = (0..64 * 48).map(|i| [(i % 64) as f64, (i / 64) as f64, z]).collect();
    ///     OrganizedPointCloud::new(48, 64, points)
    /// };
    /// let mut opc = frame(1.0)?.mesh(&options)?;
    /// for z in [1.1, 1.2, 1.3] {
    ///     opc = frame(z)?.mesh_reusing(&options, opc)?;
    /// }
    /// assert_eq!(opc.mesh.vertices()[0], [0.0, 0.0, 1.3]);
    /// # Ok::<(), opc_mesh::OpcError>(())
    /// ```
    ///
    /// # Errors
    /// As [`Self::mesh`]; `previous` is dropped then.
    pub fn mesh_reusing(
        &self,
        options: &OpcMeshOptions,
        previous: OpcMesh,
    ) -> Result<OpcMesh, OpcError> {
        let (vertices, triangles, halfedges, normals) = previous.mesh.into_parts();
        self.mesh_with_buffers(
            options,
            Buffers {
                vertices: Some(vertices),
                triangles,
                halfedges: unflatten(halfedges),
                normals,
                map: unflatten(previous.triangle_map.into_vec()),
            },
        )
    }

    fn mesh_with_buffers(
        &self,
        options: &OpcMeshOptions,
        buffers: Buffers,
    ) -> Result<OpcMesh, OpcError> {
        let parts = mesh_grid(*self, buffers, options)?;
        Ok(OpcMesh {
            mesh: HalfEdgeMesh::from_parts_trusted(
                parts.vertices,
                parts.triangles,
                parts.halfedges,
                parts.normals,
            ),
            triangle_map: parts.triangle_map,
        })
    }
}

impl OrganizedPointCloud {
    /// Meshes a borrowed cloud, copying its points into the mesh; see
    /// [`OrganizedPointCloudView::mesh`].
    ///
    /// # Errors
    /// As [`OrganizedPointCloudView::mesh`].
    pub fn mesh(&self, options: &OpcMeshOptions) -> Result<OpcMesh, OpcError> {
        self.view().mesh(options)
    }

    /// Meshes the cloud reusing an earlier mesh's arrays; see
    /// [`OrganizedPointCloudView::mesh_reusing`].
    ///
    /// # Errors
    /// As [`OrganizedPointCloudView::mesh`].
    pub fn mesh_reusing(
        &self,
        options: &OpcMeshOptions,
        previous: OpcMesh,
    ) -> Result<OpcMesh, OpcError> {
        self.view().mesh_reusing(options, previous)
    }

    /// Meshes the cloud, moving its points into the mesh without copying them; see
    /// [`OrganizedPointCloudView::mesh`].
    ///
    /// ```
    /// use opc_mesh::{OpcMeshOptions, OrganizedPointCloud};
    /// let points: Vec<[f64; 3]> = (0..12).map(|i| [(i % 4) as f64, (i / 4) as f64, 1.0]).collect();
    /// let opc = OrganizedPointCloud::new(3, 4, points)?.into_mesh(&OpcMeshOptions::default())?;
    /// assert_eq!(opc.mesh.num_triangles(), 2 * 2 * 3);
    /// assert_eq!(opc.mesh.triangle_normals().map(|n| n[0]), Some([0.0, 0.0, -1.0]));
    /// # Ok::<(), opc_mesh::OpcError>(())
    /// ```
    ///
    /// # Errors
    /// As [`OrganizedPointCloudView::mesh`].
    pub fn into_mesh(self, options: &OpcMeshOptions) -> Result<OpcMesh, OpcError> {
        self.into_mesh_with_buffers(options, Buffers::default())
    }

    /// Meshes the cloud, moving its points into the mesh, and reusing an earlier mesh's
    /// other arrays (its vertices are dropped): [`Self::into_mesh`] for a stream of
    /// frames, as [`Self::mesh_reusing`] is [`Self::mesh`].
    ///
    /// ```
    /// use opc_mesh::{OpcMeshOptions, OrganizedPointCloud};
    /// let frame = |z: f64| {
    ///     let points: Vec<[f64; 3]> = (0..12).map(|i| [(i % 4) as f64, (i / 4) as f64, z]).collect();
    ///     OrganizedPointCloud::new(3, 4, points)
    /// };
    /// let options = OpcMeshOptions::default();
    /// let mut opc = frame(1.0)?.into_mesh(&options)?;
    /// for z in [1.1, 1.2] {
    ///     let fresh = frame(z)?.into_mesh(&options)?;
    ///     opc = frame(z)?.into_mesh_reusing(&options, opc)?;
    ///     assert_eq!(opc.mesh.triangles(), fresh.mesh.triangles());
    /// }
    /// assert_eq!(opc.mesh.vertices()[0], [0.0, 0.0, 1.2]);
    /// # Ok::<(), opc_mesh::OpcError>(())
    /// ```
    ///
    /// # Errors
    /// As [`OrganizedPointCloudView::mesh`]; `previous` is dropped then.
    pub fn into_mesh_reusing(
        self,
        options: &OpcMeshOptions,
        previous: OpcMesh,
    ) -> Result<OpcMesh, OpcError> {
        let (_, triangles, halfedges, normals) = previous.mesh.into_parts();
        let buffers = Buffers {
            vertices: None,
            triangles,
            halfedges: unflatten(halfedges),
            normals,
            map: unflatten(previous.triangle_map.into_vec()),
        };
        self.into_mesh_with_buffers(options, buffers)
    }

    /// Meshes the cloud into `buffers`, moving its points into the mesh.
    fn into_mesh_with_buffers(
        self,
        options: &OpcMeshOptions,
        buffers: Buffers,
    ) -> Result<OpcMesh, OpcError> {
        let (rows, cols) = (self.rows(), self.cols());
        let points = self.into_points();
        let view = OrganizedPointCloudView::from_checked(rows, cols, &points);
        let parts = mesh_grid(view, buffers, options)?;
        Ok(OpcMesh {
            mesh: HalfEdgeMesh::from_parts_trusted(
                points,
                parts.triangles,
                parts.halfedges,
                parts.normals,
            ),
            triangle_map: parts.triangle_map,
        })
    }
}

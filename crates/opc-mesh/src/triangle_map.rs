//! The GID → triangle map of a right-cut mesh (Polylidar3D §4.2, `T_map`).

use rayon::prelude::*;

/// Sentinel in a [`TriangleMap`] for a cell triangle that is not in the mesh.
pub const NO_TRIANGLE: u32 = u32::MAX;

/// One of the two triangles of a grid cell, split along the diagonal from its top-left
/// pixel `(r, c)` to its bottom-right pixel `(r + 1, c + 1)` (the "right cut").
///
/// The discriminant is the paper's `k` in `GID = 2 (r · (cols − 1) + c) + k`.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum CellTriangle {
    /// `k = 0`, the upper-right triangle: pixels `(r, c)`, `(r, c + 1)`, `(r + 1, c + 1)`.
    First = 0,
    /// `k = 1`, the lower-left triangle: pixels `(r, c)`, `(r + 1, c)`, `(r + 1, c + 1)`.
    Second = 1,
}

/// Where each triangle of the implicit right-cut mesh ended up in the meshed
/// [`HalfEdgeMesh`](halfedge_mesh::HalfEdgeMesh): for every cell triangle, identified by its
/// global id `GID = 2 (r · (cols − 1) + c) + k` (`r`, `c` the cell's top-left pixel,
/// `k` the [`CellTriangle`]), the index of the mesh triangle or [`NO_TRIANGLE`].
///
/// Mesh triangles are numbered in GID order, so the map is increasing where it is not
/// [`NO_TRIANGLE`].
///
/// ```
/// use opc_mesh::{CellTriangle, OpcMeshOptions, OrganizedPointCloud};
/// let mut points: Vec<[f64; 3]> = (0..9).map(|i| [(i % 3) as f64, (i / 3) as f64, 1.0]).collect();
/// points[1] = [f64::NAN; 3]; // pixel (0, 1): three triangles of cell row 0 are lost
/// let opc = OrganizedPointCloud::new(3, 3, points)?.mesh(&OpcMeshOptions::default())?;
/// let map = &opc.triangle_map;
/// assert_eq!(map.triangle(0, 0, CellTriangle::First), None);
/// assert_eq!(map.triangle(0, 0, CellTriangle::Second), Some(0));
/// assert_eq!(map.triangle(1, 1, CellTriangle::Second), Some(4));
/// assert_eq!(map.triangle_gids(), vec![1, 4, 5, 6, 7]);
/// # Ok::<(), opc_mesh::OpcError>(())
/// ```
///
/// `TriangleMap::default()` is the empty map of a 0 × 0 grid, storage for
/// [`OrganizedPointCloudView::mesh_reusing`](crate::OrganizedPointCloudView::mesh_reusing)
/// to grow.
#[derive(Debug, Clone, Default, PartialEq, Eq)]
pub struct TriangleMap {
    cell_rows: usize,
    cell_cols: usize,
    map: Vec<u32>,
}

impl TriangleMap {
    /// Wraps a map of `2 · cell_rows · cell_cols` entries.
    pub(crate) fn from_vec(cell_rows: usize, cell_cols: usize, map: Vec<u32>) -> Self {
        debug_assert_eq!(map.len(), 2 * cell_rows * cell_cols);
        Self {
            cell_rows,
            cell_cols,
            map,
        }
    }

    /// Number of cell rows (`rows − 1` of the cloud).
    #[inline]
    pub fn cell_rows(&self) -> usize {
        self.cell_rows
    }

    /// Number of cell columns (`cols − 1` of the cloud).
    #[inline]
    pub fn cell_cols(&self) -> usize {
        self.cell_cols
    }

    /// The global id of triangle `k` of the cell whose top-left pixel is `(row, col)`.
    ///
    /// # Panics
    /// If `col >= cell_cols` (a row index past the end gives a GID past the end, which
    /// [`Self::get`] answers with `None`).
    #[inline]
    pub fn gid(&self, row: usize, col: usize, k: CellTriangle) -> usize {
        assert!(
            col < self.cell_cols,
            "cell column {col} out of range for {} cell columns",
            self.cell_cols
        );
        2 * (row * self.cell_cols + col) + k as usize
    }

    /// The cell `(row, col)` and [`CellTriangle`] of a global id, or `None` past the end.
    #[inline]
    pub fn cell(&self, gid: usize) -> Option<(usize, usize, CellTriangle)> {
        (gid < self.map.len()).then(|| {
            let cell = gid / 2;
            let k = if gid.is_multiple_of(2) {
                CellTriangle::First
            } else {
                CellTriangle::Second
            };
            (cell / self.cell_cols, cell % self.cell_cols, k)
        })
    }

    /// The mesh triangle of global id `gid`, or `None` if it was not created (an invalid
    /// vertex) or `gid` is past the end.
    #[inline]
    pub fn get(&self, gid: usize) -> Option<u32> {
        self.map.get(gid).copied().filter(|&t| t != NO_TRIANGLE)
    }

    /// The mesh triangle `k` of cell `(row, col)`, if it exists.
    ///
    /// # Panics
    /// As [`Self::gid`].
    #[inline]
    pub fn triangle(&self, row: usize, col: usize, k: CellTriangle) -> Option<u32> {
        self.get(self.gid(row, col, k))
    }

    /// The raw map, one entry per GID: a triangle index or [`NO_TRIANGLE`].
    #[inline]
    pub fn as_slice(&self) -> &[u32] {
        &self.map
    }

    /// Gives the raw map back.
    pub fn into_vec(self) -> Vec<u32> {
        self.map
    }

    /// The inverse map: the GID of every mesh triangle, in triangle order.
    pub fn triangle_gids(&self) -> Vec<u32> {
        self.map
            .par_iter()
            .enumerate()
            .filter(|(_, t)| **t != NO_TRIANGLE)
            .map(|(gid, _)| gid as u32)
            .collect()
    }
}

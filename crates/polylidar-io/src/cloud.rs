//! Plain data types returned by the readers.

use crate::error::{ErrorKind, Format, IoError};

/// A 3D point cloud, organized (an image grid) or not.
///
/// Organized clouds (`rows > 1`) store their points row-major: point `(r, c)` is
/// `points[r * cols + c]`; a NaN coordinate marks an invalid pixel. Unorganized clouds have
/// `rows == 1` and `cols == points.len()`.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct PointCloud {
    /// Number of rows (1 for an unorganized cloud).
    pub rows: usize,
    /// Number of columns (the point count for an unorganized cloud).
    pub cols: usize,
    /// Row-major `x, y, z` coordinates, `rows * cols` of them.
    pub points: Vec<[f64; 3]>,
}

impl PointCloud {
    /// An organized cloud of `rows × cols` points.
    ///
    /// # Errors
    /// [`ErrorKind::Shape`] when `points.len() != rows * cols`.
    pub fn organized(rows: usize, cols: usize, points: Vec<[f64; 3]>) -> Result<Self, IoError> {
        if rows.checked_mul(cols) != Some(points.len()) {
            return Err(IoError::new(
                Format::Unknown,
                ErrorKind::Shape(format!(
                    "{rows} rows × {cols} columns do not match {} points",
                    points.len()
                )),
            ));
        }
        Ok(PointCloud { rows, cols, points })
    }

    /// An unorganized cloud (`rows = 1`, `cols = points.len()`).
    pub fn unorganized(points: Vec<[f64; 3]>) -> Self {
        PointCloud {
            rows: 1,
            cols: points.len(),
            points,
        }
    }

    /// Whether the cloud is an image grid (more than one row).
    pub fn is_organized(&self) -> bool {
        self.rows > 1
    }

    /// Number of points, invalid ones included.
    pub fn len(&self) -> usize {
        self.points.len()
    }

    /// Whether there are no points.
    pub fn is_empty(&self) -> bool {
        self.points.is_empty()
    }

    /// Number of points whose three coordinates are all finite.
    pub fn valid_count(&self) -> usize {
        self.points
            .iter()
            .filter(|p| p.iter().all(|v| v.is_finite()))
            .count()
    }

    /// The point at `(row, col)`, or `None` outside the grid.
    pub fn get(&self, row: usize, col: usize) -> Option<[f64; 3]> {
        if row >= self.rows || col >= self.cols {
            return None;
        }
        self.points.get(row * self.cols + col).copied()
    }
}

/// A table of 2D or 3D points read from a text file, stored flat.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct PointTable {
    /// Coordinates per point: 2 or 3.
    pub dims: usize,
    /// `len() * dims` coordinates, point after point.
    pub data: Vec<f64>,
}

impl PointTable {
    /// Number of points.
    pub fn len(&self) -> usize {
        self.data.len().checked_div(self.dims).unwrap_or(0)
    }

    /// Whether there are no points.
    pub fn is_empty(&self) -> bool {
        self.data.is_empty()
    }

    /// The points as `[x, y]` pairs, or `None` unless `dims == 2`.
    pub fn to_points_2d(&self) -> Option<Vec<[f64; 2]>> {
        (self.dims == 2).then(|| self.data.chunks_exact(2).map(|c| [c[0], c[1]]).collect())
    }

    /// The points as `[x, y, z]` triples, or `None` unless `dims == 3`.
    pub fn to_points_3d(&self) -> Option<Vec<[f64; 3]>> {
        (self.dims == 3).then(|| {
            self.data
                .chunks_exact(3)
                .map(|c| [c[0], c[1], c[2]])
                .collect()
        })
    }
}

/// A triangle mesh read from PLY or OBJ.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct MeshData {
    /// Vertex coordinates.
    pub vertices: Vec<[f64; 3]>,
    /// Triangles as vertex indices (polygons are fan-triangulated); empty for point-only
    /// files.
    pub triangles: Vec<[u32; 3]>,
}

/// What a mesh reader met beyond the triangles themselves.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub struct MeshStats {
    /// Faces in the file.
    pub faces: usize,
    /// Faces with more than three vertices, split into a triangle fan.
    pub polygons_fanned: usize,
    /// Faces with fewer than three vertices, which carry no triangle and were skipped.
    pub faces_skipped: usize,
}

/// Airborne LiDAR points with their ASPRS classification.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct LasCloud {
    /// Coordinates (scale and offset applied), in the file's units.
    pub points: Vec<[f64; 3]>,
    /// ASPRS class of each point (1 unclassified, 2 ground, 6 building, …).
    pub classification: Vec<u8>,
    /// The horizontal length unit the header declares, read as [`crate::LengthUnit`]
    /// describes; `None` when it declares none.
    pub unit: Option<crate::LengthUnit>,
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn organized_checks_length() {
        assert!(PointCloud::organized(2, 3, vec![[0.0; 3]; 5]).is_err());
        assert!(PointCloud::organized(usize::MAX, 3, vec![]).is_err());
        let c = PointCloud::organized(2, 3, vec![[1.0; 3]; 6]).unwrap();
        assert!(c.is_organized());
        assert_eq!(c.get(1, 2), Some([1.0; 3]));
        assert_eq!(c.get(2, 0), None);
    }

    #[test]
    fn table_conversions() {
        let t = PointTable {
            dims: 2,
            data: vec![1.0, 2.0, 3.0, 4.0],
        };
        assert_eq!(t.len(), 2);
        assert_eq!(t.to_points_2d().unwrap(), vec![[1.0, 2.0], [3.0, 4.0]]);
        assert!(t.to_points_3d().is_none());
    }
}

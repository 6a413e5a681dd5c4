//! Files in and out (feature `io`): any file [`polylidar_io`] reads, as the input of the
//! matching pipeline ([`Input`], [`Polylidar::extract`]), and the writers of results: the
//! GeoJSON of [`crate::output::feature_collection`] and the plane label image of an
//! organized input ([`write_labels`]).
//!
//! Every writer replaces its file atomically ([`polylidar_io::atomic`]): the bytes go to a
//! temporary file beside the target, are flushed to disk and renamed over it, so a failed
//! write (disk full, file size limit) leaves the previous file as it was and no partial
//! file behind.
//!
//! The `polylidar` command and the Python package both load and write through here, so a
//! file gives the same polygons from either.
//!
//! ```no_run
//! use polylidar::{Config, Polylidar, io::Input, output::PolygonSet};
//!
//! let input = Input::read("scan.pcd")?;
//! let polylidar = Polylidar::new(Config::preset("synpeb").unwrap_or_default())?;
//! let extraction = polylidar.extract(&input)?;
//! polylidar::io::write_geojson("planes.geojson", &extraction, input.is_3d(), PolygonSet::Extracted)?;
//! if let Some((rows, cols)) = input.grid() {
//!     polylidar::io::write_labels("labels.npy", rows, cols, &extraction.point_labels())?;
//! }
//! # Ok::<(), polylidar::PolylidarError>(())
//! ```

use std::path::Path;

use polylidar_io::InputKind;
pub use polylidar_io::{Limits, ReadNotes};

mod camera;
pub use camera::{CameraSource, DEFAULT_UNITS_PER_METRE, DepthCamera, is_missing_intrinsics};

use crate::output::{PolygonSet, feature_collection};
use crate::{DepthOptions, Extraction, OrganizedPointCloud, Polylidar, PolylidarError};

/// An input loaded for the pipeline that fits it.
#[derive(Debug, Clone, PartialEq)]
pub enum Input {
    /// A 2D point set ([`Polylidar::extract_2d`]).
    Points2d(Vec<[f64; 2]>),
    /// An unorganized 3D cloud ([`Polylidar::extract_25d`], triangulated along
    /// [`crate::Config::up`]).
    Cloud(Vec<[f64; 3]>),
    /// An organized cloud: range image, RGBD frame, depth image
    /// ([`Polylidar::extract_organized`]).
    Organized(OrganizedPointCloud),
    /// A triangle mesh ([`Polylidar::extract_mesh`]).
    Mesh {
        /// Vertex coordinates.
        vertices: Vec<[f64; 3]>,
        /// Counter-clockwise triangles, indices into `vertices`.
        triangles: Vec<[u32; 3]>,
    },
}

impl Input {
    /// Reads a file by its extension ([`polylidar_io::read_input`]): 2D points (CSV / NPY
    /// with 2 columns), clouds (PCD, NPY, CSV, LAS / LAZ, PLY / OBJ without faces; organized
    /// when they have a grid; KITTI Velodyne `.bin` frames in firing order), meshes (PLY /
    /// OBJ with faces) and 16-bit depth PNGs with
    /// their RealSense `_metadata.csv` (turned into an organized cloud with
    /// [`OrganizedPointCloud::from_depth_image`]).
    ///
    /// # Errors
    /// [`PolylidarError::Io`] for an unreadable file, [`PolylidarError::Organized`] for a
    /// grid or depth image that does not make an organized cloud.
    pub fn read(path: impl AsRef<Path>) -> Result<Self, PolylidarError> {
        Self::from_io(polylidar_io::read_input(path)?)
    }

    /// As [`Self::read`], within the memory budget `limits` (what the file and the pipeline
    /// run on it will need is estimated from the header and refused past the budget before
    /// anything is allocated), with what the read met: points of an unorganized PCD cloud
    /// with a NaN coordinate (PCL's invalid-point marker) are skipped and counted.
    ///
    /// ```
    /// use polylidar::io::{Input, Limits};
    ///
    /// let path = std::env::temp_dir().join("polylidar-doc-read-with.csv");
    /// std::fs::write(&path, "x,y\n0,0\n1,0\n0,1\n")?;
    /// let (input, notes) = Input::read_with(&path, &Limits::default())?;
    /// assert_eq!((input.len(), notes.invalid_skipped), (3, 0));
    /// let tight = Limits::default().with_max_memory(1000);
    /// assert!(Input::read_with(&path, &tight).is_err());
    /// # std::fs::remove_file(&path).ok();
    /// # Ok::<(), Box<dyn std::error::Error>>(())
    /// ```
    ///
    /// # Errors
    /// As [`Self::read`]; [`PolylidarError::Io`] with
    /// [`polylidar_io::ErrorKind::OverBudget`] past `limits`.
    pub fn read_with(
        path: impl AsRef<Path>,
        limits: &Limits,
    ) -> Result<(Self, ReadNotes), PolylidarError> {
        let (kind, notes) = polylidar_io::read_input_with(path, limits)?;
        Ok((Self::from_io(kind)?, notes))
    }

    /// The input of what a [`polylidar_io`] reader returned.
    ///
    /// ```
    /// use polylidar::io::Input;
    /// use polylidar_io::{InputKind, PointCloud};
    /// let cloud = PointCloud::organized(1, 2, vec![[0.0; 3], [1.0, 0.0, 0.0]]).unwrap();
    /// assert!(matches!(Input::from_io(InputKind::Cloud(cloud))?, Input::Cloud(_)));
    /// # Ok::<(), polylidar::PolylidarError>(())
    /// ```
    ///
    /// # Errors
    /// As [`Self::read`].
    pub fn from_io(kind: InputKind) -> Result<Self, PolylidarError> {
        Ok(match kind {
            InputKind::Points2d(points) => Input::Points2d(points),
            InputKind::Cloud(cloud) if cloud.is_organized() => Input::Organized(
                OrganizedPointCloud::new(cloud.rows, cloud.cols, cloud.points)?,
            ),
            InputKind::Cloud(cloud) => Input::Cloud(cloud.points),
            // Firing order is kept (the beams are recovered from it); reflectance stays
            // with `polylidar_io::read_kitti_bin`.
            InputKind::Scan(scan) => Input::Cloud(scan.points),
            InputKind::Mesh(mesh) => Input::Mesh {
                vertices: mesh.vertices,
                triangles: mesh.triangles,
            },
            InputKind::Depth { image, intrinsics } => {
                Input::Organized(OrganizedPointCloud::from_depth_image(
                    &image.data,
                    image.height,
                    image.width,
                    &DepthOptions::from(&intrinsics),
                )?)
            }
        })
    }

    /// Number of points (organized: valid pixels; mesh: vertices).
    pub fn len(&self) -> usize {
        match self {
            Input::Points2d(p) => p.len(),
            Input::Cloud(p) => p.len(),
            Input::Organized(c) => c.num_valid(),
            Input::Mesh { vertices, .. } => vertices.len(),
        }
    }

    /// Whether there is no point (organized: no valid pixel).
    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }

    /// The name of the kind in reports: `points_2d`, `cloud_2.5d`, `organized`, `mesh`.
    pub fn kind(&self) -> &'static str {
        match self {
            Input::Points2d(_) => "points_2d",
            Input::Cloud(_) => "cloud_2.5d",
            Input::Organized(_) => "organized",
            Input::Mesh { .. } => "mesh",
        }
    }

    /// Whether the points have a z (everything but [`Input::Points2d`]).
    pub fn is_3d(&self) -> bool {
        !matches!(self, Input::Points2d(_))
    }

    /// `(rows, cols)` of an organized input.
    pub fn grid(&self) -> Option<(usize, usize)> {
        match self {
            Input::Organized(c) => Some((c.rows(), c.cols())),
            _ => None,
        }
    }
}

impl Polylidar {
    /// Runs the pipeline that fits `input`: [`Self::extract_2d`], [`Self::extract_25d`]
    /// (or [`Self::extract_scan`] for a cloud when [`crate::Config::scan`] is set,
    /// [`Self::extract_unorganized`] when [`crate::Config::unorganized`] is),
    /// [`Self::extract_organized`] or [`Self::extract_mesh`] (which takes its own copy of
    /// the mesh).
    ///
    /// ```
    /// use polylidar::{Config, Polylidar, io::Input};
    /// let points = (0..100).map(|i| [(i % 10) as f64, (i / 10) as f64]).collect();
    /// let extraction = Polylidar::new(Config::new().with_lmax(1.5))?.extract(&Input::Points2d(points))?;
    /// assert_eq!(extraction.polygons.len(), 1);
    /// # Ok::<(), polylidar::PolylidarError>(())
    /// ```
    ///
    /// # Errors
    /// Those of the pipeline run.
    pub fn extract(&self, input: &Input) -> Result<Extraction, PolylidarError> {
        match input {
            Input::Points2d(points) => self.extract_2d(points),
            Input::Cloud(points) if self.config().scan.is_some() => self.extract_scan(points),
            Input::Cloud(points) if self.config().unorganized.is_some() => {
                self.extract_unorganized(points, None)
            }
            Input::Cloud(points) => self.extract_25d(points),
            Input::Organized(cloud) => self.extract_organized(cloud),
            Input::Mesh {
                vertices,
                triangles,
            } => self.extract_mesh(vertices.clone(), triangles.clone()),
        }
    }
}

/// Writes the GeoJSON of [`feature_collection`] to `path` atomically, creating its
/// directory.
///
/// # Errors
/// [`PolylidarError::Write`] when the directory or file cannot be written.
pub fn write_geojson(
    path: impl AsRef<Path>,
    extraction: &Extraction,
    with_z: bool,
    set: PolygonSet,
) -> Result<(), PolylidarError> {
    write_file(path, feature_collection(extraction, with_z, set).as_bytes())
}

/// Writes a label image (`rows × cols` int32 `.npy`, −1 for none; e.g.
/// [`Extraction::point_labels`] of an organized input) to `path` atomically, creating its
/// directory.
///
/// # Errors
/// [`PolylidarError::Write`] when the directory cannot be made, [`PolylidarError::Io`]
/// when `labels.len() != rows * cols` or the file cannot be written.
pub fn write_labels(
    path: impl AsRef<Path>,
    rows: usize,
    cols: usize,
    labels: &[i32],
) -> Result<(), PolylidarError> {
    let path = path.as_ref();
    create_parent(path)?;
    polylidar_io::write_npy_i32(path, &[rows, cols], labels)?;
    Ok(())
}

/// Writes `bytes` to `path` atomically ([`polylidar_io::atomic::write_atomic`]), creating
/// its directory. On failure the previous file at `path` is unchanged.
///
/// ```
/// let path = std::env::temp_dir().join("polylidar-doc-write").join("hello.txt");
/// polylidar::io::write_file(&path, b"hello")?;
/// assert_eq!(std::fs::read(&path).unwrap(), b"hello");
/// # Ok::<(), polylidar::PolylidarError>(())
/// ```
///
/// # Errors
/// [`PolylidarError::Write`] naming the path and the system's message.
pub fn write_file(path: impl AsRef<Path>, bytes: &[u8]) -> Result<(), PolylidarError> {
    let path = path.as_ref();
    create_parent(path)?;
    polylidar_io::atomic::write_atomic(path, bytes).map_err(|e| write_error(path, &e))
}

/// Creates the directory `path` will be written into.
///
/// # Errors
/// [`PolylidarError::Write`] naming the path and the system's message.
pub fn create_parent(path: impl AsRef<Path>) -> Result<(), PolylidarError> {
    let path = path.as_ref();
    match path.parent().filter(|d| !d.as_os_str().is_empty()) {
        Some(dir) => std::fs::create_dir_all(dir).map_err(|e| write_error(path, &e)),
        None => Ok(()),
    }
}

fn write_error(path: &Path, error: &std::io::Error) -> PolylidarError {
    PolylidarError::Write {
        path: path.to_path_buf(),
        message: error.to_string(),
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::Config;

    fn scratch(name: &str) -> test_fixtures::ScratchDir {
        test_fixtures::scratch_dir("polylidar-io-writers", name)
    }

    #[test]
    fn geojson_and_labels_replace_their_files_without_temporaries() {
        let dir = scratch("replace");
        let points: Vec<[f64; 2]> = (0..100)
            .map(|i| [(i % 10) as f64, (i / 10) as f64])
            .collect();
        let extraction = Polylidar::new(Config::new().with_lmax(1.5))
            .unwrap()
            .extract_2d(&points)
            .unwrap();
        let json = dir.join("planes.geojson");
        std::fs::write(&json, b"old").unwrap();
        write_geojson(&json, &extraction, false, PolygonSet::Extracted).unwrap();
        let text = std::fs::read_to_string(&json).unwrap();
        assert!(text.starts_with("{\"type\":\"FeatureCollection\""));
        write_labels(dir.join("labels.npy"), 2, 2, &[0, 1, -1, 0]).unwrap();
        assert_eq!(
            test_fixtures::dir_entries(&dir),
            ["labels.npy", "planes.geojson"]
        );
    }

    #[test]
    fn a_refused_write_leaves_the_old_file() {
        let dir = scratch("refused");
        let path = dir.join("keep.geojson");
        std::fs::write(&path, b"precious").unwrap();
        let mut permissions = std::fs::metadata(&path).unwrap().permissions();
        permissions.set_readonly(true);
        std::fs::set_permissions(&path, permissions).unwrap();
        let err = write_file(&path, b"new").unwrap_err();
        assert!(
            matches!(&err, PolylidarError::Write { path: p, .. } if p == &path),
            "{err}"
        );
        assert_eq!(std::fs::read(&path).unwrap(), b"precious");
        assert_eq!(test_fixtures::dir_entries(&dir), ["keep.geojson"]);
    }
}

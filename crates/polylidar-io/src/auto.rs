//! Reading any supported input, chosen by file extension.

use std::path::Path;

use crate::cloud::{MeshData, PointCloud};
use crate::depth::{CameraIntrinsics, DepthImage};
use crate::error::{ErrorKind, Format, IoError};
use crate::kitti::KittiScan;
use crate::limits::Limits;
use crate::{
    metadata_path_for, read_csv_points_with, read_depth_png_with, read_kitti_bin_with,
    read_las_with, read_npy_with, read_obj_with, read_pcd_with, read_ply_with,
    read_realsense_intrinsics,
};

/// What an input file holds, ready for the matching pipeline.
#[derive(Debug, Clone, PartialEq)]
pub enum InputKind {
    /// A 2D point set (CSV or NPY with 2 columns).
    Points2d(Vec<[f64; 2]>),
    /// A 3D cloud: organized (PCD with HEIGHT > 1, NPY H×W×3) or not (CSV/NPY with 3
    /// columns, PLY/OBJ without faces, LAS/LAZ).
    Cloud(PointCloud),
    /// A triangle mesh (PLY or OBJ with faces).
    Mesh(MeshData),
    /// A rotating-LiDAR frame (KITTI `.bin`): points in firing order, with reflectance.
    Scan(KittiScan),
    /// A 16-bit depth image with the intrinsics from its metadata CSV.
    Depth {
        /// The depth image.
        image: DepthImage,
        /// Camera intrinsics (size checked against the image).
        intrinsics: CameraIntrinsics,
    },
}

/// The format a path's extension names (case-insensitive), if supported.
pub fn format_of(path: impl AsRef<Path>) -> Option<Format> {
    let ext = path.as_ref().extension()?.to_str()?.to_ascii_lowercase();
    Some(match ext.as_str() {
        "csv" | "txt" | "xyz" => Format::CsvPoints,
        "npy" => Format::Npy,
        "pcd" => Format::Pcd,
        "ply" => Format::Ply,
        "obj" => Format::Obj,
        "las" | "laz" => Format::Las,
        "png" => Format::DepthPng,
        "bin" => Format::KittiBin,
        _ => return None,
    })
}

/// Reads any supported input, dispatching on the extension: `.csv`/`.txt`/`.xyz` (2 or 3
/// columns), `.npy` (N×2, N×3, H×W×3), `.pcd`, `.ply`, `.obj`, `.las`/`.laz`, `.png`
/// (16-bit depth; intrinsics from the metadata CSV found by [`metadata_path_for`]), `.bin`
/// (KITTI Velodyne frame, [`read_kitti_bin`](crate::read_kitti_bin)).
///
/// Points of an unorganized PCD cloud with a NaN or infinite coordinate (PCL's marker of
/// an invalid point) are skipped; [`read_input_with`] says how many.
///
/// # Errors
/// Unknown extension, or any error of the format's reader; an NPY of another shape; a depth
/// image whose size differs from its metadata's resolution; an input larger than the
/// budget of its size ([`Limits::for_path`]) allows.
pub fn read_input(path: impl AsRef<Path>) -> Result<InputKind, IoError> {
    let path = path.as_ref();
    read_input_with(path, &Limits::for_path(path)).map(|(kind, _)| kind)
}

/// What a read met besides the data it returns.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub struct ReadNotes {
    /// Points of an unorganized PCD cloud skipped for a NaN or infinite coordinate (PCL's
    /// invalid-point marker); organized clouds keep them as invalid pixels.
    pub invalid_skipped: usize,
}

/// As [`read_input`], within `limits`, with what the read met ([`ReadNotes`]).
///
/// ```
/// use polylidar_io::{InputKind, Limits, PcdEncoding, PcdWriteOptions, PointCloud, write_pcd_with_options};
///
/// let path = std::env::temp_dir().join("polylidar-io-doc-nan.pcd");
/// let cloud = PointCloud::unorganized(vec![[0.0, 0.0, 1.0], [f64::NAN; 3], [1.0, 0.0, 1.0]]);
/// write_pcd_with_options(&path, &cloud, &PcdWriteOptions::new(PcdEncoding::Binary))?;
/// let (kind, notes) = polylidar_io::read_input_with(&path, &Limits::default())?;
/// assert_eq!(notes.invalid_skipped, 1);
/// assert!(matches!(kind, InputKind::Cloud(c) if c.len() == 2));
/// # std::fs::remove_file(&path).ok();
/// # Ok::<(), polylidar_io::IoError>(())
/// ```
///
/// # Errors
/// As [`read_input`]; [`crate::ErrorKind::OverBudget`] past `limits`.
pub fn read_input_with(
    path: impl AsRef<Path>,
    limits: &Limits,
) -> Result<(InputKind, ReadNotes), IoError> {
    let path = path.as_ref();
    let mut notes = ReadNotes::default();
    let Some(format) = format_of(path) else {
        let ext = path
            .extension()
            .map(|e| e.to_string_lossy().into_owned())
            .unwrap_or_default();
        return Err(IoError::new(Format::Unknown, ErrorKind::UnknownExtension(ext)).at(path));
    };
    let mesh_or_cloud = |mesh: MeshData| {
        if mesh.triangles.is_empty() {
            InputKind::Cloud(PointCloud::unorganized(mesh.vertices))
        } else {
            InputKind::Mesh(mesh)
        }
    };
    let kind = match format {
        Format::CsvPoints => {
            let table = read_csv_points_with(path, limits)?;
            match (table.to_points_2d(), table.to_points_3d()) {
                (Some(p), _) => InputKind::Points2d(p),
                (_, Some(p)) => InputKind::Cloud(PointCloud::unorganized(p)),
                _ => unusable(path, &format!("{}-column table", table.dims))?,
            }
        }
        Format::Npy => {
            let array = read_npy_with(path, limits)?;
            if matches!(array.shape.as_slice(), &[_, 2]) {
                InputKind::Points2d(array.into_points_2d().map_err(|e| e.at(path))?)
            } else {
                InputKind::Cloud(array.into_point_cloud().map_err(|e| e.at(path))?)
            }
        }
        Format::Pcd => {
            let mut cloud = read_pcd_with(path, limits)?;
            if !cloud.is_organized() {
                let before = cloud.points.len();
                cloud.points.retain(|p| p.iter().all(|v| v.is_finite()));
                notes.invalid_skipped = before - cloud.points.len();
                cloud.cols = cloud.points.len();
            }
            InputKind::Cloud(cloud)
        }
        Format::Ply => mesh_or_cloud(read_ply_with(path, limits)?.0),
        Format::Obj => mesh_or_cloud(read_obj_with(path, limits)?.0),
        Format::Las => {
            InputKind::Cloud(PointCloud::unorganized(read_las_with(path, limits)?.points))
        }
        Format::KittiBin => InputKind::Scan(read_kitti_bin_with(path, limits)?),
        Format::DepthPng => {
            let image = read_depth_png_with(path, limits)?;
            let meta = metadata_path_for(path)?;
            let intrinsics = read_realsense_intrinsics(&meta)?;
            if (intrinsics.width, intrinsics.height) != (image.width, image.height) {
                return Err(IoError::new(
                    Format::DepthPng,
                    ErrorKind::Shape(format!(
                        "image is {} × {}, its metadata {} says {} × {}",
                        image.width,
                        image.height,
                        meta.display(),
                        intrinsics.width,
                        intrinsics.height
                    )),
                )
                .at(path));
            }
            InputKind::Depth { image, intrinsics }
        }
        Format::RealSenseMetadata | Format::CameraJson | Format::ColorImage | Format::Unknown => {
            unusable(path, "metadata file")?
        }
    };
    Ok((kind, notes))
}

/// The error for data that is valid but no pipeline input (cases the readers rule out are
/// reported rather than trusted).
fn unusable(path: &Path, what: &str) -> Result<InputKind, IoError> {
    Err(IoError::new(
        Format::Unknown,
        ErrorKind::Unusable(format!("a {what} is not a pipeline input")),
    )
    .at(path))
}

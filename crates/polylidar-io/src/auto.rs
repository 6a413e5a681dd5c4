//! Reading any supported input, chosen by file extension.

use std::path::Path;

use crate::cloud::{MeshData, PointCloud};
use crate::depth::{CameraIntrinsics, DepthImage};
use crate::error::{ErrorKind, Format, IoError};
use crate::kitti::KittiScan;
use crate::{
    metadata_path_for, read_csv_points, read_depth_png, read_kitti_bin, read_las, read_npy,
    read_obj, read_pcd, read_ply, read_realsense_intrinsics,
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
/// (KITTI Velodyne frame, [`read_kitti_bin`]).
///
/// # Errors
/// Unknown extension, or any error of the format's reader; an NPY of another shape; a depth
/// image whose size differs from its metadata's resolution.
pub fn read_input(path: impl AsRef<Path>) -> Result<InputKind, IoError> {
    let path = path.as_ref();
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
    Ok(match format {
        Format::CsvPoints => {
            let table = read_csv_points(path)?;
            match (table.to_points_2d(), table.to_points_3d()) {
                (Some(p), _) => InputKind::Points2d(p),
                (_, Some(p)) => InputKind::Cloud(PointCloud::unorganized(p)),
                _ => unusable(path, &format!("{}-column table", table.dims))?,
            }
        }
        Format::Npy => {
            let array = read_npy(path)?;
            if matches!(array.shape.as_slice(), &[_, 2]) {
                InputKind::Points2d(array.into_points_2d().map_err(|e| e.at(path))?)
            } else {
                InputKind::Cloud(array.into_point_cloud().map_err(|e| e.at(path))?)
            }
        }
        Format::Pcd => InputKind::Cloud(read_pcd(path)?),
        Format::Ply => mesh_or_cloud(read_ply(path)?),
        Format::Obj => mesh_or_cloud(read_obj(path)?),
        Format::Las => InputKind::Cloud(PointCloud::unorganized(read_las(path)?.points)),
        Format::KittiBin => InputKind::Scan(read_kitti_bin(path)?),
        Format::DepthPng => {
            let image = read_depth_png(path)?;
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
    })
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

//! Readers and writers for every input of polylidar-rs, returning plain data.
//!
//! | format | read | write |
//! | --- | --- | --- |
//! | PCD v0.7 (v0.6 headers tolerated): `ascii`, `binary`, `binary_compressed` (LZF) | [`read_pcd`], [`read_pcd_fields`] | [`write_pcd`], [`write_pcd_with_options`] |
//! | NumPy `.npy` v1–v3, bool/int/float dtypes of either byte order, C or Fortran order | [`read_npy`] | [`write_npy_f64`], [`write_npy_f32`], [`write_npy_i32`] |
//! | 16-bit greyscale depth PNG + RealSense `_metadata.csv` | [`read_depth_png`], [`read_realsense_intrinsics`], [`metadata_path_for`] | [`write_depth_png`] |
//! | Open3D camera JSON (`width`, `height`, column-major `intrinsic_matrix`) | [`read_open3d_camera`], [`read_camera_file`] (JSON or CSV by extension) | — |
//! | RealSense Viewer colorized depth pictures (8-bit RGB, Jet colormap): depth *order* only | [`read_colorized_depth_png`] | — |
//! | text tables of 2D/3D points | [`read_csv_points`] | — |
//! | PLY ascii / binary (both byte orders) | [`read_ply`] | [`write_ply`] (binary little-endian) |
//! | Wavefront OBJ (`v`, `f`) | [`read_obj`] | — |
//! | KITTI Velodyne `.bin` (float32 `x y z reflectance`, firing order kept) | [`read_kitti_bin`] → [`KittiScan`] | [`write_kitti_bin`] |
//! | LAS / LAZ (via the `las` crate), with the length unit of the header ([`LengthUnit`]) | [`read_las`], [`read_las_unit`], [`read_las_bounds`] | [`write_las`] |
//! | colour: RGB pictures (8/16-bit PNG, JPEG) of RGB-D frames, PCD `rgb`/`rgba`, PLY `red green blue` | [`read_color_image`] (+ [`color_path_for`]), [`read_pcd_colors`], [`read_ply_colors`] | — |
//!
//! [`read_input`] picks the reader by extension and returns an [`InputKind`]. Every reader
//! has a `parse_*` twin working on bytes in memory. Organized clouds keep their grid
//! ([`PointCloud`] with `rows > 1`, NaN marking invalid pixels).
//!
//! Every reader works within a memory budget ([`Limits`]; the plain functions use
//! [`Limits::default`], the `*_with` ones take it): what a file will cost, the reader's
//! arrays and the pipeline's share per point, is estimated from its header and refused past
//! the budget before anything is allocated; files and streams are read up to the budget
//! and no further.
//!
//! Errors ([`IoError`]) name the file, the format and the problem (the header line, the data
//! line, the byte offset of truncated data, the face with a bad index). No input makes a
//! reader panic: every parser is fed random and corrupted bytes by the property tests and
//! the fuzz targets of `fuzz/`, and sizes claimed by headers are checked against the data
//! before anything is allocated.
//!
//! Every writer replaces its file atomically ([`atomic`]): a failed write leaves the old
//! file as it was and no temporary file behind.
//!
//! Feature `opc-mesh` (off by default) converts [`CameraIntrinsics`] into the pipeline's
//! camera model, `opc_mesh::Intrinsics` and `opc_mesh::DepthOptions`.
//!
//! ```
//! use polylidar_io::{PcdEncoding, PointCloud, encode_pcd, parse_pcd, PcdWriteOptions};
//!
//! let cloud = PointCloud::organized(2, 2, vec![
//!     [0.0, 0.0, 1.0], [1.0, 0.0, 1.0],
//!     [0.0, 1.0, 1.0], [f64::NAN, f64::NAN, f64::NAN],
//! ])?;
//! let bytes = encode_pcd(&cloud, &PcdWriteOptions::new(PcdEncoding::BinaryCompressed))?;
//! let back = parse_pcd(&bytes)?;
//! assert_eq!((back.rows, back.cols), (2, 2));
//! assert_eq!(back.valid_count(), 3);
//! assert_eq!(back.points[1], [1.0, 0.0, 1.0]);
//! # Ok::<(), polylidar_io::IoError>(())
//! ```

#![forbid(unsafe_code)]
#![deny(rustdoc::broken_intra_doc_links)]

pub mod atomic;
mod auto;
mod cloud;
mod color;
mod colorized;
mod csv;
mod depth;
mod error;
mod intrinsics;
mod kitti;
mod lidar;
mod limits;
pub mod lzf;
mod npy;
mod obj;
mod pcd;
mod ply;
mod units;

pub use auto::{InputKind, ReadNotes, format_of, read_input, read_input_with};
pub use cloud::{LasCloud, MeshData, MeshStats, PointCloud, PointTable};
pub use color::{
    ColorImage, color_path_for, parse_color_image, parse_color_image_with, parse_pcd_colors,
    read_color_image, read_color_image_with, read_pcd_colors,
};
pub use colorized::{
    ColorizedDepth, parse_colorized_depth_png, parse_colorized_depth_png_with,
    read_colorized_depth_png, read_colorized_depth_png_with,
};
pub use csv::{parse_csv_points, parse_csv_points_with, read_csv_points, read_csv_points_with};
pub use depth::{
    CameraIntrinsics, DepthImage, encode_depth_png, metadata_path_for, parse_depth_png,
    parse_depth_png_with, parse_realsense_intrinsics, read_depth_png, read_depth_png_with,
    read_realsense_intrinsics, write_depth_png,
};
pub use error::{ErrorKind, Format, IoError};
pub use intrinsics::{parse_open3d_camera, read_camera_file, read_open3d_camera};
pub use kitti::{
    KITTI_RECORD_BYTES, KittiScan, encode_kitti_bin, parse_kitti_bin, parse_kitti_bin_with,
    read_kitti_bin, read_kitti_bin_with, write_kitti_bin,
};
pub use lidar::{LasWriteOptions, read_las_bounds, write_las};
pub use lidar::{parse_las, parse_las_with, read_las, read_las_unit, read_las_with};
pub use limits::{
    BUDGET_FLOOR, BUDGET_PER_INPUT_BYTE, DEFAULT_MAX_MEMORY, Limits, PIPELINE_BYTES_PER_POINT,
    default_max_memory, format_bytes, parse_memory_size, physical_memory,
};
pub use npy::{
    Dtype, NpyArray, encode_npy_f32, encode_npy_f64, encode_npy_i32, parse_npy, parse_npy_with,
    read_npy, read_npy_with, write_npy_f32, write_npy_f64, write_npy_i32,
};
pub use obj::{
    parse_obj, parse_obj_with, parse_obj_with_stats, read_obj, read_obj_with, read_obj_with_stats,
};
pub use pcd::{
    PcdColumns, PcdEncoding, PcdField, PcdHeader, PcdScalar, PcdWriteOptions, ScalarType,
    encode_pcd, parse_pcd, parse_pcd_fields, parse_pcd_fields_with, parse_pcd_header,
    parse_pcd_with, read_pcd, read_pcd_fields, read_pcd_fields_with, read_pcd_with, write_pcd,
    write_pcd_with_options,
};
pub use ply::{
    encode_ply, parse_ply, parse_ply_colors, parse_ply_with, parse_ply_with_stats, read_ply,
    read_ply_colors, read_ply_with, read_ply_with_stats, write_ply,
};
pub use units::{LengthUnit, UnknownUnit, geotiff_linear_unit, wkt_linear_unit};

#[cfg(doctest)]
#[doc = include_str!("../README.md")]
struct ReadmeDoctests;

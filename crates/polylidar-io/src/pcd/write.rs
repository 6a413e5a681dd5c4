//! Writing PCD v0.7 files with fields `x y z`.

use std::fmt::Write as _;
use std::path::Path;

use super::header::PcdEncoding;
use crate::cloud::PointCloud;
use crate::error::{ErrorKind, Format, IoError, write_file};
use crate::lzf;

/// Storage type of the coordinates in a written PCD file.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum PcdScalar {
    /// `F 4`: what PCL, MATLAB and most tools write; half the size, ~7 significant digits.
    F32,
    /// `F 8`: lossless for our `f64` points (default).
    #[default]
    F64,
}

/// Options of [`write_pcd_with_options`].
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
#[non_exhaustive]
pub struct PcdWriteOptions {
    /// Data encoding (default [`PcdEncoding::Binary`]).
    pub encoding: PcdEncoding,
    /// Coordinate type (default [`PcdScalar::F64`]).
    pub scalar: PcdScalar,
}

impl PcdWriteOptions {
    /// Options with `encoding` and the default scalar type.
    pub fn new(encoding: PcdEncoding) -> Self {
        PcdWriteOptions {
            encoding,
            scalar: PcdScalar::default(),
        }
    }

    /// Sets the coordinate type.
    #[must_use]
    pub fn with_scalar(mut self, scalar: PcdScalar) -> Self {
        self.scalar = scalar;
        self
    }
}

/// Writes `cloud` as PCD with `f64` coordinates (`WIDTH = cols`, `HEIGHT = rows`).
///
/// # Errors
/// The file cannot be written, or the cloud's shape does not match its point count, or
/// (`BinaryCompressed` only) the data exceeds the format's 4 GiB block size.
pub fn write_pcd(
    path: impl AsRef<Path>,
    cloud: &PointCloud,
    encoding: PcdEncoding,
) -> Result<(), IoError> {
    write_pcd_with_options(path, cloud, &PcdWriteOptions::new(encoding))
}

/// Writes `cloud` as PCD with the given options.
///
/// # Errors
/// As [`write_pcd`].
pub fn write_pcd_with_options(
    path: impl AsRef<Path>,
    cloud: &PointCloud,
    options: &PcdWriteOptions,
) -> Result<(), IoError> {
    let path = path.as_ref();
    let bytes = encode_pcd(cloud, options).map_err(|e| e.at(path))?;
    write_file(path, Format::Pcd, &bytes)
}

/// Encodes `cloud` as PCD bytes.
///
/// # Errors
/// As [`write_pcd`], without the file system.
pub fn encode_pcd(cloud: &PointCloud, options: &PcdWriteOptions) -> Result<Vec<u8>, IoError> {
    let err = |kind| IoError::new(Format::Pcd, kind);
    if cloud.rows.checked_mul(cloud.cols) != Some(cloud.points.len()) {
        return Err(err(ErrorKind::Shape(format!(
            "{} rows × {} columns do not match {} points",
            cloud.rows,
            cloud.cols,
            cloud.points.len()
        ))));
    }
    let (size, width) = match options.scalar {
        PcdScalar::F32 => (4, 4),
        PcdScalar::F64 => (8, 8),
    };
    let kind = match options.encoding {
        PcdEncoding::Ascii => "ascii",
        PcdEncoding::Binary => "binary",
        PcdEncoding::BinaryCompressed => "binary_compressed",
    };
    let mut out = format!(
        "# .PCD v0.7 - Point Cloud Data file format\nVERSION 0.7\nFIELDS x y z\n\
         SIZE {size} {size} {size}\nTYPE F F F\nCOUNT 1 1 1\nWIDTH {}\nHEIGHT {}\n\
         VIEWPOINT 0 0 0 1 0 0 0\nPOINTS {}\nDATA {kind}\n",
        cloud.cols,
        cloud.rows,
        cloud.points.len()
    )
    .into_bytes();
    let n = cloud.points.len();
    match options.encoding {
        PcdEncoding::Ascii => {
            let mut text = String::with_capacity(n * 3 * 12);
            for p in &cloud.points {
                // `{}` prints the shortest text that parses back to the same value.
                let _ = match options.scalar {
                    PcdScalar::F32 => {
                        writeln!(text, "{} {} {}", p[0] as f32, p[1] as f32, p[2] as f32)
                    }
                    PcdScalar::F64 => writeln!(text, "{} {} {}", p[0], p[1], p[2]),
                };
            }
            out.extend_from_slice(text.as_bytes());
        }
        PcdEncoding::Binary => {
            out.reserve(n * 3 * width);
            for p in &cloud.points {
                for &v in p {
                    push_scalar(&mut out, v, options.scalar);
                }
            }
        }
        PcdEncoding::BinaryCompressed => {
            let mut soa = Vec::with_capacity(n * 3 * width);
            for axis in 0..3 {
                for p in &cloud.points {
                    push_scalar(&mut soa, p[axis], options.scalar);
                }
            }
            let packed = lzf::compress(&soa);
            let too_big = || {
                err(ErrorKind::Unusable(
                    "binary_compressed data exceeds 4 GiB; use Binary".to_owned(),
                ))
            };
            let packed_len = u32::try_from(packed.len()).map_err(|_| too_big())?;
            let raw_len = u32::try_from(soa.len()).map_err(|_| too_big())?;
            out.extend_from_slice(&packed_len.to_le_bytes());
            out.extend_from_slice(&raw_len.to_le_bytes());
            out.extend_from_slice(&packed);
        }
    }
    Ok(out)
}

fn push_scalar(out: &mut Vec<u8>, v: f64, scalar: PcdScalar) {
    match scalar {
        PcdScalar::F32 => out.extend_from_slice(&(v as f32).to_le_bytes()),
        PcdScalar::F64 => out.extend_from_slice(&v.to_le_bytes()),
    }
}

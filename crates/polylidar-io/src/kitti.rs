//! KITTI Velodyne frames (`.bin`): little-endian float32 records `x y z reflectance`.
//!
//! The KITTI raw data and object benchmark store each rotating-LiDAR frame as a bare array of
//! 16-byte records, in the sensor frame (x forward, y left, z up, metres) and in the order the
//! sensor fired: beam after beam, each beam sweeping once round the vertical axis. That order
//! is kept, since it is what recovers a point's beam (ring) later.

use std::path::Path;

use crate::error::{ErrorKind, Format, IoError, KindResult, write_file};
use crate::limits::{Limits, times};

/// Bytes per KITTI record: four little-endian float32 (`x y z reflectance`).
pub const KITTI_RECORD_BYTES: usize = 16;

/// One rotating-LiDAR frame from a KITTI `.bin`: the points in firing order and the
/// reflectance of each.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct KittiScan {
    /// `x y z` in the sensor frame (metres), in the file's order.
    pub points: Vec<[f64; 3]>,
    /// Reflectance of each point, as stored (KITTI: 0–1).
    pub reflectance: Vec<f32>,
}

impl KittiScan {
    /// Number of points.
    pub fn len(&self) -> usize {
        self.points.len()
    }

    /// Whether there are no points.
    pub fn is_empty(&self) -> bool {
        self.points.is_empty()
    }
}

/// Reads a KITTI Velodyne `.bin` frame.
///
/// ```
/// use polylidar_io::{KittiScan, read_kitti_bin, write_kitti_bin};
/// let path = std::env::temp_dir().join(format!("polylidar-io-kitti-{}.bin", std::process::id()));
/// let scan = KittiScan {
///     points: vec![[10.0, 0.5, -1.75], [9.5, 1.0, -1.5]],
///     reflectance: vec![0.25, 0.5],
/// };
/// write_kitti_bin(&path, &scan)?;
/// assert_eq!(read_kitti_bin(&path)?, scan);
/// # std::fs::remove_file(&path).ok();
/// # Ok::<(), polylidar_io::IoError>(())
/// ```
///
/// # Errors
/// An [`IoError`] for an unreadable file, an empty one, a size that is not a whole number
/// of 16-byte records (naming the stray bytes), or a non-finite value (naming the record
/// and the field), more points than [`Limits::for_path`] allows.
pub fn read_kitti_bin(path: impl AsRef<Path>) -> Result<KittiScan, IoError> {
    let path = path.as_ref();
    read_kitti_bin_with(path, &Limits::for_path(path))
}

/// As [`read_kitti_bin`], within `limits`.
///
/// # Errors
/// As [`read_kitti_bin`]; [`ErrorKind::OverBudget`] past `limits`.
pub fn read_kitti_bin_with(path: impl AsRef<Path>, limits: &Limits) -> Result<KittiScan, IoError> {
    let path = path.as_ref();
    parse_kitti_bin_with(&limits.read_file(path, Format::KittiBin)?, limits).map_err(|e| e.at(path))
}

/// Parses the bytes of a KITTI `.bin` frame; see [`read_kitti_bin`].
///
/// ```
/// use polylidar_io::parse_kitti_bin;
/// let mut bytes = Vec::new();
/// for v in [1.0f32, 2.0, -1.5, 0.3] {
///     bytes.extend_from_slice(&v.to_le_bytes());
/// }
/// let scan = parse_kitti_bin(&bytes)?;
/// assert_eq!(scan.points, vec![[1.0, 2.0, -1.5]]);
/// assert_eq!(scan.reflectance, vec![0.3]);
/// let error = parse_kitti_bin(&bytes[..15]).unwrap_err();
/// assert!(error.to_string().contains("not a whole number of 16-byte records"));
/// # Ok::<(), polylidar_io::IoError>(())
/// ```
///
/// # Errors
/// As [`read_kitti_bin`], with no file name.
pub fn parse_kitti_bin(bytes: &[u8]) -> Result<KittiScan, IoError> {
    parse_kitti_bin_with(bytes, &Limits::for_input_size(bytes.len() as u64))
}

/// As [`parse_kitti_bin`], within `limits`.
///
/// # Errors
/// As [`read_kitti_bin_with`], with no file name.
pub fn parse_kitti_bin_with(bytes: &[u8], limits: &Limits) -> Result<KittiScan, IoError> {
    parse(bytes, limits).map_err(|k| IoError::new(Format::KittiBin, k))
}

/// The bytes of a KITTI `.bin` frame (coordinates rounded to float32).
///
/// # Errors
/// [`ErrorKind::Shape`] when `points` and `reflectance` differ in length.
pub fn encode_kitti_bin(scan: &KittiScan) -> Result<Vec<u8>, IoError> {
    if scan.points.len() != scan.reflectance.len() {
        return Err(IoError::new(
            Format::KittiBin,
            ErrorKind::Shape(format!(
                "{} points but {} reflectance values",
                scan.points.len(),
                scan.reflectance.len()
            )),
        ));
    }
    let mut bytes = Vec::with_capacity(scan.points.len() * KITTI_RECORD_BYTES);
    for (p, &r) in scan.points.iter().zip(&scan.reflectance) {
        for v in [p[0] as f32, p[1] as f32, p[2] as f32, r] {
            bytes.extend_from_slice(&v.to_le_bytes());
        }
    }
    Ok(bytes)
}

/// Writes a KITTI `.bin` frame ([`encode_kitti_bin`]).
///
/// # Errors
/// As [`encode_kitti_bin`], or the file cannot be written.
pub fn write_kitti_bin(path: impl AsRef<Path>, scan: &KittiScan) -> Result<(), IoError> {
    let path = path.as_ref();
    let bytes = encode_kitti_bin(scan).map_err(|e| e.at(path))?;
    write_file(path, Format::KittiBin, &bytes)
}

const FIELDS: [&str; 4] = ["x", "y", "z", "reflectance"];

fn parse(bytes: &[u8], limits: &Limits) -> KindResult<KittiScan> {
    if bytes.is_empty() {
        return Err(ErrorKind::Unusable("empty file: no points".to_owned()));
    }
    let stray = bytes.len() % KITTI_RECORD_BYTES;
    if stray != 0 {
        return Err(ErrorKind::Shape(format!(
            "{} bytes is not a whole number of 16-byte records (x y z reflectance as \
             float32): {stray} bytes left over after record {}",
            bytes.len(),
            bytes.len() / KITTI_RECORD_BYTES
        )));
    }
    let n = bytes.len() / KITTI_RECORD_BYTES;
    // The points (24 bytes), reflectance (4) and the pipeline's share of each.
    let estimate = (bytes.len() as u64)
        .saturating_add(times(n, 28))
        .saturating_add(limits.pipeline(n as u64));
    limits.check(estimate, || {
        format!(
            "{n} records: 28 bytes read and {} bytes in the pipeline per point",
            limits.pipeline_bytes_per_point
        )
    })?;
    let mut points = Vec::with_capacity(n);
    let mut reflectance = Vec::with_capacity(n);
    for (record, chunk) in bytes.chunks_exact(KITTI_RECORD_BYTES).enumerate() {
        let mut v = [0f32; 4];
        for (k, (slot, word)) in v.iter_mut().zip(chunk.chunks_exact(4)).enumerate() {
            let value = f32::from_le_bytes([word[0], word[1], word[2], word[3]]);
            if !value.is_finite() {
                return Err(ErrorKind::NonFinite {
                    record,
                    field: FIELDS[k],
                    value: value.to_string(),
                });
            }
            *slot = value;
        }
        points.push([f64::from(v[0]), f64::from(v[1]), f64::from(v[2])]);
        reflectance.push(v[3]);
    }
    Ok(KittiScan {
        points,
        reflectance,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    fn bytes_of(values: &[f32]) -> Vec<u8> {
        values.iter().flat_map(|v| v.to_le_bytes()).collect()
    }

    #[test]
    fn round_trip_keeps_order_and_reflectance() {
        let scan = KittiScan {
            points: vec![[1.0, 2.0, 3.0], [-4.5, 0.25, -1.75], [0.0, 0.0, 0.0]],
            reflectance: vec![0.0, 0.5, 1.0],
        };
        let bytes = encode_kitti_bin(&scan).unwrap_or_default();
        assert_eq!(bytes.len(), 48);
        assert_eq!(parse_kitti_bin(&bytes).ok(), Some(scan));
    }

    #[test]
    fn malformed_files_are_named() {
        let message = |bytes: &[u8]| {
            parse_kitti_bin(bytes)
                .err()
                .map(|e| e.to_string())
                .unwrap_or_default()
        };
        assert!(message(&[]).contains("empty file"));
        let m = message(&bytes_of(&[1.0, 2.0, 3.0, 0.5, 7.0]));
        assert!(
            m.contains("20 bytes") && m.contains("4 bytes left over after record 1"),
            "{m}"
        );
        let m = message(&bytes_of(&[1.0, 2.0, 3.0, 0.5, 1.0, f32::NAN, 3.0, 0.5]));
        assert!(
            m.contains("record 1") && m.contains("`y`") && m.contains("NaN"),
            "{m}"
        );
        let m = message(&bytes_of(&[1.0, 2.0, 3.0, f32::INFINITY]));
        assert!(m.contains("record 0") && m.contains("`reflectance`"), "{m}");
        assert!(m.starts_with("<memory>: KITTI .bin file"), "{m}");
    }

    #[test]
    fn encode_checks_lengths() {
        let scan = KittiScan {
            points: vec![[0.0; 3]],
            reflectance: vec![],
        };
        assert!(encode_kitti_bin(&scan).is_err());
    }
}

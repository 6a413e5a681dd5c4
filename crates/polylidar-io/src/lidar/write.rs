//! Writing LAS and LAZ files (point format 0, LAS 1.2) through the `las` crate, and
//! reading a file's bounds from its header alone.

use std::path::Path;

use crate::error::{ErrorKind, Format, IoError};

/// How [`write_las`] stores coordinates.
#[derive(Debug, Clone, Copy, PartialEq)]
#[non_exhaustive]
pub struct LasWriteOptions {
    /// The coordinate resolution (the header's scale, the same on x, y and z): `0.001` is
    /// millimetres for data in metres. Coordinates are rounded to it.
    pub scale: f64,
    /// Compress as LAZ; `None` decides by the file name (`.laz`).
    pub compress: Option<bool>,
}

impl Default for LasWriteOptions {
    fn default() -> Self {
        Self {
            scale: 0.001,
            compress: None,
        }
    }
}

/// Writes points as a LAS file (LAZ when [`LasWriteOptions::compress`] says so, or the
/// name ends in `.laz`): coordinates rounded to the scale (the offset is the lower corner
/// of the points' box rounded down to a multiple of 1,000), with each point's ASPRS class (`classification` empty: all 1, unclassified) and
/// `point_source_id` (empty: all 0). [`crate::read_las`] reads it back.
///
/// ```
/// use polylidar_io::{LasWriteOptions, read_las, write_las};
/// let dir = std::env::temp_dir().join(format!("las-doc-{}", std::process::id()));
/// std::fs::create_dir_all(&dir).unwrap();
/// let path = dir.join("two.laz");
/// let points = [[1.0, 2.0, 3.0], [4.5, 5.25, -6.125]];
/// write_las(&path, &points, &[2, 6], &[], &LasWriteOptions::default())?;
/// let cloud = read_las(&path)?;
/// assert_eq!(cloud.points, points);
/// assert_eq!(cloud.classification, [2, 6]);
/// # std::fs::remove_dir_all(&dir).unwrap();
/// # Ok::<(), polylidar_io::IoError>(())
/// ```
///
/// # Errors
/// An [`IoError`] naming the file for a non-finite coordinate, a scale that is not
/// positive, coordinates too far apart for 32-bit integers at that scale, class or source
/// lists of another length than the points, a class the format cannot hold (12 or above
/// 31), or a failure to write.
pub fn write_las(
    path: impl AsRef<Path>,
    points: &[[f64; 3]],
    classification: &[u8],
    point_source_id: &[u16],
    options: &LasWriteOptions,
) -> Result<(), IoError> {
    let path = path.as_ref();
    let error = |k| IoError::new(Format::Las, k).at(path);
    let compress = options.compress.unwrap_or_else(|| {
        path.extension()
            .and_then(|e| e.to_str())
            .is_some_and(|e| e.eq_ignore_ascii_case("laz"))
    });
    let header =
        header_for(points, classification, point_source_id, options, compress).map_err(error)?;
    let las_err = |e: las::Error| ErrorKind::Decoder(e.to_string());
    // Written beside the target and renamed over it at the end (crate::atomic): a failed
    // write leaves the old file as it was.
    let (staged, file) =
        crate::atomic::StagedFile::create(path).map_err(|e| error(ErrorKind::Os(e)))?;
    let mut writer =
        las::Writer::new(std::io::BufWriter::new(file), header).map_err(|e| error(las_err(e)))?;
    for (i, p) in points.iter().enumerate() {
        let class = classification.get(i).copied().unwrap_or(1);
        let point = las::Point {
            x: p[0],
            y: p[1],
            z: p[2],
            classification: las::point::Classification::new(class)
                .map_err(|e| error(las_err(e)))?,
            point_source_id: point_source_id.get(i).copied().unwrap_or(0),
            ..las::Point::default()
        };
        writer.write_point(point).map_err(|e| error(las_err(e)))?;
    }
    writer.close().map_err(|e| error(las_err(e)))?;
    drop(writer);
    staged.commit().map_err(|e| error(ErrorKind::Os(e)))
}

/// The header of a file of `points`, after checking what [`write_las`] documents.
fn header_for(
    points: &[[f64; 3]],
    classification: &[u8],
    point_source_id: &[u16],
    options: &LasWriteOptions,
    compress: bool,
) -> Result<las::Header, ErrorKind> {
    let scale = options.scale;
    if !(scale.is_finite() && scale > 0.0) {
        return Err(ErrorKind::Shape(format!("scale {scale} is not positive")));
    }
    for (name, len) in [
        ("classification", classification.len()),
        ("point_source_id", point_source_id.len()),
    ] {
        if len != 0 && len != points.len() {
            return Err(ErrorKind::Shape(format!(
                "{len} {name} values for {} points",
                points.len()
            )));
        }
    }
    if let Some(i) = points.iter().position(|p| !p.iter().all(|c| c.is_finite())) {
        return Err(ErrorKind::Shape(format!("point {i} is not finite")));
    }
    if let Some(&c) = classification.iter().find(|&&c| c == 12 || c > 31) {
        return Err(ErrorKind::Shape(format!(
            "class {c} does not fit LAS point format 0"
        )));
    }
    let mut transforms = [las::Transform { scale, offset: 0.0 }; 3];
    for (k, t) in transforms.iter_mut().enumerate() {
        let (lo, hi) = points
            .iter()
            .fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), p| {
                (lo.min(p[k]), hi.max(p[k]))
            });
        if lo > hi {
            break;
        }
        t.offset = (lo / 1000.0).floor() * 1000.0;
        if (hi - t.offset) / scale > f64::from(i32::MAX) {
            return Err(ErrorKind::Shape(format!(
                "coordinates from {lo} to {hi} do not fit 32-bit integers at scale {scale}"
            )));
        }
    }
    let mut builder = las::Builder::from((1, 2));
    builder.point_format =
        las::point::Format::new(0).map_err(|e| ErrorKind::Decoder(e.to_string()))?;
    builder.point_format.is_compressed = compress;
    builder.generating_software = "polylidar-io".into();
    builder.transforms = las::Vector {
        x: transforms[0],
        y: transforms[1],
        z: transforms[2],
    };
    builder
        .into_header()
        .map_err(|e| ErrorKind::Decoder(e.to_string()))
}

/// The box a LAS or LAZ file's header declares (`min`, `max`, each `[x, y, z]`) and its
/// point count, without decoding the points: what a tiling plan needs of each file.
///
/// # Errors
/// An [`IoError`] naming the file when it cannot be opened or its header is not LAS.
pub fn read_las_bounds(path: impl AsRef<Path>) -> Result<([f64; 3], [f64; 3], u64), IoError> {
    let path = path.as_ref();
    let error = |k| IoError::new(Format::Las, k).at(path);
    let file = std::fs::File::open(path).map_err(|e| error(ErrorKind::Os(e)))?;
    let header = las::Header::new(std::io::BufReader::new(file))
        .map_err(|e| error(ErrorKind::Decoder(e.to_string())))?;
    let b = header.bounds();
    Ok((
        [b.min.x, b.min.y, b.min.z],
        [b.max.x, b.max.y, b.max.z],
        header.number_of_points(),
    ))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn round_trips_las_and_laz_at_the_scale() {
        let points: Vec<[f64; 3]> = (0..5000)
            .map(|i| {
                let t = f64::from(i);
                [
                    636_000.0 + 0.37 * t,
                    849_000.0 - 0.11 * t,
                    400.0 + (t * 0.01).sin(),
                ]
            })
            .collect();
        let classes: Vec<u8> = (0..5000).map(|i| [1, 2, 5, 6][i % 4]).collect();
        let sources: Vec<u16> = (0..5000).map(|i| (i * 7 % 65536) as u16).collect();
        let dir = test_fixtures::scratch_dir("las-write", "round-trip");
        for name in ["a.las", "a.laz"] {
            let path = dir.join(name);
            write_las(
                &path,
                &points,
                &classes,
                &sources,
                &LasWriteOptions::default(),
            )
            .unwrap();
            let cloud = crate::read_las(&path).unwrap();
            assert_eq!(cloud.classification, classes);
            for (p, q) in points.iter().zip(&cloud.points) {
                for k in 0..3 {
                    assert!((p[k] - q[k]).abs() <= 0.0005 + 1e-9, "{p:?} {q:?}");
                }
            }
            let (min, max, n) = read_las_bounds(&path).unwrap();
            assert_eq!(n, 5000);
            assert!((min[0] - 636_000.0).abs() < 1e-3 && (max[1] - 849_000.0).abs() < 1e-3);
        }
        let las = std::fs::metadata(dir.join("a.las")).unwrap().len();
        let laz = std::fs::metadata(dir.join("a.laz")).unwrap().len();
        assert!(laz < las / 2, "{laz} vs {las}");
    }

    #[test]
    fn refuses_what_it_cannot_store() {
        let dir = test_fixtures::scratch_dir("las-write", "refused");
        let path = dir.join("bad.las");
        let o = LasWriteOptions::default();
        assert!(write_las(&path, &[[f64::NAN, 0.0, 0.0]], &[], &[], &o).is_err());
        assert!(write_las(&path, &[[0.0; 3]], &[1, 2], &[], &o).is_err());
        assert!(write_las(&path, &[[0.0; 3]], &[12], &[], &o).is_err());
        assert!(write_las(&path, &[[0.0; 3], [1e8, 0.0, 0.0]], &[], &[], &o).is_err());
        let zero = LasWriteOptions { scale: 0.0, ..o };
        assert!(write_las(&path, &[[0.0; 3]], &[], &[], &zero).is_err());
        assert!(read_las_bounds(dir.join("missing.las")).is_err());
        write_las(&path, &[], &[], &[], &o).unwrap();
        assert!(crate::read_las(&path).unwrap().points.is_empty());
    }
}

//! ASPRS LAS and LAZ (compressed) airborne LiDAR files, through the `las` crate.

use std::io::{BufReader, Cursor, Read, Seek};
use std::path::Path;

use crate::cloud::LasCloud;
use crate::error::{ErrorKind, Format, IoError, KindResult};
use crate::limits::Limits;

mod guard;
mod write;
pub use write::{LasWriteOptions, read_las_bounds, write_las};
mod quiet;

/// Bytes of point records decoded per batch: bounds memory use by what the file really
/// holds, whatever its header claims (records may be up to 64 KiB long).
const BATCH_BYTES: u64 = 8 << 20;

/// Reads a LAS or LAZ file: coordinates (scale and offset applied), classification, and
/// the length unit its header declares.
///
/// # Errors
/// An [`IoError`] naming the file and what is wrong: the header field that does not fit
/// the file (by name and byte position), the point records that are truncated or corrupt
/// (with their LAZ chunk), or more points than [`Limits::for_path`] allows.
pub fn read_las(path: impl AsRef<Path>) -> Result<LasCloud, IoError> {
    let path = path.as_ref();
    read_las_with(path, &Limits::for_path(path))
}

/// As [`read_las`], within `limits` (the header's point count times 25 bytes per point
/// read and the pipeline's share, checked before decoding).
///
/// # Errors
/// As [`read_las`]; [`ErrorKind::OverBudget`] past `limits`.
pub fn read_las_with(path: impl AsRef<Path>, limits: &Limits) -> Result<LasCloud, IoError> {
    let path = path.as_ref();
    let file = std::fs::File::open(path)
        .map_err(|e| IoError::new(Format::Las, ErrorKind::Os(e)).at(path))?;
    decode(BufReader::new(file), limits).map_err(|k| IoError::new(Format::Las, k).at(path))
}

/// The length unit the header of a LAS or LAZ file declares (see [`crate::LengthUnit`]),
/// without decoding its points; `None` when it declares none.
///
/// # Errors
/// An [`IoError`] naming the file when it cannot be opened or its header is not LAS.
pub fn read_las_unit(path: impl AsRef<Path>) -> Result<Option<crate::LengthUnit>, IoError> {
    let path = path.as_ref();
    let error = |k| IoError::new(Format::Las, k).at(path);
    let file = std::fs::File::open(path).map_err(|e| error(ErrorKind::Os(e)))?;
    let mut read = BufReader::new(file);
    guard::check_header(&mut read).map_err(error)?;
    let header = quiet::catch(|| las::Header::new(read))
        .map_err(|panic| error(ErrorKind::Corrupt(format!("LAS header: {panic}"))))?
        .map_err(|e| error(header_error(e)))?;
    Ok(crate::units::las_header_unit(&header))
}

/// Parses LAS or LAZ bytes; see [`read_las`].
///
/// # Errors
/// As [`read_las`], with no file name.
pub fn parse_las(bytes: &[u8]) -> Result<LasCloud, IoError> {
    parse_las_with(bytes, &Limits::for_input_size(bytes.len() as u64))
}

/// As [`parse_las`], within `limits`.
///
/// # Errors
/// As [`read_las_with`], with no file name.
pub fn parse_las_with(bytes: &[u8], limits: &Limits) -> Result<LasCloud, IoError> {
    decode(Cursor::new(bytes.to_vec()), limits).map_err(|k| IoError::new(Format::Las, k))
}

/// Bytes kept per point: coordinates and classification.
const BYTES_PER_POINT: u64 = 25;

/// Checks the header, the budget, then decodes with the `las` crate; a panic of its LAZ
/// decoder on corrupt data (seen when fuzzing: slice bounds in `laz`) becomes an error
/// without a word on stderr, and nothing of the decoder's state survives the call.
fn decode<R: Read + Seek + Send + Sync + 'static>(
    mut read: R,
    limits: &Limits,
) -> KindResult<LasCloud> {
    let layout = guard::check_header(&mut read)?;
    let batch = BATCH_BYTES.min(layout.points.saturating_mul(layout.record_len));
    let estimate = layout
        .points
        .saturating_mul(BYTES_PER_POINT)
        .saturating_add(limits.pipeline(layout.points))
        .saturating_add(batch);
    limits.check(estimate, || {
        format!(
            "{} point records (from the header): {BYTES_PER_POINT} bytes read and {} bytes in \
             the pipeline per point",
            layout.points, limits.pipeline_bytes_per_point
        )
    })?;
    let mut done = 0u64;
    let mut batch_len = 0u64;
    quiet::catch(|| decode_unguarded(read, &layout, &mut done, &mut batch_len)).unwrap_or_else(
        |panic| {
            Err(ErrorKind::Corrupt(format!(
                "{} cannot be decoded ({panic})",
                layout.describe(done, batch_len)
            )))
        },
    )
}

/// Whether `e` is the end of the data met too early, reported by `las` or by `laz`.
fn is_eof(e: &las::Error) -> bool {
    let eof = |io: &std::io::Error| io.kind() == std::io::ErrorKind::UnexpectedEof;
    match e {
        las::Error::Io(io) => eof(io),
        las::Error::LasZipError(laz::LasZipError::IoError(io)) => eof(io),
        _ => false,
    }
}

/// The message of a `las` error met while reading the header, the VLRs and (LAZ) the
/// chunk table.
fn header_error(e: las::Error) -> ErrorKind {
    match e {
        e if is_eof(&e) => ErrorKind::BadHeader(
            "the file ends inside its header, its variable-length records or (LAZ) its \
             chunk table"
                .to_owned(),
        ),
        las::Error::LasZipError(laz::LasZipError::MissingChunkTable) => ErrorKind::Corrupt(
            "the LAZ chunk table (at the offset the first 8 bytes of the point data give) \
             is missing"
                .to_owned(),
        ),
        other => ErrorKind::Decoder(format!("LAS header: {other}")),
    }
}

fn decode_unguarded<R: Read + Seek + Send + Sync + 'static>(
    read: R,
    layout: &guard::Layout,
    done: &mut u64,
    batch_len: &mut u64,
) -> KindResult<LasCloud> {
    let mut reader = las::Reader::new(read).map_err(header_error)?;
    let total = reader.header().number_of_points();
    let mut cloud = LasCloud {
        unit: crate::units::las_header_unit(reader.header()),
        ..LasCloud::default()
    };
    let mut batch = las::PointDataBuilder::new()
        .for_header(reader.header())
        .build();
    let record_len = u64::from(reader.header().point_format().len()).max(1);
    let batch_points = (BATCH_BYTES / record_len).max(1);
    while *done < total {
        *batch_len = batch_points.min(total - *done);
        let n = reader
            .fill_points(*batch_len, &mut batch)
            .map_err(|e| point_error(e, layout, *done, *batch_len))?;
        if n == 0 {
            return Err(ErrorKind::Shape(format!(
                "the header declares {total} point records, the data ends after {done}"
            )));
        }
        cloud.points.extend(
            batch
                .x()
                .zip(batch.y())
                .zip(batch.z())
                .map(|((x, y), z)| [x, y, z]),
        );
        cloud.classification.extend(batch.classification());
        *done += n;
    }
    Ok(cloud)
}

/// The message of a `las` error met while decoding `count` points from `first` on.
fn point_error(e: las::Error, layout: &guard::Layout, first: u64, count: u64) -> ErrorKind {
    let which = layout.describe(first, count);
    match e {
        e if is_eof(&e) => {
            if layout.compressed {
                ErrorKind::Corrupt(format!(
                    "the compressed data ends inside {which}: the file is truncated or its \
                     chunk table is wrong"
                ))
            } else {
                ErrorKind::Shape(format!("the file ends inside {which}"))
            }
        }
        las::Error::Io(io) if layout.compressed => {
            ErrorKind::Corrupt(format!("{which} cannot be decompressed: {io}"))
        }
        las::Error::LasZipError(laz) => {
            ErrorKind::Corrupt(format!("{which} cannot be decompressed: {laz}"))
        }
        other => ErrorKind::Decoder(format!("{which}: {other}")),
    }
}

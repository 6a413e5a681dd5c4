//! ASPRS LAS and LAZ (compressed) airborne LiDAR files, through the `las` crate.

use std::io::{BufReader, Cursor, Read, Seek};
use std::path::Path;

use crate::cloud::LasCloud;
use crate::error::{ErrorKind, Format, IoError, KindResult};

mod guard;

/// Bytes of point records decoded per batch: bounds memory use by what the file really
/// holds, whatever its header claims (records may be up to 64 KiB long).
const BATCH_BYTES: u64 = 8 << 20;

/// Reads a LAS or LAZ file: coordinates (scale and offset applied), classification, and
/// the length unit its header declares.
///
/// # Errors
/// An [`IoError`] naming the file and the decoder's message (bad signature, unsupported
/// version or point format, truncated or corrupt point data).
pub fn read_las(path: impl AsRef<Path>) -> Result<LasCloud, IoError> {
    let path = path.as_ref();
    let file = std::fs::File::open(path)
        .map_err(|e| IoError::new(Format::Las, ErrorKind::Os(e)).at(path))?;
    decode(BufReader::new(file)).map_err(|k| IoError::new(Format::Las, k).at(path))
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
    guard::check_claimed_sizes(&mut read).map_err(error)?;
    let header = las::Header::new(read).map_err(|e| error(ErrorKind::Decoder(e.to_string())))?;
    Ok(crate::units::las_header_unit(&header))
}

/// Parses LAS or LAZ bytes; see [`read_las`].
///
/// # Errors
/// As [`read_las`], with no file name.
pub fn parse_las(bytes: &[u8]) -> Result<LasCloud, IoError> {
    decode(Cursor::new(bytes.to_vec())).map_err(|k| IoError::new(Format::Las, k))
}

/// Decodes with the `las` crate, turning a panic of its LAZ decoder on corrupt data (seen
/// when fuzzing: slice bounds in `laz`) into an error; nothing of the decoder's state
/// survives the call.
fn decode<R: Read + Seek + Send + Sync + 'static>(mut read: R) -> KindResult<LasCloud> {
    guard::check_claimed_sizes(&mut read)?;
    std::panic::catch_unwind(std::panic::AssertUnwindSafe(|| decode_unguarded(read)))
        .unwrap_or_else(|payload| {
            let message = payload
                .downcast_ref::<&str>()
                .map(|s| (*s).to_owned())
                .or_else(|| payload.downcast_ref::<String>().cloned())
                .unwrap_or_default();
            Err(ErrorKind::Decoder(format!(
                "the LAS/LAZ decoder failed on corrupt data ({message})"
            )))
        })
}

fn decode_unguarded<R: Read + Seek + Send + Sync + 'static>(read: R) -> KindResult<LasCloud> {
    let las_err = |e: las::Error| ErrorKind::Decoder(e.to_string());
    let mut reader = las::Reader::new(read).map_err(las_err)?;
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
    let mut done = 0u64;
    while done < total {
        let n = reader
            .fill_points(batch_points.min(total - done), &mut batch)
            .map_err(las_err)?;
        if n == 0 {
            return Err(ErrorKind::Shape(format!(
                "header declares {total} points, the data ends after {done}"
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
        done += n;
    }
    Ok(cloud)
}

//! Point Cloud Library `.pcd` files: v0.7 (v0.6/v0.5 headers tolerated), `DATA ascii`,
//! `binary` and `binary_compressed` (LZF, fields stored column by column).

mod decode;
mod header;
mod write;

use std::path::Path;

pub use header::{PcdEncoding, PcdField, PcdHeader, ScalarType};
pub use write::{PcdScalar, PcdWriteOptions, encode_pcd, write_pcd, write_pcd_with_options};

use crate::cloud::PointCloud;
use crate::error::{ErrorKind, Format, IoError, KindResult, read_file};
use decode::{Wanted, prepare};

fn err(kind: ErrorKind) -> IoError {
    IoError::new(Format::Pcd, kind)
}

/// Reads a PCD file into a [`PointCloud`], keeping `WIDTH × HEIGHT` organization
/// (`rows = HEIGHT`, `cols = WIDTH`).
///
/// Fields `x`, `y` and `z` (any numeric type, `COUNT 1`) are required; other fields
/// (`intensity`, `rgb`, `normal_x`, …) are skipped.
///
/// # Errors
/// An [`IoError`] naming the file and the problem: unreadable file, malformed header line,
/// unsupported `DATA` kind, missing `x`/`y`/`z`, truncated or corrupt data.
pub fn read_pcd(path: impl AsRef<Path>) -> Result<PointCloud, IoError> {
    let path = path.as_ref();
    parse_pcd(&read_file(path, Format::Pcd)?).map_err(|e| e.at(path))
}

/// Parses PCD bytes into a [`PointCloud`]; see [`read_pcd`].
///
/// # Errors
/// As [`read_pcd`], with no file name.
pub fn parse_pcd(bytes: &[u8]) -> Result<PointCloud, IoError> {
    parse_xyz(bytes).map_err(err)
}

fn parse_xyz(bytes: &[u8]) -> KindResult<PointCloud> {
    let header = header::parse_header(bytes)?;
    let mut wanted = [Wanted {
        field: 0,
        element: 0,
    }; 3];
    for (w, name) in wanted.iter_mut().zip(["x", "y", "z"]) {
        let field = header
            .fields
            .iter()
            .position(|f| f.name == name)
            .ok_or_else(|| ErrorKind::MissingField(name.to_owned()))?;
        if header.fields[field].count != 1 {
            return Err(ErrorKind::Unsupported {
                what: "coordinate field COUNT",
                value: format!("{name} has COUNT {}", header.fields[field].count),
            });
        }
        w.field = field;
    }
    let data = prepare(&header, bytes)?;
    let mut points = vec![[0.0f64; 3]; header.points()];
    data.decode(&wanted, |axis, i, v| points[i][axis] = v)?;
    Ok(PointCloud {
        rows: header.height,
        cols: header.width,
        points,
    })
}

/// The packed `rgb` / `rgba` colours of every point, or `None` without such a field.
/// Binary data is read as the field's raw 32 bits (a float's bits may be a NaN pattern,
/// which a float conversion would not keep); ascii floats through their `f32` bits.
pub(crate) fn packed_colors(bytes: &[u8]) -> KindResult<Option<Vec<[u8; 3]>>> {
    let mut header = header::parse_header(bytes)?;
    let Some(field) = header
        .fields
        .iter()
        .position(|f| (f.name == "rgb" || f.name == "rgba") && f.ty.size() == 4)
    else {
        return Ok(None);
    };
    let float = header.fields[field].ty == ScalarType::F32;
    if header.encoding != PcdEncoding::Ascii {
        header.fields[field].ty = ScalarType::U32;
    }
    let data = prepare(&header, bytes)?;
    let mut colors = vec![[0u8; 3]; header.points()];
    let ascii_float = float && header.encoding == PcdEncoding::Ascii;
    data.decode(&[Wanted { field, element: 0 }], |_, i, v| {
        let bits = if ascii_float {
            (v as f32).to_bits()
        } else {
            v as u32
        };
        colors[i] = crate::color::unpack(bits);
    })?;
    Ok(Some(colors))
}

/// Parses only the header of PCD bytes.
///
/// # Errors
/// A malformed or incomplete header.
pub fn parse_pcd_header(bytes: &[u8]) -> Result<PcdHeader, IoError> {
    header::parse_header(bytes).map_err(err)
}

/// Every scalar of every field of a PCD file, as named `f64` columns.
#[derive(Debug, Clone, PartialEq)]
pub struct PcdColumns {
    /// `WIDTH` (columns of an organized cloud).
    pub width: usize,
    /// `HEIGHT` (rows; 1 for an unorganized cloud).
    pub height: usize,
    /// Column names: the field name, or `name[k]` for element `k` of a field with `COUNT > 1`.
    pub names: Vec<String>,
    /// One `Vec` of `width × height` values per name, in point order.
    pub values: Vec<Vec<f64>>,
}

impl PcdColumns {
    /// The column called `name`.
    pub fn column(&self, name: &str) -> Option<&[f64]> {
        self.names
            .iter()
            .position(|n| n == name)
            .map(|k| self.values[k].as_slice())
    }
}

/// Reads every field of a PCD file (e.g. `intensity`, `label`) as `f64` columns.
///
/// Integer values convert exactly up to 2⁵³; packed `rgb` floats come back as the float
/// value, not the packed bytes.
///
/// # Errors
/// As [`read_pcd`], except that `x`, `y`, `z` are not required.
pub fn read_pcd_fields(path: impl AsRef<Path>) -> Result<PcdColumns, IoError> {
    let path = path.as_ref();
    parse_pcd_fields(&read_file(path, Format::Pcd)?).map_err(|e| e.at(path))
}

/// Parses every field of PCD bytes; see [`read_pcd_fields`].
///
/// # Errors
/// As [`read_pcd_fields`], with no file name.
pub fn parse_pcd_fields(bytes: &[u8]) -> Result<PcdColumns, IoError> {
    let header = header::parse_header(bytes).map_err(err)?;
    let mut wanted = Vec::new();
    let mut names = Vec::new();
    for (field, f) in header.fields.iter().enumerate() {
        for element in 0..f.count {
            wanted.push(Wanted { field, element });
            names.push(if f.count == 1 {
                f.name.clone()
            } else {
                format!("{}[{element}]", f.name)
            });
        }
    }
    let data = prepare(&header, bytes).map_err(err)?;
    let mut values = vec![vec![0.0f64; header.points()]; wanted.len()];
    data.decode(&wanted, |slot, i, v| values[slot][i] = v)
        .map_err(err)?;
    Ok(PcdColumns {
        width: header.width,
        height: header.height,
        names,
        values,
    })
}

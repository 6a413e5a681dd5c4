//! Point Cloud Library `.pcd` files: v0.7 (v0.6/v0.5 headers tolerated), `DATA ascii`,
//! `binary` and `binary_compressed` (LZF, fields stored column by column).

mod decode;
mod header;
mod write;

use std::path::Path;

pub use header::{PcdEncoding, PcdField, PcdHeader, ScalarType};
pub use write::{PcdScalar, PcdWriteOptions, encode_pcd, write_pcd, write_pcd_with_options};

use crate::cloud::PointCloud;
use crate::error::{ErrorKind, Format, IoError, KindResult};
use crate::limits::Limits;
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
/// NaN coordinates (PCL's invalid-point marker) are kept, organized or not; see
/// [`crate::read_input`] for a read that skips them in unorganized clouds.
///
/// # Errors
/// An [`IoError`] naming the file and the problem: unreadable file, malformed header line,
/// unsupported `DATA` kind, missing `x`/`y`/`z`, truncated or corrupt data, more points
/// than [`Limits::for_path`] allows.
pub fn read_pcd(path: impl AsRef<Path>) -> Result<PointCloud, IoError> {
    let path = path.as_ref();
    read_pcd_with(path, &Limits::for_path(path))
}

/// As [`read_pcd`], within `limits`.
///
/// # Errors
/// As [`read_pcd`]; [`ErrorKind::OverBudget`] past `limits`.
pub fn read_pcd_with(path: impl AsRef<Path>, limits: &Limits) -> Result<PointCloud, IoError> {
    let path = path.as_ref();
    parse_pcd_with(&limits.read_file(path, Format::Pcd)?, limits).map_err(|e| e.at(path))
}

/// Parses PCD bytes into a [`PointCloud`]; see [`read_pcd`].
///
/// # Errors
/// As [`read_pcd`], with no file name.
pub fn parse_pcd(bytes: &[u8]) -> Result<PointCloud, IoError> {
    parse_pcd_with(bytes, &Limits::for_input_size(bytes.len() as u64))
}

/// As [`parse_pcd`], within `limits`.
///
/// # Errors
/// As [`read_pcd_with`], with no file name.
pub fn parse_pcd_with(bytes: &[u8], limits: &Limits) -> Result<PointCloud, IoError> {
    parse_xyz(bytes, limits).map_err(err)
}

/// The budget check of a read of `header` whose output takes `per_point` bytes per point
/// (plus the pipeline's share when `pipeline`), given the bytes of the decompressed block.
fn budget<'a>(
    header: &'a PcdHeader,
    bytes: &'a [u8],
    limits: &'a Limits,
    per_point: u64,
    pipeline: bool,
) -> impl FnOnce(u64) -> KindResult<()> + 'a {
    move |block| {
        let n = header.points() as u64;
        let share = if pipeline { limits.pipeline(n) } else { 0 };
        let estimate = (bytes.len() as u64)
            .saturating_add(block)
            .saturating_add(n.saturating_mul(per_point))
            .saturating_add(share);
        limits.check(estimate, || {
            format!(
                "{n} points (WIDTH {} × HEIGHT {}): {block} bytes decompressed, {per_point} \
                 bytes read and {} bytes in the pipeline per point",
                header.width,
                header.height,
                if pipeline {
                    limits.pipeline_bytes_per_point
                } else {
                    0
                }
            )
        })
    }
}

fn parse_xyz(bytes: &[u8], limits: &Limits) -> KindResult<PointCloud> {
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
    let data = prepare(&header, bytes, budget(&header, bytes, limits, 24, true))?;
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
pub(crate) fn packed_colors(bytes: &[u8], limits: &Limits) -> KindResult<Option<Vec<[u8; 3]>>> {
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
    let data = prepare(&header, bytes, budget(&header, bytes, limits, 3, false))?;
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
/// As [`read_pcd`], except that `x`, `y`, `z` are not required; the budget counts 8 bytes
/// per value and no pipeline share.
pub fn read_pcd_fields(path: impl AsRef<Path>) -> Result<PcdColumns, IoError> {
    let path = path.as_ref();
    read_pcd_fields_with(path, &Limits::for_path(path))
}

/// As [`read_pcd_fields`], within `limits`.
///
/// # Errors
/// As [`read_pcd_fields`]; [`ErrorKind::OverBudget`] past `limits`.
pub fn read_pcd_fields_with(
    path: impl AsRef<Path>,
    limits: &Limits,
) -> Result<PcdColumns, IoError> {
    let path = path.as_ref();
    parse_pcd_fields_with(&limits.read_file(path, Format::Pcd)?, limits).map_err(|e| e.at(path))
}

/// Parses every field of PCD bytes; see [`read_pcd_fields`].
///
/// # Errors
/// As [`read_pcd_fields`], with no file name.
pub fn parse_pcd_fields(bytes: &[u8]) -> Result<PcdColumns, IoError> {
    parse_pcd_fields_with(bytes, &Limits::for_input_size(bytes.len() as u64))
}

/// Bytes of bookkeeping per column of [`PcdColumns`] (its name, its `Vec`, its decoder
/// slot), beyond its values.
const COLUMN_OVERHEAD: u64 = 96;

/// As [`parse_pcd_fields`], within `limits`.
///
/// # Errors
/// As [`read_pcd_fields_with`], with no file name.
pub fn parse_pcd_fields_with(bytes: &[u8], limits: &Limits) -> Result<PcdColumns, IoError> {
    let header = header::parse_header(bytes).map_err(err)?;
    // Every element of every field becomes a column: `COUNT 100000000` is 10⁸ columns.
    let columns = header
        .fields
        .iter()
        .fold(0u64, |acc, f| acc.saturating_add(f.count as u64));
    let per_point = columns.saturating_mul(8);
    let overhead = columns.saturating_mul(COLUMN_OVERHEAD);
    let check_columns = |block: u64| {
        budget(&header, bytes, &limits.reading_only(), per_point, false)(
            block.saturating_add(overhead),
        )
        .map_err(|e| match e {
            ErrorKind::OverBudget {
                what,
                estimate,
                limit,
            } => ErrorKind::OverBudget {
                what: format!("{columns} columns (the fields' COUNTs summed) of {what}"),
                estimate,
                limit,
            },
            other => other,
        })
    };
    // The columns are counted before the data is checked: a header alone can claim them.
    check_columns(0).map_err(err)?;
    let data = prepare(&header, bytes, check_columns).map_err(err)?;
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

//! Text tables of 2D or 3D points (`.csv`, `.txt`, `.xyz`).

use std::path::Path;

use crate::cloud::PointTable;
use crate::error::{ErrorKind, Format, IoError, KindResult};
use crate::limits::{Limits, times};

/// Reads a text table of points: one point per line, 2 or 3 numbers separated by commas,
/// semicolons, spaces or tabs; `#` starts a comment; one header line whose fields are all
/// names, none a number (e.g. `x,y,z`), may precede the data. Every data line must have as
/// many numbers as the first.
///
/// Values are kept as written (`nan` and `inf` included); callers that need finite
/// coordinates check them.
///
/// # Errors
/// An [`IoError`] naming the line: a value that is not a number (also in a first row that
/// mixes numbers and names, such as a mistyped data row), a row of the wrong length, a
/// first row with neither 2 nor 3 values, or no data row at all; more lines than the budget of
/// the file's size ([`Limits::for_path`]) allows.
pub fn read_csv_points(path: impl AsRef<Path>) -> Result<PointTable, IoError> {
    let path = path.as_ref();
    read_csv_points_with(path, &Limits::for_path(path))
}

/// As [`read_csv_points`], within `limits`.
///
/// # Errors
/// As [`read_csv_points`]; [`ErrorKind::OverBudget`] past `limits`.
pub fn read_csv_points_with(
    path: impl AsRef<Path>,
    limits: &Limits,
) -> Result<PointTable, IoError> {
    let path = path.as_ref();
    parse_csv_points_with(&limits.read_file(path, Format::CsvPoints)?, limits)
        .map_err(|e| e.at(path))
}

/// Parses a text table of points; see [`read_csv_points`].
///
/// # Errors
/// As [`read_csv_points`], with no file name.
pub fn parse_csv_points(bytes: &[u8]) -> Result<PointTable, IoError> {
    parse_csv_points_with(bytes, &Limits::for_input_size(bytes.len() as u64))
}

/// As [`parse_csv_points`], within `limits`.
///
/// # Errors
/// As [`read_csv_points_with`], with no file name.
pub fn parse_csv_points_with(bytes: &[u8], limits: &Limits) -> Result<PointTable, IoError> {
    parse(bytes, limits).map_err(|k| IoError::new(Format::CsvPoints, k))
}

fn is_separator(c: char) -> bool {
    matches!(c, ',' | ';' | ' ' | '\t' | '\r')
}

/// Bytes a row may cost: three `f64` in the table, the point array made of it, and the
/// pipeline's share.
fn row_bytes(limits: &Limits) -> u64 {
    48u64.saturating_add(limits.pipeline_bytes_per_point)
}

fn parse(bytes: &[u8], limits: &Limits) -> KindResult<PointTable> {
    // Every line may be a point: the count of lines bounds what the table will hold.
    let lines = bytes.iter().filter(|&&b| b == b'\n').count() + 1;
    let estimate = (bytes.len() as u64).saturating_add(times(lines, row_bytes(limits)));
    limits.check(estimate, || {
        format!(
            "{lines} lines, each a possible point of {} bytes (its coordinates, twice, and \
             the pipeline's share)",
            row_bytes(limits)
        )
    })?;
    let mut dims = 0usize;
    let mut data = Vec::new();
    let mut seen_content = false;
    let mut row = [0.0f64; 3];
    for (k, raw) in bytes.split(|&b| b == b'\n').enumerate() {
        let line_no = k + 1;
        let line_error = |reason: String| ErrorKind::Line {
            line: line_no,
            reason,
        };
        let line = std::str::from_utf8(raw).map_err(|_| line_error("not UTF-8 text".to_owned()))?;
        let line = line.split('#').next().unwrap_or_default();
        let mut count = 0usize;
        let mut numbers = 0usize;
        let mut first_bad: Option<&str> = None;
        for token in line.split(is_separator).filter(|t| !t.is_empty()) {
            match token.parse::<f64>() {
                Ok(v) => {
                    if count < 3 {
                        row[count] = v;
                    }
                    numbers += 1;
                }
                Err(_) => {
                    first_bad.get_or_insert(token);
                }
            }
            count += 1;
        }
        if count == 0 {
            continue;
        }
        let header_allowed = !seen_content;
        seen_content = true;
        if let Some(bad) = first_bad {
            // Only a row of names is a header: a row mixing numbers and other text is a
            // data row with a typo, not to be dropped silently.
            if header_allowed && numbers == 0 {
                continue;
            }
            let reason = if header_allowed {
                format!(
                    "{bad:?} is not a number; the first row has {numbers} numbers among its \
                     {count} values, so it is data, not a header (a header holds only names)"
                )
            } else {
                format!("{bad:?} is not a number")
            };
            return Err(line_error(reason));
        }
        if dims == 0 {
            if count != 2 && count != 3 {
                return Err(line_error(format!(
                    "{count} values; a point has 2 or 3 coordinates"
                )));
            }
            dims = count;
        } else if count != dims {
            return Err(line_error(format!(
                "{count} values, the first row has {dims}"
            )));
        }
        data.extend_from_slice(&row[..dims]);
    }
    if dims == 0 {
        return Err(ErrorKind::Unusable("no data rows".to_owned()));
    }
    Ok(PointTable { dims, data })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn reads_common_layouts() {
        let t = parse_csv_points(b"# points\nx,y\n1,2\n3.5, -4\n\n5;6 # trailing\n").unwrap();
        assert_eq!(t.dims, 2);
        assert_eq!(t.data, vec![1.0, 2.0, 3.5, -4.0, 5.0, 6.0]);
        let t = parse_csv_points(b"1 2 3\r\n4\t5\t6\r\n").unwrap();
        assert_eq!(t.dims, 3);
        assert_eq!(t.len(), 2);
    }

    #[test]
    fn errors_name_the_line() {
        let e = parse_csv_points(b"x,y\n1,2\n3,4,5\n").unwrap_err();
        assert!(matches!(e.kind, ErrorKind::Line { line: 3, .. }), "{e}");
        let e = parse_csv_points(b"1,2\n3,abc\n").unwrap_err();
        assert!(
            e.to_string().contains("line 2") && e.to_string().contains("abc"),
            "{e}"
        );
        assert!(parse_csv_points(b"1,2,3,4\n").is_err());
        assert!(parse_csv_points(b"# nothing\n").is_err());
        assert!(parse_csv_points(b"x,y\nu,v\n").is_err());
    }

    #[test]
    fn a_mistyped_first_row_is_an_error_not_a_header() {
        let e = parse_csv_points(b"1.0,2.O,3\n4,5,6\n").unwrap_err();
        assert!(matches!(e.kind, ErrorKind::Line { line: 1, .. }), "{e}");
        assert!(e.to_string().contains("\"2.O\""), "{e}");
        // A header of names only is still skipped.
        assert_eq!(parse_csv_points(b"x;y;z\n4,5,6\n").unwrap().len(), 1);
    }
}

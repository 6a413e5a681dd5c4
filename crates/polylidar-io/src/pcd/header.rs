//! PCD header parsing (v0.7, tolerant of v0.6/v0.5 files).

use crate::error::{ErrorKind, KindResult};

/// Numeric type of a PCD field (`TYPE` letter and `SIZE`).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum ScalarType {
    /// `I 1`
    I8,
    /// `I 2`
    I16,
    /// `I 4`
    I32,
    /// `I 8`
    I64,
    /// `U 1`
    U8,
    /// `U 2`
    U16,
    /// `U 4`
    U32,
    /// `U 8`
    U64,
    /// `F 4`
    F32,
    /// `F 8`
    F64,
}

impl ScalarType {
    /// The type for a `TYPE` letter and a `SIZE` in bytes, if valid.
    pub fn from_letter_size(letter: char, size: usize) -> Option<Self> {
        Some(match (letter, size) {
            ('I', 1) => ScalarType::I8,
            ('I', 2) => ScalarType::I16,
            ('I', 4) => ScalarType::I32,
            ('I', 8) => ScalarType::I64,
            ('U', 1) => ScalarType::U8,
            ('U', 2) => ScalarType::U16,
            ('U', 4) => ScalarType::U32,
            ('U', 8) => ScalarType::U64,
            ('F', 4) => ScalarType::F32,
            ('F', 8) => ScalarType::F64,
            _ => return None,
        })
    }

    /// Size in bytes.
    pub fn size(self) -> usize {
        match self {
            ScalarType::I8 | ScalarType::U8 => 1,
            ScalarType::I16 | ScalarType::U16 => 2,
            ScalarType::I32 | ScalarType::U32 | ScalarType::F32 => 4,
            ScalarType::I64 | ScalarType::U64 | ScalarType::F64 => 8,
        }
    }
}

/// How the point data follows the header.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum PcdEncoding {
    /// One text line per point.
    Ascii,
    /// Raw little-endian records, point after point.
    #[default]
    Binary,
    /// LZF-compressed, field by field (structure of arrays).
    BinaryCompressed,
}

/// One `FIELDS` entry.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct PcdField {
    /// Field name (`x`, `intensity`, `rgb`, …).
    pub name: String,
    /// Numeric type.
    pub ty: ScalarType,
    /// Elements per point (`COUNT`).
    pub count: usize,
    /// Byte offset of the field inside one point record.
    pub offset: usize,
}

/// A parsed PCD header.
#[derive(Debug, Clone, PartialEq)]
pub struct PcdHeader {
    /// `VERSION` as written (e.g. `0.7`, `.7`), empty if absent.
    pub version: String,
    /// The fields, in record order.
    pub fields: Vec<PcdField>,
    /// `WIDTH` (columns).
    pub width: usize,
    /// `HEIGHT` (rows; 1 for unorganized clouds).
    pub height: usize,
    /// `VIEWPOINT` (tx ty tz qw qx qy qz).
    pub viewpoint: [f64; 7],
    /// Data encoding.
    pub encoding: PcdEncoding,
    /// Bytes of one point record.
    pub point_size: usize,
    /// Byte offset in the file where point data starts.
    pub data_start: usize,
}

impl PcdHeader {
    /// Number of points (`WIDTH × HEIGHT`).
    pub fn points(&self) -> usize {
        self.width * self.height
    }

    /// The field called `name`.
    pub fn field(&self, name: &str) -> Option<&PcdField> {
        self.fields.iter().find(|f| f.name == name)
    }
}

fn malformed(line: usize, reason: impl Into<String>) -> ErrorKind {
    ErrorKind::Header {
        line,
        reason: reason.into(),
    }
}

fn parse_usize_list(line: usize, keyword: &str, items: &[&str]) -> KindResult<Vec<usize>> {
    items
        .iter()
        .map(|t| {
            t.parse::<usize>()
                .map_err(|_| malformed(line, format!("{keyword} value {t:?} is not a count")))
        })
        .collect()
}

fn parse_one_usize(line: usize, keyword: &str, items: &[&str]) -> KindResult<usize> {
    match items {
        [one] => one
            .parse::<usize>()
            .map_err(|_| malformed(line, format!("{keyword} value {one:?} is not a count"))),
        _ => Err(malformed(
            line,
            format!("{keyword} needs one value, found {}", items.len()),
        )),
    }
}

#[derive(Default)]
struct RawHeader {
    version: String,
    names: Option<Vec<String>>,
    sizes: Option<Vec<usize>>,
    types: Option<Vec<char>>,
    counts: Option<Vec<usize>>,
    width: Option<usize>,
    height: Option<usize>,
    points: Option<usize>,
    viewpoint: Option<[f64; 7]>,
}

/// Parses the header of a PCD file and finds where the data starts.
pub fn parse_header(bytes: &[u8]) -> KindResult<PcdHeader> {
    let mut raw = RawHeader::default();
    let mut pos = 0;
    let mut line_no = 0;
    loop {
        if pos >= bytes.len() {
            return Err(ErrorKind::BadHeader(
                "no DATA line: the header never ends".to_owned(),
            ));
        }
        line_no += 1;
        let end = bytes[pos..]
            .iter()
            .position(|&b| b == b'\n')
            .map_or(bytes.len(), |k| pos + k);
        let line_bytes = &bytes[pos..end];
        pos = (end + 1).min(bytes.len());
        let line = std::str::from_utf8(line_bytes)
            .map_err(|_| malformed(line_no, "not UTF-8 text"))?
            .trim();
        if line.is_empty() || line.starts_with('#') {
            continue;
        }
        let mut tokens = line.split_ascii_whitespace();
        let keyword = tokens.next().unwrap_or_default();
        let items: Vec<&str> = tokens.collect();
        if keyword == "DATA" {
            let encoding = match items.as_slice() {
                ["ascii"] => PcdEncoding::Ascii,
                ["binary"] => PcdEncoding::Binary,
                ["binary_compressed"] => PcdEncoding::BinaryCompressed,
                _ => {
                    return Err(ErrorKind::Unsupported {
                        what: "DATA kind",
                        value: items.join(" "),
                    });
                }
            };
            return finish(raw, encoding, pos);
        }
        apply_keyword(&mut raw, line_no, keyword, &items)?;
    }
}

fn apply_keyword(
    raw: &mut RawHeader,
    line: usize,
    keyword: &str,
    items: &[&str],
) -> KindResult<()> {
    match keyword {
        "VERSION" => raw.version = items.join(" "),
        "FIELDS" | "COLUMNS" => {
            if items.is_empty() {
                return Err(malformed(line, "FIELDS lists no field"));
            }
            raw.names = Some(items.iter().map(|s| (*s).to_owned()).collect());
        }
        "SIZE" => raw.sizes = Some(parse_usize_list(line, keyword, items)?),
        "COUNT" => raw.counts = Some(parse_usize_list(line, keyword, items)?),
        "TYPE" => {
            let types = items
                .iter()
                .map(|t| match t.as_bytes() {
                    [c @ (b'I' | b'U' | b'F')] => Ok(char::from(*c)),
                    _ => Err(malformed(line, format!("TYPE {t:?} is not I, U or F"))),
                })
                .collect::<KindResult<Vec<char>>>()?;
            raw.types = Some(types);
        }
        "WIDTH" => raw.width = Some(parse_one_usize(line, keyword, items)?),
        "HEIGHT" => raw.height = Some(parse_one_usize(line, keyword, items)?),
        "POINTS" => raw.points = Some(parse_one_usize(line, keyword, items)?),
        "VIEWPOINT" => {
            let values: Vec<f64> = items
                .iter()
                .map(|t| t.parse::<f64>())
                .collect::<Result<_, _>>()
                .map_err(|_| malformed(line, "VIEWPOINT values are not numbers"))?;
            let vp: [f64; 7] = values
                .try_into()
                .map_err(|_| malformed(line, "VIEWPOINT needs 7 numbers"))?;
            raw.viewpoint = Some(vp);
        }
        other => return Err(malformed(line, format!("unknown keyword {other:?}"))),
    }
    Ok(())
}

fn finish(raw: RawHeader, encoding: PcdEncoding, data_start: usize) -> KindResult<PcdHeader> {
    let bad = |s: String| ErrorKind::BadHeader(s);
    let names = raw.names.ok_or_else(|| bad("no FIELDS line".to_owned()))?;
    let n = names.len();
    let sizes = raw.sizes.ok_or_else(|| bad("no SIZE line".to_owned()))?;
    let types = raw.types.unwrap_or_else(|| vec!['F'; n]);
    let counts = raw.counts.unwrap_or_else(|| vec![1; n]);
    if sizes.len() != n || types.len() != n || counts.len() != n {
        return Err(bad(format!(
            "{n} FIELDS but {} SIZE, {} TYPE and {} COUNT entries",
            sizes.len(),
            types.len(),
            counts.len()
        )));
    }
    let mut fields = Vec::with_capacity(n);
    let mut offset = 0usize;
    for (((name, &size), &letter), &count) in names.into_iter().zip(&sizes).zip(&types).zip(&counts)
    {
        let ty =
            ScalarType::from_letter_size(letter, size).ok_or_else(|| ErrorKind::Unsupported {
                what: "field type",
                value: format!("{name}: TYPE {letter} SIZE {size}"),
            })?;
        if count == 0 {
            return Err(bad(format!("field {name} has COUNT 0")));
        }
        let bytes = count
            .checked_mul(size)
            .ok_or_else(|| bad(format!("field {name} is too large")))?;
        fields.push(PcdField {
            name,
            ty,
            count,
            offset,
        });
        offset = offset
            .checked_add(bytes)
            .ok_or_else(|| bad("point record is too large".to_owned()))?;
    }
    let (width, height) = match (raw.width, raw.height, raw.points) {
        (Some(w), h, _) => (w, h.unwrap_or(1)),
        (None, None, Some(p)) => (p, 1),
        _ => return Err(bad("no WIDTH line".to_owned())),
    };
    let total = width
        .checked_mul(height)
        .ok_or_else(|| bad(format!("WIDTH {width} × HEIGHT {height} overflows")))?;
    if let Some(p) = raw.points
        && p != total
    {
        return Err(bad(format!(
            "POINTS {p} differs from WIDTH {width} × HEIGHT {height}"
        )));
    }
    Ok(PcdHeader {
        version: raw.version,
        fields,
        width,
        height,
        viewpoint: raw.viewpoint.unwrap_or([0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0]),
        encoding,
        point_size: offset,
        data_start,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn parses_minimal_v07_header() {
        let text = b"# c\nVERSION 0.7\nFIELDS x y z rgb\nSIZE 4 4 4 4\nTYPE F F F U\nCOUNT 1 1 1 1\nWIDTH 3\nHEIGHT 2\nVIEWPOINT 0 0 0 1 0 0 0\nPOINTS 6\nDATA binary\nXYZ";
        let h = parse_header(text).unwrap();
        assert_eq!(h.fields.len(), 4);
        assert_eq!(h.point_size, 16);
        assert_eq!(h.field("rgb").unwrap().offset, 12);
        assert_eq!((h.width, h.height), (3, 2));
        assert_eq!(h.encoding, PcdEncoding::Binary);
        assert_eq!(&text[h.data_start..], b"XYZ");
    }

    #[test]
    fn tolerates_old_headers() {
        let h =
            parse_header(b"VERSION .6\nCOLUMNS x y z\nSIZE 4 4 4\nPOINTS 5\nDATA ascii\n").unwrap();
        assert_eq!((h.width, h.height), (5, 1));
        assert!(
            h.fields
                .iter()
                .all(|f| f.ty == ScalarType::F32 && f.count == 1)
        );
    }

    #[test]
    fn header_errors_name_the_line() {
        let err =
            parse_header(b"VERSION 0.7\nFIELDS x y z\nSIZE 4 four 4\nDATA ascii\n").unwrap_err();
        assert!(matches!(err, ErrorKind::Header { line: 3, .. }), "{err}");
        let err = parse_header(b"FIELDS x\nSIZE 4\nWIDTH 2\nDATA zip\n").unwrap_err();
        assert!(err.to_string().contains("DATA kind"), "{err}");
        let err = parse_header(b"FIELDS x\nSIZE 4\nWIDTH 2\nPOINTS 3\nDATA ascii\n").unwrap_err();
        assert!(err.to_string().contains("POINTS 3"), "{err}");
        assert!(parse_header(b"FIELDS x\nSIZE 3\nWIDTH 1\nDATA ascii\n").is_err());
        assert!(parse_header(b"FIELDS x\nSIZE 4\n").is_err());
    }
}

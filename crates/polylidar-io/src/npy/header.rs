//! The NPY preamble and its Python-literal header dictionary.

use crate::error::{ErrorKind, KindResult, take};

/// Element type of an NPY array (the `descr` entry without byte order).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Dtype {
    /// `b1` (bool)
    Bool,
    /// `i1`
    I8,
    /// `i2`
    I16,
    /// `i4`
    I32,
    /// `i8`
    I64,
    /// `u1`
    U8,
    /// `u2`
    U16,
    /// `u4`
    U32,
    /// `u8`
    U64,
    /// `f4`
    F32,
    /// `f8`
    F64,
}

impl Dtype {
    /// Bytes per element.
    pub fn size(self) -> usize {
        match self {
            Dtype::Bool | Dtype::I8 | Dtype::U8 => 1,
            Dtype::I16 | Dtype::U16 => 2,
            Dtype::I32 | Dtype::U32 | Dtype::F32 => 4,
            Dtype::I64 | Dtype::U64 | Dtype::F64 => 8,
        }
    }
}

/// What the header says about the array.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct NpyHeader {
    /// Element type.
    pub dtype: Dtype,
    /// Whether elements are stored big-endian.
    pub big_endian: bool,
    /// Whether the data is in Fortran (column-major) order.
    pub fortran_order: bool,
    /// Array shape (empty for a 0-d array).
    pub shape: Vec<usize>,
    /// Byte offset where the data starts.
    pub data_start: usize,
}

const MAGIC: &[u8] = b"\x93NUMPY";

/// Parses the preamble and header dictionary of NPY bytes.
pub fn parse_header(bytes: &[u8]) -> KindResult<NpyHeader> {
    let pre = take(bytes, 0, 8, "NPY magic and version")?;
    if &pre[..6] != MAGIC {
        return Err(ErrorKind::BadHeader(
            "missing the \\x93NUMPY magic: not an NPY file".to_owned(),
        ));
    }
    let (len, start) = match pre[6] {
        1 => {
            let l = take(bytes, 8, 2, "NPY v1 header length")?;
            (usize::from(u16::from_le_bytes([l[0], l[1]])), 10)
        }
        2 | 3 => {
            let l = take(bytes, 8, 4, "NPY v2 header length")?;
            (u32::from_le_bytes([l[0], l[1], l[2], l[3]]) as usize, 12)
        }
        v => {
            return Err(ErrorKind::Unsupported {
                what: "NPY version",
                value: format!("{v}.{}", pre[7]),
            });
        }
    };
    let text = take(bytes, start, len, "NPY header dictionary")?;
    let text = std::str::from_utf8(text)
        .map_err(|_| ErrorKind::BadHeader("header dictionary is not text".to_owned()))?;
    let dict = parse_dict(text)?;
    let descr = dict.descr.ok_or_else(|| missing("descr"))?;
    let (dtype, big_endian) = parse_descr(&descr)?;
    Ok(NpyHeader {
        dtype,
        big_endian,
        fortran_order: dict.fortran_order.ok_or_else(|| missing("fortran_order"))?,
        shape: dict.shape.ok_or_else(|| missing("shape"))?,
        data_start: start + len,
    })
}

fn missing(key: &str) -> ErrorKind {
    ErrorKind::BadHeader(format!("header dictionary has no '{key}' entry"))
}

fn parse_descr(descr: &str) -> KindResult<(Dtype, bool)> {
    let unsupported = || ErrorKind::Unsupported {
        what: "dtype",
        value: descr.to_owned(),
    };
    let mut chars = descr.chars();
    let order = chars.next().ok_or_else(unsupported)?;
    let big_endian = match order {
        '<' | '|' => false,
        '>' => true,
        '=' => cfg!(target_endian = "big"),
        _ => return Err(unsupported()),
    };
    let dtype = match chars.as_str() {
        "b1" | "?" => Dtype::Bool,
        "i1" => Dtype::I8,
        "i2" => Dtype::I16,
        "i4" => Dtype::I32,
        "i8" => Dtype::I64,
        "u1" => Dtype::U8,
        "u2" => Dtype::U16,
        "u4" => Dtype::U32,
        "u8" => Dtype::U64,
        "f4" => Dtype::F32,
        "f8" => Dtype::F64,
        _ => return Err(unsupported()),
    };
    Ok((dtype, big_endian))
}

#[derive(Default)]
struct Dict {
    descr: Option<String>,
    fortran_order: Option<bool>,
    shape: Option<Vec<usize>>,
}

/// A tiny cursor over the Python literal `{'descr': '<f8', 'fortran_order': False, 'shape': (2, 3), }`.
struct Cursor<'a> {
    s: &'a [u8],
    pos: usize,
}

impl<'a> Cursor<'a> {
    fn skip_ws(&mut self) {
        while self.s.get(self.pos).is_some_and(u8::is_ascii_whitespace) {
            self.pos += 1;
        }
    }

    fn peek(&mut self) -> Option<u8> {
        self.skip_ws();
        self.s.get(self.pos).copied()
    }

    fn error(&self, what: &str) -> ErrorKind {
        ErrorKind::BadHeader(format!(
            "header dictionary: {what} at character {}",
            self.pos + 1
        ))
    }

    fn expect(&mut self, c: u8) -> KindResult<()> {
        if self.peek() == Some(c) {
            self.pos += 1;
            Ok(())
        } else {
            Err(self.error(&format!("expected '{}'", char::from(c))))
        }
    }

    fn string(&mut self) -> KindResult<String> {
        let quote = self.peek().filter(|q| *q == b'\'' || *q == b'"');
        let Some(quote) = quote else {
            return Err(self.error("expected a quoted string"));
        };
        self.pos += 1;
        let start = self.pos;
        while self.s.get(self.pos).is_some_and(|&c| c != quote) {
            self.pos += 1;
        }
        if self.pos >= self.s.len() {
            return Err(self.error("unterminated string"));
        }
        let value = String::from_utf8_lossy(&self.s[start..self.pos]).into_owned();
        self.pos += 1;
        Ok(value)
    }

    fn word(&mut self) -> &'a [u8] {
        self.skip_ws();
        let s: &'a [u8] = self.s;
        let start = self.pos;
        while s.get(self.pos).is_some_and(u8::is_ascii_alphanumeric) {
            self.pos += 1;
        }
        &s[start..self.pos]
    }

    fn tuple(&mut self) -> KindResult<Vec<usize>> {
        self.expect(b'(')?;
        let mut dims = Vec::new();
        loop {
            if self.peek() == Some(b')') {
                self.pos += 1;
                return Ok(dims);
            }
            let w = self.word();
            let dim = std::str::from_utf8(w)
                .ok()
                .and_then(|t| t.strip_suffix('L').unwrap_or(t).parse::<usize>().ok())
                .ok_or_else(|| self.error("shape entry is not a non-negative integer"))?;
            dims.push(dim);
            match self.peek() {
                Some(b',') => self.pos += 1,
                Some(b')') => {}
                _ => return Err(self.error("expected ',' or ')' in shape")),
            }
        }
    }
}

fn parse_dict(text: &str) -> KindResult<Dict> {
    let mut c = Cursor {
        s: text.as_bytes(),
        pos: 0,
    };
    let mut dict = Dict::default();
    c.expect(b'{')?;
    loop {
        if c.peek() == Some(b'}') {
            return Ok(dict);
        }
        let key = c.string()?;
        c.expect(b':')?;
        match key.as_str() {
            "descr" => {
                if c.peek() == Some(b'[') {
                    return Err(ErrorKind::Unsupported {
                        what: "dtype",
                        value: "structured (record) array".to_owned(),
                    });
                }
                dict.descr = Some(c.string()?);
            }
            "fortran_order" => {
                dict.fortran_order = Some(match c.word() {
                    b"True" => true,
                    b"False" => false,
                    _ => return Err(c.error("fortran_order is not True or False")),
                });
            }
            "shape" => dict.shape = Some(c.tuple()?),
            other => return Err(c.error(&format!("unexpected key '{other}'"))),
        }
        match c.peek() {
            Some(b',') => c.pos += 1,
            Some(b'}') => {}
            _ => return Err(c.error("expected ',' or '}'")),
        }
    }
}

/// The header bytes (preamble + padded dictionary) for an array written by this crate.
pub fn encode_header(descr: &str, shape: &[usize]) -> Vec<u8> {
    let dims = match shape {
        [one] => format!("({one},)"),
        _ => format!(
            "({})",
            shape
                .iter()
                .map(usize::to_string)
                .collect::<Vec<_>>()
                .join(", ")
        ),
    };
    let mut dict = format!("{{'descr': '{descr}', 'fortran_order': False, 'shape': {dims}, }}");
    // Pad with spaces and a final newline so the data starts on a 64-byte boundary.
    let preamble = if dict.len() + 11 > usize::from(u16::MAX) {
        12
    } else {
        10
    };
    let total = (preamble + dict.len() + 1).div_ceil(64) * 64;
    while preamble + dict.len() + 1 < total {
        dict.push(' ');
    }
    dict.push('\n');
    let mut out = Vec::with_capacity(total);
    out.extend_from_slice(MAGIC);
    if preamble == 10 {
        out.extend_from_slice(&[1, 0]);
        // The branch above guarantees the length fits in u16.
        out.extend_from_slice(&(dict.len() as u16).to_le_bytes());
    } else {
        out.extend_from_slice(&[2, 0]);
        out.extend_from_slice(&(dict.len() as u32).to_le_bytes());
    }
    out.extend_from_slice(dict.as_bytes());
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn parses_numpy_written_header() {
        let mut bytes = encode_header("<f8", &[120, 212, 3]);
        assert_eq!(bytes.len() % 64, 0);
        bytes.extend_from_slice(&[0; 8]);
        let h = parse_header(&bytes).unwrap();
        assert_eq!(h.shape, vec![120, 212, 3]);
        assert_eq!(h.dtype, Dtype::F64);
        assert!(!h.big_endian && !h.fortran_order);
        assert_eq!(h.data_start % 64, 0);
    }

    #[test]
    fn dict_variants() {
        let d =
            parse_dict("{\"shape\": (5,), \"fortran_order\": True, \"descr\": \">i2\"}").unwrap();
        assert_eq!(d.shape, Some(vec![5]));
        assert_eq!(d.fortran_order, Some(true));
        assert_eq!(parse_descr(">i2").unwrap(), (Dtype::I16, true));
        assert_eq!(parse_dict("{'shape': ()}").unwrap().shape, Some(vec![]));
        assert!(parse_dict("{'shape': (3, -1)}").is_err());
        assert!(parse_dict("{'descr': [('x', '<f4')]}").is_err());
        assert!(parse_descr("<c16").is_err());
        assert!(parse_dict("{'shape': (3,").is_err());
    }
}

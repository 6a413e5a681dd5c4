//! Decoding PCD point data (ascii, binary, binary_compressed) into columns of `f64`.

use std::borrow::Cow;

use super::header::{PcdEncoding, PcdHeader, ScalarType};
use crate::error::{ErrorKind, KindResult, take};
use crate::lzf;

/// One scalar to extract from every point: element `element` of field `field`.
#[derive(Debug, Clone, Copy)]
pub struct Wanted {
    /// Index into `PcdHeader::fields`.
    pub field: usize,
    /// Element inside the field (`0..count`).
    pub element: usize,
}

/// Point data whose extent has been checked against the header, ready to decode.
pub struct Data<'a> {
    header: &'a PcdHeader,
    bytes: &'a [u8],
    /// The record block (binary and binary_compressed); `None` for ascii.
    block: Option<Cow<'a, [u8]>>,
}

/// Checks that the data following the header can hold `WIDTH × HEIGHT` points (and
/// decompresses it), so that callers may allocate per-point storage safely.
///
/// `budget` is called once the extent of the data has been checked and before anything is
/// allocated, with the bytes the decompressed block will take (0 when nothing is
/// decompressed); its error stops the read.
pub fn prepare<'a>(
    header: &'a PcdHeader,
    bytes: &'a [u8],
    budget: impl FnOnce(u64) -> KindResult<()>,
) -> KindResult<Data<'a>> {
    let block = match header.encoding {
        PcdEncoding::Ascii => {
            let available = bytes.len().saturating_sub(header.data_start);
            let tokens: usize = header.fields.iter().map(|f| f.count).sum();
            // Each point line holds `tokens` numbers and as many separators or newline.
            let needed = header.points().saturating_mul(tokens.saturating_mul(2));
            if needed > available + 1 {
                return Err(ErrorKind::Truncated {
                    what: "ascii point data",
                    offset: header.data_start,
                    needed,
                    available,
                });
            }
            budget(0)?;
            None
        }
        PcdEncoding::Binary | PcdEncoding::BinaryCompressed => {
            Some(data_block(header, bytes, budget)?)
        }
    };
    Ok(Data {
        header,
        bytes,
        block,
    })
}

impl Data<'_> {
    /// Calls `sink(slot, point, value)` for every point and every `wanted[slot]`.
    pub fn decode(&self, wanted: &[Wanted], sink: impl FnMut(usize, usize, f64)) -> KindResult<()> {
        match &self.block {
            None => decode_ascii(self.header, self.bytes, wanted, sink),
            Some(block) => {
                decode_binary(self.header, block, wanted, sink);
                Ok(())
            }
        }
    }
}

fn data_size(header: &PcdHeader) -> KindResult<usize> {
    header
        .points()
        .checked_mul(header.point_size)
        .ok_or_else(|| {
            ErrorKind::BadHeader(format!(
                "{} points of {} bytes overflow",
                header.points(),
                header.point_size
            ))
        })
}

/// The raw data block: borrowed for `binary`, decompressed for `binary_compressed`.
fn data_block<'a>(
    header: &PcdHeader,
    bytes: &'a [u8],
    budget: impl FnOnce(u64) -> KindResult<()>,
) -> KindResult<Cow<'a, [u8]>> {
    let size = data_size(header)?;
    let start = header.data_start;
    if header.encoding == PcdEncoding::Binary {
        let block = take(bytes, start, size, "binary point data")?;
        budget(0)?;
        return Ok(Cow::Borrowed(block));
    }
    let sizes = take(bytes, start, 8, "compressed block sizes")?;
    let compressed = u32::from_le_bytes([sizes[0], sizes[1], sizes[2], sizes[3]]) as usize;
    let uncompressed = u32::from_le_bytes([sizes[4], sizes[5], sizes[6], sizes[7]]) as usize;
    if uncompressed != size {
        return Err(ErrorKind::Corrupt(format!(
            "uncompressed size {uncompressed} differs from {} points × {} bytes = {size}",
            header.points(),
            header.point_size
        )));
    }
    let packed = take(bytes, start + 8, compressed, "LZF compressed data")?;
    lzf::check_expansion(packed.len(), size)?;
    budget(size as u64)?;
    Ok(Cow::Owned(lzf::decompress(packed, size)?))
}

/// Where one scalar column lies in the data block, and how it is stored.
#[derive(Clone, Copy)]
struct Column {
    start: usize,
    stride: usize,
    ty: ScalarType,
}

fn column(header: &PcdHeader, w: Wanted) -> Column {
    let f = &header.fields[w.field];
    let size = f.ty.size();
    match header.encoding {
        // Structure of arrays: each field's block holds `count` values per point.
        PcdEncoding::BinaryCompressed => Column {
            start: header.points() * f.offset + w.element * size,
            stride: f.count * size,
            ty: f.ty,
        },
        _ => Column {
            start: f.offset + w.element * size,
            stride: header.point_size,
            ty: f.ty,
        },
    }
}

fn scan<const S: usize>(
    data: &[u8],
    stride: usize,
    n: usize,
    conv: impl Fn([u8; S]) -> f64,
    mut f: impl FnMut(usize, f64),
) {
    for (i, chunk) in data.chunks(stride).take(n).enumerate() {
        let mut b = [0u8; S];
        b.copy_from_slice(&chunk[..S]);
        f(i, conv(b));
    }
}

fn decode_binary(
    header: &PcdHeader,
    block: &[u8],
    wanted: &[Wanted],
    mut sink: impl FnMut(usize, usize, f64),
) {
    let n = header.points();
    if n == 0 {
        return;
    }
    for (slot, &w) in wanted.iter().enumerate() {
        let col = column(header, w);
        // `block` holds n × point_size bytes, so every value of the column lies inside it.
        let data = &block[col.start..];
        let (stride, put) = (col.stride, |i: usize, v: f64| sink(slot, i, v));
        match col.ty {
            ScalarType::I8 => scan(data, stride, n, |b| f64::from(i8::from_le_bytes(b)), put),
            ScalarType::I16 => scan(data, stride, n, |b| f64::from(i16::from_le_bytes(b)), put),
            ScalarType::I32 => scan(data, stride, n, |b| f64::from(i32::from_le_bytes(b)), put),
            ScalarType::I64 => scan(data, stride, n, |b| i64::from_le_bytes(b) as f64, put),
            ScalarType::U8 => scan(data, stride, n, |b| f64::from(u8::from_le_bytes(b)), put),
            ScalarType::U16 => scan(data, stride, n, |b| f64::from(u16::from_le_bytes(b)), put),
            ScalarType::U32 => scan(data, stride, n, |b| f64::from(u32::from_le_bytes(b)), put),
            ScalarType::U64 => scan(data, stride, n, |b| u64::from_le_bytes(b) as f64, put),
            ScalarType::F32 => scan(data, stride, n, |b| f64::from(f32::from_le_bytes(b)), put),
            ScalarType::F64 => scan(data, stride, n, f64::from_le_bytes, put),
        }
    }
}

fn decode_ascii(
    header: &PcdHeader,
    bytes: &[u8],
    wanted: &[Wanted],
    mut sink: impl FnMut(usize, usize, f64),
) -> KindResult<()> {
    // Flat token index of every wanted scalar.
    let mut first_token = Vec::with_capacity(header.fields.len());
    let mut tokens_per_point = 0usize;
    for f in &header.fields {
        first_token.push(tokens_per_point);
        tokens_per_point += f.count;
    }
    let n = header.points();
    let data = bytes.get(header.data_start..).unwrap_or_default();
    if n == 0 {
        if data.iter().all(u8::is_ascii_whitespace) {
            return Ok(());
        }
        return Err(ErrorKind::Shape(
            "DATA ascii has point lines, the header declares 0 points".to_owned(),
        ));
    }
    // Whether each token is an `F 4` value; `prepare` checked that the data has room for
    // at least one line of `tokens_per_point` values.
    let is_f32: Vec<bool> = header
        .fields
        .iter()
        .flat_map(|f| std::iter::repeat_n(f.ty == ScalarType::F32, f.count))
        .collect();
    let targets: Vec<(usize, usize)> = wanted
        .iter()
        .enumerate()
        .map(|(slot, w)| (first_token[w.field] + w.element, slot))
        .collect();
    let header_lines = bytes[..header.data_start.min(bytes.len())]
        .iter()
        .filter(|&&b| b == b'\n')
        .count();
    let mut point = 0usize;
    // Grows with the tokens really present, never with what the header claims.
    let mut values: Vec<f64> = Vec::new();
    for (k, raw_line) in data.split(|&b| b == b'\n').enumerate() {
        let line_no = header_lines + k + 1;
        let line = std::str::from_utf8(raw_line)
            .map_err(|_| ErrorKind::Line {
                line: line_no,
                reason: "not UTF-8 text".to_owned(),
            })?
            .trim();
        if line.is_empty() {
            continue;
        }
        if point == n {
            return Err(ErrorKind::Line {
                line: line_no,
                reason: format!("more point lines than the {n} the header declares"),
            });
        }
        let mut count = 0usize;
        values.clear();
        for (k, token) in line.split_ascii_whitespace().enumerate() {
            if let Some(&single) = is_f32.get(k) {
                // An `F 4` value is the f32 nearest to its text, as the writer meant it.
                let value = if single {
                    token.parse::<f32>().map(f64::from)
                } else {
                    token.parse::<f64>()
                };
                values.push(value.map_err(|_| ErrorKind::Line {
                    line: line_no,
                    reason: format!("value {} ({token:?}) is not a number", k + 1),
                })?);
            }
            count += 1;
        }
        if count != tokens_per_point {
            return Err(ErrorKind::Line {
                line: line_no,
                reason: format!("{count} values, the fields need {tokens_per_point}"),
            });
        }
        for &(token, slot) in &targets {
            sink(slot, point, values[token]);
        }
        point += 1;
    }
    if point != n {
        return Err(ErrorKind::Shape(format!(
            "DATA ascii has {point} point lines, the header declares {n}"
        )));
    }
    Ok(())
}

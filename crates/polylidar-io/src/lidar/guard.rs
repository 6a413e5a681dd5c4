//! Checks of a LAS/LAZ file's header against the file, made before the `las` crate reads
//! it: each field that does not fit is reported by name and byte position, and sizes that
//! would make the decoder allocate gigabytes (a corrupt extended VLR length or LAZ chunk
//! count) are refused before they are.

use std::io::{Read, Seek, SeekFrom};

use crate::error::{ErrorKind, KindResult};

/// Bytes of the public header block of LAS 1.0–1.2 (1.3 adds 8, 1.4 adds 148).
const MIN_HEADER: usize = 227;
/// Bytes of the LAS 1.4 public header block.
const HEADER_14: usize = 375;
/// Bytes of a variable-length record's header.
const VLR_HEADER: u64 = 54;
/// Bytes of an extended variable-length record's header.
const EVLR_HEADER: u64 = 60;

fn u16_at(b: &[u8], at: usize) -> u16 {
    u16::from_le_bytes([b[at], b[at + 1]])
}

fn u32_at(b: &[u8], at: usize) -> u32 {
    u32::from_le_bytes([b[at], b[at + 1], b[at + 2], b[at + 3]])
}

fn u64_at(b: &[u8], at: usize) -> u64 {
    let mut a = [0u8; 8];
    a.copy_from_slice(&b[at..at + 8]);
    u64::from_le_bytes(a)
}

/// Reads up to `buf.len()` bytes at `pos`; returns how many were read.
fn read_at<R: Read + Seek>(r: &mut R, pos: u64, buf: &mut [u8]) -> std::io::Result<usize> {
    r.seek(SeekFrom::Start(pos))?;
    let mut filled = 0;
    while filled < buf.len() {
        match r.read(&mut buf[filled..])? {
            0 => break,
            n => filled += n,
        }
    }
    Ok(filled)
}

/// What the header says about the point data, once checked against the file.
#[derive(Debug, Clone, Copy)]
pub struct Layout {
    /// Point records the header declares.
    pub points: u64,
    /// Bytes of one (uncompressed) point record.
    pub record_len: u64,
    /// Whether the point data is LAZ-compressed.
    pub compressed: bool,
    /// Points per LAZ chunk, from the LASzip VLR (`None` when absent or variable).
    pub chunk_size: Option<u64>,
}

impl Layout {
    /// `first–last` point records of a batch, with the LAZ chunk(s) they fall in.
    pub fn describe(&self, first: u64, count: u64) -> String {
        let last = first + count.max(1) - 1;
        let mut text = if count <= 1 {
            format!("point record {first}")
        } else {
            format!("point records {first}–{last}")
        };
        if let Some(size) = self.chunk_size.filter(|_| self.compressed) {
            let (a, b) = (first / size, last / size);
            if a == b {
                text.push_str(&format!(" (LAZ chunk {a})"));
            } else {
                text.push_str(&format!(" (LAZ chunks {a}–{b})"));
            }
        }
        text
    }
}

fn bad(text: String) -> ErrorKind {
    ErrorKind::BadHeader(text)
}

/// Checks the header of `r` against its length and rewinds it.
pub fn check_header<R: Read + Seek>(r: &mut R) -> KindResult<Layout> {
    let len = r.seek(SeekFrom::End(0))?;
    let mut head = [0u8; HEADER_14];
    let got = read_at(r, 0, &mut head)?;
    if got < 4 || &head[..4] != b"LASF" {
        return Err(ErrorKind::Unsupported {
            what: "file signature",
            value: format!(
                "{:?} (a LAS file starts with \"LASF\")",
                String::from_utf8_lossy(&head[..got.min(4)])
            ),
        });
    }
    if got < MIN_HEADER {
        return Err(ErrorKind::Truncated {
            what: "the LAS public header block",
            offset: 0,
            needed: MIN_HEADER,
            available: got,
        });
    }
    let minor = head[25];
    let header_size = u64::from(u16_at(&head, 94));
    if header_size < MIN_HEADER as u64 || header_size > len {
        return Err(bad(format!(
            "header size (bytes 94–95) is {header_size}: it must be at least {MIN_HEADER} \
             and within the {len}-byte file"
        )));
    }
    let point_start = u64::from(u32_at(&head, 96));
    if point_start < header_size || point_start > len {
        return Err(bad(format!(
            "offset to point data (bytes 96–99) is {point_start}: it must lie between the \
             end of the {header_size}-byte header and the end of the {len}-byte file"
        )));
    }
    let format_byte = head[104];
    let compressed = format_byte & 0x80 != 0;
    let record_len = u64::from(u16_at(&head, 105));
    let legacy = u64::from(u32_at(&head, 107));
    // The `las` crate reads the LAS 1.4 fields of a 1.4 file whatever its header size
    // says, so they are checked on the same condition.
    let fields_14 = minor >= 4 && got == HEADER_14;
    let points = if fields_14 {
        legacy.max(u64_at(&head, 247))
    } else {
        legacy
    };
    let vlrs = u32_at(&head, 100);
    let chunk_size = check_vlrs(r, len, header_size, vlrs)?;
    if !compressed && points > 0 {
        let room = len - point_start;
        let needed = points.saturating_mul(record_len);
        if needed > room {
            return Err(bad(format!(
                "number of point records (bytes 107–110{}) is {points} records of {record_len} \
                 bytes from byte {point_start}, {needed} bytes, but the file ends after {} \
                 complete records",
                if minor >= 4 {
                    ", or 247–254 in LAS 1.4"
                } else {
                    ""
                },
                room.checked_div(record_len).unwrap_or(0)
            )));
        }
    }
    if fields_14 {
        check_evlrs(r, len, u64_at(&head, 235), u32_at(&head, 243))?;
    }
    if compressed {
        check_laz_chunks(r, len, point_start)?;
    }
    r.seek(SeekFrom::Start(0))?;
    Ok(Layout {
        points,
        record_len,
        compressed,
        chunk_size,
    })
}

/// Walks the VLRs: each must lie inside the file. Returns the LAZ chunk size of a LASzip
/// VLR, if there is one with a fixed size.
fn check_vlrs<R: Read + Seek>(
    r: &mut R,
    len: u64,
    start: u64,
    count: u32,
) -> KindResult<Option<u64>> {
    let mut pos = start;
    let mut chunk_size = None;
    for k in 0..count {
        let mut vlr = [0u8; VLR_HEADER as usize];
        if pos + VLR_HEADER > len || read_at(r, pos, &mut vlr)? < vlr.len() {
            return Err(bad(format!(
                "number of variable-length records (bytes 100–103) is {count}, but the \
                 {len}-byte file ends inside the header of record {k} at byte {pos}"
            )));
        }
        let data_len = u64::from(u16_at(&vlr, 20));
        if pos + VLR_HEADER + data_len > len {
            return Err(bad(format!(
                "variable-length record {k} at byte {pos} claims {data_len} bytes of data, \
                 past the end of the {len}-byte file"
            )));
        }
        if vlr[2..16].starts_with(b"laszip encoded") && u16_at(&vlr, 18) == 22204 {
            let mut data = [0u8; 16];
            if data_len >= 16 && read_at(r, pos + VLR_HEADER, &mut data)? == 16 {
                let size = u32_at(&data, 12);
                // u32::MAX marks variable-sized chunks.
                chunk_size = (size > 0 && size != u32::MAX).then_some(u64::from(size));
            }
        }
        pos += VLR_HEADER + data_len;
    }
    Ok(chunk_size)
}

fn check_evlrs<R: Read + Seek>(r: &mut R, len: u64, start: u64, count: u32) -> KindResult<()> {
    let mut pos = start;
    for k in 0..count {
        let mut evlr = [0u8; EVLR_HEADER as usize];
        if pos.saturating_add(EVLR_HEADER) > len || read_at(r, pos, &mut evlr)? < evlr.len() {
            break;
        }
        let size = u64_at(&evlr, 20);
        if size > len {
            return Err(bad(format!(
                "extended variable-length record {k} at byte {pos} claims {size} bytes in a \
                 file of {len}"
            )));
        }
        pos = pos + EVLR_HEADER + size;
    }
    Ok(())
}

fn check_laz_chunks<R: Read + Seek>(r: &mut R, len: u64, data_start: u64) -> KindResult<()> {
    let mut word = [0u8; 8];
    if read_at(r, data_start, &mut word)? < 8 {
        return Err(ErrorKind::Truncated {
            what: "the LAZ chunk table offset",
            offset: usize::try_from(data_start).unwrap_or(usize::MAX),
            needed: 8,
            available: usize::try_from(len.saturating_sub(data_start)).unwrap_or(usize::MAX),
        });
    }
    let mut table = i64::from_le_bytes(word);
    if table <= data_start as i64 && len >= 8 {
        // The writer could not seek back: the offset is repeated at the end of the file.
        if read_at(r, len - 8, &mut word)? == 8 {
            table = i64::from_le_bytes(word);
        }
    }
    let Ok(table) = u64::try_from(table) else {
        return Ok(());
    };
    if table <= data_start || read_at(r, table, &mut word)? < 8 {
        return Ok(());
    }
    let chunks = u64::from(u32_at(&word, 4));
    // Every chunk holds at least one compressed point, which takes more than one byte.
    if chunks > len {
        return Err(ErrorKind::Corrupt(format!(
            "LAZ chunk table at byte {table} claims {chunks} chunks in a file of {len} bytes"
        )));
    }
    Ok(())
}

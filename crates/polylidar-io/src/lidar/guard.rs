//! Checks of sizes that LAS/LAZ headers claim, made before the `las` crate allocates them.
//!
//! A corrupt extended VLR length or LAZ chunk count would otherwise make the decoder try
//! to allocate up to tens of GiB and abort the process; here they are compared with the
//! file's real length and reported as errors.

use std::io::{Read, Seek, SeekFrom};

use crate::error::{ErrorKind, KindResult};

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

/// Checks the claimed sizes of `r` and rewinds it; anything else is left to the decoder.
pub fn check_claimed_sizes<R: Read + Seek>(r: &mut R) -> KindResult<()> {
    let len = r.seek(SeekFrom::End(0))?;
    let mut head = [0u8; 375];
    let got = read_at(r, 0, &mut head)?;
    if got >= 227 && &head[..4] == b"LASF" {
        if head[25] >= 4 && got == 375 && u16_at(&head, 94) >= 375 {
            check_evlrs(r, len, u64_at(&head, 235), u32_at(&head, 243))?;
        }
        if head[104] & 0x80 != 0 {
            check_laz_chunks(r, len, u64::from(u32_at(&head, 96)))?;
        }
    }
    r.seek(SeekFrom::Start(0))?;
    Ok(())
}

fn too_large(what: String) -> ErrorKind {
    ErrorKind::Corrupt(what)
}

fn check_evlrs<R: Read + Seek>(r: &mut R, len: u64, start: u64, count: u32) -> KindResult<()> {
    let mut pos = start;
    for k in 0..count {
        let mut evlr = [0u8; 60];
        if pos.saturating_add(60) > len || read_at(r, pos, &mut evlr)? < 60 {
            break;
        }
        let size = u64_at(&evlr, 20);
        if size > len {
            return Err(too_large(format!(
                "extended VLR {k} claims {size} bytes in a file of {len}"
            )));
        }
        pos = pos + 60 + size;
    }
    Ok(())
}

fn check_laz_chunks<R: Read + Seek>(r: &mut R, len: u64, data_start: u64) -> KindResult<()> {
    let mut word = [0u8; 8];
    if read_at(r, data_start, &mut word)? < 8 {
        return Ok(());
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
        return Err(too_large(format!(
            "LAZ chunk table claims {chunks} chunks in a file of {len} bytes"
        )));
    }
    Ok(())
}

//! LZF compression as used by PCD `binary_compressed` (Marc Lehmann's liblzf format).
//!
//! The stream is a sequence of chunks, each led by a control byte `c`:
//! * `c < 32`: a literal run of `c + 1` bytes follows;
//! * otherwise a back-reference: length `(c >> 5) + 2` (when `c >> 5 == 7` one more byte is
//!   added to the length), distance `((c & 0x1f) << 8) + next byte + 1` back from the end of
//!   the output produced so far; the copy may overlap its own output.
//!
//! The decoder checks every bound and returns an error on corrupt input; the encoder is a
//! greedy hash-table matcher producing streams any LZF decoder accepts.

use crate::error::ErrorKind;

/// Longest literal run one control byte can carry.
const MAX_LITERAL: usize = 32;
/// Farthest back-reference distance.
const MAX_OFFSET: usize = 1 << 13;
/// Longest back-reference: 7 + 255 + 2 bytes.
const MAX_REF: usize = (1 << 8) + (1 << 3);
/// Shortest back-reference worth encoding.
const MIN_MATCH: usize = 3;
/// log2 of the match-finder hash table size.
const HASH_LOG: u32 = 14;
/// Upper bound of output bytes per input byte (a 3-byte reference yields 264 bytes).
const MAX_RATIO: usize = MAX_REF.div_ceil(3);

/// Decompresses `input` into exactly `expected_len` bytes.
///
/// # Errors
/// [`ErrorKind::Corrupt`] naming the input byte where a literal run or back-reference
/// goes out of bounds, or when the output length differs from `expected_len`.
pub fn decompress(input: &[u8], expected_len: usize) -> Result<Vec<u8>, ErrorKind> {
    let corrupt =
        |at: usize, what: &str| ErrorKind::Corrupt(format!("LZF chunk at byte {at}: {what}"));
    check_expansion(input.len(), expected_len)?;
    let mut out: Vec<u8> = Vec::with_capacity(expected_len);
    let mut i = 0;
    while i < input.len() {
        let start = i;
        let ctrl = usize::from(input[i]);
        i += 1;
        if ctrl < MAX_LITERAL {
            let len = ctrl + 1;
            let Some(run) = input.get(i..i + len) else {
                return Err(corrupt(start, "literal run past the end of the input"));
            };
            if out.len() + len > expected_len {
                return Err(corrupt(start, "output longer than the declared size"));
            }
            out.extend_from_slice(run);
            i += len;
        } else {
            let mut len = ctrl >> 5;
            if len == 7 {
                let Some(&extra) = input.get(i) else {
                    return Err(corrupt(
                        start,
                        "back-reference length past the end of the input",
                    ));
                };
                len += usize::from(extra);
                i += 1;
            }
            let Some(&low) = input.get(i) else {
                return Err(corrupt(
                    start,
                    "back-reference distance past the end of the input",
                ));
            };
            i += 1;
            let distance = ((ctrl & 0x1f) << 8) + usize::from(low) + 1;
            let len = len + 2;
            if distance > out.len() {
                return Err(corrupt(
                    start,
                    "back-reference before the start of the output",
                ));
            }
            if out.len() + len > expected_len {
                return Err(corrupt(start, "output longer than the declared size"));
            }
            let from = out.len() - distance;
            if distance == 1 {
                let byte = out[from];
                out.resize(out.len() + len, byte);
            } else {
                // An overlapping copy repeats the last `distance` bytes: copy in steps that
                // never read past what has been written.
                let (mut src, mut left) = (from, len);
                while left > 0 {
                    let step = left.min(distance);
                    out.extend_from_within(src..src + step);
                    src += step;
                    left -= step;
                }
            }
        }
    }
    if out.len() != expected_len {
        return Err(ErrorKind::Corrupt(format!(
            "LZF output has {} bytes, the header declares {expected_len}",
            out.len()
        )));
    }
    Ok(out)
}

/// Checks that `compressed` bytes of LZF can expand to `expected_len` bytes at all (a
/// back-reference of 3 bytes yields at most 264), before anything is allocated.
///
/// # Errors
/// [`ErrorKind::Corrupt`] naming both sizes when they cannot match.
pub fn check_expansion(compressed: usize, expected_len: usize) -> Result<(), ErrorKind> {
    if expected_len > compressed.saturating_mul(MAX_RATIO) {
        return Err(ErrorKind::Corrupt(format!(
            "LZF claims {expected_len} bytes from {compressed} compressed bytes, more than \
             the format can expand to ({MAX_RATIO}:1)"
        )));
    }
    Ok(())
}

fn hash3(a: u8, b: u8, c: u8) -> usize {
    let v = (u32::from(a) << 16) | (u32::from(b) << 8) | u32::from(c);
    (v.wrapping_mul(2_654_435_761) >> (32 - HASH_LOG)) as usize
}

fn flush_literals(out: &mut Vec<u8>, literals: &[u8]) {
    for chunk in literals.chunks(MAX_LITERAL) {
        // chunk.len() is in 1..=32, so the control byte is in 0..=31.
        out.push((chunk.len() - 1) as u8);
        out.extend_from_slice(chunk);
    }
}

fn emit_reference(out: &mut Vec<u8>, len: usize, distance: usize) {
    // len in MIN_MATCH..=MAX_REF and distance in 1..=MAX_OFFSET keep every byte in range.
    let l = len - 2;
    let o = distance - 1;
    if l < 7 {
        out.push(((l << 5) | (o >> 8)) as u8);
    } else {
        out.push(((7 << 5) | (o >> 8)) as u8);
        out.push((l - 7) as u8);
    }
    out.push((o & 0xff) as u8);
}

/// Compresses `input` into an LZF stream (never fails; incompressible data grows by at most
/// one byte in 32).
pub fn compress(input: &[u8]) -> Vec<u8> {
    let mut out = Vec::with_capacity(input.len() + input.len() / MAX_LITERAL + 1);
    // Position + 1 of the last occurrence of each 3-byte hash; 0 = none.
    let mut table = vec![0usize; 1 << HASH_LOG];
    let mut literal_start = 0;
    let mut i = 0;
    while i + MIN_MATCH <= input.len() {
        let h = hash3(input[i], input[i + 1], input[i + 2]);
        let candidate = table[h];
        table[h] = i + 1;
        if candidate > 0 {
            let r = candidate - 1;
            let distance = i - r;
            if distance <= MAX_OFFSET && input[r..r + MIN_MATCH] == input[i..i + MIN_MATCH] {
                let max_len = MAX_REF.min(input.len() - i);
                let mut len = MIN_MATCH;
                while len < max_len && input[r + len] == input[i + len] {
                    len += 1;
                }
                flush_literals(&mut out, &input[literal_start..i]);
                emit_reference(&mut out, len, distance);
                for k in i + 1..(i + len).min(input.len() - (MIN_MATCH - 1)) {
                    table[hash3(input[k], input[k + 1], input[k + 2])] = k + 1;
                }
                i += len;
                literal_start = i;
                continue;
            }
        }
        i += 1;
    }
    flush_literals(&mut out, &input[literal_start..]);
    out
}

#[cfg(test)]
mod tests {
    use super::*;
    use proptest::prelude::*;

    #[test]
    fn hand_made_stream_decodes() {
        // literal "abc", then a reference of length 6 at distance 3 (overlapping copy).
        let stream = [2, b'a', b'b', b'c', (4 << 5), 2];
        assert_eq!(decompress(&stream, 9).unwrap(), b"abcabcabc");
        // A run of one byte: distance 1, length 5.
        assert_eq!(decompress(&[0, b'z', 3 << 5, 0], 6).unwrap(), b"zzzzzz");
        // Distance 2, length 7 (odd, so the last step is partial).
        assert_eq!(
            decompress(&[1, b'x', b'y', 5 << 5, 1], 9).unwrap(),
            b"xyxyxyxyx"
        );
    }

    #[test]
    fn long_reference_uses_extra_length_byte() {
        let data = vec![7u8; 1000];
        let packed = compress(&data);
        assert!(packed.len() < 30, "{} bytes", packed.len());
        assert_eq!(decompress(&packed, data.len()).unwrap(), data);
    }

    #[test]
    fn empty_round_trip() {
        assert!(compress(&[]).is_empty());
        assert!(decompress(&[], 0).unwrap().is_empty());
    }

    #[test]
    fn corrupt_streams_are_errors() {
        assert!(decompress(&[5, 1, 2], 6).is_err()); // literal run past end
        assert!(decompress(&[1 << 5, 0], 3).is_err()); // reference before start
        assert!(decompress(&[0, 1, 7 << 5], 40).is_err()); // missing length byte
        assert!(decompress(&[0, 1], 2).is_err()); // too short output
        assert!(decompress(&[0, 1], 1_000_000).is_err()); // impossible expansion
    }

    proptest! {
        #[test]
        fn round_trip(data in proptest::collection::vec(0u8..4, 0..3000)) {
            let packed = compress(&data);
            prop_assert_eq!(decompress(&packed, data.len()).unwrap(), data);
        }

        #[test]
        fn round_trip_random_bytes(data in proptest::collection::vec(any::<u8>(), 0..2000)) {
            let packed = compress(&data);
            prop_assert!(packed.len() <= data.len() + data.len() / 32 + 1);
            prop_assert_eq!(decompress(&packed, data.len()).unwrap(), data);
        }

        #[test]
        fn random_input_never_panics(data in proptest::collection::vec(any::<u8>(), 0..500), len in 0usize..5000) {
            let _ = decompress(&data, len);
        }
    }
}

//! 16-bit depth PNG images and the RealSense `_metadata.csv` camera intrinsics.

use std::io::Cursor;
use std::path::{Path, PathBuf};

use crate::error::{ErrorKind, Format, IoError, KindResult, write_file};
use crate::limits::{Limits, times};

/// A 16-bit single-channel depth image, row-major; 0 means "no depth".
#[derive(Debug, Clone, PartialEq, Eq, Default)]
pub struct DepthImage {
    /// Columns.
    pub width: usize,
    /// Rows.
    pub height: usize,
    /// `width × height` raw depth values (multiply by the depth scale for metres).
    pub data: Vec<u16>,
}

/// Pinhole intrinsics of a depth camera, in pixels.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct CameraIntrinsics {
    /// Image width.
    pub width: usize,
    /// Image height.
    pub height: usize,
    /// Focal length along x.
    pub fx: f64,
    /// Focal length along y.
    pub fy: f64,
    /// Principal point x.
    pub ppx: f64,
    /// Principal point y.
    pub ppy: f64,
    /// Metres per depth unit, when the metadata states it (RealSense's default is 0.001).
    pub depth_scale: Option<f64>,
}

/// Reads a 16-bit greyscale PNG depth image.
///
/// # Errors
/// Unreadable or corrupt PNG, or an image that is not 16-bit single-channel (8-bit,
/// colour, alpha or palette images are rejected rather than guessed at); more pixels than
/// [`Limits::for_path`] allows (each costs its decoded bytes and the pipeline's share).
pub fn read_depth_png(path: impl AsRef<Path>) -> Result<DepthImage, IoError> {
    let path = path.as_ref();
    read_depth_png_with(path, &Limits::for_path(path))
}

/// As [`read_depth_png`], within `limits`.
///
/// # Errors
/// As [`read_depth_png`]; [`ErrorKind::OverBudget`] past `limits`.
pub fn read_depth_png_with(path: impl AsRef<Path>, limits: &Limits) -> Result<DepthImage, IoError> {
    let path = path.as_ref();
    parse_depth_png_with(&limits.read_file(path, Format::DepthPng)?, limits).map_err(|e| e.at(path))
}

/// Decodes 16-bit greyscale PNG bytes; see [`read_depth_png`].
///
/// # Errors
/// As [`read_depth_png`], with no file name.
pub fn parse_depth_png(bytes: &[u8]) -> Result<DepthImage, IoError> {
    parse_depth_png_with(bytes, &Limits::for_input_size(bytes.len() as u64))
}

/// As [`parse_depth_png`], within `limits`.
///
/// # Errors
/// As [`read_depth_png_with`], with no file name.
pub fn parse_depth_png_with(bytes: &[u8], limits: &Limits) -> Result<DepthImage, IoError> {
    decode_png(bytes, limits).map_err(|k| IoError::new(Format::DepthPng, k))
}

fn decode_png(bytes: &[u8], limits: &Limits) -> KindResult<DepthImage> {
    let decoder = png::Decoder::new(Cursor::new(bytes));
    let mut reader = decoder
        .read_info()
        .map_err(|e| ErrorKind::Decoder(e.to_string()))?;
    let (color, depth) = reader.output_color_type();
    if color != png::ColorType::Grayscale || depth != png::BitDepth::Sixteen {
        let hint = if color == png::ColorType::Rgb {
            " (an RGB picture is a colorized depth visualization without metric depth; \
             see read_colorized_depth_png)"
        } else {
            ""
        };
        return Err(ErrorKind::NotDepth(format!(
            "{} {color:?} image; depth images are 16-bit greyscale{hint}",
            bit_text(depth)
        )));
    }
    // The decoder's buffer, the u16 samples, and the cloud and mesh made of each pixel.
    let size = checked_buffer_size(&reader, bytes.len(), limits, 2, true)?;
    let mut buf = vec![0u8; size];
    let frame = reader
        .next_frame(&mut buf)
        .map_err(|e| ErrorKind::Decoder(e.to_string()))?;
    let width = frame.width as usize;
    let height = frame.height as usize;
    let data: Vec<u16> = buf[..frame.buffer_size()]
        .chunks_exact(2)
        .map(|c| u16::from_be_bytes([c[0], c[1]]))
        .collect();
    if data.len() != width * height {
        return Err(ErrorKind::Shape(format!(
            "{} samples for a {width} × {height} image",
            data.len()
        )));
    }
    Ok(DepthImage {
        width,
        height,
        data,
    })
}

/// Deflate expands at most ~1032:1; a larger claimed image is corrupt.
const MAX_INFLATE_RATIO: usize = 1100;

/// The decoder's output buffer size, refused when the header claims more pixels than
/// `file_len` compressed bytes can hold (a corrupt header would otherwise allocate GiBs),
/// or when the buffer, `decoded_per_pixel` bytes of the caller's copy per pixel and (with
/// `pipeline`) the pipeline's share per pixel exceed `limits`.
pub(crate) fn checked_buffer_size<R: std::io::BufRead + std::io::Seek>(
    reader: &png::Reader<R>,
    file_len: usize,
    limits: &Limits,
    decoded_per_pixel: u64,
    pipeline: bool,
) -> KindResult<usize> {
    let (width, height) = (reader.info().width, reader.info().height);
    let size = reader.output_buffer_size().ok_or_else(|| {
        ErrorKind::Decoder(format!("a {width} × {height} image is too large to decode"))
    })?;
    if size > file_len.saturating_mul(MAX_INFLATE_RATIO) {
        return Err(ErrorKind::Corrupt(format!(
            "the header claims {width} × {height} pixels ({size} bytes), more than \
             {file_len} compressed bytes can hold"
        )));
    }
    let pixels = u64::from(width) * u64::from(height);
    let share = if pipeline { limits.pipeline(pixels) } else { 0 };
    let estimate = (file_len as u64)
        .saturating_add(size as u64)
        .saturating_add(pixels.saturating_mul(decoded_per_pixel))
        .saturating_add(share);
    limits.check(estimate, || {
        format!(
            "{width} × {height} pixels: {} bytes decoded, {decoded_per_pixel} bytes kept and \
             {} bytes in the pipeline per pixel",
            times(size, 1).checked_div(pixels).unwrap_or(0),
            if pipeline {
                limits.pipeline_bytes_per_point
            } else {
                0
            }
        )
    })?;
    Ok(size)
}

pub(crate) fn bit_text(depth: png::BitDepth) -> &'static str {
    match depth {
        png::BitDepth::One => "1-bit",
        png::BitDepth::Two => "2-bit",
        png::BitDepth::Four => "4-bit",
        png::BitDepth::Eight => "8-bit",
        png::BitDepth::Sixteen => "16-bit",
    }
}

/// Writes a 16-bit greyscale PNG depth image.
///
/// # Errors
/// `data.len() != width × height`, a size beyond PNG's `u32`, or a file system error.
pub fn write_depth_png(path: impl AsRef<Path>, image: &DepthImage) -> Result<(), IoError> {
    let path = path.as_ref();
    let bytes = encode_depth_png(image).map_err(|e| e.at(path))?;
    write_file(path, Format::DepthPng, &bytes)
}

/// Encodes a depth image as 16-bit greyscale PNG bytes.
///
/// # Errors
/// As [`write_depth_png`], without the file system.
pub fn encode_depth_png(image: &DepthImage) -> Result<Vec<u8>, IoError> {
    let err = |k| IoError::new(Format::DepthPng, k);
    if image.width.checked_mul(image.height) != Some(image.data.len()) {
        return Err(err(ErrorKind::Shape(format!(
            "{} samples for a {} × {} image",
            image.data.len(),
            image.width,
            image.height
        ))));
    }
    let too_big = || {
        err(ErrorKind::Unusable(
            "image dimensions exceed u32".to_owned(),
        ))
    };
    let w = u32::try_from(image.width).map_err(|_| too_big())?;
    let h = u32::try_from(image.height).map_err(|_| too_big())?;
    let mut out = Vec::new();
    let mut encoder = png::Encoder::new(&mut out, w, h);
    encoder.set_color(png::ColorType::Grayscale);
    encoder.set_depth(png::BitDepth::Sixteen);
    let be: Vec<u8> = image.data.iter().flat_map(|v| v.to_be_bytes()).collect();
    let png_err = |e: png::EncodingError| err(ErrorKind::Decoder(e.to_string()));
    let mut writer = encoder.write_header().map_err(png_err)?;
    writer.write_image_data(&be).map_err(png_err)?;
    writer.finish().map_err(png_err)?;
    Ok(out)
}

/// Reads camera intrinsics from a RealSense Viewer `_metadata.csv` (`key,value` lines:
/// `Resolution x`, `Resolution y`, `Fx`, `Fy`, `PPx`, `PPy`, and optionally
/// `Depth Units`/`Depth Scale`).
///
/// # Errors
/// Unreadable file, a needed key missing, or a value that is not a number.
pub fn read_realsense_intrinsics(path: impl AsRef<Path>) -> Result<CameraIntrinsics, IoError> {
    let path = path.as_ref();
    // A metadata file is a few hundred bytes: 16 MiB bounds a FIFO or device named like one.
    let bytes = Limits::default()
        .with_max_memory(METADATA_MAX_BYTES)
        .read_file(path, Format::RealSenseMetadata)?;
    parse_realsense_intrinsics(&String::from_utf8_lossy(&bytes)).map_err(|e| e.at(path))
}

/// The most bytes a RealSense metadata file may hold.
const METADATA_MAX_BYTES: u64 = 16 << 20;

/// Parses RealSense metadata CSV text; see [`read_realsense_intrinsics`].
///
/// # Errors
/// As [`read_realsense_intrinsics`], with no file name.
pub fn parse_realsense_intrinsics(text: &str) -> Result<CameraIntrinsics, IoError> {
    parse_metadata(text).map_err(|k| IoError::new(Format::RealSenseMetadata, k))
}

fn parse_metadata(text: &str) -> KindResult<CameraIntrinsics> {
    let mut values: [Option<f64>; 7] = [None; 7];
    const KEYS: [&str; 6] = ["resolution x", "resolution y", "fx", "fy", "ppx", "ppy"];
    for (k, line) in text.lines().enumerate() {
        let mut parts = line.splitn(2, [',', ':']);
        let key = parts.next().unwrap_or_default().trim().to_ascii_lowercase();
        let value = parts
            .next()
            .unwrap_or_default()
            .trim()
            .trim_end_matches(',');
        let slot = match key.as_str() {
            "depth units" | "depth scale" | "depth unit" => Some(6),
            _ => KEYS.iter().position(|name| *name == key),
        };
        let Some(slot) = slot else { continue };
        let v = value.parse::<f64>().map_err(|_| ErrorKind::Line {
            line: k + 1,
            reason: format!("{key} value {value:?} is not a number"),
        })?;
        if !v.is_finite() || (slot != 6 && v < 0.0) {
            return Err(ErrorKind::Line {
                line: k + 1,
                reason: format!("{key} value {v} is out of range"),
            });
        }
        values[slot] = Some(v);
    }
    let get =
        |slot: usize| values[slot].ok_or_else(|| ErrorKind::MissingField(KEYS[slot].to_owned()));
    let dim = |slot: usize| -> KindResult<usize> {
        let v = get(slot)?;
        if v.fract() != 0.0 || v > 1e9 {
            return Err(ErrorKind::BadHeader(format!(
                "{} {v} is not an image size",
                KEYS[slot]
            )));
        }
        Ok(v as usize)
    };
    Ok(CameraIntrinsics {
        width: dim(0)?,
        height: dim(1)?,
        fx: get(2)?,
        fy: get(3)?,
        ppx: get(4)?,
        ppy: get(5)?,
        depth_scale: values[6],
    })
}

/// Finds the metadata CSV of a depth PNG: `<stem>_metadata.csv` (RealSense Viewer:
/// `001_big_depth.png` → `001_big_depth_metadata.csv`), then the same without a `_depth`
/// suffix, then `<stem>.csv`.
///
/// # Errors
/// [`ErrorKind::MissingMetadata`] listing every path tried.
pub fn metadata_path_for(depth_png: impl AsRef<Path>) -> Result<PathBuf, IoError> {
    let png = depth_png.as_ref();
    let stem = png
        .file_stem()
        .map(|s| s.to_string_lossy().into_owned())
        .unwrap_or_default();
    let mut names = vec![format!("{stem}_metadata.csv")];
    if let Some(base) = stem.strip_suffix("_depth") {
        names.push(format!("{base}_metadata.csv"));
    }
    names.push(format!("{stem}.csv"));
    let tried: Vec<PathBuf> = names.iter().map(|n| png.with_file_name(n)).collect();
    if let Some(found) = tried.iter().find(|p| p.is_file()) {
        return Ok(found.clone());
    }
    Err(IoError::new(
        Format::RealSenseMetadata,
        ErrorKind::MissingMetadata { tried },
    )
    .at(png))
}

#[cfg(test)]
mod tests {
    use super::*;

    const SMALL: &str = "Frame Info: \nType,Depth\nFormat,Z16\nResolution x,424\nResolution y,240\n\
                         Bytes per pixel,2\n\nIntrinsic:,\nFx,212.924622\nFy,212.924622\n\
                         PPx,212.933899\nPPy,119.977364\nDistorsion,Brown Conrady\n";

    #[test]
    fn parses_realsense_metadata() {
        let k = parse_realsense_intrinsics(SMALL).unwrap();
        assert_eq!((k.width, k.height), (424, 240));
        assert_eq!(k.fx, 212.924622);
        assert_eq!(k.ppy, 119.977364);
        assert_eq!(k.depth_scale, None);
        let with_scale = format!("{SMALL}Depth Units,0.0001\n");
        assert_eq!(
            parse_realsense_intrinsics(&with_scale).unwrap().depth_scale,
            Some(0.0001)
        );
    }

    #[test]
    fn metadata_errors() {
        let e =
            parse_realsense_intrinsics("Fx,1\nFy,1\nPPx,1\nPPy,1\nResolution x,2\n").unwrap_err();
        assert!(e.to_string().contains("resolution y"), "{e}");
        let e = parse_realsense_intrinsics("Fx,abc\n").unwrap_err();
        assert!(matches!(e.kind, ErrorKind::Line { line: 1, .. }), "{e}");
    }

    fn crc32(bytes: &[u8]) -> u32 {
        let mut crc = !0u32;
        for &b in bytes {
            crc ^= u32::from(b);
            for _ in 0..8 {
                crc = (crc >> 1) ^ (0xEDB8_8320 & 0u32.wrapping_sub(crc & 1));
            }
        }
        !crc
    }

    #[test]
    fn huge_claimed_size_is_refused_before_allocating() {
        let mut bytes = encode_depth_png(&DepthImage {
            width: 1,
            height: 1,
            data: vec![5],
        })
        .unwrap();
        // IHDR data sits at bytes 16..29 (width, height, …), its CRC at 29..33.
        bytes[16..20].copy_from_slice(&60_000u32.to_be_bytes());
        bytes[20..24].copy_from_slice(&60_000u32.to_be_bytes());
        let crc = crc32(&bytes[12..29]);
        bytes[29..33].copy_from_slice(&crc.to_be_bytes());
        let e = parse_depth_png(&bytes).unwrap_err();
        assert!(matches!(e.kind, ErrorKind::Corrupt(_)), "{e}");
    }

    #[test]
    fn png_round_trip_and_rejections() {
        let img = DepthImage {
            width: 3,
            height: 2,
            data: vec![0, 1, 1000, 65535, 42, 7],
        };
        let bytes = encode_depth_png(&img).unwrap();
        assert_eq!(parse_depth_png(&bytes).unwrap(), img);
        // An 8-bit image is not a depth image.
        let mut out = Vec::new();
        let mut enc = png::Encoder::new(&mut out, 2, 1);
        enc.set_color(png::ColorType::Grayscale);
        enc.set_depth(png::BitDepth::Eight);
        let mut w = enc.write_header().unwrap();
        w.write_image_data(&[1, 2]).unwrap();
        w.finish().unwrap();
        let e = parse_depth_png(&out).unwrap_err();
        assert!(matches!(e.kind, ErrorKind::NotDepth(_)), "{e}");
        assert!(parse_depth_png(&bytes[..bytes.len() / 2]).is_err());
    }
}

//! Colour: the RGB picture of an RGB-D frame (8-bit PNG or JPEG), the colour image found
//! beside a depth image, and per-point colours of PCD (`rgb` / `rgba`) and PLY (`red`,
//! `green`, `blue`) files.

use std::io::Cursor;
use std::path::{Path, PathBuf};

use zune_jpeg::JpegDecoder;
use zune_jpeg::zune_core::bytestream::ZCursor;
use zune_jpeg::zune_core::colorspace::ColorSpace;
use zune_jpeg::zune_core::options::DecoderOptions;

use crate::depth::checked_buffer_size;
use crate::error::{ErrorKind, Format, IoError, KindResult};
use crate::limits::Limits;

/// An RGB picture, row-major, top row first.
#[derive(Debug, Clone, PartialEq, Eq, Default)]
pub struct ColorImage {
    /// Columns.
    pub width: usize,
    /// Rows.
    pub height: usize,
    /// `width × height` colours.
    pub rgb: Vec<[u8; 3]>,
}

/// Reads an RGB picture: PNG (8- or 16-bit; grey, RGB, with or without alpha, palette) or
/// JPEG (baseline or progressive), told apart by their first bytes.
///
/// # Errors
/// Unreadable file, neither PNG nor JPEG, or a corrupt picture.
pub fn read_color_image(path: impl AsRef<Path>) -> Result<ColorImage, IoError> {
    let path = path.as_ref();
    read_color_image_with(path, &Limits::for_path(path))
}

/// As [`read_color_image`], within `limits` (the picture's buffers count, no pipeline
/// share: that of the depth image it colours is counted by its reader).
///
/// # Errors
/// As [`read_color_image`]; [`ErrorKind::OverBudget`] past `limits`.
pub fn read_color_image_with(
    path: impl AsRef<Path>,
    limits: &Limits,
) -> Result<ColorImage, IoError> {
    let path = path.as_ref();
    parse_color_image_with(&limits.read_file(path, Format::ColorImage)?, limits)
        .map_err(|e| e.at(path))
}

/// Decodes PNG or JPEG bytes; see [`read_color_image`].
///
/// ```
/// // A 1 × 1 red PNG.
/// let mut bytes = Vec::new();
/// let mut encoder = png::Encoder::new(&mut bytes, 1, 1);
/// encoder.set_color(png::ColorType::Rgb);
/// encoder.write_header()?.write_image_data(&[255, 0, 0])?;
/// let image = polylidar_io::parse_color_image(&bytes)?;
/// assert_eq!(image.rgb, vec![[255, 0, 0]]);
/// # Ok::<(), Box<dyn std::error::Error>>(())
/// ```
///
/// # Errors
/// As [`read_color_image`], with no file name.
pub fn parse_color_image(bytes: &[u8]) -> Result<ColorImage, IoError> {
    parse_color_image_with(bytes, &Limits::for_input_size(bytes.len() as u64))
}

/// As [`parse_color_image`], within `limits`.
///
/// # Errors
/// As [`read_color_image_with`], with no file name.
pub fn parse_color_image_with(bytes: &[u8], limits: &Limits) -> Result<ColorImage, IoError> {
    let decoded = if bytes.starts_with(&[0x89, b'P', b'N', b'G']) {
        decode_png(bytes, limits)
    } else if bytes.starts_with(&[0xFF, 0xD8]) {
        decode_jpeg(bytes, limits)
    } else {
        Err(ErrorKind::Unsupported {
            what: "picture format",
            value: "neither PNG nor JPEG".to_owned(),
        })
    };
    decoded.map_err(|k| IoError::new(Format::ColorImage, k))
}

fn decode_png(bytes: &[u8], limits: &Limits) -> KindResult<ColorImage> {
    let mut decoder = png::Decoder::new(Cursor::new(bytes));
    decoder.set_transformations(png::Transformations::EXPAND | png::Transformations::STRIP_16);
    let mut reader = decoder
        .read_info()
        .map_err(|e| ErrorKind::Decoder(e.to_string()))?;
    let size = checked_buffer_size(&reader, bytes.len(), limits, 3, false)?;
    let mut buf = vec![0u8; size];
    let frame = reader
        .next_frame(&mut buf)
        .map_err(|e| ErrorKind::Decoder(e.to_string()))?;
    let channels = match frame.color_type {
        png::ColorType::Grayscale => 1,
        png::ColorType::GrayscaleAlpha => 2,
        png::ColorType::Rgb => 3,
        png::ColorType::Rgba => 4,
        png::ColorType::Indexed => {
            return Err(ErrorKind::Decoder("palette not expanded".to_owned()));
        }
    };
    let (width, height) = (frame.width as usize, frame.height as usize);
    let rgb = buf[..frame.buffer_size()]
        .chunks_exact(channels)
        .map(|p| {
            if channels < 3 {
                [p[0]; 3]
            } else {
                [p[0], p[1], p[2]]
            }
        })
        .collect::<Vec<_>>();
    image(width, height, rgb)
}

fn decode_jpeg(bytes: &[u8], limits: &Limits) -> KindResult<ColorImage> {
    let options = DecoderOptions::default().jpeg_set_out_colorspace(ColorSpace::RGB);
    let mut decoder = JpegDecoder::new_with_options(ZCursor::new(bytes), options);
    decoder
        .decode_headers()
        .map_err(|e| ErrorKind::Decoder(format!("JPEG: {e:?}")))?;
    if let Some((width, height)) = decoder.dimensions() {
        // The decoder's RGB buffer and the pixels kept, 3 bytes each.
        let pixels = (width as u64).saturating_mul(height as u64);
        let estimate = (bytes.len() as u64).saturating_add(pixels.saturating_mul(6));
        limits.check(estimate, || {
            format!("{width} × {height} pixels: 3 bytes decoded and 3 bytes kept per pixel")
        })?;
    }
    let pixels = decoder
        .decode()
        .map_err(|e| ErrorKind::Decoder(format!("JPEG: {e:?}")))?;
    let info = decoder
        .info()
        .ok_or_else(|| ErrorKind::Decoder("JPEG without a frame header".to_owned()))?;
    let rgb = pixels.chunks_exact(3).map(|p| [p[0], p[1], p[2]]).collect();
    image(usize::from(info.width), usize::from(info.height), rgb)
}

fn image(width: usize, height: usize, rgb: Vec<[u8; 3]>) -> KindResult<ColorImage> {
    if rgb.len() != width * height {
        return Err(ErrorKind::Shape(format!(
            "{} pixels decoded for a {width} × {height} picture",
            rgb.len()
        )));
    }
    Ok(ColorImage { width, height, rgb })
}

/// The colour picture of a depth image: the depth file's name with `depth` replaced by
/// `color`, `colour` or `rgb`, as `.png`, `.jpg` or `.jpeg` (`frame_depth_0001.png` →
/// `frame_color_0001.jpg`, `tum_depth.png` → `tum_color.png`), the first that exists.
///
/// # Errors
/// [`ErrorKind::MissingMetadata`] listing the paths tried when none exists.
pub fn color_path_for(depth: impl AsRef<Path>) -> Result<PathBuf, IoError> {
    let depth = depth.as_ref();
    let stem = depth
        .file_stem()
        .map(|s| s.to_string_lossy().into_owned())
        .unwrap_or_default();
    let mut tried = Vec::new();
    if stem.contains("depth") {
        for name in ["color", "colour", "rgb"] {
            for ext in ["png", "jpg", "jpeg"] {
                let candidate =
                    depth.with_file_name(format!("{}.{ext}", stem.replace("depth", name)));
                if candidate.is_file() {
                    return Ok(candidate);
                }
                tried.push(candidate);
            }
        }
    }
    Err(IoError::new(Format::ColorImage, ErrorKind::MissingMetadata { tried }).at(depth))
}

/// The colour of every point of a PCD file from its `rgb` or `rgba` field (packed
/// `0x00RRGGBB` as in PCL, stored as a float or an unsigned integer), or `None` when it
/// has neither.
///
/// # Errors
/// As [`crate::read_pcd`].
pub fn read_pcd_colors(path: impl AsRef<Path>) -> Result<Option<Vec<[u8; 3]>>, IoError> {
    let path = path.as_ref();
    let limits = Limits::for_path(path);
    crate::pcd::packed_colors(&limits.read_file(path, Format::Pcd)?, &limits)
        .map_err(|k| IoError::new(Format::Pcd, k).at(path))
}

/// Parses the colours of PCD bytes; see [`read_pcd_colors`].
///
/// # Errors
/// As [`crate::parse_pcd`].
pub fn parse_pcd_colors(bytes: &[u8]) -> Result<Option<Vec<[u8; 3]>>, IoError> {
    crate::pcd::packed_colors(bytes, &Limits::for_input_size(bytes.len() as u64))
        .map_err(|k| IoError::new(Format::Pcd, k))
}

/// The bytes of a packed PCL colour.
#[inline]
pub(crate) fn unpack(bits: u32) -> [u8; 3] {
    [(bits >> 16) as u8, (bits >> 8) as u8, bits as u8]
}

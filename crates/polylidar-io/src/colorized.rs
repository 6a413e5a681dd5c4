//! Colorized depth pictures (RealSense Viewer "Jet" colormap): recovering the depth *order*.
//!
//! The RealSense Viewer saves depth frames as 8-bit RGB pictures: zero depth is black, and
//! depth runs along the Jet colormap blue → cyan → yellow → red → dark red from near to far.
//! The mapping's range (and, with histogram equalization, its shape) is not stored, so such
//! a picture gives each pixel's position along the colormap — monotonic in depth — but not
//! metric depth. [`ColorizedDepth::to_depth_image`] turns it into a depth image under an
//! explicit, caller-chosen linear range: an approximation for exercising the pipeline, not a
//! measurement.

use std::collections::HashMap;
use std::io::Cursor;
use std::path::Path;

use crate::depth::{DepthImage, bit_text, checked_buffer_size};
use crate::error::{ErrorKind, Format, IoError, KindResult};
use crate::limits::Limits;

/// The Jet colormap of the RealSense colorizer, near to far.
const JET: [[f32; 3]; 5] = [
    [0.0, 0.0, 255.0],
    [0.0, 255.0, 255.0],
    [255.0, 255.0, 0.0],
    [255.0, 0.0, 0.0],
    [50.0, 0.0, 0.0],
];

/// Farthest RGB distance from the colormap still read as a colormap colour.
const MAX_COLOR_DISTANCE: f32 = 30.0;

/// Share of coloured pixels allowed off the colormap before the picture is rejected.
const MAX_OFF_MAP_SHARE: f64 = 0.01;

/// A depth picture decoded to positions along its colormap.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct ColorizedDepth {
    /// Columns.
    pub width: usize,
    /// Rows.
    pub height: usize,
    /// Row-major position along the colormap: 0 nearest (blue) to 1 farthest (dark red);
    /// NaN where the picture is black (no depth).
    pub data: Vec<f32>,
}

impl ColorizedDepth {
    /// Pixels with a depth (not black).
    pub fn valid_count(&self) -> usize {
        self.data.iter().filter(|v| !v.is_nan()).count()
    }

    /// A depth image under the assumption that the colormap spans `near..=far` depth units
    /// linearly (RealSense Viewer without histogram equalization); black pixels become 0.
    ///
    /// This is an approximation chosen by the caller: the picture does not store its range.
    pub fn to_depth_image(&self, near: u16, far: u16) -> DepthImage {
        let (near, far) = (f32::from(near), f32::from(far));
        let data = self
            .data
            .iter()
            .map(|&t| {
                if t.is_nan() {
                    0
                } else {
                    // t in [0, 1] keeps the value between near and far, inside u16.
                    (near + t * (far - near)).round() as u16
                }
            })
            .collect();
        DepthImage {
            width: self.width,
            height: self.height,
            data,
        }
    }
}

/// Position along [`JET`] (0..=1) of an RGB colour and its distance from the colormap.
fn jet_position(c: [f32; 3]) -> (f32, f32) {
    let mut best = (0.0f32, f32::INFINITY);
    for (i, seg) in JET.windows(2).enumerate() {
        let (a, b) = (seg[0], seg[1]);
        let d = [b[0] - a[0], b[1] - a[1], b[2] - a[2]];
        let len2 = d[0] * d[0] + d[1] * d[1] + d[2] * d[2];
        let s = (((c[0] - a[0]) * d[0] + (c[1] - a[1]) * d[1] + (c[2] - a[2]) * d[2]) / len2)
            .clamp(0.0, 1.0);
        let dist2 = (0..3)
            .map(|k| (c[k] - a[k] - s * d[k]).powi(2))
            .sum::<f32>();
        if dist2 < best.1 {
            best = ((i as f32 + s) / (JET.len() - 1) as f32, dist2);
        }
    }
    (best.0, best.1.sqrt())
}

/// Reads an 8-bit RGB depth picture colorized with the RealSense Jet colormap.
///
/// # Errors
/// Unreadable or corrupt PNG, an image that is not 8-bit RGB, or more than 1 % of coloured
/// pixels off the Jet colormap (not a colorized depth picture).
pub fn read_colorized_depth_png(path: impl AsRef<Path>) -> Result<ColorizedDepth, IoError> {
    let path = path.as_ref();
    read_colorized_depth_png_with(path, &Limits::for_path(path))
}

/// As [`read_colorized_depth_png`], within `limits`.
///
/// # Errors
/// As [`read_colorized_depth_png`]; [`ErrorKind::OverBudget`] past `limits`.
pub fn read_colorized_depth_png_with(
    path: impl AsRef<Path>,
    limits: &Limits,
) -> Result<ColorizedDepth, IoError> {
    let path = path.as_ref();
    parse_colorized_depth_png_with(&limits.read_file(path, Format::DepthPng)?, limits)
        .map_err(|e| e.at(path))
}

/// Decodes a colorized depth picture from PNG bytes; see [`read_colorized_depth_png`].
///
/// # Errors
/// As [`read_colorized_depth_png`], with no file name.
pub fn parse_colorized_depth_png(bytes: &[u8]) -> Result<ColorizedDepth, IoError> {
    parse_colorized_depth_png_with(bytes, &Limits::for_input_size(bytes.len() as u64))
}

/// As [`parse_colorized_depth_png`], within `limits`.
///
/// # Errors
/// As [`read_colorized_depth_png_with`], with no file name.
pub fn parse_colorized_depth_png_with(
    bytes: &[u8],
    limits: &Limits,
) -> Result<ColorizedDepth, IoError> {
    decode(bytes, limits).map_err(|k| IoError::new(Format::DepthPng, k))
}

fn decode(bytes: &[u8], limits: &Limits) -> KindResult<ColorizedDepth> {
    let mut reader = png::Decoder::new(Cursor::new(bytes))
        .read_info()
        .map_err(|e| ErrorKind::Decoder(e.to_string()))?;
    let (color, depth) = reader.output_color_type();
    if color != png::ColorType::Rgb || depth != png::BitDepth::Eight {
        return Err(ErrorKind::NotDepth(format!(
            "{} {color:?} image; a colorized depth picture is 8-bit RGB",
            bit_text(depth)
        )));
    }
    // The decoder's buffer, the f32 depth order, and the cloud and mesh made of each pixel.
    let size = checked_buffer_size(&reader, bytes.len(), limits, 4, true)?;
    let mut buf = vec![0u8; size];
    let frame = reader
        .next_frame(&mut buf)
        .map_err(|e| ErrorKind::Decoder(e.to_string()))?;
    let (width, height) = (frame.width as usize, frame.height as usize);
    let mut off_map = 0usize;
    let mut coloured = 0usize;
    // Pictures hold a few hundred distinct colours: project each once.
    let mut seen: HashMap<[u8; 3], (f32, f32)> = HashMap::new();
    let data: Vec<f32> = buf[..frame.buffer_size()]
        .chunks_exact(3)
        .map(|c| {
            if c == [0, 0, 0] {
                return f32::NAN;
            }
            coloured += 1;
            let key = [c[0], c[1], c[2]];
            let (t, dist) = *seen.entry(key).or_insert_with(|| {
                jet_position([f32::from(c[0]), f32::from(c[1]), f32::from(c[2])])
            });
            if dist > MAX_COLOR_DISTANCE {
                off_map += 1;
            }
            t
        })
        .collect();
    if data.len() != width * height {
        return Err(ErrorKind::Shape(format!(
            "{} pixels for a {width} × {height} image",
            data.len()
        )));
    }
    if off_map as f64 > MAX_OFF_MAP_SHARE * coloured as f64 {
        return Err(ErrorKind::NotDepth(format!(
            "{off_map} of {coloured} coloured pixels are off the Jet colormap: not a colorized depth picture"
        )));
    }
    Ok(ColorizedDepth {
        width,
        height,
        data,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    fn rgb_png(width: u32, pixels: &[[u8; 3]]) -> Vec<u8> {
        let mut out = Vec::new();
        let mut enc = png::Encoder::new(&mut out, width, pixels.len() as u32 / width);
        enc.set_color(png::ColorType::Rgb);
        enc.set_depth(png::BitDepth::Eight);
        let mut w = enc.write_header().unwrap();
        w.write_image_data(pixels.as_flattened()).unwrap();
        w.finish().unwrap();
        out
    }

    #[test]
    fn control_points_map_to_their_positions() {
        for (i, c) in JET.iter().enumerate() {
            let (t, d) = jet_position(*c);
            assert!(
                (t - i as f32 / 4.0).abs() < 1e-6 && d < 1e-3,
                "{i}: {t} {d}"
            );
        }
        // Halfway between yellow and red.
        let (t, _) = jet_position([255.0, 128.0, 0.0]);
        assert!((t - 0.625).abs() < 0.01, "{t}");
    }

    #[test]
    fn decodes_and_converts() {
        let px = [[0, 0, 255], [0, 0, 0], [255, 255, 0], [50, 0, 0]];
        let img = parse_colorized_depth_png(&rgb_png(2, &px)).unwrap();
        assert_eq!((img.width, img.height, img.valid_count()), (2, 2, 3));
        let depth = img.to_depth_image(1000, 5000);
        assert_eq!(depth.data, vec![1000, 0, 3000, 5000]);
    }

    #[test]
    fn rejects_pictures_off_the_colormap() {
        let px = [[0, 255, 0], [255, 0, 255], [128, 128, 128], [0, 0, 255]];
        let e = parse_colorized_depth_png(&rgb_png(2, &px)).unwrap_err();
        assert!(matches!(e.kind, ErrorKind::NotDepth(_)), "{e}");
    }
}

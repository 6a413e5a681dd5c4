//! The unwrapped image of the icosahedron (Cohen et al.): five charts side by side, each
//! `n` columns × `2n` rows of vertices (`n = 2^level`) with a one-pixel border copied from the
//! adjoining charts, so a 3×3 window around any chart pixel sees its neighbours on the sphere.

#[cfg(feature = "png")]
use std::io::Write;
#[cfg(feature = "png")]
use std::path::Path;
use std::sync::Arc;

#[cfg(feature = "png")]
use crate::FastGaError;
use crate::icosahedron::{CHARTS, Lattice, NORTH_POLE, SOUTH_POLE};

/// Pixel → vertex map of the unwrapped image at one level.
#[derive(Debug, Clone)]
pub(crate) struct ImageLayout {
    pub(crate) n: u32,
    pub(crate) width: u32,
    pub(crate) height: u32,
    /// Row-major vertex index of every pixel.
    pub(crate) pixel_vertex: Arc<[u32]>,
}

impl ImageLayout {
    pub(crate) fn new(level: u32) -> Self {
        let lattice = Lattice::new(level);
        let n = lattice.n;
        let (width, height) = (CHARTS * (n + 2), 2 * n + 2);
        let mut pixel_vertex = Vec::with_capacity((width * height) as usize);
        for y in 0..height {
            for x in 0..width {
                let chart = x / (n + 2);
                let s = x % (n + 2);
                pixel_vertex.push(padded_vertex(lattice, chart, s, i64::from(y) - 1));
            }
        }
        Self {
            n,
            width,
            height,
            pixel_vertex: pixel_vertex.into(),
        }
    }

    #[cfg(test)]
    fn is_chart_pixel(&self, x: u32, y: u32) -> bool {
        is_chart_pixel(self.n, x, y)
    }
}

/// Whether pixel (x, y) is inside a chart (not padding) of an image with `n × 2n` charts: each
/// vertex but the poles is inside exactly one chart.
#[inline]
fn is_chart_pixel(n: u32, x: u32, y: u32) -> bool {
    let s = x % (n + 2);
    (1..=n).contains(&s) && (1..=2 * n).contains(&y)
}

/// Vertex shown at chart coordinates `s` in `0..=n+1`, `t` in `-1..=2n` of `chart`: inside and
/// on the chart's own border by [`Lattice::vertex`], beyond its other two sides by unfolding the
/// neighbouring chart `chart − 1` across the shared edge.
fn padded_vertex(lattice: Lattice, chart: u32, s: u32, t: i64) -> u32 {
    let n = lattice.n;
    let prev = (chart + CHARTS - 1) % CHARTS;
    let n64 = i64::from(n);
    if s == n + 1 {
        if t < n64 {
            // Across upper ring vertex c – lower ring vertex c: chart c − 1 continues flat.
            lattice.owned(prev, 1, (t + n64) as u32)
        } else if t < 2 * n64 {
            // Across lower ring vertex c – south pole: chart c − 1's bottom side, turned 60°.
            lattice.owned(prev, (t - n64) as u32 + 1, 2 * n - 1)
        } else {
            SOUTH_POLE
        }
    } else if t < 0 {
        // Across north pole – upper ring vertex c: chart c − 1's side s = 0, turned 60°.
        if s == 0 {
            NORTH_POLE
        } else {
            lattice.owned(prev, 1, s - 1)
        }
    } else {
        lattice.vertex(chart, s, t as u32)
    }
}

/// The unwrapped icosahedron as an image of vertex values normalised to 0–255 (the largest
/// vertex value maps to 255, zero to 0).
///
/// For level `L` it is `5·(2^L + 2)` pixels wide and `2^(L+1) + 2` high (90 × 34 at level 4).
#[derive(Debug, Clone)]
pub struct UnwrappedImage {
    width: u32,
    height: u32,
    values: Vec<f64>,
    pixel_vertex: Arc<[u32]>,
    chart_size: u32,
}

impl UnwrappedImage {
    pub(crate) fn new(layout: &ImageLayout, vertex_values: &[f64]) -> Self {
        let max = vertex_values.iter().copied().fold(0.0, f64::max);
        let scale = if max > 0.0 { 255.0 / max } else { 0.0 };
        let values = layout
            .pixel_vertex
            .iter()
            .map(|&v| vertex_values[v as usize] * scale)
            .collect();
        Self {
            width: layout.width,
            height: layout.height,
            values,
            pixel_vertex: Arc::clone(&layout.pixel_vertex),
            chart_size: layout.n,
        }
    }

    /// Width in pixels.
    pub fn width(&self) -> u32 {
        self.width
    }

    /// Height in pixels.
    pub fn height(&self) -> u32 {
        self.height
    }

    /// Row-major pixel values in [0, 255].
    pub fn values(&self) -> &[f64] {
        &self.values
    }

    /// Value at column `x`, row `y`.
    ///
    /// # Panics
    /// If (x, y) is outside the image.
    pub fn value(&self, x: u32, y: u32) -> f64 {
        assert!(
            x < self.width && y < self.height,
            "pixel ({x}, {y}) is outside the image"
        );
        self.values[(y * self.width + x) as usize]
    }

    /// The icosahedron vertex shown at column `x`, row `y`.
    ///
    /// # Panics
    /// If (x, y) is outside the image.
    pub fn vertex_at(&self, x: u32, y: u32) -> u32 {
        assert!(
            x < self.width && y < self.height,
            "pixel ({x}, {y}) is outside the image"
        );
        self.pixel_vertex[(y * self.width + x) as usize]
    }

    /// Row-major vertex index of every pixel.
    pub fn pixel_vertices(&self) -> &[u32] {
        &self.pixel_vertex
    }

    /// Whether (x, y) lies inside a chart rather than in the copied one-pixel border.
    pub fn is_chart_pixel(&self, x: u32, y: u32) -> bool {
        is_chart_pixel(self.chart_size, x, y)
    }

    /// The values rounded to 8-bit grey levels, row-major.
    pub fn to_gray8(&self) -> Vec<u8> {
        self.values
            .iter()
            .map(|v| v.round().clamp(0.0, 255.0) as u8)
            .collect()
    }

    /// Encodes the image as an 8-bit greyscale PNG into `writer`.
    ///
    /// # Errors
    /// [`FastGaError::Png`] if encoding or writing fails.
    #[cfg(feature = "png")]
    pub fn write_png_to<W: Write>(&self, writer: W) -> Result<(), FastGaError> {
        let mut encoder = png::Encoder::new(writer, self.width, self.height);
        encoder.set_color(png::ColorType::Grayscale);
        encoder.set_depth(png::BitDepth::Eight);
        let mut png_writer = encoder.write_header()?;
        png_writer.write_image_data(&self.to_gray8())?;
        png_writer.finish()?;
        Ok(())
    }

    /// Writes the image as an 8-bit greyscale PNG file at `path`, atomically: the encoded
    /// image goes to a temporary file beside `path` (`.<name>.<process id>.<n>.tmp`), is
    /// flushed to disk and renamed over `path`. A reader sees the old file or the new one; a
    /// write that fails leaves the old file as it was and no temporary file. A symbolic link
    /// at `path` is replaced, not followed.
    ///
    /// # Errors
    /// [`FastGaError::Png`] if encoding fails (nothing is written then), [`FastGaError::Io`]
    /// if the temporary file cannot be created or written or cannot replace `path` (a missing
    /// directory, a directory at `path`).
    #[cfg(feature = "png")]
    pub fn write_png(&self, path: impl AsRef<Path>) -> Result<(), FastGaError> {
        let path = path.as_ref();
        let mut bytes = Vec::new();
        self.write_png_to(&mut bytes)?;
        png_file::write_atomically(path, &bytes).map_err(|source| FastGaError::Io {
            path: path.to_path_buf(),
            source,
        })
    }
}

/// The atomic file write behind [`UnwrappedImage::write_png`].
#[cfg(feature = "png")]
mod png_file {
    use std::fs::{File, OpenOptions};
    use std::io::{self, Write};
    use std::path::{Path, PathBuf};
    use std::sync::atomic::{AtomicU64, Ordering};

    /// Temporary names tried before giving up (a name is taken only when an earlier process
    /// with the same id left its temporary file behind).
    const NAME_ATTEMPTS: u32 = 16;

    /// Makes the temporary names of one process distinct across calls and threads.
    static NEXT_TEMP: AtomicU64 = AtomicU64::new(0);

    /// Writes `bytes` to a new temporary file beside `path`, flushes it to disk and renames
    /// it over `path`; on any failure the temporary file is removed.
    pub(super) fn write_atomically(path: &Path, bytes: &[u8]) -> io::Result<()> {
        let (mut file, temp) = create_temp(path)?;
        let written = file.write_all(bytes).and_then(|()| file.sync_all());
        drop(file);
        let result = written.and_then(|()| std::fs::rename(&temp, path));
        if result.is_err() {
            // The write's error is the one reported; removing the temporary file is all
            // that can be done about it.
            let _ = std::fs::remove_file(&temp);
        }
        result
    }

    /// Creates a temporary file that did not exist before, in the directory of `path`.
    fn create_temp(path: &Path) -> io::Result<(File, PathBuf)> {
        let name = path.file_name().ok_or_else(|| {
            io::Error::new(io::ErrorKind::InvalidInput, "the path does not name a file")
        })?;
        let dir = path.parent().unwrap_or_else(|| Path::new(""));
        let mut taken = io::Error::from(io::ErrorKind::AlreadyExists);
        for _ in 0..NAME_ATTEMPTS {
            let n = NEXT_TEMP.fetch_add(1, Ordering::Relaxed);
            let temp = dir.join(format!(
                ".{}.{}.{n}.tmp",
                name.to_string_lossy(),
                std::process::id()
            ));
            match OpenOptions::new().write(true).create_new(true).open(&temp) {
                Ok(file) => return Ok((file, temp)),
                Err(e) if e.kind() == io::ErrorKind::AlreadyExists => taken = e,
                Err(e) => return Err(e),
            }
        }
        Err(taken)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::Icosahedron;

    #[test]
    fn size_matches_the_paper_at_level_4() {
        let layout = ImageLayout::new(4);
        assert_eq!((layout.width, layout.height), (90, 34));
    }

    #[test]
    fn every_vertex_but_the_poles_is_in_exactly_one_chart_pixel() {
        for level in 0..=4 {
            let layout = ImageLayout::new(level);
            let mut seen = vec![0; Lattice::new(level).vertex_count()];
            for y in 0..layout.height {
                for x in 0..layout.width {
                    if layout.is_chart_pixel(x, y) {
                        seen[layout.pixel_vertex[(y * layout.width + x) as usize] as usize] += 1;
                    }
                }
            }
            assert_eq!(seen[NORTH_POLE as usize], 0);
            assert_eq!(seen[SOUTH_POLE as usize], 0);
            assert!(seen[2..].iter().all(|&k| k == 1));
        }
    }

    /// The 3×3 window of each chart pixel holds its six lattice neighbours, each a neighbour on
    /// the sphere, and together with the two remaining corners all its neighbours on the sphere.
    #[test]
    fn windows_see_the_neighbours_on_the_sphere() {
        const LATTICE_STEPS: [(i64, i64); 6] = [(1, 0), (0, 1), (-1, 1), (-1, 0), (0, -1), (1, -1)];
        for level in 0..=4 {
            let ico = Icosahedron::new(level).unwrap();
            let layout = ImageLayout::new(level);
            let at =
                |x: i64, y: i64| layout.pixel_vertex[(y * i64::from(layout.width) + x) as usize];
            for y in 0..layout.height {
                for x in 0..layout.width {
                    if !layout.is_chart_pixel(x, y) {
                        continue;
                    }
                    let (x, y) = (i64::from(x), i64::from(y));
                    let v = at(x, y);
                    let ring = ico.vertex_neighbors(v);
                    for (dx, dy) in LATTICE_STEPS {
                        let w = at(x + dx, y + dy);
                        assert!(
                            ring.contains(&w),
                            "level {level} pixel ({x},{y}) step ({dx},{dy})"
                        );
                    }
                    let mut window: Vec<u32> = (-1..=1)
                        .flat_map(|dy| (-1..=1).map(move |dx| (dx, dy)))
                        .map(|(dx, dy)| at(x + dx, y + dy))
                        .collect();
                    window.sort_unstable();
                    assert!(ring.iter().all(|w| window.binary_search(w).is_ok()));
                }
            }
        }
    }

    #[cfg(feature = "png")]
    #[test]
    fn png_round_trips_through_the_encoder() {
        let layout = ImageLayout::new(2);
        let values: Vec<f64> = (0..Lattice::new(2).vertex_count())
            .map(|v| v as f64)
            .collect();
        let image = UnwrappedImage::new(&layout, &values);
        let mut bytes = Vec::new();
        image.write_png_to(&mut bytes).unwrap();
        assert_eq!(&bytes[1..4], b"PNG");
        assert!(image.values().iter().all(|v| (0.0..=255.0).contains(v)));
    }
}

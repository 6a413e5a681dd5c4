//! Texture generation (§V, Alg. 1–2): a picture of the plane at `r` texels per unit
//! length, each texel inside the polygon coloured by its nearest point
//! (ties to the point listed first).

use rayon::prelude::*;

use crate::PlanarMeshError;
use crate::nearest::PointGrid;
use crate::polygon::Polygon2;

/// How many texels per unit length (per metre for metric input) a texture gets.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Resolution {
    /// This many texels per unit length (the paper's `r`; it uses 100 per metre).
    PerUnit(f64),
    /// One texel per point spacing: `sqrt(points / polygon area)` per unit length.
    FromDensity,
}

impl Default for Resolution {
    fn default() -> Self {
        Resolution::PerUnit(DEFAULT_TEXELS_PER_UNIT)
    }
}

/// The paper's resolution factor: 100 texels per metre.
pub const DEFAULT_TEXELS_PER_UNIT: f64 = 100.0;

/// Texture settings.
#[derive(Debug, Clone, Copy, PartialEq)]
#[non_exhaustive]
pub struct TextureOptions {
    /// Texels per unit length.
    pub resolution: Resolution,
    /// Largest width or height in texels; a larger plane gets a coarser texture.
    pub max_size: u32,
    /// Texels outside the polygon but next to it (8-neighbourhood) are coloured too, so
    /// that filtering at the mesh's edge does not blend in black. Alg. 1 leaves them black
    /// (`false`).
    pub bleed: bool,
}

impl Default for TextureOptions {
    fn default() -> Self {
        Self {
            resolution: Resolution::default(),
            max_size: 4096,
            bleed: true,
        }
    }
}

impl TextureOptions {
    /// The defaults: 100 texels per unit, at most 4096 × 4096, one texel of bleed.
    pub fn new() -> Self {
        Self::default()
    }

    /// Sets the resolution.
    pub fn with_resolution(mut self, resolution: Resolution) -> Self {
        self.resolution = resolution;
        self
    }

    /// Sets the largest side in texels.
    pub fn with_max_size(mut self, max_size: u32) -> Self {
        self.max_size = max_size;
        self
    }

    /// Sets whether texels next to the polygon are coloured.
    pub fn with_bleed(mut self, bleed: bool) -> Self {
        self.bleed = bleed;
        self
    }

    pub(crate) fn validate(&self) -> Result<(), PlanarMeshError> {
        if let Resolution::PerUnit(r) = self.resolution
            && !(r.is_finite() && r > 0.0)
        {
            return Err(PlanarMeshError::BadOption {
                name: "resolution",
                value: r,
                expected: "texels per unit length, finite and > 0",
            });
        }
        if self.max_size == 0 {
            return Err(PlanarMeshError::BadOption {
                name: "max_size",
                value: 0.0,
                expected: "at least 1 texel",
            });
        }
        Ok(())
    }
}

/// An RGB texture of one plane. Texel `(col, row)` (row 0 at the top) covers plane
/// coordinates `x ∈ origin.x + [col, col + 1] / texels_per_unit` and
/// `y ∈ origin.y + [height − row − 1, height − row] / texels_per_unit`.
#[derive(Debug, Clone, PartialEq)]
pub struct Texture {
    /// Width in texels.
    pub width: u32,
    /// Height in texels.
    pub height: u32,
    /// Row-major RGB bytes, top row first.
    pub rgb: Vec<u8>,
    /// Plane coordinates of the texture's lower-left corner.
    pub origin: [f64; 2],
    /// Texels per unit length.
    pub texels_per_unit: f64,
    /// Texels inside the polygon (coloured by Alg. 1; bleed texels not counted).
    pub inside: usize,
}

impl Texture {
    /// Texture coordinates of plane point `p` (Alg. 2): `u` rightwards, `v` upwards, both
    /// 0–1 over the texture.
    #[inline]
    pub fn uv(&self, p: [f64; 2]) -> [f64; 2] {
        [
            (p[0] - self.origin[0]) * self.texels_per_unit / f64::from(self.width),
            (p[1] - self.origin[1]) * self.texels_per_unit / f64::from(self.height),
        ]
    }

    /// Plane coordinates of the centre of texel `(col, row)`.
    #[inline]
    pub fn texel_center(&self, col: u32, row: u32) -> [f64; 2] {
        [
            self.origin[0] + (f64::from(col) + 0.5) / self.texels_per_unit,
            self.origin[1] + (f64::from(self.height - row) - 0.5) / self.texels_per_unit,
        ]
    }

    /// The colour of texel `(col, row)` (black outside the texture).
    pub fn texel(&self, col: u32, row: u32) -> [u8; 3] {
        if col >= self.width || row >= self.height {
            return [0; 3];
        }
        let i = 3 * (row as usize * self.width as usize + col as usize);
        [self.rgb[i], self.rgb[i + 1], self.rgb[i + 2]]
    }

    /// The colour at texture coordinates `uv` (nearest texel).
    pub fn sample(&self, uv: [f64; 2]) -> [u8; 3] {
        let col = (uv[0] * f64::from(self.width)).floor();
        let row = ((1.0 - uv[1]) * f64::from(self.height)).floor();
        let clamp = |v: f64, n: u32| v.clamp(0.0, f64::from(n.saturating_sub(1))) as u32;
        self.texel(clamp(col, self.width), clamp(row, self.height))
    }
}

/// The texels per unit length `resolution` gives for this polygon and point count, capped
/// so that neither side exceeds `max_size`.
fn texels_per_unit(options: &TextureOptions, polygon: &Polygon2, points: usize) -> f64 {
    let [lo, hi] = polygon.bbox;
    let extent = (hi[0] - lo[0]).max(hi[1] - lo[1]);
    let wanted = match options.resolution {
        Resolution::PerUnit(r) => r,
        Resolution::FromDensity => (points as f64 / polygon.area().max(f64::MIN_POSITIVE)).sqrt(),
    };
    let cap = f64::from(options.max_size.saturating_sub(1).max(1)) / extent.max(f64::MIN_POSITIVE);
    wanted.min(cap)
}

/// The texture of `polygon` from `points` (plane coordinates) and their `colors`.
///
/// # Errors
/// [`PlanarMeshError::TooFewPoints`] without points.
pub(crate) fn generate(
    polygon: &Polygon2,
    points: &[[f64; 2]],
    colors: &[[u8; 3]],
    options: &TextureOptions,
) -> Result<Texture, PlanarMeshError> {
    let r = texels_per_unit(options, polygon, points.len());
    let [lo, hi] = polygon.bbox;
    let size = |span: f64| ((span * r).ceil().max(1.0) as u32).min(options.max_size.max(1));
    let (width, height) = (size(hi[0] - lo[0]), size(hi[1] - lo[1]));
    let mut texture = Texture {
        width,
        height,
        rgb: vec![0; 3 * width as usize * height as usize],
        origin: lo,
        texels_per_unit: r,
        inside: 0,
    };
    let w = width as usize;
    // Alg. 1's "inside H" by scanlines: 1 inside, 2 bleed.
    let mut mask = vec![0u8; w * height as usize];
    mask.par_chunks_mut(w)
        .enumerate()
        .for_each_init(Vec::new, |xs, (row, line)| {
            let y = texture.texel_center(0, row as u32)[1];
            polygon.crossings(y, xs);
            for span in xs.chunks_exact(2) {
                let first = ((span[0] - lo[0]) * r - 0.5).ceil().max(0.0) as usize;
                let last = ((span[1] - lo[0]) * r - 0.5).floor();
                if last < 0.0 {
                    continue;
                }
                for m in line.iter_mut().take((last as usize + 1).min(w)).skip(first) {
                    *m = 1;
                }
            }
        });
    texture.inside = mask.iter().filter(|&&m| m == 1).count();
    if options.bleed {
        bleed(&mut mask, w, height as usize);
    }
    let grid = texel_grid(points, polygon.area(), lo, r).ok_or(PlanarMeshError::TooFewPoints(0))?;
    let mut rgb = std::mem::take(&mut texture.rgb);
    let centre = |col: usize, row: usize| texture.texel_center(col as u32, row as u32);
    rgb.par_chunks_mut(3 * w)
        .zip(mask.par_chunks(w))
        .enumerate()
        .for_each(|(row, (line, m))| {
            for (col, texel) in line.chunks_exact_mut(3).enumerate() {
                if m[col] != 0 {
                    let nearest = grid.nearest(centre(col, row));
                    texel.copy_from_slice(&colors[nearest as usize]);
                }
            }
        });
    texture.rgb = rgb;
    Ok(texture)
}

/// Points per grid cell [`texel_grid`] aims at.
const POINTS_PER_CELL: f64 = 3.0;

/// The points bucketed for the texels' queries. Where there is at least a point per texel,
/// the cells are texels divided into an odd number `m × m` of cells of about
/// [`POINTS_PER_CELL`] points each, so that each texel's centre is the centre of a cell and
/// most searches end in that cell. Sparser points get cells of about two points each,
/// wherever they fall.
fn texel_grid(points: &[[f64; 2]], area: f64, origin: [f64; 2], r: f64) -> Option<PointGrid> {
    let per_texel = points.len() as f64 / (area * r * r);
    if per_texel >= 1.0 {
        let m = 2.0
            * ((per_texel / POINTS_PER_CELL).sqrt() / 2.0 - 0.5)
                .round()
                .max(0.0)
            + 1.0;
        if let Some(grid) = PointGrid::on_lattice(points, origin, 1.0 / (m * r)) {
            return Some(grid);
        }
    }
    PointGrid::new(points, area, 2.0)
}

/// Marks (2) every unmarked texel with a marked (1) 8-neighbour: the marked texels grown
/// by a column each way, row by row, then by a row each way.
fn bleed(mask: &mut [u8], w: usize, h: usize) {
    let mut wide = vec![0u8; w * h];
    for (src, dst) in mask.chunks_exact(w).zip(wide.chunks_exact_mut(w)) {
        for col in 0..w {
            let (left, right) = (col.saturating_sub(1), (col + 1).min(w - 1));
            dst[col] = u8::from(src[left] == 1 || src[col] == 1 || src[right] == 1);
        }
    }
    for row in 0..h {
        let (up, down) = (row.saturating_sub(1) * w, (row + 1).min(h - 1) * w);
        let at = row * w;
        for col in 0..w {
            if mask[at + col] == 0 && (wide[up + col] | wide[at + col] | wide[down + col]) != 0 {
                mask[at + col] = 2;
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Bleed marks exactly the unmarked texels with a marked 8-neighbour, on masks of
    /// every small size, borders included.
    #[test]
    fn bleed_marks_the_8_neighbours_of_marked_texels() {
        let mut state = 5u64;
        for (w, h) in [(1, 1), (1, 5), (6, 1), (2, 2), (7, 4), (13, 9)] {
            for _ in 0..20 {
                let mask: Vec<u8> = (0..w * h)
                    .map(|_| {
                        state = state
                            .wrapping_mul(6_364_136_223_846_793_005)
                            .wrapping_add(1_442_695_040_888_963_407);
                        u8::from(state >> 61 == 0)
                    })
                    .collect();
                let mut got = mask.clone();
                bleed(&mut got, w, h);
                for row in 0..h {
                    for col in 0..w {
                        let near = (row.saturating_sub(1)..=(row + 1).min(h - 1)).any(|r| {
                            (col.saturating_sub(1)..=(col + 1).min(w - 1))
                                .any(|c| mask[r * w + c] == 1)
                        });
                        let i = row * w + col;
                        let want = if mask[i] == 1 { 1 } else { 2 * u8::from(near) };
                        assert_eq!(got[i], want, "{w}×{h} at ({col}, {row})");
                    }
                }
            }
        }
    }
}

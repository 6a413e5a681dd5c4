//! The organized range image of a rotating scan: one row per beam, one column per azimuth
//! step, NaN where the sensor got no return.

use std::f64::consts::{PI, TAU};

use rayon::prelude::*;

use crate::rings::{PARALLEL_CHUNK, azimuth};
use crate::{Rings, ScanError};

/// Marks a pixel with no point in [`RangeImage::source`].
pub const NO_POINT: u32 = u32::MAX;

/// A `rows × cols` range image rebuilt from a rotating scan: row `r` is beam `r` of the
/// [`Rings`] (the top beam first for KITTI), column `c` the azimuth step `c` turning
/// clockwise seen from above (to the right, seen from the sensor) from straight behind, so
/// that straight ahead is the middle column. It reads like a panoramic camera picture.
///
/// Two points of one beam that fall in one pixel keep the nearer (the other is reported in
/// [`Self::collisions`]); pixels without a point are NaN.
///
/// ```
/// use rotating_scan::{RangeImage, Rings};
/// // One beam, 8 samples round the sensor at 45° steps.
/// let points: Vec<[f64; 3]> = (0..8)
///     .map(|k| { let a = (k as f64 * 45.0_f64).to_radians(); [5.0 * a.cos(), 5.0 * a.sin(), -1.0] })
///     .collect();
/// let rings = Rings::from_members(&[(0..8).collect()], 8)?;
/// let image = RangeImage::build(&points, &rings, 8)?;
/// assert_eq!((image.rows, image.cols), (1, 8));
/// assert_eq!(image.source[4], 0); // straight ahead: the middle column
/// assert_eq!(image.collisions, 0);
/// # Ok::<(), rotating_scan::ScanError>(())
/// ```
#[derive(Debug, Clone, PartialEq)]
pub struct RangeImage {
    /// Rows (beams).
    pub rows: usize,
    /// Columns (azimuth steps over a full turn).
    pub cols: usize,
    /// Row-major points, NaN where there is none.
    pub points: Vec<[f64; 3]>,
    /// Index of each pixel's point in the scan, [`NO_POINT`] where there is none.
    pub source: Vec<u32>,
    /// Points left out because a nearer point of their beam took their pixel.
    pub collisions: usize,
}

impl RangeImage {
    /// Rebuilds the image of `rings` of `points` with `cols` columns over a full turn
    /// (`0`: the median number of points per non-empty beam, which suits a scan with all
    /// its azimuths; fewer columns than points per beam merge neighbours, more leave gaps).
    ///
    /// # Errors
    /// [`ScanError::MemberOutOfRange`] when a ring refers past `points`,
    /// [`ScanError::Parameter`] for an image over 2³² pixels or without columns.
    pub fn build(points: &[[f64; 3]], rings: &Rings, cols: usize) -> Result<Self, ScanError> {
        let rows = rings.len();
        let cols = if cols == 0 {
            median_ring_size(rings)
        } else {
            cols
        };
        let pixels = rows.checked_mul(cols).filter(|&n| n < NO_POINT as usize);
        let Some(pixels) = pixels.filter(|_| cols > 0) else {
            return Err(ScanError::Parameter {
                field: "range image size",
                value: format!("{rows} × {cols}"),
                reason: "needs at least one column and fewer than 2^32 pixels",
            });
        };
        rings.check_members(points.len())?;
        // Row r holds beam r only: the rows are filled in parallel.
        let mut source = vec![NO_POINT; pixels];
        let rings: Vec<&[u32]> = rings.iter().collect();
        let collisions = source
            .par_chunks_mut(cols)
            .zip(rings.par_iter())
            .map_init(Vec::new, |range2, (row, ring)| {
                fill_row(points, ring, row, range2)
            })
            .sum();
        let nan = [f64::NAN; 3];
        let points = source
            .par_iter()
            .with_min_len(PARALLEL_CHUNK)
            .map(|&i| points.get(i as usize).copied().unwrap_or(nan))
            .collect();
        Ok(Self {
            rows,
            cols,
            points,
            source,
            collisions,
        })
    }

    /// Number of pixels with a point.
    pub fn valid(&self) -> usize {
        self.source.iter().filter(|&&i| i != NO_POINT).count()
    }
}

/// Fills one row of the image (`row`: its pixels' sources, all [`NO_POINT`]) with the
/// points of one beam, the nearest kept where two share a pixel; `range2` is scratch space.
/// Returns the points left out for a nearer one. Members past `points` are skipped (the
/// caller has refused them).
fn fill_row(points: &[[f64; 3]], ring: &[u32], row: &mut [u32], range2: &mut Vec<f64>) -> usize {
    let cols = row.len();
    range2.clear();
    range2.resize(cols, f64::INFINITY);
    let scale = cols as f64 / TAU;
    let mut collisions = 0;
    for &i in ring {
        let Some(p) = points.get(i as usize) else {
            continue;
        };
        // Clockwise from straight behind: azimuth π → 0, 0 → cols / 2.
        let turn = (PI - azimuth(p)).rem_euclid(TAU);
        let c = ((turn * scale) as usize).min(cols - 1);
        let d2 = p[0] * p[0] + p[1] * p[1] + p[2] * p[2];
        if row[c] != NO_POINT {
            collisions += 1;
            if d2 >= range2[c] {
                continue;
            }
        }
        row[c] = i;
        range2[c] = d2;
    }
    collisions
}

fn median_ring_size(rings: &Rings) -> usize {
    let mut sizes: Vec<usize> = rings.iter().map(<[u32]>::len).filter(|&n| n > 0).collect();
    if sizes.is_empty() {
        return 0;
    }
    let mid = sizes.len() / 2;
    *sizes.select_nth_unstable(mid).1
}

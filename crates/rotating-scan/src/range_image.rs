//! The organized range image of a rotating scan: one row per beam, one column per azimuth
//! step, NaN where the sensor got no return.

use std::f64::consts::{PI, TAU};

use crate::rings::azimuth;
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
        let mut source = vec![NO_POINT; pixels];
        let mut range2 = vec![f64::INFINITY; pixels];
        let mut collisions = 0;
        let scale = cols as f64 / TAU;
        for (r, ring) in rings.iter().enumerate() {
            for &i in ring {
                let Some(p) = points.get(i as usize) else {
                    return Err(ScanError::MemberOutOfRange {
                        index: i,
                        points: points.len(),
                    });
                };
                // Clockwise from straight behind: azimuth π → 0, 0 → cols / 2.
                let turn = (PI - azimuth(p)).rem_euclid(TAU);
                let c = ((turn * scale) as usize).min(cols - 1);
                let pixel = r * cols + c;
                let d2 = p[0] * p[0] + p[1] * p[1] + p[2] * p[2];
                if source[pixel] != NO_POINT {
                    collisions += 1;
                    if d2 >= range2[pixel] {
                        continue;
                    }
                }
                source[pixel] = i;
                range2[pixel] = d2;
            }
        }
        let nan = [f64::NAN; 3];
        let points = source
            .iter()
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

fn median_ring_size(rings: &Rings) -> usize {
    let mut sizes: Vec<usize> = rings.iter().map(<[u32]>::len).filter(|&n| n > 0).collect();
    if sizes.is_empty() {
        return 0;
    }
    let mid = sizes.len() / 2;
    *sizes.select_nth_unstable(mid).1
}

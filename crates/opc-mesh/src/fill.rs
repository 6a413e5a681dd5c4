//! Filling isolated missing returns of an organized cloud before meshing.
//!
//! Depth cameras drop returns at grazing incidence and at random: a plane seen at a slant
//! comes back riddled with single invalid pixels, each of which removes the six triangles
//! around it, so the plane's mesh falls apart into pieces too small to keep. An invalid
//! pixel surrounded by valid ones that agree in range is put back at their mean; a pixel
//! on a depth jump (neighbours at different ranges) stays invalid.

use rayon::prelude::*;

use crate::{OpcError, OrganizedPointCloud, is_valid};

/// When an invalid pixel is filled ([`OrganizedPointCloud::fill_missing`]).
#[derive(Debug, Clone, Copy, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
#[cfg_attr(feature = "serde", serde(default, deny_unknown_fields))]
#[non_exhaustive]
pub struct FillConfig {
    /// Valid pixels needed among the 8 around it, 1–8. Default 4.
    pub min_neighbours: u8,
    /// Largest spread of those neighbours' ranges (distance from the origin), as a share
    /// of the smallest: they must lie on one surface. Default 0.03.
    pub max_spread: f64,
}

impl Default for FillConfig {
    fn default() -> Self {
        Self {
            min_neighbours: 4,
            max_spread: 0.03,
        }
    }
}

impl FillConfig {
    /// Sets [`Self::min_neighbours`].
    pub fn with_min_neighbours(mut self, min_neighbours: u8) -> Self {
        self.min_neighbours = min_neighbours;
        self
    }

    /// Sets [`Self::max_spread`].
    pub fn with_max_spread(mut self, max_spread: f64) -> Self {
        self.max_spread = max_spread;
        self
    }

    /// Checks the ranges [`OrganizedPointCloud::fill_missing`] needs (outside them it
    /// fills nothing).
    ///
    /// ```
    /// use opc_mesh::{FillConfig, OpcError};
    ///
    /// assert!(FillConfig::default().validate().is_ok());
    /// let error = FillConfig::default().with_min_neighbours(9).validate().unwrap_err();
    /// assert!(matches!(error, OpcError::InvalidParameter { name: "min_neighbours", .. }));
    /// ```
    ///
    /// # Errors
    /// [`OpcError::InvalidParameter`] naming the first field out of range.
    pub fn validate(&self) -> Result<(), OpcError> {
        if !(1..=8).contains(&self.min_neighbours) {
            return Err(OpcError::InvalidParameter {
                name: "min_neighbours",
                value: self.min_neighbours.to_string(),
                expected: "1 to 8",
            });
        }
        if !(self.max_spread.is_finite() && self.max_spread >= 0.0) {
            return Err(OpcError::InvalidParameter {
                name: "max_spread",
                value: self.max_spread.to_string(),
                expected: "a finite share ≥ 0",
            });
        }
        Ok(())
    }
}

impl OrganizedPointCloud {
    /// Fills every invalid pixel (not on the image border) that has at least
    /// `options.min_neighbours` valid pixels among its 8 neighbours whose ranges spread by
    /// at most `options.max_spread` of the nearest: it takes their mean. Only the original
    /// valid pixels count, so the result does not depend on the order of filling (rows run
    /// in parallel on the rayon pool). Returns which pixels were filled (one flag per
    /// point); options out of range fill nothing.
    ///
    /// ```
    /// use opc_mesh::{FillConfig, OrganizedPointCloud};
    ///
    /// // A 3 × 3 patch of a wall 2 m away with its centre missing.
    /// let mut points: Vec<[f64; 3]> =
    ///     (0..9).map(|i| [(i % 3) as f64 * 0.01, (i / 3) as f64 * 0.01, 2.0]).collect();
    /// points[4] = [f64::NAN; 3];
    /// let mut cloud = OrganizedPointCloud::new(3, 3, points)?;
    /// let filled = cloud.fill_missing(&FillConfig::default());
    /// assert_eq!(filled.iter().filter(|&&f| f).count(), 1);
    /// assert_eq!(cloud.point(1, 1), [0.01, 0.01, 2.0]);
    /// # Ok::<(), Box<dyn std::error::Error>>(())
    /// ```
    pub fn fill_missing(&mut self, options: &FillConfig) -> Vec<bool> {
        let (rows, cols) = (self.rows(), self.cols());
        let mut filled = vec![false; rows * cols];
        if options.validate().is_err() || rows < 3 || cols < 3 {
            return filled;
        }
        let points = self.points();
        let fills: Vec<(usize, [f64; 3])> = (1..rows - 1)
            .into_par_iter()
            .with_min_len(16)
            .flat_map_iter(|r| {
                (1..cols - 1).filter_map(move |c| {
                    let i = r * cols + c;
                    if is_valid(&points[i]) {
                        return None;
                    }
                    fill_value(points, cols, r, c, options).map(|p| (i, p))
                })
            })
            .collect();
        let points = self.points_mut();
        for (i, p) in fills {
            points[i] = p;
            filled[i] = true;
        }
        filled
    }
}

/// The mean of the valid 8-neighbours of pixel `(r, c)` if there are enough of them and
/// their ranges agree.
fn fill_value(
    points: &[[f64; 3]],
    cols: usize,
    r: usize,
    c: usize,
    options: &FillConfig,
) -> Option<[f64; 3]> {
    let mut count = 0u8;
    let mut sum = [0.0; 3];
    let (mut near, mut far) = (f64::INFINITY, 0.0f64);
    for row in points[(r - 1) * cols..(r + 2) * cols].chunks_exact(cols) {
        for q in &row[c - 1..c + 2] {
            if !is_valid(q) {
                continue;
            }
            count += 1;
            for (s, v) in sum.iter_mut().zip(q) {
                *s += v;
            }
            let range = (q[0] * q[0] + q[1] * q[1] + q[2] * q[2]).sqrt();
            near = near.min(range);
            far = far.max(range);
        }
    }
    (count >= options.min_neighbours && far - near <= options.max_spread * near)
        .then(|| sum.map(|s| s / f64::from(count)))
}

#[cfg(test)]
mod tests {
    #![allow(clippy::unwrap_used)]

    use super::*;

    fn wall(rows: usize, cols: usize, depth: impl Fn(usize, usize) -> f64) -> Vec<[f64; 3]> {
        (0..rows * cols)
            .map(|i| {
                let (r, c) = (i / cols, i % cols);
                [c as f64 * 0.01, r as f64 * 0.01, depth(r, c)]
            })
            .collect()
    }

    #[test]
    fn isolated_holes_on_a_plane_are_filled_onto_it() {
        // A tilted plane z = 2 + 0.1 x with every fifth pixel missing.
        let mut points = wall(20, 20, |_, c| 2.0 + 0.001 * c as f64);
        let holes: Vec<usize> = (0..400).filter(|i| i % 5 == 2).collect();
        for &i in &holes {
            points[i] = [f64::NAN; 3];
        }
        let mut cloud = OrganizedPointCloud::new(20, 20, points).unwrap();
        let filled = cloud.fill_missing(&FillConfig::default());
        for (i, p) in cloud.points().iter().enumerate() {
            let (r, c) = (i / 20, i % 20);
            let border = r == 0 || c == 0 || r == 19 || c == 19;
            assert_eq!(filled[i], holes.contains(&i) && !border, "pixel {i}");
            if filled[i] {
                // The mean of points on a plane lies on it.
                assert!((p[2] - (2.0 + 0.1 * p[0])).abs() < 1e-12, "{p:?}");
            }
        }
    }

    #[test]
    fn holes_on_a_depth_jump_or_with_few_neighbours_stay() {
        // A step from 2 m to 3 m between columns 4 and 5; the pixel at the step is missing.
        let mut points = wall(5, 10, |_, c| if c < 5 { 2.0 } else { 3.0 });
        points[2 * 10 + 5] = [f64::NAN; 3];
        // Far from the step, a missing pixel with only three valid neighbours.
        for i in [11, 12, 13, 21, 22, 23] {
            points[i] = [f64::NAN; 3];
        }
        let mut cloud = OrganizedPointCloud::new(5, 10, points).unwrap();
        let filled = cloud.fill_missing(&FillConfig::default());
        assert!(!filled[25]);
        assert!(!filled[22]);
        assert!(!is_valid(&cloud.points()[25]));
        // With three neighbours enough (and those filled before now counting), it fills;
        // the step still does not.
        let options = FillConfig {
            min_neighbours: 3,
            ..FillConfig::default()
        };
        let filled = cloud.fill_missing(&options);
        assert!(filled[22]);
        assert!(!filled[25]);
    }

    #[test]
    fn options_out_of_range_fill_nothing() {
        let mut points = wall(3, 3, |_, _| 1.0);
        points[4] = [f64::NAN; 3];
        let mut cloud = OrganizedPointCloud::new(3, 3, points).unwrap();
        for options in [
            FillConfig {
                min_neighbours: 0,
                ..FillConfig::default()
            },
            FillConfig {
                min_neighbours: 9,
                ..FillConfig::default()
            },
            FillConfig {
                max_spread: f64::NAN,
                ..FillConfig::default()
            },
        ] {
            assert!(cloud.fill_missing(&options).iter().all(|f| !f));
        }
    }
}

//! Organized clouds: merging blocks of pixels before the pipeline runs
//! ([`Config::decimate`](crate::Config::decimate)), and mapping the labels of the coarser
//! grid back onto the input's pixels.

use opc_mesh::{OpcError, OrganizedPointCloud, OrganizedPointCloudView};
use rayon::prelude::*;
use serde::{Deserialize, Serialize};

use crate::PolylidarError;
use crate::config::{deserialize_count_or_auto, serialize_count_or_auto};

/// How an organized cloud is decimated before smoothing and meshing: each `f × f` block
/// of pixels becomes one point, the robust mean of
/// [`OrganizedPointCloud::decimate`](opc_mesh::OrganizedPointCloud::decimate).
///
/// Polylidar3D's RealSense parameters (the `rgbd` preset) were chosen for the D435i's
/// depth sampled at 424 × 240 and decimated by 2 by the SDK (212 × 120): at a camera's
/// full resolution the same pixel neighbourhoods see more noise against the point
/// spacing and every stage costs four to nine times as much. `"auto"` decimates to about
/// 424 columns: on the synthetic RGB-D suite (Table 10b of `cargo xtask bench`) that
/// found more planes than the full resolution, and decimating to the paper's 212
/// instead found fewer at 640 × 480 and 848 × 480 and labelled far fewer points right.
///
/// ```
/// use polylidar::{DecimateConfig, DecimateFactor};
///
/// let auto = DecimateConfig::default();
/// assert_eq!(auto.factor, DecimateFactor::Auto);
/// assert_eq!(auto.factor_for(480, 640), 2); // Kinect, ICL-NUIM, TUM
/// assert_eq!(auto.factor_for(480, 848), 2); // RealSense D435
/// assert_eq!(auto.factor_for(240, 424), 1); // already at the working width
/// assert_eq!(auto.factor_for(720, 1280), 3);
/// let fixed: DecimateConfig = toml::from_str("factor = 4").unwrap();
/// assert_eq!(fixed.factor_for(480, 640), 4);
/// ```
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
#[non_exhaustive]
pub struct DecimateConfig {
    /// The block side in pixels, 1 (no decimation) to 16, or `"auto"`.
    pub factor: DecimateFactor,
    /// With `"auto"`: the width to decimate to, in pixels; the factor is the whole
    /// number (at least 1) nearest to `cols / target_columns`. Default 424.
    pub target_columns: u32,
    /// A block's point averages the pixels whose range lies within this share of its
    /// median pixel's range (pixels beyond lie across a depth jump). Default 0.02.
    pub range_tolerance: f64,
}

/// The block side of [`DecimateConfig`]: a count, or chosen from the frame's width. In
/// TOML and JSON a number or the string `"auto"`.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum DecimateFactor {
    /// Blocks of this side (1: none).
    Fixed(u32),
    /// The factor that brings the width nearest to [`DecimateConfig::target_columns`].
    Auto,
}

/// Largest [`DecimateFactor::Fixed`] factor.
pub const MAX_DECIMATE_FACTOR: u32 = 16;

impl Default for DecimateConfig {
    fn default() -> Self {
        Self {
            factor: DecimateFactor::Auto,
            target_columns: 424,
            range_tolerance: 0.02,
        }
    }
}

impl DecimateConfig {
    /// Sets [`Self::factor`].
    #[must_use]
    pub fn with_factor(mut self, factor: DecimateFactor) -> Self {
        self.factor = factor;
        self
    }

    /// Sets [`Self::target_columns`] (with `"auto"`: the width to decimate to). The
    /// paper's D435i frames, sampled at 424 × 240, were decimated by 2 to 212 × 120 by
    /// the RealSense SDK before Polylidar3D saw them; `with_target_columns(212)` works on
    /// that grid (faster, and fewer small planes found: Tables 8 and 10b of
    /// `cargo xtask bench`).
    ///
    /// ```
    /// use polylidar::DecimateConfig;
    /// let paper = DecimateConfig::default().with_target_columns(212);
    /// assert_eq!(paper.factor_for(240, 424), 2);
    /// assert_eq!(paper.factor_for(480, 640), 3);
    /// assert_eq!(paper.factor_for(480, 848), 4);
    /// ```
    #[must_use]
    pub fn with_target_columns(mut self, target_columns: u32) -> Self {
        self.target_columns = target_columns;
        self
    }

    /// The block side for a `rows × cols` frame: the fixed factor, or for `"auto"` the
    /// whole number nearest to `cols / target_columns`, at least 1 and small enough to
    /// leave 2 rows and columns.
    pub fn factor_for(&self, rows: usize, cols: usize) -> usize {
        match self.factor {
            DecimateFactor::Fixed(n) => n as usize,
            DecimateFactor::Auto => {
                let target = f64::from(self.target_columns.max(1));
                let nearest = (cols as f64 / target).round() as usize;
                let most = (rows / 2).min(cols / 2).min(MAX_DECIMATE_FACTOR as usize);
                nearest.min(most).max(1)
            }
        }
    }

    /// Checks the ranges.
    ///
    /// # Errors
    /// [`PolylidarError::Config`] naming the field.
    pub fn validate(&self) -> Result<(), PolylidarError> {
        let bad = PolylidarError::config;
        if let DecimateFactor::Fixed(n) = self.factor
            && !(1..=MAX_DECIMATE_FACTOR).contains(&n)
        {
            return bad(
                "decimate.factor",
                n.to_string(),
                "must be 1 to 16 or \"auto\"",
            );
        }
        if self.target_columns < 2 {
            return bad(
                "decimate.target_columns",
                self.target_columns.to_string(),
                "must be at least 2",
            );
        }
        if !(self.range_tolerance.is_finite() && self.range_tolerance >= 0.0) {
            return bad(
                "decimate.range_tolerance",
                self.range_tolerance.to_string(),
                "must be a finite share ≥ 0",
            );
        }
        Ok(())
    }

    /// The decimated cloud, its points written into the buffer `points` gives (asked
    /// for only when the frame is decimated), and how its grid maps onto `input`'s
    /// pixels; or `None` when the factor for this frame is 1.
    pub(crate) fn apply(
        &self,
        input: OrganizedPointCloudView<'_>,
        points: impl FnOnce() -> Vec<[f64; 3]>,
    ) -> Result<Option<(OrganizedPointCloud, Decimation)>, OpcError> {
        let factor = self.factor_for(input.rows(), input.cols());
        if factor <= 1 {
            return Ok(None);
        }
        let decimated = input.decimate_into(factor, self.range_tolerance, points())?;
        let decimation = Decimation {
            factor,
            rows: input.rows(),
            cols: input.cols(),
            members: decimated.members,
            valid_pixels: decimated.valid_pixels,
        };
        Ok(Some((decimated.cloud, decimation)))
    }
}

impl Serialize for DecimateFactor {
    fn serialize<S: serde::Serializer>(&self, serializer: S) -> Result<S::Ok, S::Error> {
        let count = match self {
            Self::Fixed(n) => Some(*n),
            Self::Auto => None,
        };
        serialize_count_or_auto(count, serializer)
    }
}

impl<'de> Deserialize<'de> for DecimateFactor {
    fn deserialize<D: serde::Deserializer<'de>>(deserializer: D) -> Result<Self, D::Error> {
        Ok(
            deserialize_count_or_auto(deserializer, "a block side in pixels")?
                .map_or(Self::Auto, Self::Fixed),
        )
    }
}

/// How the grid of a decimated extraction maps onto the input's pixels
/// ([`crate::Extraction::decimation`]): mesh vertex `(r, c)` stands for the input's
/// pixels `(r · factor .. (r + 1) · factor, c · factor .. (c + 1) · factor)`.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Decimation {
    /// The block side.
    pub factor: usize,
    /// The input's rows.
    pub rows: usize,
    /// The input's columns.
    pub cols: usize,
    /// Which input pixels their block's point averaged, row-major
    /// ([`opc_mesh::Decimated::members`]): valid, and on the surface the point lies on.
    members: Vec<bool>,
    /// The input's valid pixels.
    valid_pixels: usize,
}

impl Decimation {
    /// The input's valid (finite) pixels.
    pub fn valid_pixels(&self) -> usize {
        self.valid_pixels
    }

    /// The input pixels the decimated points averaged (valid, on their block's surface).
    pub fn member_pixels(&self) -> usize {
        self.members.iter().filter(|&&m| m).count()
    }

    /// The label of every input pixel from the labels of the decimated grid's points: a
    /// pixel its block's point averaged takes the block's label; an invalid one, or one
    /// across a depth jump from that point, `-1`.
    pub(crate) fn expand(&self, labels: &[i32]) -> Vec<i32> {
        let cols_small = self.cols.div_ceil(self.factor);
        let mut out = vec![-1i32; self.rows * self.cols];
        out.par_chunks_mut(self.cols)
            .enumerate()
            .for_each(|(r, row)| {
                let small = &labels[(r / self.factor) * cols_small..][..cols_small];
                for (c, label) in row.iter_mut().enumerate() {
                    if self.members[r * self.cols + c] {
                        *label = small[c / self.factor];
                    }
                }
            });
        out
    }
}

impl Decimation {
    /// The decimated grid's `(rows, cols)`.
    pub fn grid(&self) -> (usize, usize) {
        (
            self.rows.div_ceil(self.factor),
            self.cols.div_ceil(self.factor),
        )
    }

    /// The member pixels (row-major indices) of every block, block by block.
    fn blocks(&self) -> impl Iterator<Item = impl Iterator<Item = usize> + '_> + '_ {
        let (rows, cols) = self.grid();
        (0..rows * cols).map(move |b| {
            let (r, c) = (b / cols * self.factor, b % cols * self.factor);
            (r..(r + self.factor).min(self.rows))
                .flat_map(move |i| {
                    (c..(c + self.factor).min(self.cols)).map(move |j| i * self.cols + j)
                })
                .filter(|&i| self.members[i])
        })
    }

    /// One colour per point of the decimated grid (per mesh vertex) from one per input
    /// pixel: the mean of the colours of the pixels the point averaged, black for a block
    /// without any.
    ///
    /// # Errors
    /// [`PolylidarError::Config`] when `colors` is not one per input pixel.
    pub fn block_colors(&self, colors: &[[u8; 3]]) -> Result<Vec<[u8; 3]>, PolylidarError> {
        self.check_len("colors", colors.len())?;
        Ok(self
            .blocks()
            .map(|pixels| {
                let (sum, n) = pixels.fold(([0u32; 3], 0u32), |(mut sum, n), i| {
                    for (s, v) in sum.iter_mut().zip(colors[i]) {
                        *s += u32::from(v);
                    }
                    (sum, n + 1)
                });
                sum.map(|s| (s + n / 2).checked_div(n).unwrap_or(0) as u8)
            })
            .collect())
    }

    /// One label per point of the decimated grid from one per input pixel (ground
    /// truth, say): the label most of the block's valid pixels carry (`-1` counts as a
    /// label; the smallest wins a tie) among the pixels the point averaged, `-1` for a
    /// block without any.
    ///
    /// # Errors
    /// [`PolylidarError::Config`] when `labels` is not one per input pixel.
    pub fn block_labels(&self, labels: &[i32]) -> Result<Vec<i32>, PolylidarError> {
        self.check_len("labels", labels.len())?;
        let mut seen: Vec<i32> = Vec::with_capacity(self.factor * self.factor);
        Ok(self
            .blocks()
            .map(|pixels| {
                seen.clear();
                seen.extend(pixels.map(|i| labels[i]));
                seen.sort_unstable();
                seen.chunk_by(|a, b| a == b)
                    .fold((-1, 0), |(best, most), run| {
                        if run.len() > most {
                            (run[0], run.len())
                        } else {
                            (best, most)
                        }
                    })
                    .0
            })
            .collect())
    }

    fn check_len(&self, field: &'static str, len: usize) -> Result<(), PolylidarError> {
        if len == self.rows * self.cols {
            return Ok(());
        }
        Err(PolylidarError::Config {
            field,
            value: len.to_string(),
            reason: "must be one per input pixel of the decimated cloud",
        })
    }
}

#[cfg(test)]
mod tests {
    #![allow(clippy::unwrap_used)]

    use super::*;

    #[test]
    fn labels_expand_onto_valid_pixels_of_their_block() {
        // 5 × 7 input, factor 2: a 3 × 4 grid with partial blocks at the right and bottom.
        let mut points = vec![[0.0, 0.0, 1.0]; 35];
        points[8] = [f64::NAN; 3]; // (1, 1)
        points[34] = [f64::NAN; 3]; // (4, 6)
        let view = OrganizedPointCloudView::new(5, 7, &points).unwrap();
        let config = DecimateConfig::default().with_factor(DecimateFactor::Fixed(2));
        let (cloud, decimation) = config.apply(view, Vec::new).unwrap().unwrap();
        assert_eq!((cloud.rows(), cloud.cols()), (3, 4));
        let small: Vec<i32> = (0..12).collect();
        let labels = decimation.expand(&small);
        for r in 0..5 {
            for c in 0..7 {
                let want = if (r, c) == (1, 1) || (r, c) == (4, 6) {
                    -1
                } else {
                    (r / 2 * 4 + c / 2) as i32
                };
                assert_eq!(labels[r * 7 + c], want, "pixel ({r}, {c})");
            }
        }
    }

    #[test]
    fn colours_and_truth_come_down_to_the_blocks() {
        // 3 × 4 input, factor 2: blocks of 2 × 2 and, in the last row, 1 × 2 pixels.
        let mut points = vec![[0.0, 0.0, 1.0]; 12];
        points[0] = [f64::NAN; 3];
        let view = OrganizedPointCloudView::new(3, 4, &points).unwrap();
        let config = DecimateConfig::default().with_factor(DecimateFactor::Fixed(2));
        let (_, decimation) = config.apply(view, Vec::new).unwrap().unwrap();
        assert_eq!(decimation.grid(), (2, 2));
        assert_eq!(decimation.member_pixels(), 11);
        let colors: Vec<[u8; 3]> = (0..12u8).map(|i| [i, 10 * i, 255 - i]).collect();
        // Block 0 leaves out the invalid pixel 0: pixels 1, 4, 5.
        let mean = |pixels: &[u8]| -> [u8; 3] {
            let n = pixels.len() as u32;
            [0, 1, 2].map(|k| {
                let sum: u32 = pixels
                    .iter()
                    .map(|&i| u32::from(colors[i as usize][k]))
                    .sum();
                ((sum + n / 2) / n) as u8
            })
        };
        assert_eq!(
            decimation.block_colors(&colors).unwrap(),
            vec![
                mean(&[1, 4, 5]),
                mean(&[2, 3, 6, 7]),
                mean(&[8, 9]),
                mean(&[10, 11])
            ]
        );
        let truth = [9, 1, 2, 2, 1, 3, -1, -1, 4, 5, 7, 7];
        // Block 0: 1, 1, 3 (pixel 0 invalid); block 1: 2, 2, −1, −1 (tie: the smaller);
        // block 2: 4, 5 (tie); block 3: 7, 7.
        assert_eq!(decimation.block_labels(&truth).unwrap(), vec![1, -1, 4, 7]);
        assert!(decimation.block_colors(&colors[1..]).is_err());
        assert!(decimation.block_labels(&truth[1..]).is_err());
    }

    #[test]
    fn factor_one_leaves_the_cloud_alone() {
        let points = vec![[0.0, 0.0, 1.0]; 240 * 424];
        let view = OrganizedPointCloudView::new(240, 424, &points).unwrap();
        // A frame left alone asks for no buffer (the recycled one stays for meshing).
        let asked = std::cell::Cell::new(false);
        let out = DecimateConfig::default().apply(view, || {
            asked.set(true);
            Vec::new()
        });
        assert!(out.unwrap().is_none());
        assert!(!asked.get());
        // Auto never leaves fewer than 2 rows or columns.
        assert_eq!(DecimateConfig::default().factor_for(3, 5000), 1);
    }

    #[test]
    fn bad_values_are_named() {
        for (config, field) in [
            (
                DecimateConfig::default().with_factor(DecimateFactor::Fixed(0)),
                "decimate.factor",
            ),
            (
                DecimateConfig::default().with_factor(DecimateFactor::Fixed(17)),
                "decimate.factor",
            ),
            (
                DecimateConfig {
                    target_columns: 1,
                    ..DecimateConfig::default()
                },
                "decimate.target_columns",
            ),
            (
                DecimateConfig {
                    range_tolerance: f64::NAN,
                    ..DecimateConfig::default()
                },
                "decimate.range_tolerance",
            ),
        ] {
            let error = config.validate().unwrap_err();
            assert!(
                matches!(error, PolylidarError::Config { field: f, .. } if f == field),
                "{error}"
            );
        }
        let auto: DecimateConfig = toml::from_str(r#"factor = "auto""#).unwrap();
        assert_eq!(auto.factor, DecimateFactor::Auto);
        assert!(toml::from_str::<DecimateConfig>(r#"factor = "half""#).is_err());
    }
}

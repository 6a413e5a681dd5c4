//! Block decimation of an organized cloud, as a depth camera's decimation filter does.
//!
//! A full-resolution depth frame has many times the pixels of the resolution
//! Polylidar3D's RealSense parameters were chosen for (the D435i sampled at 424 × 240 and
//! decimated by 2 by its SDK), so every stage costs that much more and a plane's noise,
//! seen over the same pixel neighbourhoods, scatters its triangle normals more widely.
//! Merging each `f × f` block of pixels into one point gives the coarser grid and
//! averages the noise away.
//!
//! A block's point is a robust mean: of its valid pixels, those whose range (distance
//! from the origin, the sensor) lies within a share of the median pixel's range are
//! averaged. A block straddling a depth jump thus takes the surface its median pixel lies
//! on instead of a point floating between the two.

use std::ops::Range;

use rayon::prelude::*;

use crate::view::strided_shape;
use crate::{OpcError, OrganizedPointCloud, OrganizedPointCloudView, is_valid};

/// The largest factor accepted.
const MAX_FACTOR: usize = 16;

impl OrganizedPointCloudView<'_> {
    /// Merges every `factor × factor` block of pixels into one point: the mean of the
    /// block's valid points whose range lies within `range_tolerance` (a share, e.g.
    /// `0.02`) of the range of the block's median point, the lower median for an even
    /// count (a point whose squared range overflows counts as invalid); invalid (NaN)
    /// where the block has no valid point. Blocks at the right and
    /// bottom edges may be partial: the cloud has `⌈rows / factor⌉ × ⌈cols / factor⌉`
    /// points and point `(r, c)` stands for pixels `(r · factor .. (r + 1) · factor,
    /// c · factor .. (c + 1) · factor)`, those of them it averaged marked in
    /// [`Decimated::members`]. Rows run in parallel on the rayon pool; the result does not
    /// depend on the thread count.
    ///
    /// ```
    /// use opc_mesh::OrganizedPointCloud;
    ///
    /// // A 4 × 4 patch of a wall 2 m away; pixel (0, 0) sees a cable 1 m in front of it.
    /// let points: Vec<[f64; 3]> = (0..16)
    ///     .map(|i| {
    ///         let (r, c) = (i / 4, i % 4);
    ///         let z = if i == 0 { 1.0 } else { 2.0 };
    ///         [c as f64 * 0.01 * z, r as f64 * 0.01 * z, z]
    ///     })
    ///     .collect();
    /// let cloud = OrganizedPointCloud::new(4, 4, points)?;
    /// let small = cloud.decimate(2, 0.02)?;
    /// assert_eq!((small.cloud.rows(), small.cloud.cols()), (2, 2));
    /// // The first block is the wall's three pixels; the cable's is left out.
    /// let [x, y, z] = small.cloud.point(0, 0);
    /// assert!((x - 0.04 / 3.0).abs() < 1e-12 && (y - 0.04 / 3.0).abs() < 1e-12 && z == 2.0);
    /// assert!(!small.members[0] && small.members[1] && small.members[4]);
    /// # Ok::<(), opc_mesh::OpcError>(())
    /// ```
    ///
    /// # Errors
    /// [`OpcError::InvalidParameter`] for a factor of 0 or above 16, or a tolerance that is
    /// not a finite share ≥ 0; [`OpcError::TooSmall`] when fewer than 2 rows or columns
    /// would remain.
    pub fn decimate(&self, factor: usize, range_tolerance: f64) -> Result<Decimated, OpcError> {
        self.decimate_into(factor, range_tolerance, Vec::new())
    }

    /// [`Self::decimate`] writing the points into `points` (its contents are replaced),
    /// for example the vertices of the previous frame's mesh: a buffer the process
    /// already has costs no page faults.
    ///
    /// ```
    /// use opc_mesh::OrganizedPointCloud;
    ///
    /// let cloud = OrganizedPointCloud::new(4, 4, vec![[0.0, 0.0, 1.0]; 16])?;
    /// let buffer = Vec::with_capacity(4);
    /// let at = buffer.as_ptr();
    /// let small = cloud.decimate_into(2, 0.02, buffer)?;
    /// assert_eq!(small.cloud.points().as_ptr(), at);
    /// assert_eq!(small.cloud, cloud.decimate(2, 0.02)?.cloud);
    /// # Ok::<(), opc_mesh::OpcError>(())
    /// ```
    ///
    /// # Errors
    /// As [`Self::decimate`].
    pub fn decimate_into(
        &self,
        factor: usize,
        range_tolerance: f64,
        mut points: Vec<[f64; 3]>,
    ) -> Result<Decimated, OpcError> {
        if factor == 0 || factor > MAX_FACTOR {
            return Err(OpcError::InvalidParameter {
                name: "factor",
                value: factor.to_string(),
                expected: "1 to 16",
            });
        }
        if !(range_tolerance.is_finite() && range_tolerance >= 0.0) {
            return Err(OpcError::InvalidParameter {
                name: "range_tolerance",
                value: range_tolerance.to_string(),
                expected: "a finite share ≥ 0",
            });
        }
        let (rows, cols) = strided_shape(self.rows(), self.cols(), factor)?;
        let input = self.points();
        let (in_rows, in_cols) = (self.rows(), self.cols());
        points.clear();
        points.resize(rows * cols, [0.0; 3]);
        let mut members = vec![false; in_rows * in_cols];
        let valid_pixels = points
            .par_chunks_mut(cols)
            .zip(members.par_chunks_mut(factor * in_cols))
            .enumerate()
            .map_init(Block::default, |block, (r, (out, members))| {
                let block_rows = members.len() / in_cols;
                let input = &input[r * factor * in_cols..][..members.len()];
                let mut valid_pixels = 0;
                // Full 2 × 2 blocks, the common case, in a kernel of their own.
                let full = if factor == 2 && block_rows == 2 {
                    let (top, bottom) = input.split_at(in_cols);
                    let (members_top, members_bottom) = members.split_at_mut(in_cols);
                    let blocks = in_cols / 2;
                    valid_pixels += two_by_two_row(
                        [top, bottom],
                        range_tolerance,
                        &mut out[..blocks],
                        [members_top, members_bottom],
                    );
                    blocks
                } else {
                    0
                };
                for (c, o) in out.iter_mut().enumerate().skip(full) {
                    let (c0, c1) = (c * factor, ((c + 1) * factor).min(in_cols));
                    block.fill(input, in_cols, block_rows, c0..c1);
                    valid_pixels += block.finite;
                    let (low, high) = block.window(range_tolerance);
                    let (mut sum, mut count, mut k) = ([0.0; 3], 0.0, 0);
                    for i in 0..block_rows {
                        for member in &mut members[i * in_cols + c0..i * in_cols + c1] {
                            *member = add_if_inside(
                                (&mut sum, &mut count),
                                block.points[k],
                                block.range2[k],
                                (low, high),
                            );
                            k += 1;
                        }
                    }
                    let inverse = 1.0 / count;
                    *o = sum.map(|s| s * inverse);
                }
                valid_pixels
            })
            .sum();
        Ok(Decimated {
            cloud: OrganizedPointCloud::new(rows, cols, points)?,
            members,
            valid_pixels,
        })
    }
}

impl OrganizedPointCloud {
    /// Merges every `factor × factor` block of pixels into one point; see
    /// [`OrganizedPointCloudView::decimate`].
    ///
    /// # Errors
    /// As [`OrganizedPointCloudView::decimate`].
    pub fn decimate(&self, factor: usize, range_tolerance: f64) -> Result<Decimated, OpcError> {
        self.view().decimate(factor, range_tolerance)
    }

    /// Decimates into a buffer of points; see [`OrganizedPointCloudView::decimate_into`].
    ///
    /// # Errors
    /// As [`OrganizedPointCloudView::decimate`].
    pub fn decimate_into(
        &self,
        factor: usize,
        range_tolerance: f64,
        points: Vec<[f64; 3]>,
    ) -> Result<Decimated, OpcError> {
        self.view().decimate_into(factor, range_tolerance, points)
    }
}

/// A decimated cloud ([`OrganizedPointCloudView::decimate`]) and which input pixels
/// each of its points stands for.
#[derive(Debug, Clone, PartialEq)]
pub struct Decimated {
    /// One point per block of pixels.
    pub cloud: OrganizedPointCloud,
    /// One flag per input pixel, row-major: whether its block's point averaged it (it is
    /// valid and within the range tolerance of the block's median). A pixel left out
    /// lies across a depth jump from the surface its block's point lies on.
    pub members: Vec<bool>,
    /// The input's valid pixels ([`OrganizedPointCloudView::num_valid`]), counted on
    /// the way.
    pub valid_pixels: usize,
}

/// One block's pixels: their points and squared ranges (infinite for invalid ones), and
/// room to select a large block's median.
struct Block {
    points: [[f64; 3]; MAX_FACTOR * MAX_FACTOR],
    range2: [f64; MAX_FACTOR * MAX_FACTOR],
    len: usize,
    /// Pixels with a finite squared range, which take part in the median.
    valid: usize,
    /// Valid (finite) pixels.
    finite: usize,
    scratch: Vec<f64>,
}

impl Default for Block {
    fn default() -> Self {
        Self {
            points: [[0.0; 3]; MAX_FACTOR * MAX_FACTOR],
            range2: [0.0; MAX_FACTOR * MAX_FACTOR],
            len: 0,
            valid: 0,
            finite: 0,
            scratch: Vec::new(),
        }
    }
}

impl Block {
    /// Takes the pixels of columns `cols` of the first `rows` rows of `input` (rows of
    /// `stride` points).
    fn fill(&mut self, input: &[[f64; 3]], stride: usize, rows: usize, cols: Range<usize>) {
        let (mut n, mut valid, mut finite) = (0, 0, 0);
        for i in 0..rows {
            for p in &input[i * stride + cols.start..i * stride + cols.end] {
                let (r2, is_finite) = ordering_range2(p);
                self.points[n] = *p;
                self.range2[n] = r2;
                valid += usize::from(r2.is_finite());
                finite += usize::from(is_finite);
                n += 1;
            }
        }
        self.len = n;
        self.valid = valid;
        self.finite = finite;
    }

    /// The bounds of the squared ranges within `tolerance` of the lower median range of
    /// the valid points (an empty window without any): |r − m| ≤ t·m, squared on both
    /// sides of m. Infinite ranges fall outside.
    fn window(&mut self, tolerance: f64) -> (f64, f64) {
        if self.valid == 0 {
            return EMPTY_WINDOW;
        }
        // Invalid points order last, so the median of the valid ones has `middle` before
        // it.
        let middle = (self.valid - 1) / 2;
        let range2 = &self.range2[..self.len];
        let median2 = if let [a, b, c, d] = *range2 {
            sorted_four([a, b, c, d])[middle]
        } else if range2.len() <= SMALL_BLOCK {
            small_block_median(range2, middle)
        } else {
            self.scratch.clear();
            self.scratch.extend_from_slice(range2);
            *self
                .scratch
                .select_nth_unstable_by(middle, f64::total_cmp)
                .1
        };
        window_around(median2, tolerance)
    }
}

/// The first `out.len()` 2 × 2 blocks of a pair of rows (the `top` and `bottom` rows'
/// pixels): one point per block into `out`, and into `members` (the two rows' flags) the
/// pixels each averaged; returns their valid pixels. Each block as [`two_by_two`], without
/// branches, so that the loop vectorises; compiled also for AVX-512 and AVX2, chosen at
/// run time. The arithmetic is the same on every target (no fused multiply-add), so
/// results do not depend on the CPU.
#[multiversion::multiversion(targets("x86_64+avx512f+avx512vl+avx512bw+avx512dq", "x86_64+avx2"))]
fn two_by_two_row(
    [top, bottom]: [&[[f64; 3]]; 2],
    tolerance: f64,
    out: &mut [[f64; 3]],
    [members_top, members_bottom]: [&mut [bool]; 2],
) -> usize {
    let blocks = out.len();
    let (top, bottom) = (&top[..2 * blocks], &bottom[..2 * blocks]);
    let (members_top, members_bottom) = (
        &mut members_top[..2 * blocks],
        &mut members_bottom[..2 * blocks],
    );
    let mut valid_pixels = 0;
    for c in 0..blocks {
        let pixels = [top[2 * c], top[2 * c + 1], bottom[2 * c], bottom[2 * c + 1]];
        let (point, inside, finite) = two_by_two(pixels, tolerance);
        out[c] = point;
        members_top[2 * c] = inside[0];
        members_top[2 * c + 1] = inside[1];
        members_bottom[2 * c] = inside[2];
        members_bottom[2 * c + 1] = inside[3];
        valid_pixels += finite;
    }
    valid_pixels
}

/// Blocks of up to this many pixels (4 × 4) take their median by [`small_block_median`].
const SMALL_BLOCK: usize = 16;

/// The squared range with `middle` others before it (ties by position) among the at
/// most [`SMALL_BLOCK`] squared ranges of a block: a fixed number of comparisons without
/// branches, where sorting would mispredict on every block. Squared ranges are never NaN
/// (invalid pixels' are infinite), so plain comparisons order them; padding with
/// infinities past the block's pixels puts none before them, and the fixed length lets
/// the comparisons vectorise (compiled also for AVX-512 and AVX2, chosen at run time).
#[multiversion::multiversion(targets("x86_64+avx512f+avx512vl+avx512bw+avx512dq", "x86_64+avx2"))]
fn small_block_median(range2: &[f64], middle: usize) -> f64 {
    let mut padded = [f64::INFINITY; SMALL_BLOCK];
    padded[..range2.len()].copy_from_slice(range2);
    let mut median2 = 0.0;
    for (i, &r) in padded.iter().enumerate().take(range2.len()) {
        let mut before = 0;
        for (j, &q) in padded.iter().enumerate() {
            before += usize::from((q < r) | ((q == r) & (j < i)));
        }
        median2 = if before == middle { r } else { median2 };
    }
    median2
}

/// A full 2 × 2 block (its pixels in row-major order) without [`Block`]'s copies and
/// loops: its point, which of its pixels it averaged and its valid pixels, computed as
/// [`Block::fill`], [`Block::window`] and the mean do.
#[inline(always)]
fn two_by_two(pixels: [[f64; 3]; 4], tolerance: f64) -> ([f64; 3], [bool; 4], usize) {
    let mut range2 = [0.0; 4];
    let (mut valid, mut finite) = (0, 0);
    for (r2, p) in range2.iter_mut().zip(&pixels) {
        let is_finite;
        (*r2, is_finite) = ordering_range2(p);
        valid += usize::from(r2.is_finite());
        finite += usize::from(is_finite);
    }
    // The lower median of the valid ones, which order first: the second of three or
    // four, the first of one or two. Selected, not indexed, so that blocks vectorise.
    let sorted = sorted_four(range2);
    let median2 = if valid >= 3 { sorted[1] } else { sorted[0] };
    let window = window_around(median2, tolerance);
    let (low, high) = if valid == 0 { EMPTY_WINDOW } else { window };
    let (mut sum, mut count) = ([0.0; 3], 0.0);
    let mut members = [false; 4];
    for ((member, r2), p) in members.iter_mut().zip(range2).zip(pixels) {
        *member = add_if_inside((&mut sum, &mut count), p, r2, (low, high));
    }
    let inverse = 1.0 / count;
    (sum.map(|s| s * inverse), members, finite)
}

/// The window that holds no squared range.
const EMPTY_WINDOW: (f64, f64) = (1.0, 0.0);

/// A pixel's squared range as blocks order it (infinite unless the pixel is valid and
/// its square finite: a point so far out that its square overflows would otherwise
/// order with the invalid ones), and whether it is valid.
#[inline(always)]
fn ordering_range2(p: &[f64; 3]) -> (f64, bool) {
    let is_finite = is_valid(p);
    let r2 = range2(p);
    (
        if is_finite && r2.is_finite() {
            r2
        } else {
            f64::INFINITY
        },
        is_finite,
    )
}

/// Adds point `p` to a block's running sum and count when its squared range `r2` lies in
/// the window `(low, high)`; whether it did (branch-free).
#[inline(always)]
fn add_if_inside(
    (sum, count): (&mut [f64; 3], &mut f64),
    p: [f64; 3],
    r2: f64,
    (low, high): (f64, f64),
) -> bool {
    let inside = (low <= r2) & (r2 <= high);
    for (s, v) in sum.iter_mut().zip(p) {
        *s += if inside { v } else { 0.0 };
    }
    *count += if inside { 1.0 } else { 0.0 };
    inside
}

/// Four squared ranges in ascending order, by a network of minima and maxima (they are
/// never NaN, so plain comparisons, one instruction each, do).
#[inline(always)]
fn sorted_four([a, b, c, d]: [f64; 4]) -> [f64; 4] {
    let sort = |x: f64, y: f64| if x < y { (x, y) } else { (y, x) };
    let (a, b) = sort(a, b);
    let (c, d) = sort(c, d);
    let (a, c) = sort(a, c);
    let (b, d) = sort(b, d);
    let (b, c) = sort(b, c);
    [a, b, c, d]
}

/// The bounds of the squared ranges within `tolerance` of the range whose square is
/// `median2`.
#[inline(always)]
fn window_around(median2: f64, tolerance: f64) -> (f64, f64) {
    let low = (1.0 - tolerance).max(0.0);
    let high = 1.0 + tolerance;
    (median2 * low * low, median2 * high * high)
}

/// The squared range (distance from the origin) of a point: blocks are ordered and
/// compared by it, which orders them as the range does without a square root.
#[inline(always)]
fn range2(p: &[f64; 3]) -> f64 {
    p[0] * p[0] + p[1] * p[1] + p[2] * p[2]
}

#[cfg(test)]
mod tests {
    #![allow(clippy::unwrap_used)]

    use proptest::prelude::*;

    use super::*;

    fn range(p: &[f64; 3]) -> f64 {
        range2(p).sqrt()
    }

    /// The definition, pixel by pixel: sort each block's valid points by range, take the
    /// lower median, average those within the tolerance; they are the members.
    fn oracle(
        cloud: &OrganizedPointCloud,
        factor: usize,
        tolerance: f64,
    ) -> (Vec<[f64; 3]>, Vec<bool>) {
        let (rows, cols) = (cloud.rows().div_ceil(factor), cloud.cols().div_ceil(factor));
        let mut out = Vec::new();
        let mut members = vec![false; cloud.rows() * cloud.cols()];
        for r in 0..rows {
            for c in 0..cols {
                let mut block: Vec<([f64; 3], usize)> = Vec::new();
                for i in r * factor..((r + 1) * factor).min(cloud.rows()) {
                    for j in c * factor..((c + 1) * factor).min(cloud.cols()) {
                        let p = cloud.point(i, j);
                        if is_valid(&p) && range(&p).is_finite() {
                            block.push((p, i * cloud.cols() + j));
                        }
                    }
                }
                if block.is_empty() {
                    out.push([f64::NAN; 3]);
                    continue;
                }
                block.sort_by(|a, b| range(&a.0).total_cmp(&range(&b.0)));
                let median = range(&block[(block.len() - 1) / 2].0);
                let kept: Vec<&([f64; 3], usize)> = block
                    .iter()
                    .filter(|(p, _)| (range(p) - median).abs() <= tolerance * median)
                    .collect();
                for (_, i) in &kept {
                    members[*i] = true;
                }
                out.push(
                    [0, 1, 2]
                        .map(|k| kept.iter().map(|(p, _)| p[k]).sum::<f64>() / kept.len() as f64),
                );
            }
        }
        (out, members)
    }

    fn same(a: &[[f64; 3]], b: &[[f64; 3]]) -> bool {
        a.len() == b.len()
            && a.iter().zip(b).all(|(p, q)| {
                p.iter()
                    .zip(q)
                    .all(|(x, y)| (x.is_nan() && y.is_nan()) || (x - y).abs() <= 1e-12)
            })
    }

    proptest! {
        /// Random clouds with missing pixels and depth jumps, every factor and odd shapes
        /// (partial blocks): the same points as the definition.
        #[test]
        fn matches_the_definition(
            rows in 2usize..23,
            cols in 2usize..23,
            factor in 1usize..6,
            tolerance in 0.0f64..0.2,
            seed in any::<u64>(),
        ) {
            prop_assume!(rows.div_ceil(factor) >= 2 && cols.div_ceil(factor) >= 2);
            let mut state = seed | 1;
            let mut next = || {
                state ^= state << 13;
                state ^= state >> 7;
                state ^= state << 17;
                (state % 10_000) as f64 / 10_000.0
            };
            let points: Vec<[f64; 3]> = (0..rows * cols)
                .map(|i| {
                    let u = next();
                    if u < 0.15 {
                        return [f64::NAN; 3];
                    }
                    let z = if u < 0.4 { 1.0 + next() } else { 3.0 + 0.05 * next() };
                    [(i % cols) as f64 * 0.01 * z, (i / cols) as f64 * 0.01 * z, z]
                })
                .collect();
            let cloud = OrganizedPointCloud::new(rows, cols, points).unwrap();
            let small = cloud.decimate(factor, tolerance).unwrap();
            let shape = (small.cloud.rows(), small.cloud.cols());
            prop_assert_eq!(shape, (rows.div_ceil(factor), cols.div_ceil(factor)));
            let (points, members) = oracle(&cloud, factor, tolerance);
            prop_assert!(same(small.cloud.points(), &points));
            prop_assert_eq!(small.members, members);
            prop_assert_eq!(small.valid_pixels, cloud.num_valid());
        }
    }

    #[test]
    fn a_plane_stays_on_its_plane_with_less_noise() {
        // z = 2 + 0.1 x with ±1 mm alternating noise: 2 × 2 blocks cancel it.
        let points: Vec<[f64; 3]> = (0..40 * 40)
            .map(|i| {
                let (r, c) = (i / 40, i % 40);
                let x = c as f64 * 0.01;
                let noise = if (r + c) % 2 == 0 { 0.001 } else { -0.001 };
                [x, r as f64 * 0.01, 2.0 + 0.1 * x + noise]
            })
            .collect();
        let small = OrganizedPointCloud::new(40, 40, points)
            .unwrap()
            .decimate(2, 0.02)
            .unwrap();
        assert!(small.members.iter().all(|&m| m));
        for p in small.cloud.points() {
            assert!((p[2] - (2.0 + 0.1 * p[0])).abs() < 1e-12, "{p:?}");
        }
    }

    #[test]
    fn empty_blocks_are_invalid_and_factor_one_copies() {
        let mut points = vec![[0.1, 0.2, 1.0]; 16];
        for i in [0, 1, 4, 5] {
            points[i] = [f64::NAN; 3];
        }
        let cloud = OrganizedPointCloud::new(4, 4, points).unwrap();
        let small = cloud.decimate(2, 0.02).unwrap();
        assert!(!is_valid(&small.cloud.point(0, 0)));
        assert_eq!(small.cloud.num_valid(), 3);
        assert_eq!(small.members.iter().filter(|&&m| m).count(), 12);
        let copy = cloud.decimate(1, 0.02).unwrap();
        assert!(same(copy.cloud.points(), cloud.points()));
        assert_eq!(
            copy.members,
            cloud.points().iter().map(is_valid).collect::<Vec<_>>()
        );
    }

    #[test]
    fn points_whose_range_overflows_are_left_out() {
        let mut points = vec![[0.0, 0.0, 1.0]; 16];
        points[0] = [1e200, 0.0, 1.0];
        points[1] = [f64::NAN; 3];
        let small = OrganizedPointCloud::new(4, 4, points)
            .unwrap()
            .decimate(2, 0.02)
            .unwrap();
        assert_eq!(small.cloud.point(0, 0), [0.0, 0.0, 1.0]);
        assert!(!small.members[0] && !small.members[1] && small.members[4]);
        // The far point is valid (finite), only left out of its block's mean.
        assert_eq!(small.valid_pixels, 15);
    }

    #[test]
    fn bad_parameters_are_named() {
        let cloud = OrganizedPointCloud::new(4, 4, vec![[0.0, 0.0, 1.0]; 16]).unwrap();
        for (factor, tolerance, name) in [
            (0, 0.02, "factor"),
            (17, 0.02, "factor"),
            (2, f64::NAN, "range_tolerance"),
            (2, -0.1, "range_tolerance"),
        ] {
            let error = cloud.decimate(factor, tolerance).unwrap_err();
            assert!(
                matches!(error, OpcError::InvalidParameter { name: n, .. } if n == name),
                "{error}"
            );
        }
        assert!(matches!(
            cloud.decimate(4, 0.02),
            Err(OpcError::TooSmall { rows: 1, cols: 1 })
        ));
    }
}

//! A spatially coherent order of the points (Morton / Z-order).

use rayon::prelude::*;

/// Cells per axis of the Morton grid (21 bits: three axes fill a `u64`).
const MORTON_CELLS: f64 = ((1u64 << 21) - 1) as f64;

/// The point indices in Morton (Z-curve) order over the points' bounding cube: points
/// near each other in space come near each other in the order (ties: by index, so the
/// order is the same on any thread count).
///
/// Shuffled clouds (merged scans, SLAM maps, files written in any order) make every pass
/// over neighbourhoods jump through memory; processed in this order, the same passes
/// read mostly cached data. Non-finite coordinates sort as the cube's lowest corner.
///
/// ```
/// use cloud_normals::spatial_order;
/// let points = [[9.0, 9.0, 9.0], [0.0, 0.0, 0.0], [8.9, 9.0, 9.0], [0.1, 0.0, 0.0]];
/// assert_eq!(spatial_order(&points), vec![1, 3, 2, 0]);
/// ```
pub fn spatial_order(points: &[[f64; 3]]) -> Vec<u32> {
    let finite = points.iter().filter(|p| p.iter().all(|c| c.is_finite()));
    let (min, max) = finite.fold(
        ([f64::INFINITY; 3], [f64::NEG_INFINITY; 3]),
        |(lo, hi), p| {
            (
                std::array::from_fn(|a| lo[a].min(p[a])),
                std::array::from_fn(|a| hi[a].max(p[a])),
            )
        },
    );
    let extent = (0..3).map(|a| max[a] - min[a]).fold(0.0, f64::max);
    let scale = if extent.is_finite() && extent > 0.0 {
        MORTON_CELLS / extent
    } else {
        0.0
    };
    let mut keyed: Vec<(u64, u32)> = points
        .par_iter()
        .enumerate()
        .map(|(i, p)| {
            // `as` saturates: NaN to 0, and the range is 0..=MORTON_CELLS.
            let cell = |a: usize| ((p[a] - min[a]) * scale) as u64;
            (
                spread(cell(0)) | spread(cell(1)) << 1 | spread(cell(2)) << 2,
                i as u32,
            )
        })
        .collect();
    keyed.par_sort_unstable();
    keyed.into_iter().map(|(_, i)| i).collect()
}

/// The low 21 bits of `x` spread to every third bit.
fn spread(x: u64) -> u64 {
    let mut x = x & 0x1f_ffff;
    x = (x | x << 32) & 0x001f_0000_0000_ffff;
    x = (x | x << 16) & 0x001f_0000_ff00_00ff;
    x = (x | x << 8) & 0x100f_00f0_0f00_f00f;
    x = (x | x << 4) & 0x10c3_0c30_c30c_30c3;
    x = (x | x << 2) & 0x1249_2492_4924_9249;
    x
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn spread_puts_each_bit_three_places_apart() {
        for bit in 0..21 {
            assert_eq!(spread(1 << bit), 1 << (3 * bit));
        }
        assert_eq!(spread(u64::MAX), 0x1249_2492_4924_9249);
    }

    #[test]
    fn octants_come_one_after_the_other() {
        // The eight corners of a cube: Morton order is x, then y, then z as the fastest bit.
        let corners: Vec<[f64; 3]> = (0..8)
            .rev()
            .map(|i| [(i & 1) as f64, ((i >> 1) & 1) as f64, ((i >> 2) & 1) as f64])
            .collect();
        let order = spatial_order(&corners);
        let sorted: Vec<[f64; 3]> = order.iter().map(|&i| corners[i as usize]).collect();
        let expected: Vec<[f64; 3]> = (0..8)
            .map(|i| [(i & 1) as f64, ((i >> 1) & 1) as f64, ((i >> 2) & 1) as f64])
            .collect();
        assert_eq!(sorted, expected);
    }

    #[test]
    fn degenerate_clouds_keep_the_index_order() {
        assert_eq!(spatial_order(&[[1.0; 3]; 4]), vec![0, 1, 2, 3]);
        assert_eq!(spatial_order(&[]), Vec::<u32>::new());
        let with_nan = [[f64::NAN, 0.0, 0.0], [1.0, 1.0, 1.0], [0.0, 0.0, 0.0]];
        assert_eq!(spatial_order(&with_nan), vec![0, 2, 1]);
    }
}

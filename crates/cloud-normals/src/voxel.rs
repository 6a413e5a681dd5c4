//! Voxel-grid downsampling: one representative point per occupied cube.

use rayon::prelude::*;

use crate::NormalsError;
use crate::knn::check_points;

/// Bits per axis of a voxel key.
const BITS: u32 = 21;

/// A cloud reduced to one point per occupied voxel.
#[derive(Debug, Clone, PartialEq)]
pub struct Voxels {
    /// Per occupied voxel, the input point nearest to the mean of its points (an input
    /// point, so that its attributes, normals included, stay valid); in the order of the
    /// voxels' keys.
    pub representatives: Vec<u32>,
    /// Per input point, its voxel (index into `representatives`).
    pub voxel_of: Vec<u32>,
}

/// Downsamples `points` to one per cube of side `size` (in the points' unit; cubes aligned
/// on the cloud's minimum corner).
///
/// ```
/// use cloud_normals::voxel_downsample;
/// let points = [[0.1, 0.1, 0.0], [0.2, 0.2, 0.0], [0.3, 0.3, 0.0], [1.5, 0.0, 0.0]];
/// let voxels = voxel_downsample(&points, 1.0)?;
/// assert_eq!(voxels.representatives, [1, 3]);
/// assert_eq!(voxels.voxel_of, [0, 0, 0, 1]);
/// # Ok::<(), cloud_normals::NormalsError>(())
/// ```
///
/// # Errors
/// [`NormalsError::BadVoxelSize`], [`NormalsError::TooManyVoxels`] when the cloud spans
/// more than 2²¹ voxels along an axis, and the errors of a bad cloud
/// ([`NormalsError::Empty`], [`NormalsError::NonFinite`]).
pub fn voxel_downsample(points: &[[f64; 3]], size: f64) -> Result<Voxels, NormalsError> {
    if !(size.is_finite() && size > 0.0) {
        return Err(NormalsError::BadVoxelSize { size });
    }
    check_points(points)?;
    let mut min = [f64::INFINITY; 3];
    let mut max = [f64::NEG_INFINITY; 3];
    for p in points {
        for a in 0..3 {
            min[a] = min[a].min(p[a]);
            max[a] = max[a].max(p[a]);
        }
    }
    let cells = (0..3)
        .map(|a| ((max[a] - min[a]) / size).floor() + 1.0)
        .fold(0.0, f64::max);
    if cells > f64::from(1u32 << BITS) {
        return Err(NormalsError::TooManyVoxels { cells, size });
    }
    let cell = |p: &[f64; 3]| -> [u64; 3] {
        std::array::from_fn(|a| ((p[a] - min[a]) / size).floor() as u64)
    };
    let mut keyed: Vec<(u64, u32)> = points
        .par_iter()
        .enumerate()
        .map(|(i, p)| {
            let [x, y, z] = cell(p);
            ((x << (2 * BITS)) | (y << BITS) | z, i as u32)
        })
        .collect();
    keyed.par_sort_unstable();
    let mut representatives = Vec::new();
    let mut voxel_of = vec![0u32; points.len()];
    let mut start = 0;
    while start < keyed.len() {
        let key = keyed[start].0;
        let end = start + keyed[start..].partition_point(|&(k, _)| k == key);
        let members = &keyed[start..end];
        let mut mean = [0.0; 3];
        for &(_, i) in members {
            for a in 0..3 {
                mean[a] += points[i as usize][a];
            }
        }
        let mean = mean.map(|m| m / members.len() as f64);
        let d2 = |i: u32| {
            let p = points[i as usize];
            (0..3).map(|a| (p[a] - mean[a]).powi(2)).sum::<f64>()
        };
        let mut best = members[0].1;
        for &(_, i) in &members[1..] {
            if d2(i) < d2(best) {
                best = i;
            }
        }
        let voxel = representatives.len() as u32;
        representatives.push(best);
        for &(_, i) in members {
            voxel_of[i as usize] = voxel;
        }
        start = end;
    }
    Ok(Voxels {
        representatives,
        voxel_of,
    })
}

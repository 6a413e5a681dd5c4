//! Group assignment (Alg. 4).

use halfedge_mesh::HalfEdgeMesh;
use rayon::prelude::*;

use crate::{SegmentError, SegmentationConfig};

/// Group of a triangle that takes part in no segment.
pub const NO_GROUP: u32 = u32::MAX;

/// Triangles per parallel work item.
const CHUNK: usize = 8192;

/// What group assignment dropped and kept.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub struct GroupCounts {
    /// Triangles whose longest edge exceeds `lmax`.
    pub dropped_lmax: usize,
    /// Triangles too far from every dominant normal.
    pub dropped_normal: usize,
    /// Triangles assigned to a group.
    pub grouped: usize,
}

impl GroupCounts {
    fn add(self, o: Self) -> Self {
        Self {
            dropped_lmax: self.dropped_lmax + o.dropped_lmax,
            dropped_normal: self.dropped_normal + o.dropped_normal,
            grouped: self.grouped + o.grouped,
        }
    }
}

/// Assigns each triangle the index of its most similar dominant normal, or [`NO_GROUP`]
/// (Alg. 4). Ties go to the lower index.
///
/// # Errors
/// [`SegmentError::MissingNormals`], [`SegmentError::BadDominantNormal`],
/// [`SegmentError::Config`].
pub fn assign_groups(
    mesh: &HalfEdgeMesh,
    dominant: &[[f64; 3]],
    config: &SegmentationConfig,
) -> Result<(Vec<u32>, GroupCounts), SegmentError> {
    config.validate()?;
    check_dominant(dominant)?;
    let normals = mesh
        .triangle_normals()
        .ok_or(SegmentError::MissingNormals)?;
    let vertices = mesh.vertices();
    let lmax2 = if config.lmax > 0.0 {
        config.lmax * config.lmax
    } else {
        f64::INFINITY
    };
    let mut groups = vec![NO_GROUP; mesh.num_triangles()];
    let counts = groups
        .par_chunks_mut(CHUNK)
        .zip(mesh.triangles().par_chunks(CHUNK))
        .zip(normals.par_chunks(CHUNK))
        .map(|((groups, triangles), normals)| {
            let mut counts = GroupCounts::default();
            for ((g, tri), n) in groups.iter_mut().zip(triangles).zip(normals) {
                let [a, b, c] = tri.map(|v| vertices[v as usize]);
                if dist2(a, b).max(dist2(b, c)).max(dist2(c, a)) > lmax2 {
                    counts.dropped_lmax += 1;
                    continue;
                }
                let (mut best, mut best_dot) = (NO_GROUP, f64::NEG_INFINITY);
                for (j, d) in dominant.iter().enumerate() {
                    let dot = n[0] * d[0] + n[1] * d[1] + n[2] * d[2];
                    if dot > best_dot {
                        (best, best_dot) = (j as u32, dot);
                    }
                }
                if best_dot >= config.norm_thresh {
                    *g = best;
                    counts.grouped += 1;
                } else {
                    counts.dropped_normal += 1;
                }
            }
            counts
        })
        .reduce(GroupCounts::default, GroupCounts::add);
    Ok((groups, counts))
}

fn check_dominant(dominant: &[[f64; 3]]) -> Result<(), SegmentError> {
    for (index, d) in dominant.iter().enumerate() {
        let len2 = d[0] * d[0] + d[1] * d[1] + d[2] * d[2];
        if !len2.is_finite() || (len2 - 1.0).abs() > 1e-6 {
            return Err(SegmentError::BadDominantNormal { index, normal: *d });
        }
    }
    Ok(())
}

#[inline]
pub(crate) fn dist2(p: [f64; 3], q: [f64; 3]) -> f64 {
    (p[0] - q[0]) * (p[0] - q[0]) + (p[1] - q[1]) * (p[1] - q[1]) + (p[2] - q[2]) * (p[2] - q[2])
}

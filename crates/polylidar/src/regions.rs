//! Region growing of the 2D and 2.5D paths: edge-connected sets of kept triangles.
//!
//! This is Polylidar's (2D paper) region growing, not planeseg's (3D paper, Alg. 5), on
//! purpose: on the 2D and 2.5D paths every triangle that passed the filters (α, `lmax`,
//! angle to `up`) belongs to the one plane being extracted, so a region is simply an
//! edge-connected component, with no dominant normal, plane offset or refinement to test.
//! planeseg's grower needs triangle normals, dominant normals and a `z_thresh`, none of
//! which the 2D path has; the organized, mesh and unorganized paths use planeseg.

use halfedge_mesh::{HalfEdgeMesh, NO_TWIN};

/// Label of a triangle that belongs to no region.
pub(crate) const NO_REGION: u32 = u32::MAX;

/// Edge-connected regions of kept triangles, stored flat: region `r` is
/// `triangles[offsets[r]..offsets[r + 1]]`. `labels[t]` is the region of triangle `t`.
#[derive(Debug, Clone, Default)]
pub(crate) struct Regions {
    pub labels: Vec<u32>,
    pub triangles: Vec<u32>,
    pub offsets: Vec<u32>,
}

impl Regions {
    /// Grows regions from seeds taken in triangle order, so the result is deterministic.
    /// The label array doubles as the visited set: no hashing.
    pub fn grow(mesh: &HalfEdgeMesh, keep: &[bool]) -> Self {
        let twins = mesh.halfedges();
        let mut labels = vec![NO_REGION; keep.len()];
        let mut triangles = Vec::with_capacity(keep.iter().filter(|&&k| k).count());
        let mut offsets = vec![0u32];
        for seed in 0..keep.len() {
            if !keep[seed] || labels[seed] != NO_REGION {
                continue;
            }
            let id = (offsets.len() - 1) as u32;
            labels[seed] = id;
            let start = triangles.len();
            triangles.push(seed as u32);
            let mut next = start;
            while next < triangles.len() {
                let t = triangles[next] as usize;
                next += 1;
                for &twin in &twins[3 * t..3 * t + 3] {
                    if twin == NO_TWIN {
                        continue;
                    }
                    let n = (twin / 3) as usize;
                    if keep[n] && labels[n] == NO_REGION {
                        labels[n] = id;
                        triangles.push(n as u32);
                    }
                }
            }
            offsets.push(triangles.len() as u32);
        }
        Self {
            labels,
            triangles,
            offsets,
        }
    }

    /// Number of regions.
    pub fn len(&self) -> usize {
        self.offsets.len() - 1
    }

    /// The triangles of region `r`.
    pub fn region(&self, r: usize) -> &[u32] {
        &self.triangles[self.offsets[r] as usize..self.offsets[r + 1] as usize]
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn two_squares_touching_at_a_corner_are_two_regions() {
        let vertices = vec![
            [0.0, 0.0, 0.0],
            [1.0, 0.0, 0.0],
            [1.0, 1.0, 0.0],
            [0.0, 1.0, 0.0],
            [2.0, 1.0, 0.0],
            [2.0, 2.0, 0.0],
            [1.0, 2.0, 0.0],
        ];
        let triangles = vec![[0, 1, 2], [0, 2, 3], [2, 4, 5], [2, 5, 6]];
        let mesh = HalfEdgeMesh::from_triangles(vertices, triangles).unwrap();
        let regions = Regions::grow(&mesh, &[true; 4]);
        assert_eq!(regions.len(), 2);
        assert_eq!(regions.region(0), [0, 1]);
        assert_eq!(regions.region(1), [2, 3]);
        let regions = Regions::grow(&mesh, &[true, false, true, true]);
        assert_eq!(regions.len(), 2);
        assert_eq!(regions.labels[1], NO_REGION);
    }
}

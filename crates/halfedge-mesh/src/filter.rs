//! Polylidar's triangle filter and region growing (2D paper; the 2D and 2.5D paths of
//! Polylidar3D): [`TriangleFilter`] keeps the triangles of a mesh that pass the α,
//! `lmax` and up-direction tests, [`Regions`] groups the kept ones into edge-connected
//! regions, each extracted as one polygon with holes.

use rayon::prelude::*;

use crate::{HalfEdgeMesh, MeshError, NO_TWIN, cross_normal};

/// Triangles per parallel work item.
const CHUNK: usize = 8192;

/// How many triangles each test of a [`TriangleFilter`] removed (a triangle is counted
/// under the first test it fails, in the order normal, `lmax`, α).
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
#[non_exhaustive]
pub struct FilterCounts {
    /// Triangles whose normal is too far from the up direction.
    pub normal: usize,
    /// Triangles with an edge longer than `lmax`.
    pub lmax: usize,
    /// Triangles of circumradius above α.
    pub alpha: usize,
}

impl FilterCounts {
    fn add(self, other: Self) -> Self {
        Self {
            normal: self.normal + other.normal,
            lmax: self.lmax + other.lmax,
            alpha: self.alpha + other.alpha,
        }
    }
}

/// Polylidar's triangle filter (2D paper, and the 2.5D path of Polylidar3D): a triangle is
/// kept when its circumradius is at most `alpha`, its longest edge at most `lmax`, and its
/// normal within a minimum cosine of an up direction; a zero length or `None` disables a
/// test.
///
/// ```
/// use halfedge_mesh::{HalfEdgeMesh, TriangleFilter};
///
/// // A right triangle with legs 3 and 4: hypotenuse 5, circumradius 2.5.
/// let mesh = HalfEdgeMesh::from_triangles(
///     vec![[0.0, 0.0, 0.0], [3.0, 0.0, 0.0], [0.0, 4.0, 0.0]],
///     vec![[0, 1, 2]],
/// )?;
/// let (keep, dropped) = TriangleFilter::new().with_lmax(4.9).apply(&mesh);
/// assert_eq!((keep, dropped.lmax), (vec![false], 1));
/// let (keep, _) = TriangleFilter::new().with_alpha(2.6).apply(&mesh);
/// assert_eq!(keep, [true]);
/// # Ok::<(), halfedge_mesh::MeshError>(())
/// ```
#[derive(Debug, Clone, Copy, Default, PartialEq)]
#[non_exhaustive]
pub struct TriangleFilter {
    /// Largest circumradius kept; 0 keeps every triangle.
    pub alpha: f64,
    /// Longest edge kept; 0 keeps every triangle.
    pub lmax: f64,
    /// Unit up vector and the least cosine between it and a kept triangle's normal (the
    /// mesh's triangle normals; a mesh without them passes this test).
    pub normal: Option<([f64; 3], f64)>,
}

impl TriangleFilter {
    /// No test: every triangle is kept.
    pub fn new() -> Self {
        Self::default()
    }

    /// Sets [`Self::alpha`].
    pub fn with_alpha(mut self, alpha: f64) -> Self {
        self.alpha = alpha;
        self
    }

    /// Sets [`Self::lmax`].
    pub fn with_lmax(mut self, lmax: f64) -> Self {
        self.lmax = lmax;
        self
    }

    /// Sets [`Self::normal`]: triangles whose unit normal has a cosine below `min_cos`
    /// with the unit vector `up` are dropped.
    pub fn with_up(mut self, up: [f64; 3], min_cos: f64) -> Self {
        self.normal = Some((up, min_cos));
        self
    }

    /// Marks the triangles that pass every test, in parallel; and how many each test
    /// dropped.
    pub fn apply(&self, mesh: &HalfEdgeMesh) -> (Vec<bool>, FilterCounts) {
        let vertices = mesh.vertices();
        let normals = mesh.triangle_normals().unwrap_or(&[]);
        let mut keep = vec![false; mesh.num_triangles()];
        let dropped = keep
            .par_chunks_mut(CHUNK)
            .zip(mesh.triangles().par_chunks(CHUNK))
            .enumerate()
            .map(|(chunk, (keep, triangles))| {
                let mut dropped = FilterCounts::default();
                for (i, (k, tri)) in keep.iter_mut().zip(triangles).enumerate() {
                    let t = chunk * CHUNK + i;
                    match self.test(vertices, normals.get(t), *tri) {
                        Verdict::Keep => *k = true,
                        Verdict::Normal => dropped.normal += 1,
                        Verdict::Lmax => dropped.lmax += 1,
                        Verdict::Alpha => dropped.alpha += 1,
                    }
                }
                dropped
            })
            .reduce(FilterCounts::default, FilterCounts::add);
        (keep, dropped)
    }

    #[inline]
    fn test(&self, vertices: &[[f64; 3]], normal: Option<&[f64; 3]>, tri: [u32; 3]) -> Verdict {
        if let (Some((up, min_cos)), Some(n)) = (self.normal, normal)
            && n[0] * up[0] + n[1] * up[1] + n[2] * up[2] < min_cos
        {
            return Verdict::Normal;
        }
        if self.lmax <= 0.0 && self.alpha <= 0.0 {
            return Verdict::Keep;
        }
        let [a, b, c] = tri.map(|v| vertices[v as usize]);
        let d2 = |p: [f64; 3], q: [f64; 3]| {
            (p[0] - q[0]) * (p[0] - q[0])
                + (p[1] - q[1]) * (p[1] - q[1])
                + (p[2] - q[2]) * (p[2] - q[2])
        };
        let (ab, bc, ca) = (d2(a, b), d2(b, c), d2(c, a));
        if self.lmax > 0.0 && ab.max(bc).max(ca) > self.lmax * self.lmax {
            return Verdict::Lmax;
        }
        if self.alpha > 0.0 {
            // R = |ab| |bc| |ca| / (4 area) and |cross| = 2 area, so R² = ab·bc·ca / (4 |cross|²).
            let n = cross_normal(a, b, c);
            let cross2 = n[0] * n[0] + n[1] * n[1] + n[2] * n[2];
            if ab * bc * ca > 4.0 * self.alpha * self.alpha * cross2 {
                return Verdict::Alpha;
            }
        }
        Verdict::Keep
    }
}

enum Verdict {
    Keep,
    Normal,
    Lmax,
    Alpha,
}

/// Label of a triangle that belongs to no region.
pub const NO_REGION: u32 = u32::MAX;

/// Polylidar's region growing (2D paper): the edge-connected components of the kept
/// triangles, stored flat (region `r` is `triangles[offsets[r]..offsets[r + 1]]`).
///
/// Not planeseg's region growing (Polylidar3D, Alg. 5), on purpose: on the 2D and 2.5D
/// paths every kept triangle belongs to the one plane being extracted, so a region is an
/// edge-connected component, with no dominant normal, plane offset or refinement to test.
///
/// ```
/// use halfedge_mesh::{HalfEdgeMesh, NO_REGION, Regions};
///
/// // Two triangles sharing an edge, and a third touching them at a corner only.
/// let mesh = HalfEdgeMesh::from_triangles(
///     vec![[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [1.0, 1.0, 0.0], [0.0, 1.0, 0.0],
///          [2.0, 1.0, 0.0], [2.0, 2.0, 0.0]],
///     vec![[0, 1, 2], [0, 2, 3], [2, 4, 5]],
/// )?;
/// let regions = Regions::grow(&mesh, &[true, true, true])?;
/// assert_eq!(regions.len(), 2);
/// assert_eq!(regions.region(0), [0, 1]);
/// let regions = Regions::grow(&mesh, &[true, false, true])?;
/// assert!(Regions::grow(&mesh, &[true]).is_err());
/// assert_eq!(regions.labels()[1], NO_REGION);
/// # Ok::<(), halfedge_mesh::MeshError>(())
/// ```
#[derive(Debug, Clone, Default, PartialEq, Eq)]
pub struct Regions {
    labels: Vec<u32>,
    triangles: Vec<u32>,
    offsets: Vec<u32>,
}

impl Regions {
    /// Grows regions over the triangles `keep` marks (one flag per triangle), from seeds
    /// taken in triangle order, so the result is deterministic. The label array doubles
    /// as the visited set: no hashing.
    ///
    /// # Errors
    /// [`MeshError::LengthMismatch`] when `keep` does not hold one flag per triangle.
    pub fn grow(mesh: &HalfEdgeMesh, keep: &[bool]) -> Result<Self, MeshError> {
        if keep.len() != mesh.num_triangles() {
            return Err(MeshError::LengthMismatch {
                what: "keep flags",
                found: keep.len(),
                expected: mesh.num_triangles(),
            });
        }
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
        Ok(Self {
            labels,
            triangles,
            offsets,
        })
    }

    /// Number of regions.
    pub fn len(&self) -> usize {
        self.offsets.len() - 1
    }

    /// Whether there is no region.
    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }

    /// The region of every triangle, [`NO_REGION`] for triangles not kept.
    pub fn labels(&self) -> &[u32] {
        &self.labels
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
    fn circumradius_and_edge_tests_match_the_formulas() {
        // Right triangle with legs 3, 4: hypotenuse 5, circumradius 2.5.
        let mesh = HalfEdgeMesh::from_triangles(
            vec![[0.0, 0.0, 0.0], [3.0, 0.0, 0.0], [0.0, 4.0, 0.0]],
            vec![[0, 1, 2]],
        )
        .unwrap();
        let run = |alpha, lmax| {
            TriangleFilter::new()
                .with_alpha(alpha)
                .with_lmax(lmax)
                .apply(&mesh)
        };
        assert_eq!(run(2.6, 0.0).0, [true]);
        assert_eq!(run(2.4, 0.0).1.alpha, 1);
        assert_eq!(run(0.0, 5.1).0, [true]);
        assert_eq!(run(0.0, 4.9).1.lmax, 1);
        let tilted = TriangleFilter::new().with_up([0.0, 0.6, 0.8], 0.9);
        assert_eq!(tilted.apply(&mesh).1.normal, 1);
    }

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
        let regions = Regions::grow(&mesh, &[true; 4]).unwrap();
        assert_eq!(regions.len(), 2);
        assert_eq!(regions.region(0), [0, 1]);
        assert_eq!(regions.region(1), [2, 3]);
        let regions = Regions::grow(&mesh, &[true, false, true, true]).unwrap();
        assert_eq!(regions.len(), 2);
        assert_eq!(regions.labels()[1], NO_REGION);
    }
}

//! The α-complex of a 2D point set: the Delaunay triangles whose circumradius is at most α,
//! computed in parallel over vertical strips.
//!
//! The plane is cut at `k − 1` abscissae into strip cores; band `i` holds the points of core
//! `i` plus those within a margin `m > 2α` of it. A triangle is *owned* by the core holding
//! its smallest-index vertex `v`. A triangle of circumradius `R ≤ α` lies with its
//! circumcircle in `[v.x − 2R, v.x + 2R]`, inside the band of its owner; so its circle is
//! empty of band points iff it is empty of all points, and it is a triangle of the band's
//! triangulation iff it is one of the global triangulation. The triangulation is unique
//! (exact predicates, cocircular ties perturbed by point index, see
//! [`predicates`](super::predicates)), so every strip agrees on it and each triangle is
//! found exactly once, by its owner.
//!
//! The radius test is the float test of the Polylidar filter, `|ab|² |bc|² |ca|² ≤
//! 4 α² |ab × ac|²` evaluated from the smallest-index vertex `a`. Its rounding can only
//! matter when a triangle has an edge shorter than `1e-12 α` (then the cross product may
//! carry a large relative error); each strip checks its edges and, if it finds one that
//! short, the whole computation falls back to a single strip, which needs no margin.
//!
//! Twins inside a strip come from its triangulation; twins across strips are found by
//! sorting the remaining edges on their vertex pair. The result depends on the number of
//! strips only through the order of the triangles, and not at all on the thread count.

use rayon::prelude::*;

use super::predicates::orient;
use super::{Collinear, triangulate};
use crate::delaunay::{check_count, check_point};
use crate::mesh::NO_TWIN;
use crate::{HalfEdgeMesh, MeshError};

/// Below this many points per strip a strip is not worth its margin.
const POINTS_PER_STRIP: usize = 16_384;
/// The most strips the automatic choice makes.
const MAX_STRIPS: usize = 32;
/// Strip cores are at least this many margins wide.
const MIN_CORE_MARGINS: f64 = 4.0;
/// Edges shorter than this many α make the float radius test unreliable enough to matter.
const TINY_EDGE: f64 = 1e-12;

/// Options for [`HalfEdgeMesh::alpha_complex_2d_with_options`].
///
/// ```
/// use halfedge_mesh::AlphaComplexOptions;
/// let options = AlphaComplexOptions::new().strips(4);
/// assert_eq!(options.strips, 4);
/// ```
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq, Hash)]
#[non_exhaustive]
pub struct AlphaComplexOptions {
    /// Number of vertical strips triangulated in parallel; `0` (the default) chooses from
    /// the point count and the extent of the points: the largest power of two not above
    /// one strip per 8,192 points, 32 strips, or cores 8 α wide. The strips, never the
    /// thread count, fix the output order; the set of triangles is the same for any number
    /// of strips.
    pub strips: usize,
}

impl AlphaComplexOptions {
    /// The defaults: automatic strip count.
    pub fn new() -> Self {
        Self::default()
    }

    /// Sets the number of strips (`0`: automatic).
    pub fn strips(mut self, strips: usize) -> Self {
        self.strips = strips;
        self
    }
}

/// What [`HalfEdgeMesh::alpha_complex_2d`] found besides the mesh.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub struct AlphaComplexReport {
    /// Input points left out because an equal point (same coordinates) is in the
    /// triangulation; of each group of equal points the first one is kept.
    pub duplicate_points: usize,
    /// Triangles of the whole Delaunay triangulation: `2n − 2 − h` for `n` distinct
    /// points of which `h` lie on the convex hull boundary (true of every triangulation).
    pub delaunay_triangles: usize,
    /// Delaunay triangles left out for a circumradius above α
    /// (`delaunay_triangles − ` kept triangles).
    pub dropped_alpha: usize,
    /// Strips actually used (1 after a fallback, see the module documentation).
    pub strips: usize,
}

impl HalfEdgeMesh {
    /// The α-complex of a 2D point set: exactly the triangles of
    /// [`delaunay_2d`](Self::delaunay_2d) whose circumradius is at most `alpha`, with twins
    /// among themselves (half-edges next to a dropped triangle are border edges).
    /// Computed in parallel over vertical strips (rayon; the current thread pool), with a
    /// result independent of the thread count.
    ///
    /// The radius test is the one of the Polylidar triangle filter, evaluated from each
    /// triangle's smallest vertex index, which comes first in its triangle here; so running
    /// that filter again keeps every triangle. Vertices are all input points with `z = 0`;
    /// every normal is `+z`. `alpha ≤ 0` or NaN keeps no triangle, `+∞` keeps all.
    ///
    /// ```
    /// use halfedge_mesh::HalfEdgeMesh;
    /// // A unit square and a far point: only the square's triangles are small.
    /// let points = [[0.0, 0.0], [1.0, 0.0], [1.0, 1.0], [0.0, 1.0], [9.0, 0.5]];
    /// let (mesh, report) = HalfEdgeMesh::alpha_complex_2d(&points, 1.0)?;
    /// assert_eq!(mesh.num_triangles(), 2);
    /// assert_eq!(report.delaunay_triangles, 3);
    /// assert_eq!(report.dropped_alpha, 1);
    /// # Ok::<(), halfedge_mesh::MeshError>(())
    /// ```
    ///
    /// # Errors
    /// As [`Self::delaunay_2d`].
    pub fn alpha_complex_2d(
        points: &[[f64; 2]],
        alpha: f64,
    ) -> Result<(Self, AlphaComplexReport), MeshError> {
        Self::alpha_complex_2d_with_options(points, alpha, &AlphaComplexOptions::default())
    }

    /// [`Self::alpha_complex_2d`] with a chosen number of strips.
    ///
    /// # Errors
    /// As [`Self::delaunay_2d`].
    pub fn alpha_complex_2d_with_options(
        points: &[[f64; 2]],
        alpha: f64,
        options: &AlphaComplexOptions,
    ) -> Result<(Self, AlphaComplexReport), MeshError> {
        check_count(points.len())?;
        for (i, p) in points.iter().enumerate() {
            check_point(i, *p)?;
        }
        if all_collinear(points) {
            return Err(MeshError::Collinear {
                count: points.len(),
            });
        }
        // No triangle has a circumradius ≤ 0 (or ≤ NaN); the squared test needs α ≥ 0.
        let alpha = if alpha > 0.0 { alpha } else { 0.0 };
        let margin = 2.0 * alpha * 1.01;
        let strips = Strips::new(points, margin, options.strips);
        let mut parts = alpha_parts(points, alpha, &strips);
        if parts.iter().any(|p| p.tiny_edge) && strips.count() > 1 {
            parts = alpha_parts(points, alpha, &Strips::single());
        }
        let report_strips = parts.len();
        let (triangles, halfedges) = assemble(&parts);
        let duplicates: usize = parts.iter().map(|p| p.duplicates).sum();
        let hull = hull_size(points, parts.iter().flat_map(|p| p.hull.iter().copied()));
        let delaunay_triangles = 2 * (points.len() - duplicates) - 2 - hull;
        let report = AlphaComplexReport {
            duplicate_points: duplicates,
            delaunay_triangles,
            dropped_alpha: delaunay_triangles - triangles.len(),
            strips: report_strips,
        };
        let vertices = points.iter().map(|p| [p[0], p[1], 0.0]).collect();
        let normals = vec![[0.0, 0.0, 1.0]; triangles.len()];
        Ok((
            Self::from_parts_trusted(vertices, triangles, halfedges, normals),
            report,
        ))
    }
}

/// Whether every point lies on one line (or all coincide).
fn all_collinear(points: &[[f64; 2]]) -> bool {
    let a = points[0];
    let Some(b) = points.iter().find(|p| **p != a) else {
        return true;
    };
    points.iter().all(|p| orient(a, *b, *p) == 0.0)
}

/// The strip layout: cores `[cuts[i − 1], cuts[i])` (unbounded at both ends) and bands
/// widened by the margin on each side.
struct Strips {
    cuts: Vec<f64>,
    margin: f64,
}

impl Strips {
    fn single() -> Self {
        Self {
            cuts: Vec::new(),
            margin: f64::INFINITY,
        }
    }

    /// Cuts at quantiles of the abscissae (estimated from a regular sample of the points).
    fn new(points: &[[f64; 2]], margin: f64, requested: usize) -> Self {
        let (lo, hi) = points
            .iter()
            .fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), p| {
                (lo.min(p[0]), hi.max(p[0]))
            });
        let k = if requested > 0 {
            requested
        } else {
            let by_width = ((hi - lo) / (MIN_CORE_MARGINS * margin)).floor();
            let by_width = if by_width >= 1.0 {
                by_width.min(MAX_STRIPS as f64) as usize
            } else {
                1
            };
            let by_count = (points.len() / POINTS_PER_STRIP).clamp(1, MAX_STRIPS);
            // A power of two, so that the strips share out evenly over common thread counts.
            1 << by_count.min(by_width).ilog2()
        };
        if k <= 1 || margin.is_nan() || margin <= 0.0 || margin == f64::INFINITY {
            return Self::single();
        }
        let step = (points.len() / 4096).max(1);
        let mut sample: Vec<f64> = points.iter().step_by(step).map(|p| p[0]).collect();
        sample.sort_unstable_by(f64::total_cmp);
        let mut cuts: Vec<f64> = (1..k).map(|i| sample[i * sample.len() / k]).collect();
        cuts.dedup();
        Self { cuts, margin }
    }

    fn count(&self) -> usize {
        self.cuts.len() + 1
    }

    /// Whether abscissa `x` is in core `i`.
    #[inline]
    fn in_core(&self, i: usize, x: f64) -> bool {
        (i == 0 || x >= self.cuts[i - 1]) && (i == self.cuts.len() || x < self.cuts[i])
    }

    /// The closed abscissa range of band `i`, rounded outwards.
    fn band(&self, i: usize) -> (f64, f64) {
        let widen = |x: f64, dir: f64| {
            let y = x + dir * self.margin;
            y + dir * 4.0 * f64::EPSILON * (x.abs() + y.abs())
        };
        let lo = if i == 0 {
            f64::NEG_INFINITY
        } else {
            widen(self.cuts[i - 1], -1.0)
        };
        let hi = if i == self.cuts.len() {
            f64::INFINITY
        } else {
            widen(self.cuts[i], 1.0)
        };
        (lo, hi)
    }
}

/// What one strip contributes.
struct Part {
    /// Owned triangles within α, smallest vertex first, global vertex ids.
    triangles: Vec<[u32; 3]>,
    /// Twins inside this part (local half-edge indices) or [`NO_TWIN`] for edges left to
    /// the seam linking.
    halfedges: Vec<u32>,
    /// Edges of `triangles` without a twin here: (unordered vertex pair key, local half-edge).
    seams: Vec<(u64, u32)>,
    /// Duplicate points among the core's points.
    duplicates: usize,
    /// Core points on the band's hull: candidates for the global hull.
    hull: Vec<u32>,
    /// Whether the band's triangulation has an edge shorter than `TINY_EDGE · α`.
    tiny_edge: bool,
}

fn alpha_parts(points: &[[f64; 2]], alpha: f64, strips: &Strips) -> Vec<Part> {
    (0..strips.count())
        .into_par_iter()
        .map(|i| strip_part(points, alpha, strips, i))
        .collect()
}

/// Triangulates band `i` and keeps the triangles core `i` owns.
fn strip_part(points: &[[f64; 2]], alpha: f64, strips: &Strips, i: usize) -> Part {
    let (lo, hi) = strips.band(i);
    let (ids, coords): (Vec<u32>, Vec<[f64; 2]>) = if strips.count() == 1 {
        ((0..points.len() as u32).collect(), points.to_vec())
    } else {
        points
            .iter()
            .enumerate()
            .filter(|(_, p)| lo <= p[0] && p[0] <= hi)
            .map(|(k, p)| (k as u32, *p))
            .unzip()
    };
    let tri = match triangulate(&coords, Some(&ids)) {
        Ok(tri) => tri,
        Err(Collinear) => {
            return collinear_part(points, &ids, |v| strips.in_core(i, points[v as usize][0]));
        }
    };
    // Work on the sweep's positions: coordinates in insertion order, ranks = global ids.
    let (xy, gid) = (&tri.coords, &tri.ranks);
    let in_core = |p: u32| strips.in_core(i, xy[p as usize][0]);
    let core_points = coords.iter().filter(|p| strips.in_core(i, p[0])).count();
    let distinct_core = (0..xy.len() as u32).filter(|&p| in_core(p)).count();
    let hull = tri
        .hull
        .iter()
        .filter(|&&p| in_core(p))
        .map(|&p| gid[p as usize])
        .collect();

    // Pass 1: owned triangles within α get a local index; edges are checked for length.
    let tiny2 = {
        let t = TINY_EDGE * alpha;
        t * t
    };
    let mut tiny_edge = false;
    let num_triangles = tri.tris.len() / 3;
    let mut local = vec![NO_TWIN; num_triangles];
    let mut triangles = Vec::with_capacity(num_triangles);
    let mut rotations: Vec<u8> = Vec::with_capacity(num_triangles);
    for (t, v) in tri.tris.chunks_exact(3).enumerate() {
        let g = [gid[v[0] as usize], gid[v[1] as usize], gid[v[2] as usize]];
        let r = rotation(g);
        let (r1, r2) = (NEXT[r], NEXT[NEXT[r]]);
        let [a, b, c] = [xy[v[r] as usize], xy[v[r1] as usize], xy[v[r2] as usize]];
        let (ab, bc, ca) = (dist2(a, b), dist2(b, c), dist2(c, a));
        tiny_edge |= ab.min(bc).min(ca) < tiny2;
        if in_core(v[r]) && within_alpha(a, b, c, ab, bc, ca, alpha) {
            local[t] = triangles.len() as u32;
            triangles.push([g[r], g[r1], g[r2]]);
            rotations.push(r as u8);
        }
    }

    // Pass 2: twins among kept triangles; the other edges go to the seam linking.
    let mut halfedges = vec![NO_TWIN; 3 * triangles.len()];
    let mut seams = Vec::new();
    for (t, &l) in local.iter().enumerate() {
        if l == NO_TWIN {
            continue;
        }
        let (v, r) = (triangles[l as usize], rotations[l as usize] as usize);
        for k in 0..3 {
            let h = 3 * l as usize + k;
            // Corner k of the rotated triangle is corner (r + k) % 3 of the sweep's.
            let twin = tri.halfedges[3 * t + ROTATE[r][k]];
            if twin != NO_TWIN {
                let lu = local[twin as usize / 3];
                if lu != NO_TWIN {
                    let ru = rotations[lu as usize] as usize;
                    halfedges[h] = 3 * lu + UNROTATE[ru][twin as usize % 3];
                    continue;
                }
            }
            let (p, q) = (v[k], v[NEXT[k]]);
            seams.push(((u64::from(p.min(q)) << 32) | u64::from(p.max(q)), h as u32));
        }
    }
    Part {
        triangles,
        halfedges,
        seams,
        duplicates: core_points - distinct_core,
        hull,
        tiny_edge,
    }
}

/// A band whose points are collinear contributes no triangle; its distinct core points
/// are all hull candidates.
fn collinear_part(points: &[[f64; 2]], ids: &[u32], in_core: impl Fn(u32) -> bool) -> Part {
    let mut core: Vec<u32> = ids.iter().copied().filter(|&v| in_core(v)).collect();
    let total = core.len();
    core.sort_unstable_by(|&a, &b| {
        let (p, q) = (points[a as usize], points[b as usize]);
        p[0].total_cmp(&q[0])
            .then(p[1].total_cmp(&q[1]))
            .then(a.cmp(&b))
    });
    core.dedup_by(|a, b| points[*a as usize] == points[*b as usize]);
    Part {
        triangles: Vec::new(),
        halfedges: Vec::new(),
        seams: Vec::new(),
        duplicates: total - core.len(),
        hull: core,
        tiny_edge: false,
    }
}

/// The corner after each corner.
const NEXT: [usize; 3] = [1, 2, 0];
/// `ROTATE[r][k]`: the corner of a triangle that is corner `k` once rotated by `r`.
const ROTATE: [[usize; 3]; 3] = [[0, 1, 2], [1, 2, 0], [2, 0, 1]];
/// `UNROTATE[r][c]`: the inverse of [`ROTATE`].
const UNROTATE: [[u32; 3]; 3] = [[0, 1, 2], [2, 0, 1], [1, 2, 0]];

/// Position of the smallest vertex id.
#[inline]
fn rotation(v: [u32; 3]) -> usize {
    if v[0] < v[1] {
        if v[0] < v[2] { 0 } else { 2 }
    } else if v[1] < v[2] {
        1
    } else {
        2
    }
}

#[inline]
fn dist2(p: [f64; 2], q: [f64; 2]) -> f64 {
    (p[0] - q[0]) * (p[0] - q[0]) + (p[1] - q[1]) * (p[1] - q[1])
}

/// The Polylidar filter's α test from corner `a`: circumradius `R` with
/// `R² = |ab|² |bc|² |ca|² / (4 |ab × ac|²)`, kept when `R ≤ α`.
#[inline]
fn within_alpha(
    a: [f64; 2],
    b: [f64; 2],
    c: [f64; 2],
    ab: f64,
    bc: f64,
    ca: f64,
    alpha: f64,
) -> bool {
    let cross = (b[0] - a[0]) * (c[1] - a[1]) - (b[1] - a[1]) * (c[0] - a[0]);
    ab * bc * ca <= 4.0 * alpha * alpha * (cross * cross)
}

/// Concatenates the parts and links the seam edges by sorting them on their vertex pair.
fn assemble(parts: &[Part]) -> (Vec<[u32; 3]>, Vec<u32>) {
    let total: usize = parts.iter().map(|p| p.triangles.len()).sum();
    let mut triangles = Vec::with_capacity(total);
    let mut halfedges = Vec::with_capacity(3 * total);
    let mut seams = Vec::with_capacity(parts.iter().map(|p| p.seams.len()).sum());
    for part in parts {
        let offset = 3 * triangles.len() as u32;
        triangles.extend_from_slice(&part.triangles);
        halfedges.extend(
            part.halfedges
                .iter()
                .map(|&h| if h == NO_TWIN { NO_TWIN } else { h + offset }),
        );
        seams.extend(part.seams.iter().map(|&(key, h)| (key, h + offset)));
    }
    seams.sort_unstable();
    for pair in seams.chunk_by(|x, y| x.0 == y.0) {
        if let [(_, a), (_, b)] = pair {
            halfedges[*a as usize] = *b;
            halfedges[*b as usize] = *a;
        }
    }
    (triangles, halfedges)
}

/// Number of points on the boundary of the convex hull of `candidates` (points on a hull
/// edge included, duplicates counted once): Andrew's monotone chain with exact turns.
fn hull_size(points: &[[f64; 2]], candidates: impl Iterator<Item = u32>) -> usize {
    let mut c: Vec<[f64; 2]> = candidates.map(|v| points[v as usize]).collect();
    c.sort_unstable_by(|p, q| p[0].total_cmp(&q[0]).then(p[1].total_cmp(&q[1])));
    c.dedup();
    let chain = |iter: &mut dyn Iterator<Item = [f64; 2]>| {
        let mut chain: Vec<[f64; 2]> = Vec::new();
        for p in iter {
            while chain.len() >= 2
                && orient(chain[chain.len() - 2], chain[chain.len() - 1], p) < 0.0
            {
                chain.pop();
            }
            chain.push(p);
        }
        chain.len()
    };
    chain(&mut c.iter().copied()) + chain(&mut c.iter().rev().copied()) - 2
}

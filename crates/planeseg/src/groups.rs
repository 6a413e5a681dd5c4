//! Group assignment (Alg. 4).

use std::sync::atomic::AtomicU32;

use halfedge_mesh::HalfEdgeMesh;
use rayon::prelude::*;

use crate::vec3::{Vec3, add, corners, cross, dot, scale, sub};
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
    assign(mesh, dominant, config).map(|a| (a.groups, a.counts))
}

/// The result of [`assign`].
pub(crate) struct Assignment {
    /// Group per triangle.
    pub groups: Vec<u32>,
    /// What region growing reads of each triangle, in one place.
    pub slots: Vec<Slot>,
    /// The point the volumes are taken from: a corner of the mesh's first triangle with
    /// finite corners, so that coordinates relative to it stay small.
    pub reference: [f64; 3],
    /// The grouped triangles by group, in triangle order: `buckets[c][g]` lists those of
    /// group `g` among triangles `c · CHUNK ..`, so that group `g`'s triangles are the
    /// concatenation of `buckets[..][g]`.
    pub buckets: Vec<Vec<Vec<u32>>>,
    pub counts: GroupCounts,
}

/// The state of a grouped triangle not yet in a segment: `FREE - g` for group `g`. Once in
/// a segment the state is the segment's seed, a triangle index; triangle indices stay below
/// `u32::MAX / 3` (half-edge indices are `u32`), far from these values. One word per
/// triangle answers "is it free and in my group" with a single load.
pub(crate) const FREE: u32 = u32::MAX - 2;

/// The group [`assign`] gives a triangle dropped by the `lmax` test until it counts the
/// drops and replaces it by [`NO_GROUP`].
const DROPPED_LMAX: u32 = u32::MAX - 1;

/// Per triangle, all that region growing reads of a neighbour, so that visiting it costs
/// one cache line.
#[derive(Debug)]
pub(crate) struct Slot {
    /// `FREE - g` while free in group `g`, the seed once in a segment, [`NO_GROUP`] if in
    /// no group. Only the task of group `g` writes the labels of its triangles; the others
    /// only read them.
    pub label: AtomicU32,
    /// `det(a − r, b − r, c − r)` for the corners `a, b, c` and the
    /// [`reference`](Assignment::reference) point `r`: six times the signed volume of
    /// the tetrahedron the triangle spans with `r`, the one per-triangle term of a
    /// segment's centroid (see `boundary_plane`); 0 if in no group.
    pub volume: f32,
    /// The offset of the centroid along the group's dominant normal, what the
    /// point-to-plane test of region growing compares; 0 if in no group.
    pub offset: f64,
}

impl Slot {
    /// The slot of a triangle in no group.
    fn none() -> Self {
        Self {
            label: AtomicU32::new(NO_GROUP),
            volume: 0.0,
            offset: 0.0,
        }
    }
}

/// [`assign_groups`] with what region growing and the segment planes need, computed
/// while the triangle's corners are at hand. Every output array is written once, in
/// parallel: this pass moves more memory than it computes.
pub(crate) fn assign(
    mesh: &HalfEdgeMesh,
    dominant: &[[f64; 3]],
    config: &SegmentationConfig,
) -> Result<Assignment, SegmentError> {
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
    let reference = reference_point(mesh);
    let lookup = NearestLookup::new(dominant);
    let mut groups = Vec::new();
    let mut slots = Vec::new();
    mesh.triangles()
        .par_iter()
        .zip(normals)
        .with_min_len(CHUNK)
        // Neighbouring triangles mostly share a group: try the last one first.
        .map_init(
            || 0,
            |last, (tri, n)| {
                let [a, b, c] = corners(vertices, *tri);
                let (u, v, w) = (sub(b, a), sub(c, a), sub(c, b));
                if dot(u, u).max(dot(v, v)).max(dot(w, w)) > lmax2 {
                    return (DROPPED_LMAX, Slot::none());
                }
                let (best, best_dot) = match lookup.sure_nearest(*n, *last) {
                    Some(dot) => (*last, dot),
                    None => lookup.nearest(*n, dominant),
                };
                // Also drops a NaN similarity.
                if best_dot
                    .partial_cmp(&config.norm_thresh)
                    .is_none_or(|o| o.is_lt())
                {
                    return (NO_GROUP, Slot::none());
                }
                *last = best;
                let centroid = add(a, scale(add(u, v), 1.0 / 3.0));
                let slot = Slot {
                    label: AtomicU32::new(FREE - best),
                    volume: dot(cross(u, v), sub(a, reference)) as f32,
                    offset: dot(dominant[best as usize], centroid),
                };
                (best, slot)
            },
        )
        .unzip_into_vecs(&mut groups, &mut slots);
    let (buckets, counts): (Vec<_>, Vec<_>) = groups
        .par_chunks_mut(CHUNK)
        .enumerate()
        .map(|(c, chunk)| bucket(chunk, c * CHUNK, dominant.len()))
        .unzip();
    let counts = counts
        .into_iter()
        .fold(GroupCounts::default(), GroupCounts::add);
    Ok(Assignment {
        groups,
        slots,
        reference,
        buckets,
        counts,
    })
}

/// Lists the triangles of `chunk` (the first is triangle `first`) by group, counts them
/// and replaces [`DROPPED_LMAX`] by [`NO_GROUP`].
fn bucket(chunk: &mut [u32], first: usize, groups: usize) -> (Vec<Vec<u32>>, GroupCounts) {
    let mut buckets = vec![Vec::new(); groups];
    let mut counts = GroupCounts::default();
    for (t, g) in (first as u32..).zip(chunk) {
        match *g {
            NO_GROUP => counts.dropped_normal += 1,
            DROPPED_LMAX => {
                *g = NO_GROUP;
                counts.dropped_lmax += 1;
            }
            group => {
                buckets[group as usize].push(t);
                counts.grouped += 1;
            }
        }
    }
    (buckets, counts)
}

/// A corner of the first triangle whose corners are all finite (the origin if none).
fn reference_point(mesh: &HalfEdgeMesh) -> [f64; 3] {
    let v = mesh.vertices();
    mesh.triangles()
        .iter()
        .map(|&t| corners(v, t))
        .find(|corners| corners.iter().flatten().all(|x| x.is_finite()))
        .map_or([0.0; 3], |[a, _, _]| a)
}

/// Cells per cube-face side of [`NearestLookup`].
const CUBE_CELLS: usize = 32;

/// For each cell of a cube map over the sphere, the dominant normals that can be the
/// nearest (largest dot product) to some direction in the cell, in index order; a
/// triangle normal then compares only those (usually one or two) instead of all.
///
/// Exact: a cell with centre `c` and angular radius `r` (its farthest corner) keeps
/// normal `j` unless `angle(c, d_j) − r > min_k angle(c, d_k) + r`, in which case every
/// direction in the cell is nearer to that `d_k` than to `d_j`. The scan over the
/// candidates in index order then picks what a scan over all normals picks.
///
/// Before that, [`Self::sure_nearest`] settles most triangles with one dot product: a
/// direction within half the angle from `d_j` to its closest other dominant normal is
/// strictly nearer to `d_j` than to any other (triangle inequality on the sphere).
struct NearestLookup {
    /// Start of each cell's candidates in `candidates` (one more entry than cells).
    offsets: Vec<u32>,
    candidates: Vec<u32>,
    /// Per dominant normal `j`, `(d_j, c_j)`: a direction whose dot product with `d_j`
    /// exceeds `c_j` has `d_j` as its strictly nearest dominant normal.
    sure: Vec<([f64; 3], f64)>,
}

impl NearestLookup {
    fn new(dominant: &[[f64; 3]]) -> Self {
        let n = CUBE_CELLS;
        let mut offsets = Vec::with_capacity(6 * n * n + 1);
        let mut candidates = Vec::new();
        offsets.push(0);
        let mut dots = vec![0.0; dominant.len()];
        for face in 0..6 {
            for i in 0..n {
                for j in 0..n {
                    let corner = |di: usize, dj: usize| {
                        let u = 2.0 * (i + di) as f64 / n as f64 - 1.0;
                        let v = 2.0 * (j + dj) as f64 / n as f64 - 1.0;
                        let p = face_point(face, u, v);
                        scale(p, 1.0 / dot(p, p).sqrt())
                    };
                    let corners = [corner(0, 0), corner(1, 0), corner(0, 1), corner(1, 1)];
                    let sum = corners.iter().fold([0.0; 3], |s, &c| add(s, c));
                    let centre = scale(sum, 1.0 / dot(sum, sum).sqrt());
                    let radius = corners
                        .iter()
                        .map(|c| angle(centre, *c))
                        .fold(0.0, f64::max);
                    for (dot, d) in dots.iter_mut().zip(dominant) {
                        *dot = centre[0] * d[0] + centre[1] * d[1] + centre[2] * d[2];
                    }
                    // Angles compared through their cosines: one arc cosine per cell.
                    let nearest = dots.iter().copied().fold(-1.0, f64::max).min(1.0).acos();
                    let limit = (nearest + 2.0 * radius + 1e-9)
                        .min(std::f64::consts::PI)
                        .cos();
                    candidates.extend(
                        (0..dominant.len() as u32).filter(|&k| dots[k as usize] >= limit - 1e-12),
                    );
                    offsets.push(candidates.len() as u32);
                }
            }
        }
        let sure = dominant
            .iter()
            .enumerate()
            .map(|(j, &d)| {
                let closest = dominant
                    .iter()
                    .enumerate()
                    .filter(|&(k, _)| k != j)
                    .map(|(_, &e)| angle(d, e))
                    .fold(std::f64::consts::PI, f64::min);
                // The margin covers the rounding of the dot products compared.
                (d, (0.5 * closest).cos() + 1e-9)
            })
            .collect();
        Self {
            offsets,
            candidates,
            sure,
        }
    }

    /// `Some(dot(n, d_j))` if `d_j` is certainly the nearest dominant normal to `n`
    /// ; `None` if that takes [`Self::nearest`] (or `j` is out of range).
    #[inline]
    fn sure_nearest(&self, n: [f64; 3], j: u32) -> Option<f64> {
        let &(d, limit) = self.sure.get(j as usize)?;
        let dot = dot(n, d);
        (dot > limit).then_some(dot)
    }

    /// The nearest of the `dominant` normals to `n` (the lowest index on a tie) and its
    /// dot product; `(NO_GROUP, −∞)` for a NaN `n`.
    #[inline]
    fn nearest(&self, n: [f64; 3], dominant: &[[f64; 3]]) -> (u32, f64) {
        let (mut best, mut best_dot) = (NO_GROUP, f64::NEG_INFINITY);
        for &j in self.candidates(n) {
            let dot = dot(n, dominant[j as usize]);
            if dot > best_dot {
                (best, best_dot) = (j, dot);
            }
        }
        (best, best_dot)
    }

    /// The candidates for direction `d` (any length; NaN gives an empty list).
    #[inline]
    fn candidates(&self, d: [f64; 3]) -> &[u32] {
        let a = d.map(f64::abs);
        let (face, m, u, v) = if a[0] >= a[1] && a[0] >= a[2] {
            (usize::from(d[0] < 0.0), a[0], d[1], d[2])
        } else if a[1] >= a[2] {
            (2 + usize::from(d[1] < 0.0), a[1], d[0], d[2])
        } else {
            (4 + usize::from(d[2] < 0.0), a[2], d[0], d[1])
        };
        if m.is_nan() || m <= 0.0 {
            return &[];
        }
        let n = CUBE_CELLS as f64;
        let cell = |x: f64| (((x / m + 1.0) * 0.5 * n) as usize).min(CUBE_CELLS - 1);
        let index = (face * CUBE_CELLS + cell(u)) * CUBE_CELLS + cell(v);
        &self.candidates[self.offsets[index] as usize..self.offsets[index + 1] as usize]
    }
}

/// The point of cube face `face` at face coordinates `u, v ∈ [−1, 1]`, matching
/// [`NearestLookup::candidates`].
fn face_point(face: usize, u: f64, v: f64) -> [f64; 3] {
    let s = if face.is_multiple_of(2) { 1.0 } else { -1.0 };
    match face / 2 {
        0 => [s, u, v],
        1 => [u, s, v],
        _ => [u, v, s],
    }
}

fn angle(a: Vec3, b: Vec3) -> f64 {
    dot(a, b).clamp(-1.0, 1.0).acos()
}

fn check_dominant(dominant: &[[f64; 3]]) -> Result<(), SegmentError> {
    for (index, d) in dominant.iter().enumerate() {
        let len2 = dot(*d, *d);
        if !len2.is_finite() || (len2 - 1.0).abs() > 1e-6 {
            return Err(SegmentError::BadDominantNormal { index, normal: *d });
        }
    }
    Ok(())
}

//! Group assignment (Alg. 4).

use std::sync::atomic::Ordering::Relaxed;
use std::sync::atomic::{AtomicU8, AtomicU32};

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
    /// Triangles near enough to a dominant normal whose longest edge exceeds `lmax`.
    pub dropped_lmax: usize,
    /// Triangles too far from every dominant normal (whatever their edges).
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
    let mut assignment = Assignment::default();
    assignment.assign(mesh, dominant, config)?;
    let groups = assignment
        .slots
        .par_iter()
        .map(|slot| match slot.label.load(Relaxed) {
            NO_GROUP => NO_GROUP,
            free => FREE - free,
        })
        .collect();
    Ok((groups, assignment.counts))
}

/// Group assignment with what region growing and the segment planes need, in buffers
/// kept across calls.
#[derive(Debug, Default)]
pub(crate) struct Assignment {
    /// What region growing reads of each triangle, in one place.
    pub slots: Vec<Slot>,
    /// The point the volumes are taken from: a corner of the mesh's first triangle with
    /// finite corners, so that coordinates relative to it stay small.
    pub reference: [f64; 3],
    /// The grouped triangles by group, in triangle order: `buckets[c][g]` lists those of
    /// group `g` among triangles `c · CHUNK ..`, so that group `g`'s triangles are the
    /// concatenation of `buckets[..][g]`.
    pub buckets: Vec<Vec<Vec<u32>>>,
    /// Per triangle, 1 once in a segment, else 0: the seed scan's view of the labels, a
    /// byte per triangle that stays cached where the slots do not. Like a label, only
    /// the task of the triangle's group writes it.
    pub taken: Vec<AtomicU8>,
    pub counts: GroupCounts,
}

/// The state of a grouped triangle not yet in a segment: `FREE - g` for group `g`. Once in
/// a segment the state is the segment's seed, a triangle index; triangle indices stay below
/// `u32::MAX / 3` (half-edge indices are `u32`), far from these values. One word per
/// triangle answers "is it free and in my group" with a single load.
pub(crate) const FREE: u32 = u32::MAX - 1;

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

impl Assignment {
    /// Assigns the groups of `mesh`'s triangles, overwriting the previous contents. Each
    /// output is written once, in parallel, in one pass over the triangles: this pass
    /// moves more memory than it computes.
    pub fn assign(
        &mut self,
        mesh: &HalfEdgeMesh,
        dominant: &[[f64; 3]],
        config: &SegmentationConfig,
    ) -> Result<(), SegmentError> {
        config.validate()?;
        check_dominant(dominant)?;
        let normals = mesh
            .triangle_normals()
            .ok_or(SegmentError::MissingNormals)?;
        // Few dominant normals are scanned; the table pays only for more.
        let lookup = (dominant.len() > SCAN_MAX).then(|| NearestLookup::new(dominant));
        self.reference = reference_point(mesh);
        let kernel = Kernel {
            vertices: mesh.vertices(),
            dominant,
            lookup: lookup.as_ref(),
            lmax2: if config.lmax > 0.0 {
                config.lmax * config.lmax
            } else {
                f64::INFINITY
            },
            norm_thresh: config.norm_thresh,
            reference: self.reference,
        };
        let n = mesh.num_triangles();
        self.slots.resize_with(n, Slot::none);
        self.taken.resize_with(n, AtomicU8::default);
        self.buckets.resize_with(n.div_ceil(CHUNK), Vec::new);
        self.counts = self
            .slots
            .par_chunks_mut(CHUNK)
            .zip(mesh.triangles().par_chunks(CHUNK))
            .zip(normals.par_chunks(CHUNK))
            .zip(self.buckets.par_iter_mut())
            .zip(self.taken.par_chunks_mut(CHUNK))
            .enumerate()
            .map(|(c, ((((slots, tris), normals), buckets), taken))| {
                taken.iter_mut().for_each(|t| *t.get_mut() = 0);
                buckets.resize_with(dominant.len(), Vec::new);
                buckets.iter_mut().for_each(Vec::clear);
                chunk(&kernel, (c * CHUNK) as u32, tris, normals, slots, buckets)
            })
            .reduce(GroupCounts::default, GroupCounts::add);
        Ok(())
    }
}

/// Triangles per block of the assignment kernel: the lanes of its vector arithmetic.
const LANES: usize = 8;

/// What group assignment needs of the mesh and the parameters.
struct Kernel<'a> {
    vertices: &'a [[f64; 3]],
    dominant: &'a [[f64; 3]],
    /// `None` with at most [`SCAN_MAX`] dominant normals, which are scanned.
    lookup: Option<&'a NearestLookup>,
    lmax2: f64,
    norm_thresh: f64,
    reference: [f64; 3],
}

/// Assigns one chunk (its first triangle is `first`), filling `slots` and `buckets`;
/// compiled also for AVX-512 and AVX2 and chosen at run time.
#[multiversion::multiversion(targets("x86_64+avx512f+avx512vl+avx512bw+avx512dq", "x86_64+avx2"))]
fn chunk(
    kernel: &Kernel<'_>,
    first: u32,
    tris: &[[u32; 3]],
    normals: &[[f64; 3]],
    slots: &mut [Slot],
    buckets: &mut [Vec<u32>],
) -> GroupCounts {
    let mut out = ChunkOut {
        buckets,
        counts: GroupCounts::default(),
        // Neighbouring triangles mostly share a group: try the last one first.
        last: 0,
    };
    let (tri_blocks, tri_rest) = tris.as_chunks::<LANES>();
    let (normal_blocks, normal_rest) = normals.as_chunks::<LANES>();
    let (slot_blocks, slot_rest) = slots.as_chunks_mut::<LANES>();
    let mut t = first;
    for ((tris, normals), slots) in tri_blocks.iter().zip(normal_blocks).zip(slot_blocks) {
        kernel.block(t, tris, normals, slots, &mut out);
        t += LANES as u32;
    }
    for ((tri, normal), slot) in tri_rest.iter().zip(normal_rest).zip(slot_rest) {
        kernel.block(t, &[*tri], &[*normal], std::array::from_mut(slot), &mut out);
        t += 1;
    }
    out.counts
}

impl Kernel<'_> {
    /// Assigns `N` consecutive triangles, the first being `first`: the nearest dominant
    /// normal, most often settled by one dot product with the last group's (vectorised
    /// over the block); then, only for the triangles near enough to it (a third of a
    /// depth frame's with the `rgbd` preset), their corners, edge lengths, centroid and
    /// volume term.
    #[inline(always)]
    fn block<const N: usize>(
        &self,
        first: u32,
        tris: &[[u32; 3]; N],
        normals: &[[f64; 3]; N],
        slots: &mut [Slot; N],
        out: &mut ChunkOut<'_>,
    ) {
        let (nearest, nearest_dot) = self.nearest(normals, out.last);
        for l in 0..N {
            let (best, best_dot) = (nearest[l], nearest_dot[l]);
            // Also drops a NaN similarity.
            if best_dot
                .partial_cmp(&self.norm_thresh)
                .is_none_or(|o| o.is_lt())
            {
                slots[l] = Slot::none();
                out.counts.dropped_normal += 1;
                continue;
            }
            let [a, b, c] = corners(self.vertices, tris[l]);
            let (u, v, w) = (sub(b, a), sub(c, a), sub(c, b));
            if (dot(u, u) > self.lmax2) | (dot(v, v) > self.lmax2) | (dot(w, w) > self.lmax2) {
                slots[l] = Slot::none();
                out.counts.dropped_lmax += 1;
                continue;
            }
            out.last = best;
            let centroid = add(a, scale(add(u, v), 1.0 / 3.0));
            slots[l] = Slot {
                label: AtomicU32::new(FREE - best),
                volume: dot(cross(u, v), sub(a, self.reference)) as f32,
                offset: dot(self.dominant[best as usize], centroid),
            };
            out.buckets[best as usize].push(first + l as u32);
            out.counts.grouped += 1;
        }
    }

    /// The nearest dominant normal of each of `N` triangle normals and its dot product
    /// (`NO_GROUP` and −∞ for a NaN normal); the lowest index on a tie. With at most
    /// [`SCAN_MAX`] dominant normals a scan over all of them, lane by lane (vectorised,
    /// no branch to mispredict); with more, one dot product with the last group's
    /// normal settles most, [`NearestLookup`] the others.
    #[inline(always)]
    fn nearest<const N: usize>(&self, normals: &[[f64; 3]; N], last: u32) -> ([u32; N], [f64; N]) {
        let (mut best, mut best_dot) = ([NO_GROUP; N], [f64::NEG_INFINITY; N]);
        let Some(lookup) = self.lookup else {
            for (j, &d) in self.dominant.iter().enumerate() {
                for l in 0..N {
                    let dot = dot(normals[l], d);
                    let nearer = dot > best_dot[l];
                    best[l] = if nearer { j as u32 } else { best[l] };
                    best_dot[l] = if nearer { dot } else { best_dot[l] };
                }
            }
            return (best, best_dot);
        };
        let (d, limit) = lookup
            .sure
            .get(last as usize)
            .copied()
            .unwrap_or(([0.0; 3], f64::INFINITY));
        for l in 0..N {
            let dot = dot(normals[l], d);
            (best[l], best_dot[l]) = if dot > limit {
                (last, dot)
            } else {
                lookup.nearest(normals[l], self.dominant)
            };
        }
        (best, best_dot)
    }
}

/// Most dominant normals for which [`Kernel::nearest`] scans them all.
const SCAN_MAX: usize = 64;

/// The running state of [`chunk`].
struct ChunkOut<'a> {
    buckets: &'a mut [Vec<u32>],
    counts: GroupCounts,
    /// The group of the last grouped triangle.
    last: u32,
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
const CUBE_CELLS: usize = 16;

/// For each cell of a cube map over the sphere, the dominant normals that can be the
/// nearest (largest dot product) to some direction in the cell, in index order; a
/// triangle normal then compares only those (usually one or two) instead of all.
///
/// Exact: a cell with centre `c` and angular radius `r` (its farthest corner) keeps
/// normal `j` unless `angle(c, d_j) − r > min_k angle(c, d_k) + r`, in which case every
/// direction in the cell is nearer to that `d_k` than to `d_j`. The scan over the
/// candidates in index order then picks what a scan over all normals picks.
///
/// Before that, [`Self::sure`] settles most triangles with one dot product: a direction
/// within half the angle from `d_j` to its closest other dominant normal is strictly
/// nearer to `d_j` than to any other (triangle inequality on the sphere).
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
        // Cells in parallel blocks, each listing its cells' candidates in index order and
        // their counts; the blocks are then concatenated.
        let blocks: Vec<(Vec<u32>, Vec<u32>)> = cube_cells()
            .par_chunks(512)
            .map(|cells| {
                let mut dots = vec![0.0; dominant.len()];
                let (mut candidates, mut counts) = (Vec::new(), Vec::with_capacity(cells.len()));
                for cell in cells {
                    for (dot, d) in dots.iter_mut().zip(dominant) {
                        *dot =
                            cell.centre[0] * d[0] + cell.centre[1] * d[1] + cell.centre[2] * d[2];
                    }
                    let nearest = dots.iter().copied().fold(-1.0, f64::max).min(1.0);
                    let limit = cell.limit(nearest);
                    let before = candidates.len();
                    candidates.extend(
                        (0..dominant.len() as u32).filter(|&k| dots[k as usize] >= limit - 1e-12),
                    );
                    counts.push((candidates.len() - before) as u32);
                }
                (candidates, counts)
            })
            .collect();
        let mut offsets = Vec::with_capacity(cube_cells().len() + 1);
        offsets.push(0);
        let mut candidates = Vec::with_capacity(blocks.iter().map(|b| b.0.len()).sum());
        for (block, counts) in &blocks {
            candidates.extend_from_slice(block);
            for &count in counts {
                offsets.push(offsets[offsets.len() - 1] + count);
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

/// A cell of the cube map of [`NearestLookup`]: its centre direction and what the
/// candidate test needs of its angular radius `r` (the angle to its farthest corner).
struct CubeCell {
    centre: [f64; 3],
    /// `cos b` and `sin b` for `b = 2r + 1e-9`: a normal farther than `nearest + b` from
    /// the centre cannot be the nearest anywhere in the cell (the 1e-9 covers rounding).
    cos_b: f64,
    sin_b: f64,
}

impl CubeCell {
    /// `cos(min(a + b, π))` for the angle `a` whose cosine is `cos_a`, by the angle sum
    /// identity: no inverse cosine per cell.
    fn limit(&self, cos_a: f64) -> f64 {
        // a + b ≥ π exactly when cos a ≤ cos(π − b) = −cos b.
        if cos_a <= -self.cos_b {
            return -1.0;
        }
        let sin_a = (1.0 - cos_a * cos_a).max(0.0).sqrt();
        cos_a * self.cos_b - sin_a * self.sin_b
    }
}

/// The cells of the cube map, face by face, row by row; they depend on nothing but
/// [`CUBE_CELLS`], so they are computed once per process.
fn cube_cells() -> &'static [CubeCell] {
    static CELLS: std::sync::OnceLock<Vec<CubeCell>> = std::sync::OnceLock::new();
    CELLS.get_or_init(|| {
        let n = CUBE_CELLS;
        let mut cells = Vec::with_capacity(6 * n * n);
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
                    let b = 2.0 * radius + 1e-9;
                    cells.push(CubeCell {
                        centre,
                        cos_b: b.cos(),
                        sin_b: b.sin(),
                    });
                }
            }
        }
        cells
    })
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

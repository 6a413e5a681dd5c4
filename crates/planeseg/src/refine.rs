//! Plane refinement after region growing (an extension of Alg. 5, on by
//! [`SegmentationConfig::refine`]).
//!
//! Region growing by dominant normal misses what noise and the accumulator hide: a plane
//! whose orientation is no peak of the Gaussian accumulator is never grown, noisy
//! triangles on a found plane are left out (its segment then covers too little of it),
//! and one plane is cut into pieces wherever a strip of noisy triangles or a second
//! dominant normal separates them. Refinement works on the label of every triangle:
//!
//! 1. **Absorb**: free triangles next to a segment join it, breadth first from all
//!    segments at once, when their corners lie within `z_thresh` of the segment's plane
//!    and their normal is within [`ABSORB_COS`] of it: noisy triangles on the plane
//!    fill in, triangles of a neighbouring plane in another direction do not.
//! 2. **Grow free planes**: the triangles still free are grown into new segments by
//!    their own running plane, not a dominant normal: a neighbour joins when it fits the
//!    region's plane as absorption asks (normal within [`ABSORB_COS`], corners within
//!    `z_thresh`), so noisy normals do not stop it. Seeds are triangles whose normal is
//!    within `norm_thresh` of all three neighbours'. Regions of `min_triangles` or more
//!    become segments, and absorb their free neighbours in turn.
//! 3. **Merge**: segments that share an edge merge when one plane explains both: the
//!    normals are within `norm_thresh` (within [`ABSORB_COS`] when one is a small piece
//!    of the other, [`SMALL_PIECE_SHARE`]: its normal, measured on few noisy
//!    triangles, says little), and the root mean square distance of each one's
//!    triangles to their common plane stays within [`MERGE_RMS_GROWTH`] times the
//!    noisier segment's own spread, or below [`ADJACENT_FLOOR`] of `z_thresh`; a ridge
//!    between two planes makes the common plane fit much worse.
//! 4. **Strips dropped**: a segment keeps only if [`MIN_INTERIOR_SHARE`] of its
//!    triangles have all three neighbours in it, and [`THIN_INTERIOR_SHARE`] if it is
//!    elongated (width over length of its in-plane spread below [`STRIP_ASPECT`]): a
//!    band a few triangles wide along a smoothed crease is not a plane, and inside a
//!    large plane it would make Hoover's scoring count that plane as split.
//!
//! 5. **One plane, several polygons** ([`coplanar`]): after polygon extraction, segments
//!    that no edge connects but whose normals are within [`COPLANAR_COS`] and that pass
//!    the same plane test (with the floor [`COPLANAR_FLOOR`]) are reported as lying on
//!    one plane (a wall seen on both sides of an object in front of it); each keeps its
//!    own polygon. A small piece ([`SMALL_PIECE_SHARE`]) needs its normal within
//!    `norm_thresh` only and passes with the floor [`SMALL_PIECE_FLOOR`]. The normals
//!    compared are the area normals or, when those disagree, the least-squares normals
//!    of the triangle centroids: a piece's area normal depends on its boundary only, and
//!    a short noisy boundary tilts it (on unorganized clouds, two pieces of one wall
//!    triangulated along two directions came out 8–15° apart while their points fit
//!    planes within 3°).
//!
//!
//! Planes are area-weighted: the normal is the unit vector area of the triangles (which
//! depends only on the region's boundary, so it is robust to noise inside it), the
//! centroid and the spread are the area-weighted moments of the triangle centroids.

use halfedge_mesh::{HalfEdgeMesh, NO_TWIN};
use rayon::prelude::*;

use crate::prefetch::prefetch;
use crate::vec3::{Vec3, add, corners, cross, dot, scale, sub, unit};
use crate::{NO_GROUP, SegmentationConfig};

/// Label of a triangle in no segment.
pub(crate) const NONE: u32 = u32::MAX;

/// Cosine between a free triangle's normal and a segment's plane normal for the triangle
/// to be absorbed (about 45°): noisy triangles of the plane pass, those of a plane at a right
/// angle do not.
pub const ABSORB_COS: f64 = 0.7;

/// A refined segment is kept only if at least this share of its triangles are interior
/// (all three neighbours in the segment): strips one or two triangles wide along a depth
/// edge or a crease are not planes, and a strip lying inside a large plane would make
/// Hoover's scoring count that plane as split.
pub const MIN_INTERIOR_SHARE: f64 = 0.6;

/// A segment with less than this share of interior triangles (a band about four triangles
/// wide) is dropped too when it is elongated ([`STRIP_ASPECT`]): the rounded crease between
/// two walls after smoothing, not a plane.
pub const THIN_INTERIOR_SHARE: f64 = 0.8;

/// Width over length of the in-plane spread below which a thin segment counts as a strip.
pub const STRIP_ASPECT: f64 = 0.25;

/// Two segments merge if the merged plane's RMS distance is at most this factor times the
/// larger of their own.
pub const MERGE_RMS_GROWTH: f64 = 1.25;

/// Area-weighted plane sums of a set of triangles.
#[derive(Debug, Clone, Copy, Default)]
pub(crate) struct PlaneSums {
    /// Σ vector area (twice the area times the unit normal).
    area: Vec3,
    /// Σ weight (twice the area).
    weight: f64,
    /// Σ weight · centroid.
    first: Vec3,
    /// Σ weight · centroid ⊗ centroid: xx, xy, xz, yy, yz, zz.
    second: [f64; 6],
}

/// A plane: unit normal and a point on it.
#[derive(Debug, Clone, Copy)]
pub(crate) struct Plane {
    pub normal: Vec3,
    pub centroid: Vec3,
}

impl Plane {
    /// Signed distance of `p` to the plane.
    #[inline]
    fn distance(&self, p: Vec3) -> f64 {
        dot(self.normal, sub(p, self.centroid))
    }
}

impl PlaneSums {
    /// Adds the triangle with corners `[a, b, c]`.
    #[inline]
    fn add_triangle(&mut self, [a, b, c]: [Vec3; 3]) {
        let area = cross(sub(b, a), sub(c, a));
        let weight = dot(area, area).sqrt();
        if !weight.is_finite() || weight == 0.0 {
            return;
        }
        let m = scale(add(add(a, b), c), 1.0 / 3.0);
        self.area = add(self.area, area);
        self.weight += weight;
        self.first = add(self.first, scale(m, weight));
        let s = &mut self.second;
        s[0] += weight * m[0] * m[0];
        s[1] += weight * m[0] * m[1];
        s[2] += weight * m[0] * m[2];
        s[3] += weight * m[1] * m[1];
        s[4] += weight * m[1] * m[2];
        s[5] += weight * m[2] * m[2];
    }

    /// The sums of both sets.
    fn merged(&self, o: &Self) -> Self {
        let mut second = self.second;
        for (s, t) in second.iter_mut().zip(o.second) {
            *s += t;
        }
        Self {
            area: add(self.area, o.area),
            weight: self.weight + o.weight,
            first: add(self.first, o.first),
            second,
        }
    }

    /// The plane, or `None` without area.
    fn plane(&self) -> Option<Plane> {
        let normal = unit(self.area)?;
        (self.weight > 0.0).then(|| Plane {
            normal,
            centroid: scale(self.first, 1.0 / self.weight),
        })
    }

    /// The area-weighted centroid of the triangle centroids and their covariance
    /// `[xx, xy, xz, yy, yz, zz]`; `None` without area.
    fn moments(&self) -> Option<(Vec3, [f64; 6])> {
        if self.weight <= 0.0 {
            return None;
        }
        let w = self.weight;
        let c = scale(self.first, 1.0 / w);
        let s = &self.second;
        Some((
            c,
            [
                s[0] / w - c[0] * c[0],
                s[1] / w - c[0] * c[1],
                s[2] / w - c[0] * c[2],
                s[3] / w - c[1] * c[1],
                s[4] / w - c[1] * c[2],
                s[5] / w - c[2] * c[2],
            ],
        ))
    }

    /// The least-squares plane of the triangle centroids (area-weighted): the normal is
    /// the covariance's eigenvector of the smallest eigenvalue, turned to the side of the
    /// vector area. `None` without area, or when the spread is too thin across to fix the
    /// normal (the middle eigenvalue below [`FIT_CONDITION`] times the smallest).
    fn fitted(&self) -> Option<Plane> {
        let area_normal = unit(self.area)?;
        let (c, [xx, xy, xz, yy, yz, zz]) = self.moments()?;
        let e = plane_geom::symmetric_eigen([[xx, xy, xz], [xy, yy, yz], [xz, yz, zz]])?;
        // Also refuses a line of centroids (both eigenvalues 0); the values are finite.
        if e.values[1] <= FIT_CONDITION * e.values[0].max(0.0) {
            return None;
        }
        let n = e.vectors[0];
        let normal = if dot(n, area_normal) < 0.0 {
            scale(n, -1.0)
        } else {
            n
        };
        Some(Plane {
            normal,
            centroid: c,
        })
    }

    /// The triangles' total area.
    fn area(&self) -> f64 {
        self.weight / 2.0
    }

    /// Width over length of the triangles' spread within `plane` (√ of the smaller over
    /// the larger in-plane variance): near 0 for a strip, 1 for a disc or a square.
    fn aspect(&self, plane: &Plane) -> f64 {
        let Some((_, cov)) = self.moments() else {
            return 0.0;
        };
        // The covariance projected onto the plane, (I − nnᵀ) C (I − nnᵀ), has eigenvalues
        // 0, a, b: a + b is its trace and a·b the sum of its principal 2 × 2 minors.
        let n = plane.normal;
        let cn = [
            cov[0] * n[0] + cov[1] * n[1] + cov[2] * n[2],
            cov[1] * n[0] + cov[3] * n[1] + cov[4] * n[2],
            cov[2] * n[0] + cov[4] * n[1] + cov[5] * n[2],
        ];
        let ncn = dot(n, cn);
        let p =
            |i: usize, j: usize, cij: f64| cij - n[i] * cn[j] - cn[i] * n[j] + n[i] * n[j] * ncn;
        let (xx, xy, xz) = (p(0, 0, cov[0]), p(0, 1, cov[1]), p(0, 2, cov[2]));
        let (yy, yz, zz) = (p(1, 1, cov[3]), p(1, 2, cov[4]), p(2, 2, cov[5]));
        let trace = xx + yy + zz;
        let minors = xx * yy - xy * xy + xx * zz - xz * xz + yy * zz - yz * yz;
        let root = (trace * trace - 4.0 * minors).max(0.0).sqrt();
        let (large, small) = ((trace + root) / 2.0, (trace - root) / 2.0);
        if large <= 0.0 {
            return 0.0;
        }
        (small.max(0.0) / large).sqrt()
    }

    /// Root mean square distance of the triangle centroids to `plane`.
    fn rms(&self, plane: &Plane) -> f64 {
        if self.weight <= 0.0 {
            return 0.0;
        }
        let n = plane.normal;
        let s = &self.second;
        // E[(n·m)²] − (n·E[m])² about the centroid, then the offset to the plane.
        let nn = n[0] * n[0] * s[0]
            + 2.0 * n[0] * n[1] * s[1]
            + 2.0 * n[0] * n[2] * s[2]
            + n[1] * n[1] * s[3]
            + 2.0 * n[1] * n[2] * s[4]
            + n[2] * n[2] * s[5];
        let mean = dot(n, self.first) / self.weight;
        let offset = dot(n, plane.centroid);
        let var = nn / self.weight - mean * mean + (mean - offset) * (mean - offset);
        var.max(0.0).sqrt()
    }
}

/// A segment grown by dominant normal, handed to refinement.
#[derive(Debug)]
pub(crate) struct Grown {
    /// The dominant normal's index.
    pub group: u32,
    /// Its triangles.
    pub triangles: Vec<u32>,
}

/// The segments after refinement: each a list of triangles and the group it came from
/// (the dominant normal's index, or [`NO_GROUP`] for a plane grown from free triangles).
pub(crate) struct Refined {
    pub segments: Vec<(u32, Vec<u32>)>,
    /// Per segment, its plane's unit normal and area-weighted centroid.
    pub planes: Vec<([f64; 3], [f64; 3])>,
    /// Per segment, its boundary half-edges (twin in another segment, free or missing),
    /// in index order.
    pub boundaries: Vec<Vec<u32>>,
    /// Per segment, the first segment on the same plane (see [`coplanar`]).
    pub same_plane: Vec<u32>,
    /// Free triangles absorbed into a segment.
    pub absorbed: usize,
    /// Segments grown from free triangles.
    pub free_planes: usize,
    /// Segments merged into another.
    pub merged: usize,
}

/// What refinement reads of the mesh.
struct Mesh<'a> {
    vertices: &'a [Vec3],
    triangles: &'a [[u32; 3]],
    twins: &'a [u32],
    normals: &'a [Vec3],
    lmax2: f64,
    z_thresh: f64,
    norm_thresh: f64,
}

impl Mesh<'_> {
    #[inline]
    fn corners(&self, t: u32) -> [Vec3; 3] {
        corners(self.vertices, self.triangles[t as usize])
    }

    /// Whether triangle `t` may be in a segment at all: finite normal, edges within lmax.
    fn usable(&self, t: u32) -> bool {
        let n = self.normals[t as usize];
        if !(n[0].is_finite() && n[1].is_finite() && n[2].is_finite()) {
            return false;
        }
        self.short_edges(self.corners(t))
    }

    /// Whether every edge of the triangle with these corners is within `lmax`.
    #[inline]
    fn short_edges(&self, [a, b, c]: [Vec3; 3]) -> bool {
        let len2 = |p: Vec3, q: Vec3| {
            let d = sub(p, q);
            dot(d, d)
        };
        // Not `> lmax2`: a NaN length must fail too.
        len2(a, b) <= self.lmax2 && len2(b, c) <= self.lmax2 && len2(c, a) <= self.lmax2
    }

    /// The neighbours of `t` across its three edges (`NONE` for a border edge).
    #[inline]
    fn neighbours(&self, t: u32) -> [u32; 3] {
        let h = 3 * t as usize;
        let twins: [u32; 3] = match self.twins.get(h..h + 3) {
            Some(&[a, b, c]) => [a, b, c],
            _ => [NO_TWIN; 3],
        };
        twins.map(|twin| if twin == NO_TWIN { NONE } else { twin / 3 })
    }

    /// Whether the normal of `t` is within `norm_thresh` of all three neighbours'.
    fn smooth(&self, t: u32) -> bool {
        let normal = self.normals[t as usize];
        self.neighbours(t)
            .iter()
            .all(|&u| u != NONE && dot(self.normals[u as usize], normal) >= self.norm_thresh)
    }

    /// Whether free triangle `t` may join a segment on `plane`: [`Self::usable`], its
    /// normal within [`ABSORB_COS`] of the plane's and its corners within `z_thresh` of it.
    /// The normal is tested first (a NaN normal fails it too), so that most triangles of
    /// other planes are turned away before their corners are read.
    fn joins(&self, t: u32, plane: &Plane) -> bool {
        let cos = dot(self.normals[t as usize], plane.normal);
        if cos.is_nan() || cos < ABSORB_COS {
            return false;
        }
        let corners = self.corners(t);
        self.short_edges(corners)
            && corners
                .iter()
                .all(|&p| plane.distance(p).abs() <= self.z_thresh)
    }
}

/// Refines the segments grown by dominant normal (`grown`: group and triangles, each of
/// at least `min_triangles`): absorption, free-plane growth, merging (see the module
/// docs). Segments below `min_triangles` and `min_area` afterwards are dropped. `labels`
/// is the buffer of the triangles' segment labels, overwritten.
pub(crate) fn refine(
    mesh: &HalfEdgeMesh,
    grown: Vec<Grown>,
    config: &SegmentationConfig,
    labels: &mut Vec<u32>,
) -> Refined {
    let Some(normals) = mesh.triangle_normals() else {
        labels_of(&grown, mesh.num_triangles(), labels);
        let all: Vec<u32> = grown
            .iter()
            .flat_map(|g| g.triangles.iter().copied())
            .collect();
        return Refined {
            boundaries: boundaries(mesh.halfedges(), labels, &all, grown.len()),
            planes: grown
                .iter()
                .map(|g| crate::geometric_plane(mesh, &g.triangles))
                .collect(),
            same_plane: (0..grown.len() as u32).collect(),
            segments: grown.into_iter().map(|g| (g.group, g.triangles)).collect(),
            absorbed: 0,
            free_planes: 0,
            merged: 0,
        };
    };
    let m = Mesh {
        vertices: mesh.vertices(),
        triangles: mesh.triangles(),
        twins: mesh.halfedges(),
        normals,
        lmax2: if config.lmax > 0.0 {
            config.lmax * config.lmax
        } else {
            f64::INFINITY
        },
        z_thresh: if config.z_thresh > 0.0 {
            config.z_thresh
        } else {
            f64::INFINITY
        },
        norm_thresh: config.norm_thresh,
    };
    labels_of(&grown, mesh.num_triangles(), labels);
    let labels = labels.as_mut_slice();
    let survey = Survey::of(&m, labels, grown.len());
    let grown_planes: Vec<Option<Plane>> = survey.sums.iter().map(PlaneSums::plane).collect();
    let seeds = survey.edges;
    let mut segments: Vec<(u32, Vec<u32>)> =
        grown.into_iter().map(|g| (g.group, g.triangles)).collect();
    let mut absorbed = absorb(
        &m,
        labels,
        &mut segments,
        &grown_planes,
        seeds,
        PARALLEL_LEVEL,
    );
    let first_new = segments.len();
    let big_enough = |triangles: usize, sums: &PlaneSums| {
        triangles >= config.min_triangles.max(1)
            || (config.min_area > 0.0 && triangles >= 3 && sums.area() >= config.min_area)
    };
    // Absorption from the new segments reads only their planes.
    let mut planes = grown_planes;
    let Free {
        planes: free,
        edges: seeds,
    } = grow_free(&m, labels, &mut segments, &big_enough);
    planes.extend(free);
    let free_planes = segments.len() - first_new;
    absorbed += absorb(&m, labels, &mut segments, &planes, seeds, PARALLEL_LEVEL);
    let before = segments.len();
    let Merged {
        segments,
        sums,
        interior: inside,
        edges,
    } = merge(&m, labels, segments);
    let merged = before - segments.len();
    let kept: Vec<bool> = segments
        .iter()
        .zip(&inside)
        .zip(&sums)
        .map(|(((_, tris), &inside), sums)| {
            let share = inside as f64 / tris.len().max(1) as f64;
            let strip = share < THIN_INTERIOR_SHARE
                && sums.plane().is_some_and(|p| sums.aspect(&p) < STRIP_ASPECT);
            big_enough(tris.len(), sums) && share >= MIN_INTERIOR_SHARE && !strip
        })
        .collect();
    let mut index = vec![NONE; segments.len()];
    let mut kept_segments = Vec::new();
    let mut planes = Vec::new();
    for (s, ((segment, keep), sums)) in segments.into_iter().zip(&kept).zip(&sums).enumerate() {
        if *keep {
            index[s] = kept_segments.len() as u32;
            let plane = sums
                .plane()
                .map_or(([0.0; 3], [0.0; 3]), |p| (p.normal, p.centroid));
            planes.push(plane);
            kept_segments.push(segment);
        }
    }
    relabel(labels, &index);
    let boundaries = boundaries(m.twins, labels, &edges, kept_segments.len());
    let kept_sums: Vec<PlaneSums> = sums
        .into_iter()
        .zip(&kept)
        .filter(|(_, keep)| **keep)
        .map(|(sums, _)| sums)
        .collect();
    Refined {
        segments: kept_segments,
        planes,
        boundaries,
        same_plane: coplanar(&kept_sums, config.z_thresh, config.norm_thresh),
        absorbed,
        free_planes,
        merged,
    }
}

/// Per triangle (of `n`), the index of the grown segment it is in, or [`NONE`], into
/// `labels`.
fn labels_of(grown: &[Grown], n: usize, labels: &mut Vec<u32>) {
    labels.clear();
    labels.resize(n, NONE);
    for (s, g) in grown.iter().enumerate() {
        for &t in &g.triangles {
            labels[t as usize] = s as u32;
        }
    }
}

/// The boundary half-edges of segments `0..count` (twin in another segment, free or
/// missing) from the `candidates` that may be on one (each once), in their order.
fn boundaries(twins: &[u32], labels: &[u32], candidates: &[u32], count: usize) -> Vec<Vec<u32>> {
    let mut boundaries = vec![Vec::new(); count];
    for &t in candidates {
        let a = labels[t as usize];
        let Some(boundary) = boundaries.get_mut(a as usize) else {
            continue;
        };
        for h in 3 * t..3 * t + 3 {
            let twin = twins[h as usize];
            if twin == NO_TWIN || labels[(twin / 3) as usize] != a {
                boundary.push(h);
            }
        }
    }
    boundaries
}

/// Breadth-first absorption of free usable triangles into the segments of the `seeds`
/// triangles (segment triangles on a segment's edge), each against its segment's entry of
/// `planes` (the plane when the pass starts). Levels of `parallel_from` triangles or more
/// are searched in parallel. Returns how many joined.
fn absorb(
    m: &Mesh<'_>,
    labels: &mut [u32],
    segments: &mut [(u32, Vec<u32>)],
    planes: &[Option<Plane>],
    queue: Vec<u32>,
    parallel_from: usize,
) -> usize {
    let mut absorbed = 0;
    // Level by level, each triangle claimed by the first that finds it in level order,
    // as a first-in first-out queue would.
    let mut level = queue;
    let mut next = Vec::new();
    while !level.is_empty() {
        next.clear();
        if level.len() < parallel_from {
            // Claimed as found: what a parallel search would claim afterwards.
            for (i, &t) in level.iter().enumerate() {
                prefetch_ahead(m, labels, &level, i);
                let s = labels[t as usize];
                for u in joiners(m, labels, planes, t) {
                    // Not `u != NONE` alone: `u` may neighbour `t` across two edges.
                    if u != NONE && labels[u as usize] == NONE {
                        labels[u as usize] = s;
                        segments[s as usize].1.push(u);
                        next.push(u);
                    }
                }
            }
        } else {
            let found: Vec<Vec<(u32, u32)>> = level
                .par_chunks(ABSORB_CHUNK)
                .map(|chunk| {
                    let mut found = Vec::new();
                    for (i, &t) in chunk.iter().enumerate() {
                        prefetch_ahead(m, labels, chunk, i);
                        let s = labels[t as usize];
                        let joiners = joiners(m, labels, planes, t);
                        found.extend(joiners.into_iter().filter(|&u| u != NONE).map(|u| (u, s)));
                    }
                    found
                })
                .collect();
            for (u, s) in found.into_iter().flatten() {
                if labels[u as usize] == NONE {
                    labels[u as usize] = s;
                    segments[s as usize].1.push(u);
                    next.push(u);
                }
            }
        }
        absorbed += next.len();
        std::mem::swap(&mut level, &mut next);
    }
    absorbed
}

/// The free neighbours of segment triangle `t` that may join its segment, against that
/// segment's entry of `planes` ([`Mesh::joins`]); [`NONE`] for the others.
#[inline(always)]
fn joiners(m: &Mesh<'_>, labels: &[u32], planes: &[Option<Plane>], t: u32) -> [u32; 3] {
    let Some(plane) = planes[labels[t as usize] as usize] else {
        return [NONE; 3];
    };
    m.neighbours(t).map(|u| {
        if u != NONE && labels[u as usize] == NONE && m.joins(u, &plane) {
            u
        } else {
            NONE
        }
    })
}

/// What [`grow_free`] made besides the segments.
struct Free {
    /// The new segments' planes.
    planes: Vec<Option<Plane>>,
    /// Their triangles that had a neighbour outside the segment (or none across an edge)
    /// when growth reached them, segment by segment in growing order: every triangle on a
    /// new segment's edge, and no others but some that growth later surrounded. Those
    /// find nothing to absorb, as every interior triangle would, so absorbing from these
    /// claims what absorbing from all the new segments' triangles would, in the same
    /// order (on the 848 × 480 RealSense frame, 335,000 triangles of 190 new segments).
    edges: Vec<u32>,
}

/// Grows the free usable triangles into new segments by their running plane; regions that
/// are `big_enough` are appended to `segments` (group [`NO_GROUP`]).
fn grow_free(
    m: &Mesh<'_>,
    labels: &mut [u32],
    segments: &mut Vec<(u32, Vec<u32>)>,
    big_enough: &impl Fn(usize, &PlaneSums) -> bool,
) -> Free {
    let mut planes = Vec::new();
    let mut edges = Vec::new();
    let mut region_edges = Vec::new();
    // Triangles a rejected region visited; they may still be absorbed, but seed no more.
    const VISITED: u32 = NONE - 1;
    // Seeds are found in parallel, then grown in index order; growing only takes triangles,
    // so a seed taken meanwhile is skipped.
    let seeds: Vec<Vec<u32>> = labels
        .par_chunks(TRIANGLE_CHUNK)
        .enumerate()
        .map(|(c, chunk)| {
            let first = c * TRIANGLE_CHUNK;
            (0..chunk.len())
                .filter(|&i| chunk[i] == NONE)
                .map(|i| (first + i) as u32)
                .filter(|&t| m.usable(t) && m.smooth(t))
                .collect()
        })
        .collect();
    let mut region: Vec<u32> = Vec::new();
    for seed in seeds.into_iter().flatten() {
        if labels[seed as usize] != NONE {
            continue;
        }
        let id = segments.len() as u32;
        region.clear();
        region_edges.clear();
        region.push(seed);
        labels[seed as usize] = id;
        let mut sums = PlaneSums::default();
        sums.add_triangle(m.corners(seed));
        let mut next = 0;
        while next < region.len() {
            // The queue runs across many rows of the mesh at once, as absorption's
            // levels do: on a 848 × 480 frame the growth took 40 ms without the hints and
            // 31 ms with them (one thread, AMD EPYC).
            prefetch_ahead(m, labels, &region, next);
            let t = region[next];
            next += 1;
            let Some(plane) = sums.plane() else {
                // The triangles left in the queue are looked at no further.
                region_edges.extend_from_slice(&region[next - 1..]);
                break;
            };
            let mut edge = false;
            for u in m.neighbours(t) {
                if u == NONE || labels[u as usize] != NONE || !m.joins(u, &plane) {
                    edge |= u == NONE || labels[u as usize] != id;
                    continue;
                }
                labels[u as usize] = id;
                sums.add_triangle(m.corners(u));
                region.push(u);
            }
            if edge {
                region_edges.push(t);
            }
        }
        if big_enough(region.len(), &sums) {
            segments.push((NO_GROUP, region.clone()));
            planes.push(sums.plane());
            edges.extend_from_slice(&region_edges);
        } else {
            for &t in &region {
                labels[t as usize] = VISITED;
            }
        }
    }
    for label in labels.iter_mut() {
        if *label == VISITED {
            *label = NONE;
        }
    }
    Free { planes, edges }
}

/// Merges segments that share an edge and fit one plane (see the module docs).
fn merge(m: &Mesh<'_>, labels: &mut [u32], segments: Vec<(u32, Vec<u32>)>) -> Merged {
    // Triangles on a segment's edge may become interior by merging, and are looked at
    // again afterwards.
    let Survey {
        mut pairs,
        interior,
        mut edges,
        mut sums,
    } = Survey::of(m, labels, segments.len());
    pairs.sort_unstable();
    let mut counted: Vec<(usize, u32, u32)> = Vec::new();
    for &(a, b) in &pairs {
        match counted.last_mut() {
            Some((count, x, y)) if (*x, *y) == (a, b) => *count += 1,
            _ => counted.push((1, a, b)),
        }
    }
    // Longest shared boundaries first.
    counted.sort_unstable_by_key(|&(count, a, b)| (std::cmp::Reverse(count), a, b));

    let mut parent: Vec<u32> = (0..segments.len() as u32).collect();
    let find = |parent: &mut [u32], mut x: u32| {
        while parent[x as usize] != x {
            let up = parent[parent[x as usize] as usize];
            parent[x as usize] = up;
            x = up;
        }
        x
    };
    let floor = merge_floor(m.z_thresh, ADJACENT_FLOOR);
    for (_, a, b) in counted {
        let (ra, rb) = (find(&mut parent, a), find(&mut parent, b));
        if ra == rb {
            continue;
        }
        let (sa, sb) = (sums[ra as usize], sums[rb as usize]);
        let (Some(pa), Some(pb)) = (sa.plane(), sb.plane()) else {
            continue;
        };
        let small = sa.weight.min(sb.weight) < SMALL_PIECE_SHARE * sa.weight.max(sb.weight);
        let cos = if small {
            m.norm_thresh.min(ABSORB_COS)
        } else {
            m.norm_thresh
        };
        if dot(pa.normal, pb.normal) < cos {
            continue;
        }
        let Some(merged) = one_plane(&sa, &sb, floor) else {
            continue;
        };
        // The lower index stays the root: grown segments before free planes.
        let (root, child) = (ra.min(rb), ra.max(rb));
        parent[child as usize] = root;
        sums[root as usize] = merged;
    }
    let mut out: Vec<Option<(u32, Vec<u32>)>> = segments.into_iter().map(Some).collect();
    // Roots keep their order; every segment takes its root's new index.
    let mut index = vec![NONE; out.len()];
    let mut roots = 0;
    let mut merged_interior = Vec::new();
    for s in 0..out.len() as u32 {
        let root = find(&mut parent, s);
        if root == s {
            index[s as usize] = roots;
            roots += 1;
            merged_interior.push(0);
        } else {
            index[s as usize] = index[root as usize];
            if let Some((_, tris)) = out[s as usize].take()
                && let Some((_, into)) = out[root as usize].as_mut()
            {
                into.extend(tris);
            }
        }
        merged_interior[index[s as usize] as usize] += interior[s as usize];
    }
    relabel(labels, &index);
    edges.retain(|&t| {
        let a = labels[t as usize];
        let inside = m
            .neighbours(t)
            .iter()
            .all(|&u| u != NONE && labels[u as usize] == a);
        if inside {
            merged_interior[a as usize] += 1;
        }
        !inside
    });
    let kept_sums = out
        .iter()
        .zip(sums)
        .filter(|(segment, _)| segment.is_some())
        .map(|(_, sums)| sums)
        .collect();
    Merged {
        segments: out.into_iter().flatten().collect(),
        sums: kept_sums,
        interior: merged_interior,
        edges,
    }
}

/// Triangles of a breadth-first level per task in [`absorb`].
const ABSORB_CHUNK: usize = 1024;

/// Levels of [`absorb`] with fewer triangles are searched on the calling thread. A
/// parallel level costs a wake-up of the pool and a pass that claims what it found: on
/// a 424 × 240 `rgbd-auto` frame (121 levels, most of 1,000–7,000 triangles) absorbing
/// every level in parallel took longer on 2 threads than on one.
const PARALLEL_LEVEL: usize = 8 * ABSORB_CHUNK;

/// How many triangles of a level ahead of the one [`absorb`] looks at it asks for the
/// neighbours' labels, normals and corner indices ([`prefetch_ahead`]).
const ABSORB_AHEAD: usize = 4;

/// Cache hints for the triangles of `level` that [`absorb`] (or [`grow_free`], `level`
/// being its queue) looks at after the `i`-th, in three stages of the chain of loads it
/// makes: the half-edge twins of the triangle `2 · ABSORB_AHEAD` ahead, the labels,
/// normals and corner indices of the neighbours of the one `ABSORB_AHEAD` ahead, and the
/// corners of the free neighbours of the one `ABSORB_AHEAD / 2` ahead. The loop is bound
/// by memory latency: a level's triangles lie along the fronts of all segments, far
/// apart in memory.
#[inline(always)]
fn prefetch_ahead(m: &Mesh<'_>, labels: &[u32], level: &[u32], i: usize) {
    if let Some(&far) = level.get(i + 2 * ABSORB_AHEAD) {
        prefetch(&m.twins[3 * far as usize]);
    }
    if let Some(&near) = level.get(i + ABSORB_AHEAD) {
        for u in m.neighbours(near) {
            if u != NONE {
                prefetch(&labels[u as usize]);
                prefetch(&m.normals[u as usize]);
                prefetch(&m.triangles[u as usize]);
            }
        }
    }
    if let Some(&close) = level.get(i + ABSORB_AHEAD / 2) {
        for u in m.neighbours(close) {
            if u != NONE && labels[u as usize] == NONE {
                for v in m.triangles[u as usize] {
                    prefetch(&m.vertices[v as usize]);
                }
            }
        }
    }
}

/// Triangles per task of the passes over all triangles ([`Survey::of`], the seed search of
/// [`grow_free`], [`relabel`]).
const TRIANGLE_CHUNK: usize = 16_384;

/// What one pass over the labelled triangles says about segments `0..count`.
struct Survey {
    /// The pairs of segments that share an edge, once per shared edge, lower label first.
    pairs: Vec<(u32, u32)>,
    /// Interior triangles (all three neighbours in the same segment) per segment.
    interior: Vec<usize>,
    /// The labelled triangles on a segment's edge, in index order.
    edges: Vec<u32>,
    /// Plane sums per segment.
    sums: Vec<PlaneSums>,
}

impl Survey {
    /// Chunks of triangles in index order in parallel (reading the mesh front to back),
    /// joined in chunk order, so that the result does not depend on the thread count.
    fn of(m: &Mesh<'_>, labels: &[u32], count: usize) -> Self {
        let chunks: Vec<Self> = labels
            .par_chunks(TRIANGLE_CHUNK)
            .enumerate()
            .map(|(c, chunk)| Self::of_chunk(m, labels, c * TRIANGLE_CHUNK, chunk, count))
            .collect();
        let mut total = Self::empty(count);
        for chunk in chunks {
            total.pairs.extend(chunk.pairs);
            total.edges.extend(chunk.edges);
            for (sum, part) in total.interior.iter_mut().zip(chunk.interior) {
                *sum += part;
            }
            for (sum, part) in total.sums.iter_mut().zip(&chunk.sums) {
                *sum = sum.merged(part);
            }
        }
        total
    }

    fn empty(count: usize) -> Self {
        Self {
            pairs: Vec::new(),
            interior: vec![0; count],
            edges: Vec::new(),
            sums: vec![PlaneSums::default(); count],
        }
    }

    /// The survey of the triangles `first..first + chunk.len()` (`chunk` their labels).
    fn of_chunk(m: &Mesh<'_>, labels: &[u32], first: usize, chunk: &[u32], count: usize) -> Self {
        let mut out = Self::empty(count);
        for (i, &a) in chunk.iter().enumerate() {
            if a == NONE {
                continue;
            }
            let t = (first + i) as u32;
            out.sums[a as usize].add_triangle(m.corners(t));
            let mut inside = true;
            for u in m.neighbours(t) {
                let b = if u == NONE { NONE } else { labels[u as usize] };
                if b != a {
                    inside = false;
                    if b != NONE && a < b {
                        out.pairs.push((a, b));
                    }
                }
            }
            if inside {
                out.interior[a as usize] += 1;
            } else {
                out.edges.push(t);
            }
        }
        out
    }
}

/// The segments after merging, their plane sums, how many interior triangles each has,
/// and the triangles on a segment's edge (in index order).
struct Merged {
    segments: Vec<(u32, Vec<u32>)>,
    sums: Vec<PlaneSums>,
    interior: Vec<usize>,
    edges: Vec<u32>,
}

/// Replaces every segment label `s` by `index[s]`, in one pass over the triangles.
fn relabel(labels: &mut [u32], index: &[u32]) {
    labels
        .par_iter_mut()
        .with_min_len(TRIANGLE_CHUNK)
        .filter(|l| **l != NONE)
        .for_each(|label| *label = index[*label as usize]);
}

/// Cosine between the normals of two segments that no edge connects for them to be taken
/// as one plane (5°), besides the plane-fit test of merging.
pub const COPLANAR_COS: f64 = 0.996;

/// How many times the smallest eigenvalue of a segment's spread the middle one must be for
/// its least-squares normal to count ([`PlaneSums::fitted`]).
const FIT_CONDITION: f64 = 4.0;

/// For each segment (by its plane sums), the index of the first segment on the same plane
/// (see [`PlanarSegment::plane`](crate::PlanarSegment::plane)): segments whose area
/// normals or least-squares normals ([`PlaneSums::fitted`]) are within [`COPLANAR_COS`]
/// and that one plane explains as merging requires (a small piece: see
/// [`SMALL_PIECE_SHARE`]).
fn coplanar(sums: &[PlaneSums], z_thresh: f64, norm_thresh: f64) -> Vec<u32> {
    let floor = merge_floor(z_thresh, COPLANAR_FLOOR);
    let small_floor = merge_floor(z_thresh, SMALL_PIECE_FLOOR);
    let small_cos = norm_thresh.min(COPLANAR_COS);
    let mut plane: Vec<u32> = (0..sums.len() as u32).collect();
    let mut members: Vec<PlaneSums> = sums.to_vec();
    let mut fits: Vec<Option<Plane>> = sums.iter().map(PlaneSums::fitted).collect();
    for j in 0..sums.len() {
        let Some(pj) = sums[j].plane() else { continue };
        let fj = fits[j];
        for i in 0..j {
            if plane[i] != i as u32 {
                continue;
            }
            let Some(pi) = members[i].plane() else {
                continue;
            };
            let (wi, wj) = (members[i].weight, sums[j].weight);
            let small = wi.min(wj) < SMALL_PIECE_SHARE * wi.max(wj);
            let (cos, floor) = if small {
                (small_cos, small_floor)
            } else {
                (COPLANAR_COS, floor)
            };
            let fitted_agree = fits[i]
                .zip(fj)
                .is_some_and(|(fi, fj)| dot(fi.normal, fj.normal) >= cos);
            if dot(pi.normal, pj.normal) < cos && !fitted_agree {
                continue;
            }
            if let Some(merged) = one_plane(&members[i], &sums[j], floor) {
                plane[j] = i as u32;
                members[i] = merged;
                fits[i] = merged.fitted();
                break;
            }
        }
    }
    plane
}

/// A piece with less than this share of the other piece's area is *small*: its own
/// normal and spread, measured on few noisy triangles, say little. A disjoint small piece
/// ([`coplanar`]) joins a larger piece's plane when its normal is within `norm_thresh`
/// (the tolerance region growing applies) instead of [`COPLANAR_COS`], and one plane
/// explains both within [`SMALL_PIECE_FLOOR`] of `z_thresh` instead of
/// [`COPLANAR_FLOOR`]: the strip of a wall seen between two pieces of furniture. A small
/// piece sharing an edge with a larger segment merges into it (step 3) when its normal is
/// within [`ABSORB_COS`] and the plane test passes: a patch of a far, noisy wall that
/// smoothing tilted towards another dominant normal and that was grown for it.
pub const SMALL_PIECE_SHARE: f64 = 0.1;

/// The RMS floor of the plane test for a small disjoint piece ([`SMALL_PIECE_SHARE`]), as
/// a share of `z_thresh`: a quarter, half the floor of pieces that share an edge.
pub const SMALL_PIECE_FLOOR: f64 = 0.25;

/// The RMS below which two segments that share an edge count as one plane whatever their
/// own spread, as a share of `z_thresh`: half of it, the spread of points within
/// `z_thresh` of a plane. Pieces of a wall that depth quantisation cut into parallel
/// steps (each step flat, the steps a few centimetres apart) merge; two faces meeting at
/// an angle do not, their common plane fits far worse.
pub const ADJACENT_FLOOR: f64 = 0.5;

/// As [`ADJACENT_FLOOR`], for segments that no edge connects (`coplanar`): an eighth of
/// `z_thresh`, as two separate surfaces need more evidence to be one plane.
pub const COPLANAR_FLOOR: f64 = 0.125;

/// `share` of `z_thresh` (0 when `z_thresh` is off).
fn merge_floor(z_thresh: f64, share: f64) -> f64 {
    if z_thresh.is_finite() && z_thresh > 0.0 {
        z_thresh * share
    } else {
        0.0
    }
}

/// The sums of `a` and `b` together if one plane explains both: each one's RMS distance to
/// the merged plane is at most [`MERGE_RMS_GROWTH`] times the larger of their own, or
/// `floor`.
fn one_plane(a: &PlaneSums, b: &PlaneSums, floor: f64) -> Option<PlaneSums> {
    let (pa, pb) = (a.plane()?, b.plane()?);
    let merged = a.merged(b);
    let pm = merged.plane()?;
    let bound = (MERGE_RMS_GROWTH * a.rms(&pa).max(b.rms(&pb))).max(floor);
    (a.rms(&pm) <= bound && b.rms(&pm) <= bound).then_some(merged)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A mesh of the 60 × 60 unit grid with normals, vertex `i` at `(x, y)` lifted by
    /// `height(x, i)`, keeping the grid's triangles `t` where `keep(t)`.
    fn grid(height: impl Fn(f64, usize) -> f64, keep: impl Fn(usize) -> bool) -> HalfEdgeMesh {
        let n = 60;
        let vertices = (0..(n + 1) * (n + 1))
            .map(|i| {
                let (x, y) = ((i % (n + 1)) as f64, (i / (n + 1)) as f64);
                [x, y, height(x, i)]
            })
            .collect();
        let triangles = test_fixtures::grid_triangles(n)
            .into_iter()
            .enumerate()
            .filter(|&(t, _)| keep(t))
            .map(|(_, tri)| tri)
            .collect();
        let mut mesh = HalfEdgeMesh::from_triangles(vertices, triangles).unwrap();
        mesh.compute_triangle_normals();
        mesh
    }

    /// Refinement's view of `mesh`, edges of any length, `norm_thresh` 0.9.
    fn view(mesh: &HalfEdgeMesh, z_thresh: f64) -> Mesh<'_> {
        Mesh {
            vertices: mesh.vertices(),
            triangles: mesh.triangles(),
            twins: mesh.halfedges(),
            normals: mesh.triangle_normals().unwrap(),
            lmax2: f64::INFINITY,
            z_thresh,
            norm_thresh: 0.9,
        }
    }

    /// Heights between 0 and 1 in a scrambled order, by vertex index.
    fn noise(i: usize) -> f64 {
        (i * 7919 % 13) as f64 / 12.0
    }

    #[test]
    fn absorption_claims_the_same_triangles_searched_in_parallel_or_in_turn() {
        // Noisy heights, so that some triangles stay out and the fronts meet unevenly;
        // five segments on two planes compete for the rest.
        let mesh = grid(|_, i| 0.05 * noise(i), |_| true);
        let m = view(&mesh, 0.04);
        let plane = |z| {
            Some(Plane {
                normal: [0.0, 0.0, 1.0],
                centroid: [0.0, 0.0, z],
            })
        };
        let planes = [plane(0.0), plane(0.02), plane(0.0), plane(0.02), None];
        let seeds = [0, 119, 3600, 7199, 3660];
        let start = || {
            let mut labels = vec![NONE; mesh.num_triangles()];
            let mut segments = Vec::new();
            for (s, &t) in seeds.iter().enumerate() {
                labels[t as usize] = s as u32;
                segments.push((0, vec![t]));
            }
            (labels, segments)
        };
        let (mut parallel, mut in_turn) = (start(), start());
        let found = absorb(
            &m,
            &mut parallel.0,
            &mut parallel.1,
            &planes,
            seeds.to_vec(),
            0,
        );
        let claimed = absorb(
            &m,
            &mut in_turn.0,
            &mut in_turn.1,
            &planes,
            seeds.to_vec(),
            usize::MAX,
        );
        assert_eq!((found, &parallel), (claimed, &in_turn));
        // Every segment with a plane took part, none took everything.
        let sizes: Vec<usize> = parallel.1.iter().map(|(_, t)| t.len()).collect();
        assert!(sizes[..4].iter().all(|&k| k > 50), "{sizes:?}");
        assert_eq!(sizes[4], 1);
        assert!(found < mesh.num_triangles() - seeds.len(), "{found}");
    }

    #[test]
    fn absorbing_from_the_free_planes_edges_claims_what_absorbing_from_all_their_triangles_does() {
        // Two noisy terraces joined by a steep ramp, with bumps, on a grid with some
        // triangles missing: free growth makes several planes and leaves the bumps out;
        // absorption then takes some of what is left.
        let mesh = grid(
            |x, i| {
                let terrace = (x - 28.0).clamp(0.0, 4.0) * 1.5;
                let bump = if i % 23 == 0 { 0.05 } else { 0.0 };
                terrace + bump + 0.03 * noise(i)
            },
            |t| t % 97 != 5,
        );
        let m = view(&mesh, 0.04);
        let mut labels = vec![NONE; mesh.num_triangles()];
        let mut segments = Vec::new();
        let Free { planes, edges } = grow_free(&m, &mut labels, &mut segments, &|triangles, _| {
            triangles >= 40
        });
        let all: Vec<u32> = segments.iter().flat_map(|(_, t)| t.clone()).collect();
        assert!(segments.len() >= 2, "{}", segments.len());
        assert!(
            edges.len() < all.len() / 2,
            "{} of {}",
            edges.len(),
            all.len()
        );
        // Every triangle on a segment's edge is among the edges, in growing order.
        let on_edge = |t: u32| {
            let a = labels[t as usize];
            m.neighbours(t)
                .iter()
                .any(|&u| u == NONE || labels[u as usize] != a)
        };
        let mut rest = edges.iter();
        for &t in all.iter().filter(|&&t| on_edge(t)) {
            assert!(rest.any(|&e| e == t), "triangle {t} on an edge is missing");
        }
        // Absorbing with a looser height test than growth's, so that there is more to take
        // than growth left; levels searched in parallel and in turn.
        let wider = view(&mesh, 0.06);
        for parallel_from in [0, usize::MAX] {
            let mut from_edges = (labels.clone(), segments.clone());
            let mut from_all = (labels.clone(), segments.clone());
            let (e, a) = (edges.clone(), all.clone());
            let (x, y) = (&mut from_edges, &mut from_all);
            let found = absorb(&wider, &mut x.0, &mut x.1, &planes, e, parallel_from);
            let claimed = absorb(&wider, &mut y.0, &mut y.1, &planes, a, parallel_from);
            assert!(found > 0);
            assert_eq!((found, &from_edges), (claimed, &from_all));
        }
    }

    /// The sums of a 5 × 5 grid of right triangles (legs 0.8) whose centroids lie on the
    /// plane `z = lift` from `x = x0`, each tilted by `tilt` degrees about the x axis
    /// around its centroid: shingles, whose vector area leans by `tilt` while the
    /// centroids stay level, as a noisy boundary tilts a piece's area normal.
    fn shingles(x0: f64, lift: f64, tilt: f64) -> PlaneSums {
        let (sin, cos) = tilt.to_radians().sin_cos();
        let base = [[-0.4, -0.4], [0.4, -0.4], [-0.4, 0.4]];
        let centre = [-0.4 / 3.0, -0.4 / 3.0];
        let mut sums = PlaneSums::default();
        for i in 0..5 {
            for j in 0..5 {
                let corner = |[x, y]: [f64; 2]| {
                    let (x, y) = (x - centre[0], y - centre[1]);
                    [x0 + i as f64 + x, j as f64 + y * cos, lift + y * sin]
                };
                sums.add_triangle(base.map(corner));
            }
        }
        sums
    }

    #[test]
    fn the_fitted_plane_is_that_of_the_centroids() {
        let sums = shingles(0.0, 2.0, 10.0);
        let area = sums.plane().unwrap();
        let fitted = sums.fitted().unwrap();
        assert!((dot(area.normal, [0.0, 0.0, 1.0]) - 10f64.to_radians().cos()).abs() < 1e-12);
        assert!(
            (fitted.normal[2] - 1.0).abs() < 1e-12,
            "{:?}",
            fitted.normal
        );
        assert!((fitted.centroid[2] - 2.0).abs() < 1e-12);
        // Centroids on a line fix no normal.
        let mut line = PlaneSums::default();
        for i in 0..5 {
            let x = f64::from(i);
            line.add_triangle([[x, 0.0, 0.0], [x + 0.5, 0.0, 0.0], [x, 0.5, 0.5]]);
        }
        assert!(line.plane().is_some());
        assert!(line.fitted().is_none());
    }

    #[test]
    fn disjoint_pieces_whose_centroids_fit_one_plane_share_it() {
        let flat = shingles(0.0, 0.0, 0.0);
        // Area normals 10° apart, more than COPLANAR_COS allows: the least-squares normals
        // agree, and one plane explains both.
        assert_eq!(
            coplanar(&[flat, shingles(8.0, 0.0, 10.0)], 1.0, 0.95),
            [0, 0]
        );
        // Raised by a metre the same piece is another plane.
        assert_eq!(
            coplanar(&[flat, shingles(8.0, 1.0, 10.0)], 1.0, 0.95),
            [0, 1]
        );
        // A piece whose centroids lie on a plane 10° from the first is another plane.
        let mut tilted = PlaneSums::default();
        let (sin, cos) = 10f64.to_radians().sin_cos();
        for i in 0..5 {
            for j in 0..5 {
                let p = |x: f64, y: f64| {
                    [
                        8.0 + f64::from(i) + x,
                        (f64::from(j) + y) * cos,
                        (f64::from(j) + y) * sin,
                    ]
                };
                tilted.add_triangle([p(0.0, 0.0), p(0.8, 0.0), p(0.0, 0.8)]);
            }
        }
        assert_eq!(coplanar(&[flat, tilted], 1.0, 0.95), [0, 1]);
    }
}

//! Region growing per dominant normal (Alg. 5) with overlapped polygon extraction.

use std::sync::atomic::AtomicU8;
use std::sync::atomic::Ordering::Relaxed;
use std::sync::mpsc;

use halfedge_mesh::{HalfEdgeMesh, NO_TWIN};
use plane_geom::PlaneFrame;
use polyextract::{Extractor, Polygon};
use rayon::prelude::*;

use crate::groups::{Assignment, FREE, GroupCounts, Slot};
use crate::prefetch::prefetch;
use crate::vec3::{add, corners, cross, dot, scale, sub, unit};
use crate::{SegmentError, SegmentationConfig};

/// A planar segment and its polygon.
#[derive(Debug, Clone, PartialEq)]
pub struct PlanarSegment {
    /// Index of the dominant normal the segment was grown for; [`NO_GROUP`](crate::NO_GROUP)
    /// for a plane that refinement grew from triangles no dominant normal took.
    pub group: u32,
    /// The plane the segment lies on, as the index of the first segment (in
    /// [`Segmentation::segments`]) on it: its own index, unless refinement found an earlier
    /// segment on the same plane that no edge connects it to (a wall seen on both sides of
    /// an object in front of it).
    pub plane: u32,
    /// The triangle the segment was grown from (its smallest triangle index).
    pub seed: u32,
    /// The segment's triangles, in growing order.
    pub triangles: Vec<u32>,
    /// Area-weighted mean triangle normal (unit): the geometric plane's normal.
    pub normal: [f64; 3],
    /// Area-weighted centroid of the triangles.
    pub centroid: [f64; 3],
    /// The polygon, as point indices, extracted in the geometric plane (shell
    /// counter-clockwise seen from `normal`).
    pub polygon: Polygon,
    /// Holes dropped for having fewer than `min_hole_vertices` vertices.
    pub holes_too_small: usize,
}

/// What segmentation found, stage by stage.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub struct SegmentationCounts {
    /// Group assignment.
    pub groups: GroupCounts,
    /// Segments grown, of any size.
    pub segments_grown: usize,
    /// Segments dropped for having fewer than `min_triangles` triangles.
    pub segments_too_small: usize,
    /// Holes kept over all polygons.
    pub holes: usize,
    /// Holes dropped for having fewer than `min_hole_vertices` vertices.
    pub holes_too_small: usize,
    /// Refinement: free triangles absorbed into a neighbouring segment.
    pub absorbed: usize,
    /// Refinement: planes grown from triangles no dominant normal took.
    pub free_planes: usize,
    /// Refinement: segments merged into a neighbour on the same plane.
    pub merged: usize,
}

/// The result of [`segment`].
#[derive(Debug, Clone, PartialEq)]
pub struct Segmentation {
    /// Segments with their polygons, sorted by (group, seed).
    pub segments: Vec<PlanarSegment>,
    /// Counts per stage.
    pub counts: SegmentationCounts,
}

/// Segments `mesh` by the `dominant` unit normals and extracts a polygon per segment.
///
/// Allocates its working memory per call; [`Segmenter`] keeps it across calls.
///
/// # Errors
/// As [`assign_groups`](crate::assign_groups), and [`SegmentError::Extract`] if a
/// boundary cannot be followed.
pub fn segment(
    mesh: &HalfEdgeMesh,
    dominant: &[[f64; 3]],
    config: &SegmentationConfig,
) -> Result<Segmentation, SegmentError> {
    Segmenter::new().segment(mesh, dominant, config)
}

/// [`segment`] with its working memory (per triangle a 16-byte slot with its label,
/// offset and volume term, a "taken" byte and refinement's segment label; per group the
/// seed lists) kept across calls, for segmenting a stream of frames: fresh memory costs
/// page faults on every call. Results do not depend on what ran before.
///
/// ```
/// use halfedge_mesh::HalfEdgeMesh;
/// use planeseg::{SegmentationConfig, Segmenter};
///
/// let mut segmenter = Segmenter::new();
/// let config = SegmentationConfig::new().with_min_triangles(1);
/// for z in [0.0, 1.0, 2.0] {
///     let mesh = HalfEdgeMesh::from_triangles(
///         vec![[0.0, 0.0, z], [1.0, 0.0, z], [0.0, 1.0, z]],
///         vec![[0, 1, 2]],
///     )?;
///     let found = segmenter.segment(&mesh, &[[0.0, 0.0, 1.0]], &config)?;
///     assert_eq!(found.segments[0].centroid[2], z);
/// }
/// # Ok::<(), Box<dyn std::error::Error>>(())
/// ```
#[derive(Debug, Default)]
pub struct Segmenter {
    assignment: Assignment,
    /// Refinement's segment label per triangle.
    labels: Vec<u32>,
}

impl Segmenter {
    /// A segmenter with no memory allocated yet.
    pub fn new() -> Self {
        Self::default()
    }

    /// As [`segment`], reusing this segmenter's memory.
    ///
    /// # Errors
    /// As [`segment`].
    pub fn segment(
        &mut self,
        mesh: &HalfEdgeMesh,
        dominant: &[[f64; 3]],
        config: &SegmentationConfig,
    ) -> Result<Segmentation, SegmentError> {
        self.assignment.assign(mesh, dominant, config)?;
        grow_all(
            mesh,
            dominant.len(),
            config,
            &self.assignment,
            &mut self.labels,
        )
    }
}

/// Region growing and polygon extraction after group assignment; `labels` is
/// refinement's buffer.
fn grow_all(
    mesh: &HalfEdgeMesh,
    num_groups: usize,
    config: &SegmentationConfig,
    assignment: &Assignment,
    labels: &mut Vec<u32>,
) -> Result<Segmentation, SegmentError> {
    let Assignment {
        slots,
        reference,
        buckets,
        taken,
        counts: group_counts,
    } = assignment;
    let (reference, group_counts) = (*reference, *group_counts);
    let (sender, receiver) = mpsc::channel();
    let grower = Grower {
        mesh,
        slots,
        taken,
        reference,
        config,
    };
    // Largest groups first, so that the longest task starts at once.
    let size = |g: usize| buckets.iter().map(|b| b[g].len()).sum::<usize>();
    let mut by_size: Vec<(usize, usize)> = (0..num_groups).map(|g| (size(g), g)).collect();
    by_size.sort_by_key(|&(size, g)| (std::cmp::Reverse(size), g));
    rayon::scope(|scope| {
        for (size, g) in by_size {
            if size == 0 {
                continue;
            }
            let sender = sender.clone();
            let grower = &grower;
            scope.spawn(move |scope| {
                let mut grown = 0;
                let mut region = Region::default();
                // Seeds in triangle order: the chunks' lists of this group, one after another.
                for bucket in buckets.iter().map(|b| &b[g]) {
                    for &seed in bucket {
                        if taken[seed as usize].load(Relaxed) != 0 {
                            continue;
                        }
                        grower.grow(g as u32, seed, &mut region);
                        grown += 1;
                        if region.triangles.len() < config.min_triangles.max(1) {
                            continue;
                        }
                        if config.refine {
                            let grown = crate::refine::Grown {
                                group: g as u32,
                                triangles: region.triangles.clone(),
                            };
                            let _ = sender.send(Outcome::Region(grown));
                            continue;
                        }
                        // Copied to its size: the growing buffers stay with this task.
                        let region = region.clone();
                        let sender = sender.clone();
                        scope.spawn(move |_| {
                            let result = grower.polygon(g as u32, seed, region);
                            // The receiver outlives the scope, so sending cannot fail.
                            let _ = sender.send(Outcome::Segment(result));
                        });
                    }
                }
                let _ = sender.send(Outcome::Grown(grown));
            });
        }
    });
    drop(sender);

    let mut counts = SegmentationCounts {
        groups: group_counts,
        ..SegmentationCounts::default()
    };
    let mut results = Vec::new();
    let mut regions = Vec::new();
    for outcome in receiver {
        match outcome {
            Outcome::Grown(n) => counts.segments_grown += n,
            Outcome::Segment(result) => results.push(result),
            Outcome::Region(grown) => regions.push(grown),
        }
    }
    let kept_grown = regions.len() + results.len();
    // Per result, the result whose plane it lies on (itself unless refinement says).
    let mut same_plane: Vec<u32> = (0..results.len() as u32).collect();
    if config.refine {
        // Growth order depends on the threads; refinement must not.
        // The key reads every triangle of a region: computed once per region.
        regions.sort_by_cached_key(|r| (r.group, r.triangles.iter().min().copied()));
        let refined = crate::refine::refine(mesh, regions, config, labels);
        counts.absorbed = refined.absorbed;
        counts.free_planes = refined.free_planes;
        counts.merged = refined.merged;
        same_plane = refined.same_plane;
        let planes = &refined.planes;
        results = refined
            .segments
            .into_par_iter()
            .zip(refined.boundaries)
            .enumerate()
            .map(|(s, ((g, triangles), boundary))| {
                grower.refined_polygon(g, triangles, boundary, planes[s])
            })
            .collect();
    }
    let key = |r: &Result<PlanarSegment, (u32, u32, SegmentError)>| match r {
        Ok(s) => (s.group, s.seed),
        Err((g, s, _)) => (*g, *s),
    };
    let mut ordered: Vec<(usize, _)> = results.into_iter().enumerate().collect();
    ordered.sort_by_key(|(_, r)| key(r));
    // A plane's id is the first position, in the sorted output, of a segment on it.
    let mut first = vec![u32::MAX; ordered.len()];
    for (position, (i, _)) in ordered.iter().enumerate() {
        let p = same_plane[*i] as usize;
        first[p] = first[p].min(position as u32);
    }
    let mut segments = Vec::with_capacity(ordered.len());
    for (i, result) in ordered {
        let mut segment = result.map_err(|(_, _, e)| e)?;
        segment.plane = first[same_plane[i] as usize];
        counts.holes += segment.polygon.holes.len();
        counts.holes_too_small += segment.holes_too_small;
        segments.push(segment);
    }
    counts.segments_too_small = counts.segments_grown - kept_grown;
    Ok(Segmentation { segments, counts })
}

/// How many queued triangles ahead of the one being expanded region growing asks for
/// the neighbours' slots: far enough for the loads to arrive, near enough to stay cached.
const PREFETCH_AHEAD: usize = 8;

/// A message from a growing or extraction task.
enum Outcome {
    /// A group task finished after growing this many segments.
    Grown(usize),
    /// A segment with its polygon, or the failure keyed by (group, seed).
    Segment(Result<PlanarSegment, (u32, u32, SegmentError)>),
    /// With refinement: a grown segment, its polygon still to come.
    Region(crate::refine::Grown),
}

/// A grown region: its triangles in growing order and its boundary half-edges.
#[derive(Default, Clone)]
struct Region {
    triangles: Vec<u32>,
    boundary: Vec<u32>,
    /// The sum of the triangles' volume terms (see [`Slot::volume`]).
    volume: f64,
}

/// Shared, read-mostly state of the growing tasks.
struct Grower<'a> {
    mesh: &'a HalfEdgeMesh,
    /// Per triangle: label, offset and volume term.
    slots: &'a [Slot],
    /// Per triangle, whether it is in a segment yet (see [`Assignment::taken`]).
    taken: &'a [AtomicU8],
    reference: [f64; 3],
    config: &'a SegmentationConfig,
}

impl Grower<'_> {
    /// Grows the segment of group `g` from `seed` (breadth first over twins) into
    /// `region`, labelling its triangles with `seed`. Only this group's task touches this
    /// group's labels. A neighbour turned away now is never part of the segment (it is
    /// in another group or segment, or off the seed's plane), so the half-edge towards
    /// it is a boundary edge; collecting those here spares polygon extraction a pass
    /// over the triangles.
    fn grow(&self, g: u32, seed: u32, region: &mut Region) {
        let Region {
            triangles,
            boundary,
            volume,
        } = region;
        triangles.clear();
        boundary.clear();
        let first = &self.slots[seed as usize];
        let plane = first.offset;
        let z_thresh = if self.config.z_thresh > 0.0 {
            self.config.z_thresh
        } else {
            f64::INFINITY
        };
        let twins = self.mesh.halfedges();
        let free = FREE - g;
        first.label.store(seed, Relaxed);
        self.taken[seed as usize].store(1, Relaxed);
        *volume = f64::from(first.volume);
        triangles.push(seed);
        let mut next = 0;
        while next < triangles.len() {
            let t = triangles[next] as usize;
            // The twins of a queued triangle were asked for when it was queued.
            if let Some(&ahead) = triangles.get(next + PREFETCH_AHEAD) {
                let a = 3 * ahead as usize;
                for &tw in &twins[a..a + 3] {
                    if tw != NO_TWIN {
                        prefetch(&self.slots[(tw / 3) as usize]);
                    }
                }
            }
            next += 1;
            for (h, &twin) in (3 * t..3 * t + 3).zip(&twins[3 * t..3 * t + 3]) {
                if twin != NO_TWIN {
                    let n = twin / 3;
                    let slot = &self.slots[n as usize];
                    let label = slot.label.load(Relaxed);
                    if label == seed {
                        continue;
                    }
                    // Not `> z_thresh`: a NaN offset must fail too.
                    if label == free && (slot.offset - plane).abs() <= z_thresh {
                        slot.label.store(seed, Relaxed);
                        self.taken[n as usize].store(1, Relaxed);
                        *volume += f64::from(slot.volume);
                        triangles.push(n);
                        prefetch(&twins[3 * n as usize]);
                        continue;
                    }
                }
                boundary.push(h as u32);
            }
        }
    }

    /// The polygon of a refined segment (group `g`, or `NO_GROUP` for a plane no
    /// dominant normal explains; its boundary half-edges and its plane as refinement
    /// found them).
    fn refined_polygon(
        &self,
        g: u32,
        triangles: Vec<u32>,
        boundary: Vec<u32>,
        (normal, centroid): ([f64; 3], [f64; 3]),
    ) -> Result<PlanarSegment, (u32, u32, SegmentError)> {
        let seed = triangles.iter().min().copied().unwrap_or(0);
        let region = Region {
            triangles,
            boundary,
            volume: 0.0,
        };
        self.polygon_in_plane(g, seed, region, normal, centroid)
    }

    /// The segment's geometric plane and polygon.
    fn polygon(
        &self,
        g: u32,
        seed: u32,
        region: Region,
    ) -> Result<PlanarSegment, (u32, u32, SegmentError)> {
        let (normal, centroid) =
            boundary_plane(self.mesh, &region.boundary, region.volume, self.reference);
        self.polygon_in_plane(g, seed, region, normal, centroid)
    }

    /// The segment with its polygon, extracted in the plane of `normal`.
    fn polygon_in_plane(
        &self,
        g: u32,
        seed: u32,
        region: Region,
        normal: [f64; 3],
        centroid: [f64; 3],
    ) -> Result<PlanarSegment, (u32, u32, SegmentError)> {
        let v = self.mesh.vertices();
        let frame = PlaneFrame::from_unit_normal(normal);
        let mut polygon = Extractor::new()
            .extract_boundary(self.mesh, &region.boundary, |i| {
                frame.project(v[i as usize])
            })
            .map_err(|source| (g, seed, SegmentError::Extract { seed, source }))?;
        let before = polygon.holes.len();
        polygon
            .holes
            .retain(|h| h.len() >= self.config.min_hole_vertices);
        Ok(PlanarSegment {
            group: g,
            plane: 0,
            seed,
            triangles: region.triangles,
            normal,
            centroid,
            holes_too_small: before - polygon.holes.len(),
            polygon,
        })
    }
}

/// The geometric plane of a set of triangles: the unit normal `N / |N|` of their vector
/// area `N = Σ (b − a) × (c − a)` (the area-weighted mean of their normals, facing the side
/// they are counter-clockwise from), and the mean of their centroids weighted by their
/// areas projected on that plane. Zeros when the triangles have no area.
///
/// ```
/// use halfedge_mesh::HalfEdgeMesh;
/// let mesh = HalfEdgeMesh::from_triangles(
///     vec![[0.0, 0.0, 1.0], [2.0, 0.0, 1.0], [0.0, 2.0, 1.0]],
///     vec![[0, 1, 2]],
/// )?;
/// let (normal, centroid) = planeseg::geometric_plane(&mesh, &[0]);
/// assert_eq!(normal, [0.0, 0.0, 1.0]);
/// assert!((centroid[0] - 2.0 / 3.0).abs() < 1e-12);
/// # Ok::<(), halfedge_mesh::MeshError>(())
/// ```
pub fn geometric_plane(mesh: &HalfEdgeMesh, triangles: &[u32]) -> ([f64; 3], [f64; 3]) {
    let v = mesh.vertices();
    let corners = |t: u32| corners(v, mesh.triangles()[t as usize]);
    let area = triangles.iter().fold([0.0; 3], |area, &t| {
        let [a, b, c] = corners(t);
        add(area, cross(sub(b, a), sub(c, a)))
    });
    let Some(normal) = unit(area) else {
        return ([0.0; 3], [0.0; 3]);
    };
    let (mut weighted, mut total) = ([0.0; 3], 0.0);
    for &t in triangles {
        let [a, b, c] = corners(t);
        let w = dot(cross(sub(b, a), sub(c, a)), normal);
        weighted = add(weighted, scale(add(add(a, b), c), w / 3.0));
        total += w;
    }
    if total.is_nan() || total <= 0.0 {
        return ([0.0; 3], [0.0; 3]);
    }
    (normal, scale(weighted, 1.0 / total))
}

/// [`geometric_plane`] of a region from its boundary half-edges and `volume`, the sum over
/// its triangles `a, b, c` of `det(a − r, b − r, c − r)` for the point `reference` = `r`.
///
/// With corners taken relative to `r`, a triangle's vector area is the sum of `p × q` over
/// its edges `p → q`, and `(a + b + c) ⊗ ((b − a) × (c − a))` is the sum over its edges of
/// `(p + q) ⊗ (p × q)` plus `det(a, b, c)` times the identity. Inside the region every
/// edge appears once in each direction and cancels, so both sums over the triangles are
/// sums over the boundary edges, plus `volume` times the identity for the second: the
/// plane costs a pass over the boundary and one number per triangle.
fn boundary_plane(
    mesh: &HalfEdgeMesh,
    boundary: &[u32],
    volume: f64,
    reference: [f64; 3],
) -> ([f64; 3], [f64; 3]) {
    let v = mesh.vertices();
    let relative = |i: u32| sub(v[i as usize], reference);
    let mut area = [0.0; 3];
    // moment[k] = Σ (p + q)[k] (p × q), so that Σ (p + q) ((p × q) · n) = moment · n.
    let mut moment = [[0.0; 3]; 3];
    let tris = mesh.triangles();
    for (i, &h) in boundary.iter().enumerate() {
        // Boundary edges are scattered over the mesh: ask for the triangles two steps
        // of PREFETCH_AHEAD ahead and, once those have arrived, for their corners.
        if let Some(&far) = boundary.get(i + 2 * PREFETCH_AHEAD) {
            prefetch(&tris[far as usize / 3]);
        }
        if let Some(&near) = boundary.get(i + PREFETCH_AHEAD) {
            let (origin, destination) = (mesh.origin(near), mesh.destination(near));
            prefetch(&v[origin as usize]);
            prefetch(&v[destination as usize]);
        }
        let (p, q) = (relative(mesh.origin(h)), relative(mesh.destination(h)));
        let pq = cross(p, q);
        area = add(area, pq);
        let pq_sum = add(p, q);
        for (row, s) in moment.iter_mut().zip(pq_sum) {
            *row = add(*row, scale(pq, s));
        }
    }
    let Some(normal) = unit(area) else {
        return ([0.0; 3], [0.0; 3]);
    };
    let total = dot(area, normal);
    if total.is_nan() || total <= 0.0 {
        return ([0.0; 3], [0.0; 3]);
    }
    let moment_n = [0, 1, 2].map(|k| dot(moment[k], normal));
    let centroid = add(
        reference,
        scale(add(moment_n, scale(normal, volume)), 1.0 / (3.0 * total)),
    );
    (normal, centroid)
}

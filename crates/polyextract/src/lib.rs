//! Boundary following from Polylidar (2D paper, Alg. 1–3): turns a set of triangles of a
//! [`HalfEdgeMesh`] into one polygon, a shell plus holes given as point indices.
//!
//! The triangles must be edge-connected (a region grown over twin half-edges). Extraction
//! works in a 2D frame the caller supplies as a projection `point index → [x, y]`, so the
//! same code serves 2D point sets (the identity), 2.5D clouds (xy) and planar segments of
//! 3D meshes (coordinates in the segment's plane).
//!
//! * Boundary half-edges are those whose twin is missing or lies outside the region.
//! * The shell starts at the boundary point with the largest x; ties go to the largest y.
//! * At a vertex with several outgoing boundary edges (a hole touching the shell, two holes
//!   touching each other) the ring turns to the outgoing edge met first when rotating
//!   counter-clockwise from the edge it arrived on. That closes the ring around one
//!   connected piece of the region's complement, so rings only ever touch at single
//!   points and the polygon is valid in the OGC sense. At the start, the arrival direction
//!   is taken as `[0, 1]`, as in the paper.
//! * Remaining boundary edges form the holes, extracted in half-edge order.
//!
//! Rings are open (the first point is not repeated at the end): the shell runs
//! counter-clockwise and holes clockwise in the caller's frame.
//!
//! ```
//! use halfedge_mesh::HalfEdgeMesh;
//! use polyextract::extract_polygon;
//!
//! // A 4 × 4 grid of points; all 18 triangles of its triangulation form one region.
//! let points: Vec<[f64; 2]> = (0..16).map(|i| [(i % 4) as f64, (i / 4) as f64]).collect();
//! let mesh = HalfEdgeMesh::delaunay_2d(&points)?;
//! let region: Vec<u32> = (0..mesh.num_triangles() as u32).collect();
//! let polygon = extract_polygon(&mesh, &region, |_| true, |i| points[i as usize])?;
//! assert_eq!(polygon.shell.len(), 12);
//! assert!(polygon.holes.is_empty());
//! # Ok::<(), Box<dyn std::error::Error>>(())
//! ```

#![deny(rustdoc::broken_intra_doc_links)]

use halfedge_mesh::{HalfEdgeMesh, NO_TWIN};

/// A polygon as point indices: one shell and any number of holes, each an open ring.
#[derive(Debug, Clone, Default, PartialEq, Eq)]
pub struct Polygon {
    /// The outer ring, counter-clockwise in the extraction frame.
    pub shell: Vec<u32>,
    /// The inner rings, clockwise in the extraction frame.
    pub holes: Vec<Vec<u32>>,
}

/// Why a region could not be turned into a polygon.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
#[non_exhaustive]
pub enum ExtractError {
    /// The region has no triangle.
    #[error("the region has no triangles")]
    EmptyRegion,
    /// A triangle index is out of range for the mesh.
    #[error("region triangle {triangle} is out of range for a mesh of {num_triangles} triangles")]
    TriangleOutOfRange {
        /// The bad triangle index.
        triangle: u32,
        /// Triangles in the mesh.
        num_triangles: usize,
    },
    /// Every edge of the region has a twin inside it: a closed surface has no boundary.
    #[error("the region has no boundary edge (a closed surface cannot become a polygon)")]
    NoBoundary,
    /// Boundary following reached a point with no unused outgoing boundary edge.
    #[error(
        "broken boundary: half-edge {halfedge} ends at point {point}, which has no unused outgoing boundary edge"
    )]
    BrokenBoundary {
        /// The half-edge followed last.
        halfedge: u32,
        /// The point where the ring could not continue.
        point: u32,
    },
    /// The projection gave a non-finite coordinate for a boundary point.
    #[error("point {point} projects to a non-finite coordinate")]
    NonFinitePoint {
        /// The point index.
        point: u32,
    },
}

/// Extracts the polygon of one edge-connected region.
///
/// * `triangles`: the region's triangle indices;
/// * `is_member(t)`: whether triangle `t` belongs to the region (called for neighbours);
/// * `project(i)`: point `i` in the 2D extraction frame; the frame must see the triangles
///   from their normal side (counter-clockwise). A mirrored frame is detected and undone.
///
/// Allocates its working arrays per call; [`Extractor`] reuses them across regions.
///
/// # Errors
/// See [`ExtractError`]. A region whose boundary cannot be followed gives
/// [`ExtractError::BrokenBoundary`] naming the edge, never a silent empty polygon.
pub fn extract_polygon(
    mesh: &HalfEdgeMesh,
    triangles: &[u32],
    is_member: impl Fn(u32) -> bool,
    project: impl Fn(u32) -> [f64; 2],
) -> Result<Polygon, ExtractError> {
    Extractor::default().extract(mesh, triangles, is_member, project)
}

/// A boundary edge: where it starts, where it ends, and its half-edge id.
#[derive(Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord)]
struct BoundaryEdge {
    origin: u32,
    halfedge: u32,
    destination: u32,
}

/// Polygon extraction with scratch buffers kept between calls.
#[derive(Debug, Default, Clone)]
pub struct Extractor {
    edges: Vec<BoundaryEdge>,
    used: Vec<bool>,
}

impl Extractor {
    /// A new extractor with empty scratch buffers.
    pub fn new() -> Self {
        Self::default()
    }

    /// As [`extract_polygon`], reusing this extractor's buffers.
    ///
    /// # Errors
    /// See [`ExtractError`].
    pub fn extract(
        &mut self,
        mesh: &HalfEdgeMesh,
        triangles: &[u32],
        is_member: impl Fn(u32) -> bool,
        project: impl Fn(u32) -> [f64; 2],
    ) -> Result<Polygon, ExtractError> {
        if triangles.is_empty() {
            return Err(ExtractError::EmptyRegion);
        }
        self.collect_boundary(mesh, triangles, &is_member)?;
        self.follow(mesh, project)
    }

    /// As [`Self::extract`], for a region given by its boundary half-edges (those whose
    /// twin is missing or outside the region), in any order. Callers that find the
    /// boundary while growing the region skip the pass over its triangles.
    ///
    /// ```
    /// use halfedge_mesh::{HalfEdgeMesh, NO_TWIN};
    /// use polyextract::Extractor;
    ///
    /// let points: Vec<[f64; 2]> = (0..16).map(|i| [(i % 4) as f64, (i / 4) as f64]).collect();
    /// let mesh = HalfEdgeMesh::delaunay_2d(&points)?;
    /// let boundary: Vec<u32> = (0..mesh.halfedges().len() as u32)
    ///     .filter(|&h| mesh.halfedges()[h as usize] == NO_TWIN)
    ///     .collect();
    /// let polygon = Extractor::new().extract_boundary(&mesh, &boundary, |i| points[i as usize])?;
    /// assert_eq!(polygon.shell.len(), 12);
    /// # Ok::<(), Box<dyn std::error::Error>>(())
    /// ```
    ///
    /// # Errors
    /// See [`ExtractError`]; a half-edge out of range gives
    /// [`ExtractError::TriangleOutOfRange`] for its triangle.
    pub fn extract_boundary(
        &mut self,
        mesh: &HalfEdgeMesh,
        boundary: &[u32],
        project: impl Fn(u32) -> [f64; 2],
    ) -> Result<Polygon, ExtractError> {
        let tris = mesh.triangles();
        self.edges.clear();
        for &h in boundary {
            let Some(tri) = tris.get(h as usize / 3) else {
                return Err(ExtractError::TriangleOutOfRange {
                    triangle: h / 3,
                    num_triangles: tris.len(),
                });
            };
            self.edges.push(boundary_edge(tri, h));
        }
        self.sort_edges();
        self.follow(mesh, project)
    }

    /// Follows the rings of the collected boundary: the shell from the extreme point,
    /// then the holes.
    fn follow(
        &mut self,
        mesh: &HalfEdgeMesh,
        project: impl Fn(u32) -> [f64; 2],
    ) -> Result<Polygon, ExtractError> {
        if self.edges.is_empty() {
            return Err(ExtractError::NoBoundary);
        }
        // Any triangle of the region tells the frame's handedness; take a boundary one.
        let mirror = frame_is_mirrored(mesh, self.edges[0].halfedge / 3, &project);
        let project = |i: u32| {
            let [x, y] = project(i);
            if mirror { [-x, y] } else { [x, y] }
        };

        // Extreme point: largest x, then largest y (Alg. 1, TrackXp).
        let mut start = self.edges[0].origin;
        let mut best = project(start);
        for e in &self.edges[1..] {
            let p = project(e.origin);
            if !(p[0].is_finite() && p[1].is_finite()) {
                return Err(ExtractError::NonFinitePoint { point: e.origin });
            }
            if p[0] > best[0] || (p[0] == best[0] && p[1] > best[1]) {
                (start, best) = (e.origin, p);
            }
        }
        if !(best[0].is_finite() && best[1].is_finite()) {
            return Err(ExtractError::NonFinitePoint { point: start });
        }

        // Arriving on [0, 1] means the reversed arrival direction is [0, -1].
        let first = self
            .select(start, [best[0], best[1] - 1.0], &project)
            .ok_or(ExtractError::BrokenBoundary {
                halfedge: NO_TWIN,
                point: start,
            })?;
        let shell = self.follow_ring(first, &project)?;

        let mut holes = Vec::new();
        let mut cursor = 0;
        while let Some(offset) = self.used[cursor..].iter().position(|u| !u) {
            cursor += offset;
            holes.push(self.follow_ring(cursor, &project)?);
        }
        Ok(Polygon { shell, holes })
    }

    /// Fills `edges` with the region's boundary half-edges sorted by origin point.
    fn collect_boundary(
        &mut self,
        mesh: &HalfEdgeMesh,
        triangles: &[u32],
        is_member: &impl Fn(u32) -> bool,
    ) -> Result<(), ExtractError> {
        let tris = mesh.triangles();
        let twins = mesh.halfedges();
        self.edges.clear();
        for &t in triangles {
            let Some(tri) = tris.get(t as usize) else {
                return Err(ExtractError::TriangleOutOfRange {
                    triangle: t,
                    num_triangles: tris.len(),
                });
            };
            for i in 0..3 {
                let h = 3 * t + i as u32;
                let twin = twins[h as usize];
                if twin == NO_TWIN || !is_member(twin / 3) {
                    self.edges.push(boundary_edge(tri, h));
                }
            }
        }
        self.sort_edges();
        Ok(())
    }

    /// Sorts the boundary edges by origin point and marks them all unused.
    fn sort_edges(&mut self) {
        self.edges.sort_unstable();
        self.used.clear();
        self.used.resize(self.edges.len(), false);
    }

    /// Follows one ring from boundary edge `first` until it returns to its origin,
    /// marking edges used. Returns the ring's points, the origin last.
    fn follow_ring(
        &mut self,
        first: usize,
        project: &impl Fn(u32) -> [f64; 2],
    ) -> Result<Vec<u32>, ExtractError> {
        let start = self.edges[first].origin;
        let mut ring = Vec::new();
        let mut current = first;
        loop {
            self.used[current] = true;
            let edge = self.edges[current];
            ring.push(edge.destination);
            if edge.destination == start {
                return Ok(ring);
            }
            let back = project(edge.origin);
            current = self.select(edge.destination, back, project).ok_or(
                ExtractError::BrokenBoundary {
                    halfedge: edge.halfedge,
                    point: edge.destination,
                },
            )?;
        }
    }

    /// Picks the unused boundary edge leaving `point` that comes first counter-clockwise
    /// from the direction towards `back` (the point the ring arrived from).
    fn select(
        &self,
        point: u32,
        back: [f64; 2],
        project: &impl Fn(u32) -> [f64; 2],
    ) -> Option<usize> {
        let lo = self.edges.partition_point(|e| e.origin < point);
        // Most points start one or two boundary edges: a scan beats a second search.
        let hi = lo
            + self.edges[lo..]
                .iter()
                .position(|e| e.origin != point)
                .unwrap_or(self.edges.len() - lo);
        let mut candidates = (lo..hi).filter(|&k| !self.used[k]);
        let first = candidates.next()?;
        let Some(second) = candidates.next() else {
            return Some(first);
        };
        let p = project(point);
        let b = [back[0] - p[0], back[1] - p[1]];
        let angle = |k: usize| {
            let q = project(self.edges[k].destination);
            ccw_angle(b, [q[0] - p[0], q[1] - p[1]])
        };
        let mut best = (first, angle(first));
        for k in std::iter::once(second).chain(candidates) {
            let a = angle(k);
            if a < best.1 {
                best = (k, a);
            }
        }
        Some(best.0)
    }
}

/// The boundary edge of half-edge `h` of triangle `tri`.
#[inline]
fn boundary_edge(tri: &[u32; 3], h: u32) -> BoundaryEdge {
    let i = h as usize % 3;
    BoundaryEdge {
        origin: tri[i],
        halfedge: h,
        destination: tri[(i + 1) % 3],
    }
}

/// Counter-clockwise angle from `from` to `to`, in `(0, 2π]`.
#[inline]
fn ccw_angle(from: [f64; 2], to: [f64; 2]) -> f64 {
    let cross = from[0] * to[1] - from[1] * to[0];
    let dot = from[0] * to[0] + from[1] * to[1];
    let a = cross.atan2(dot);
    if a <= 0.0 {
        a + std::f64::consts::TAU
    } else {
        a
    }
}

/// Whether the projection shows triangle `t` clockwise (the frame looks at the back side).
fn frame_is_mirrored(mesh: &HalfEdgeMesh, t: u32, project: &impl Fn(u32) -> [f64; 2]) -> bool {
    let Some(tri) = mesh.triangles().get(t as usize) else {
        return false;
    };
    let [a, b, c] = tri.map(project);
    (b[0] - a[0]) * (c[1] - a[1]) - (b[1] - a[1]) * (c[0] - a[0]) < 0.0
}

#[doc = include_str!("../README.md")]
#[cfg(doctest)]
pub struct ReadmeDoctests;

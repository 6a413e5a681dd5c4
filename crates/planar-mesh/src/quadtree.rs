//! Quadtree decimation (§IV-A2): a square box over the polygon, subdivided uniformly to a
//! depth; nodes are interior (inside the polygon, clear of its edges), boundary (meeting an
//! edge) or exterior. Interior nodes are merged bottom-up; their corners are the interior
//! vertices.
//!
//! The tree is built top-down, which gives the same merged leaves as building the full
//! grid and merging: a node is interior exactly when no edge comes within the clearance
//! of it and its centre is inside, and then all of its descendants are interior too. Each
//! node tests only the edges that met its parent.

use crate::polygon::{Polygon2, segment_meets_box};

/// The deepest subdivision (lattice coordinates must fit in `u32` with room to spare).
pub const MAX_DEPTH: u32 = 16;

/// A node of the merged quadtree: lattice corner `(i, j)` and side `size`, in units of the
/// finest cells.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) struct Node {
    pub i: u32,
    pub j: u32,
    pub size: u32,
}

/// The decimated segment: merged interior nodes, finest boundary cells, interior vertices.
#[derive(Debug, Clone, PartialEq)]
pub(crate) struct Quadtree {
    /// Lower corner of the square box.
    pub origin: [f64; 2],
    /// Side of a finest cell.
    pub cell: f64,
    /// Subdivision depth: `2^depth` cells per side.
    pub depth: u32,
    /// Merged interior nodes.
    pub interior: Vec<Node>,
    /// Finest cells meeting the polygon's edges (within the clearance), as `i << 32 | j`,
    /// sorted.
    pub boundary: Vec<u64>,
    /// Corners of the interior nodes, as lattice keys `i << 32 | j`, sorted, unique.
    pub vertices: Vec<u64>,
}

/// [`Depth::Auto`](crate::Depth::Auto): the finest cell is at most this many median boundary
/// edges.
pub const AUTO_CELL_EDGES: f64 = 4.0;

/// The lattice key of `(i, j)`.
#[inline]
pub(crate) fn key(i: u32, j: u32) -> u64 {
    (u64::from(i) << 32) | u64::from(j)
}

/// `(i, j)` of a lattice key.
#[inline]
pub(crate) fn unkey(k: u64) -> (u32, u32) {
    ((k >> 32) as u32, k as u32)
}

impl Quadtree {
    /// Decimates `polygon` with a tree of `depth` levels; interior nodes keep `clearance`
    /// finest cells (at least a relative 1e-9 of the box) between themselves and every edge.
    pub fn build(polygon: &Polygon2, depth: u32, clearance: f64) -> Self {
        let [lo, hi] = polygon.bbox;
        let extent = (hi[0] - lo[0]).max(hi[1] - lo[1]);
        // A hair of padding keeps every interior node off the box's border.
        let pad = extent * 1e-7;
        let side = extent + 2.0 * pad;
        let origin = [lo[0] - pad, lo[1] - pad];
        let n = 1u32 << depth;
        let cell = side / f64::from(n);
        let margin = (clearance * cell).max(side * 1e-9);
        let mut tree = Self {
            origin,
            cell,
            depth,
            interior: Vec::new(),
            boundary: Vec::new(),
            vertices: Vec::new(),
        };
        // The edges near each node, as ranges of one pool: a node's children share its
        // range and append their own, so nothing is copied or allocated per node.
        let mut pool: Vec<u32> = (0..polygon.edges.len() as u32).collect();
        let root = Node {
            i: 0,
            j: 0,
            size: n,
        };
        let mut stack: Vec<(Node, u32, u32)> = vec![(root, 0, pool.len() as u32)];
        while let Some((node, start, end)) = stack.pop() {
            let lo = tree.corner(node.i, node.j);
            let hi = tree.corner(node.i + node.size, node.j + node.size);
            let (lo, hi) = (
                [lo[0] - margin, lo[1] - margin],
                [hi[0] + margin, hi[1] + margin],
            );
            let first = pool.len();
            for k in start as usize..end as usize {
                let e = pool[k];
                let [a, b] = polygon.edges[e as usize];
                if segment_meets_box(a, b, lo, hi) {
                    pool.push(e);
                }
            }
            if pool.len() == first {
                let h = 0.5 * f64::from(node.size);
                if polygon.contains(tree.point(f64::from(node.i) + h, f64::from(node.j) + h)) {
                    tree.interior.push(node);
                }
            } else if node.size == 1 {
                tree.boundary.push(key(node.i, node.j));
                pool.truncate(first);
            } else {
                let s = node.size / 2;
                let (start, end) = (first as u32, pool.len() as u32);
                for (di, dj) in [(0, 0), (s, 0), (0, s), (s, s)] {
                    let child = Node {
                        i: node.i + di,
                        j: node.j + dj,
                        size: s,
                    };
                    stack.push((child, start, end));
                }
            }
        }
        tree.boundary.sort_unstable();
        tree.interior.sort_unstable_by_key(|n| key(n.i, n.j));
        let mut vertices: Vec<u64> = tree
            .interior
            .iter()
            .flat_map(|n| {
                let (i1, j1) = (n.i + n.size, n.j + n.size);
                [key(n.i, n.j), key(i1, n.j), key(i1, j1), key(n.i, j1)]
            })
            .collect();
        vertices.sort_unstable();
        vertices.dedup();
        tree.vertices = vertices;
        tree
    }

    /// Plane coordinates of lattice point `(i, j)`.
    #[inline]
    pub fn corner(&self, i: u32, j: u32) -> [f64; 2] {
        self.point(f64::from(i), f64::from(j))
    }

    /// Plane coordinates of fractional lattice point `(i, j)`.
    #[inline]
    pub fn point(&self, i: f64, j: f64) -> [f64; 2] {
        [
            self.origin[0] + i * self.cell,
            self.origin[1] + j * self.cell,
        ]
    }

    /// Whether finest cell `(i, j)` is a boundary cell.
    pub fn is_boundary(&self, i: u32, j: u32) -> bool {
        self.boundary.binary_search(&key(i, j)).is_ok()
    }

    /// Whether lattice point `k` is an interior vertex.
    pub fn is_vertex(&self, k: u64) -> bool {
        self.vertices.binary_search(&k).is_ok()
    }
}

/// The shallowest depth whose finest cell is at most [`AUTO_CELL_EDGES`] median edge
/// lengths of the polygon (so between 2 and 4 boundary spacings): the interior meets the
/// boundary with cells a few boundary spacings wide. Finer cells keep more vertices (on
/// the RGB-D frames 20 % of the planar points at 1–2 spacings, against 13 % here) for
/// little gain in triangle shape; much coarser ones leave a wide band of thin triangles.
pub(crate) fn auto_depth(polygon: &Polygon2) -> u32 {
    let mut lengths: Vec<f64> = polygon
        .edges
        .iter()
        .map(|[a, b]| (b[0] - a[0]).hypot(b[1] - a[1]))
        .filter(|l| *l > 0.0)
        .collect();
    if lengths.is_empty() {
        return 1;
    }
    let mid = lengths.len() / 2;
    let (_, median, _) = lengths.select_nth_unstable_by(mid, f64::total_cmp);
    let [lo, hi] = polygon.bbox;
    let extent = (hi[0] - lo[0]).max(hi[1] - lo[1]);
    let depth = (extent / (AUTO_CELL_EDGES * *median)).log2().ceil();
    if depth.is_finite() {
        (depth.max(1.0) as u32).min(MAX_DEPTH)
    } else {
        1
    }
}

#[cfg(test)]
mod tests {
    #![allow(clippy::unwrap_used)]
    use super::*;

    #[test]
    fn square_interior_merges_to_four_quadrant_blocks() {
        // A square polygon slightly inside the box: the interior nodes cover all but the
        // ring of boundary cells; every interior vertex is inside.
        let p =
            Polygon2::new(vec![[0.0, 0.0], [8.0, 0.0], [8.0, 8.0], [0.0, 8.0]], vec![]).unwrap();
        let q = Quadtree::build(&p, 4, 0.0);
        assert!(!q.interior.is_empty());
        let n = 1u32 << q.depth;
        // Boundary cells: the outer ring of the 16 × 16 grid.
        assert_eq!(q.boundary.len() as u32, 4 * (n - 1));
        // Every finest cell is covered exactly once by interior or boundary nodes.
        let covered: u64 = q.interior.iter().map(|n| u64::from(n.size).pow(2)).sum();
        assert_eq!(covered + q.boundary.len() as u64, u64::from(n).pow(2));
        for &k in &q.vertices {
            let (i, j) = unkey(k);
            assert!(p.contains(q.corner(i, j)));
        }
        // Interior cells 1..15 of each axis merge into 4 blocks of 4 × 4, 20 of 2 × 2 and
        // 52 single cells.
        assert_eq!(q.interior.len(), 4 + 20 + 52);
        assert_eq!(q.interior.iter().filter(|n| n.size == 4).count(), 4);
    }

    #[test]
    fn auto_depth_matches_edge_length() {
        let ring: Vec<[f64; 2]> = (0..40)
            .map(|k| {
                let t = f64::from(k) / 40.0 * std::f64::consts::TAU;
                [t.cos(), t.sin()]
            })
            .collect();
        let p = Polygon2::new(ring, vec![]).unwrap();
        // Edge ≈ 0.157, extent 2: 2 / (4 × 0.157) ≈ 3.2 → 2^2 = 4 cells of 0.5.
        assert_eq!(auto_depth(&p), 2);
    }
}

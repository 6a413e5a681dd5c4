//! Quadtree decimation (§IV-A2): a square box over the polygon, subdivided uniformly to a
//! depth; nodes are interior (inside the polygon, clear of its edges), boundary (meeting an
//! edge) or exterior. Interior nodes are merged bottom-up; their corners are the interior
//! vertices.
//!
//! The tree is built top-down, which gives the same merged leaves as building the full
//! grid and merging: a node is interior exactly when no edge comes within the clearance
//! of it and its centre is inside, and then all of its descendants are interior too. Each
//! node tests only the edges that met its parent.

use crate::polygon::{LineCrossings, Polygon2, segment_meets_box};

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
    /// The polygon's crossings with the horizontal lattice lines and the lines halfway
    /// between them: line `k` is at `j = k / 2` (see [`Quadtree::inside`]).
    lines: LineCrossings,
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
        let lines = LineCrossings::new(polygon, 2 * n + 1, |k| {
            origin[1] + 0.5 * f64::from(k) * cell
        });
        let mut tree = Self {
            origin,
            cell,
            depth,
            interior: Vec::new(),
            boundary: Vec::new(),
            vertices: Vec::new(),
            lines,
        };
        // The edges near each node, as ranges of one pool. A node hands its edges on to
        // the children they meet; everything past a node's range when it is taken from the
        // stack belongs to subtrees already done.
        let root = Node {
            i: 0,
            j: 0,
            size: n,
        };
        let (lo, hi) = tree.node_box(root, margin);
        let mut pool: Vec<u32> = (0..polygon.edges.len() as u32)
            .filter(|&e| {
                let [a, b] = polygon.edges[e as usize];
                segment_meets_box(a, b, lo, hi)
            })
            .collect();
        let mut stack: Vec<(Node, u32, u32)> = vec![(root, 0, pool.len() as u32)];
        let mut lists: [Vec<u32>; 4] = Default::default();
        while let Some((node, start, end)) = stack.pop() {
            pool.truncate(end as usize);
            if start == end {
                if tree.inside(2 * node.i + node.size, 2 * node.j + node.size) {
                    tree.interior.push(node);
                }
                continue;
            }
            if node.size == 1 {
                tree.boundary.push(key(node.i, node.j));
                continue;
            }
            let s = node.size / 2;
            let children = [(0, 0), (s, 0), (0, s), (s, s)].map(|(di, dj)| Node {
                i: node.i + di,
                j: node.j + dj,
                size: s,
            });
            let boxes = children.map(|c| tree.node_box(c, margin));
            // An edge is tested against the children whose side of the split lines it
            // reaches (the tests `segment_meets_box` begins with); the other sides are
            // the node's, which it meets.
            let (x_low, x_high) = (boxes[0].1[0], boxes[1].0[0]);
            let (y_low, y_high) = (boxes[0].1[1], boxes[2].0[1]);
            for &e in &pool[start as usize..end as usize] {
                let [a, b] = polygon.edges[e as usize];
                let low_x = !(a[0] > x_low && b[0] > x_low);
                let high_x = !(a[0] < x_high && b[0] < x_high);
                let low_y = !(a[1] > y_low && b[1] > y_low);
                let high_y = !(a[1] < y_high && b[1] < y_high);
                let reach = [
                    low_x && low_y,
                    high_x && low_y,
                    low_x && high_y,
                    high_x && high_y,
                ];
                for c in 0..4 {
                    if reach[c] && segment_meets_box(a, b, boxes[c].0, boxes[c].1) {
                        lists[c].push(e);
                    }
                }
            }
            for (child, list) in children.into_iter().zip(&mut lists) {
                let first = pool.len() as u32;
                pool.append(list);
                stack.push((child, first, pool.len() as u32));
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
    /// The box of `node`, grown by `margin` on every side.
    #[inline]
    fn node_box(&self, node: Node, margin: f64) -> ([f64; 2], [f64; 2]) {
        let lo = self.corner(node.i, node.j);
        let hi = self.corner(node.i + node.size, node.j + node.size);
        (
            [lo[0] - margin, lo[1] - margin],
            [hi[0] + margin, hi[1] + margin],
        )
    }

    /// Whether lattice point `(i / 2, j / 2)` (half-integers included: `(2 i + 1, 2 j + 1)`
    /// is the centre of finest cell `(i, j)`) is inside the polygon (even-odd rule, from the
    /// crossings of [`LineCrossings`]).
    pub fn inside(&self, i: u32, j: u32) -> bool {
        self.lines
            .contains(j, self.point(0.5 * f64::from(i), 0.0)[0])
    }

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
    // Squared lengths: the same median, without a `hypot` per edge.
    let mut squares: Vec<f64> = polygon
        .edges
        .iter()
        .map(|[a, b]| {
            let (dx, dy) = (b[0] - a[0], b[1] - a[1]);
            dx * dx + dy * dy
        })
        .filter(|l| *l > 0.0)
        .collect();
    if squares.is_empty() {
        return 1;
    }
    let mid = squares.len() / 2;
    let (_, median, _) = squares.select_nth_unstable_by(mid, f64::total_cmp);
    let [lo, hi] = polygon.bbox;
    let extent = (hi[0] - lo[0]).max(hi[1] - lo[1]);
    let depth = (extent / (AUTO_CELL_EDGES * median.sqrt())).log2().ceil();
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

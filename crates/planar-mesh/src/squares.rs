//! The interior of the polygon-based triangulation: two right triangles per merged node
//! (§IV-B2), or, where smaller neighbours put vertices on a node's sides ("hanging"
//! vertices, the paper's T-joints), a triangulation of the node that uses them.

use spade::{DelaunayTriangulation, Point2, Triangulation};

use crate::quadtree::{Node, Quadtree, key};

/// Constant-time "is this lattice point an interior vertex" for shallow trees, a binary
/// search for deep ones.
pub(crate) struct VertexLookup<'a> {
    tree: &'a Quadtree,
    side: u64,
    bits: Vec<u64>,
}

/// Lattices up to this depth get a bitmap (2^12 + 1 squared bits: about 2 MiB).
const BITMAP_DEPTH: u32 = 12;

impl<'a> VertexLookup<'a> {
    pub fn new(tree: &'a Quadtree) -> Self {
        let side = (1u64 << tree.depth) + 1;
        let mut bits = Vec::new();
        if tree.depth <= BITMAP_DEPTH {
            bits = vec![0u64; (side * side).div_ceil(64) as usize];
            for &k in &tree.vertices {
                let at = (k >> 32) * side + (k & 0xffff_ffff);
                bits[(at / 64) as usize] |= 1 << (at % 64);
            }
        }
        Self { tree, side, bits }
    }

    #[inline]
    pub fn contains(&self, i: u32, j: u32) -> bool {
        if self.bits.is_empty() {
            return self.tree.is_vertex(key(i, j));
        }
        let at = u64::from(i) * self.side + u64::from(j);
        self.bits[(at / 64) as usize] & (1 << (at % 64)) != 0
    }
}

/// The lattice points on the sides of `node`, counter-clockwise from its lower-left
/// corner: the four corners and every interior vertex between them; and, per side (bottom,
/// right, top, left), whether it has any.
fn ring_of(node: &Node, lookup: &VertexLookup<'_>, out: &mut Vec<u64>) -> [bool; 4] {
    let (i0, j0, s) = (node.i, node.j, node.size);
    let (i1, j1) = (i0 + s, j0 + s);
    out.clear();
    let mut hanging = [false; 4];
    out.push(key(i0, j0));
    for d in 1..s {
        if lookup.contains(i0 + d, j0) {
            out.push(key(i0 + d, j0));
            hanging[0] = true;
        }
    }
    out.push(key(i1, j0));
    for d in 1..s {
        if lookup.contains(i1, j0 + d) {
            out.push(key(i1, j0 + d));
            hanging[1] = true;
        }
    }
    out.push(key(i1, j1));
    for d in 1..s {
        if lookup.contains(i1 - d, j1) {
            out.push(key(i1 - d, j1));
            hanging[2] = true;
        }
    }
    out.push(key(i0, j1));
    for d in 1..s {
        if lookup.contains(i0, j1 - d) {
            out.push(key(i0, j1 - d));
            hanging[3] = true;
        }
    }
    hanging
}

/// Triangles (as lattice keys, counter-clockwise) of every interior node. A node with
/// vertices hanging on its sides is split so that it uses them when `split(ring)` says so
/// (`ring`: its side points, corners included); otherwise it gets its two right triangles.
pub(crate) fn node_triangles(
    tree: &Quadtree,
    split: impl Fn(&[u64]) -> bool,
    mut emit: impl FnMut([u64; 3]),
) {
    let lookup = VertexLookup::new(tree);
    let mut ring = Vec::new();
    for node in &tree.interior {
        let hanging = ring_of(node, &lookup, &mut ring);
        if !hanging.iter().any(|&h| h) || !split(&ring) {
            let (i1, j1) = (node.i + node.size, node.j + node.size);
            let [a, b, c, d] = [
                key(node.i, node.j),
                key(i1, node.j),
                key(i1, j1),
                key(node.i, j1),
            ];
            emit([a, b, c]);
            emit([a, c, d]);
            continue;
        }
        // A corner whose two sides have no hanging vertex sees every other side point:
        // fan from it. Corner k sits between side k − 1 and side k.
        let corners = corner_positions(&ring);
        let free = (0..4).find(|&k| !hanging[k] && !hanging[(k + 3) % 4]);
        match free {
            Some(k) => {
                let apex = corners[k];
                let n = ring.len();
                for step in 1..n - 1 {
                    let (p, q) = ((apex + step) % n, (apex + step + 1) % n);
                    emit([ring[apex], ring[p], ring[q]]);
                }
            }
            None => delaunay_of(&ring, &mut emit),
        }
    }
}

/// Positions of the four corners in a side ring (they are the points where the ring
/// turns; the lower-left one is first).
fn corner_positions(ring: &[u64]) -> [usize; 4] {
    let mut out = [0usize; 4];
    let n = ring.len();
    let mut found = 0;
    for k in 0..n {
        let (a, b, c) = (ring[(k + n - 1) % n], ring[k], ring[(k + 1) % n]);
        let d1 = (
            (b >> 32) as i64 - (a >> 32) as i64,
            (b & 0xffff_ffff) as i64 - (a & 0xffff_ffff) as i64,
        );
        let d2 = (
            (c >> 32) as i64 - (b >> 32) as i64,
            (c & 0xffff_ffff) as i64 - (b & 0xffff_ffff) as i64,
        );
        if d1.0 * d2.1 - d1.1 * d2.0 != 0 && found < 4 {
            out[found] = k;
            found += 1;
        }
    }
    out
}

/// The Delaunay triangulation of the side points: they all lie on the node's convex
/// boundary, so it covers the node exactly and uses every one of them.
fn delaunay_of(ring: &[u64], emit: &mut impl FnMut([u64; 3])) {
    let points: Vec<Point2<f64>> = ring
        .iter()
        .map(|&k| Point2::new(f64::from((k >> 32) as u32), f64::from(k as u32)))
        .collect();
    // Lattice coordinates are small exact integers: spade accepts them.
    if let Ok(dt) = DelaunayTriangulation::<Point2<f64>>::bulk_load_stable(points) {
        for face in dt.inner_faces() {
            emit(face.vertices().map(|v| ring[v.fix().index()]));
        }
    }
}

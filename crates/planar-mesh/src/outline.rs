//! The rectilinear outline of the merged interior nodes (§IV-B2), as constraint segments
//! for the band triangulation.
//!
//! The paper traces the outline on a "degree grid" image. Here it is read off the quadtree
//! directly: an interior node never touches an exterior one (the polygon's edge would run
//! along their common side, making both boundary nodes), so every unit side on the outline
//! lies between a finest boundary cell and an interior cell. Those sides are collected from
//! the boundary cells and merged into straight segments, split at every interior vertex so
//! that the band's triangles meet the interior squares corner to corner (no T-joints on the
//! outline, no duplicate vertices).

use crate::quadtree::{Quadtree, key, unkey};

/// The outline segments as pairs of lattice keys; every endpoint is an interior vertex.
pub(crate) fn outline_segments(tree: &Quadtree) -> Vec<[u64; 2]> {
    let n = 1u32 << tree.depth;
    // Unit sides: horizontal (y, x) from (x, y) to (x + 1, y); vertical (x, y) from (x, y)
    // to (x, y + 1).
    let mut horizontal: Vec<(u32, u32)> = Vec::new();
    let mut vertical: Vec<(u32, u32)> = Vec::new();
    let interior = |i: u32, j: u32| !tree.is_boundary(i, j) && tree.inside(2 * i + 1, 2 * j + 1);
    for &k in &tree.boundary {
        let (i, j) = unkey(k);
        if i > 0 && interior(i - 1, j) {
            vertical.push((i, j));
        }
        if i + 1 < n && interior(i + 1, j) {
            vertical.push((i + 1, j));
        }
        if j > 0 && interior(i, j - 1) {
            horizontal.push((j, i));
        }
        if j + 1 < n && interior(i, j + 1) {
            horizontal.push((j + 1, i));
        }
    }
    let mut segments = Vec::new();
    merge_runs(&mut horizontal, tree, &mut segments, |line, at| {
        key(at, line)
    });
    merge_runs(&mut vertical, tree, &mut segments, key);
    segments
}

/// Merges unit sides `(line, at)` (from `at` to `at + 1` along `line`) into segments, split
/// at interior vertices; `point(line, at)` is the lattice key of a point on the line.
fn merge_runs(
    sides: &mut [(u32, u32)],
    tree: &Quadtree,
    out: &mut Vec<[u64; 2]>,
    point: impl Fn(u32, u32) -> u64,
) {
    sides.sort_unstable();
    let mut run: Option<(u32, u32, u32)> = None; // line, start, end
    for &(line, at) in sides.iter() {
        run = match run {
            Some((l, start, end)) if l == line && end == at && !tree.is_vertex(point(line, at)) => {
                Some((l, start, at + 1))
            }
            Some((l, start, end)) => {
                out.push([point(l, start), point(l, end)]);
                Some((line, at, at + 1))
            }
            None => Some((line, at, at + 1)),
        };
    }
    if let Some((l, start, end)) = run {
        out.push([point(l, start), point(l, end)]);
    }
}

//! Constrained Delaunay triangulation (`spade`) of a polygon, or of the band between a
//! polygon and a rectilinear interior outline, keeping the triangles in between.
//!
//! Triangles are classified by a flood fill from the outer face: crossing a ring edge
//! flips "inside the polygon", crossing an outline edge flips "inside the interior". A
//! triangle is kept when it is inside the polygon and not inside the interior.

use spade::handles::FixedVertexHandle;
use spade::{
    ConstrainedDelaunayTriangulation, DelaunayTriangulation, HasPosition, Intersection,
    LineIntersectionIterator, Point2, Triangulation,
};

use crate::PlanarMeshError;

/// A triangulation vertex: its position and its index in [`CdtInput::points`]
/// ([`ADDED`] for a point the triangulation added).
#[derive(Debug, Clone, Copy)]
struct Vertex {
    position: Point2<f64>,
    id: u32,
}

/// [`Vertex::id`] of a point added where constraints cross.
const ADDED: u32 = u32::MAX;

impl HasPosition for Vertex {
    type Scalar = f64;

    fn position(&self) -> Point2<f64> {
        self.position
    }
}

type Cdt = ConstrainedDelaunayTriangulation<Vertex>;

/// What to triangulate: distinct points; ring edges (polygon shell and holes) and outline
/// edges (between points at index `first_outline` and above) as constraints.
pub(crate) struct CdtInput<'a> {
    pub points: &'a [[f64; 2]],
    pub ring_edges: &'a [[u32; 2]],
    pub outline_edges: &'a [[u32; 2]],
    pub first_outline: u32,
}

/// The kept triangles (counter-clockwise) and the points the triangulation added where
/// constraint edges crossed (only for self-intersecting input), numbered from
/// `points.len()`.
pub(crate) struct CdtOutput {
    pub triangles: Vec<[u32; 3]>,
    pub added: Vec<[f64; 2]>,
}

/// Triangulates `input`.
///
/// # Errors
/// [`PlanarMeshError::Triangulation`] when `spade` rejects a point (non-finite or out of range).
pub(crate) fn triangulate(input: &CdtInput<'_>) -> Result<CdtOutput, PlanarMeshError> {
    let n = input.points.len();
    // The points in the order spade's bulk loading sorts them into.
    let order = bulk_load_order(input.points);
    let vertices: Vec<Vertex> = order
        .iter()
        .map(|&i| {
            let p = input.points[i as usize];
            Vertex {
                position: Point2::new(p[0], p[1]),
                id: i,
            }
        })
        .collect();
    // The Delaunay triangulation first, then the constraints: most ring and outline edges
    // are Delaunay edges already and only get marked.
    let delaunay = DelaunayTriangulation::<Vertex>::bulk_load(vertices)
        .map_err(|e| PlanarMeshError::Triangulation(e.to_string()))?;
    if delaunay.num_vertices() != n {
        return Err(PlanarMeshError::Triangulation(format!(
            "{} of {} points are distinct",
            delaunay.num_vertices(),
            n
        )));
    }
    let mut handle = vec![FixedVertexHandle::from_index(0); n];
    for v in delaunay.vertices() {
        handle[v.data().id as usize] = v.fix();
    }
    let mut cdt = Cdt::from(delaunay);
    let marked = add_constraints(&mut cdt, input, &handle);
    // Input indices; added points are numbered from `n` in the order spade added them.
    let original = |v: FixedVertexHandle| match cdt.vertex(v).data().id {
        ADDED => v.index() as u32,
        id => id,
    };
    let kept = keep_between(&cdt, input, &marked, original);
    Ok(CdtOutput {
        triangles: kept,
        added: cdt
            .vertices()
            .skip(n)
            .map(|v| [v.position().x, v.position().y])
            .collect(),
    })
}

/// Makes the ring and outline edges constraints, in input order, as spade's
/// `try_add_constraint` would one after the other; edges that conflict with earlier ones
/// (a ring that crosses itself after projection onto the fitted plane, where it passed
/// close to itself) are added at the end, split where they cross.
///
/// Most of them are edges of the Delaunay triangulation already. Those are marked in the
/// returned flags (by undirected edge index) instead of in spade, whose insertion walks
/// along the line and allocates for each. Before a constraint that would cross a marked
/// edge (and so conflict with it), every marked edge is handed to spade, and from then on
/// all goes through spade. No insertion meets an edge marked only here, so the
/// triangulation is the one spade builds alone.
fn add_constraints(cdt: &mut Cdt, input: &CdtInput<'_>, handle: &[FixedVertexHandle]) -> Vec<bool> {
    let mut marked = vec![false; cdt.num_undirected_edges()];
    // The marked edges' ends, while marking here.
    let mut pending: Option<Vec<[FixedVertexHandle; 2]>> = Some(Vec::new());
    let mut conflicting = Vec::new();
    for e in input.ring_edges.iter().chain(input.outline_edges) {
        let [a, b] = e.map(|v| handle[v as usize]);
        if a == b {
            continue;
        }
        let edge = cdt.get_edge_from_neighbors(a, b);
        if edge.is_some_and(|e| e.is_constraint_edge()) {
            continue;
        }
        if let Some(list) = &mut pending {
            if let Some(edge) = edge {
                marked[edge.fix().as_undirected().index()] = true;
                list.push([a, b]);
                continue;
            }
            if crosses_marked(cdt, &marked, a, b) {
                hand_over(cdt, &mut pending);
            }
        }
        if cdt.try_add_constraint(a, b).is_empty() {
            conflicting.push([a, b]);
        }
    }
    if !conflicting.is_empty() {
        hand_over(cdt, &mut pending);
    }
    for [a, b] in conflicting {
        cdt.add_constraint_and_split(a, b, |position| Vertex {
            position,
            id: ADDED,
        });
    }
    marked
}

/// Whether the segment between `a` and `b` crosses an edge marked in `marked`.
fn crosses_marked(cdt: &Cdt, marked: &[bool], a: FixedVertexHandle, b: FixedVertexHandle) -> bool {
    LineIntersectionIterator::new_from_handles(cdt, a, b).any(|i| match i {
        Intersection::EdgeIntersection(e) => marked
            .get(e.fix().as_undirected().index())
            .copied()
            .unwrap_or(false),
        _ => false,
    })
}

/// Makes the marked edges spade's constraints (they are still edges: nothing crossed
/// them) and stops marking.
fn hand_over(cdt: &mut Cdt, pending: &mut Option<Vec<[FixedVertexHandle; 2]>>) {
    for [a, b] in pending.take().into_iter().flatten() {
        cdt.try_add_constraint(a, b);
    }
}

/// The vertex order in which `spade`'s bulk loading sorts (farthest from the points' mean
/// first, then by x and y): handing the points over in it makes that sort a linear scan.
/// The mean is summed in the order spade will sum it; should the reordering change it by a
/// rounding, spade sorts again and the result is the same.
fn bulk_load_order(points: &[[f64; 2]]) -> Vec<u32> {
    let mean = |order: &mut dyn Iterator<Item = usize>| {
        let mut sum = [0.0f64; 2];
        for i in order {
            sum[0] += points[i][0];
            sum[1] += points[i][1];
        }
        let inv = 1.0 / points.len() as f64;
        [sum[0] * inv, sum[1] * inv]
    };
    let mut order: Vec<u32> = (0..points.len() as u32).collect();
    let mut centre = mean(&mut (0..points.len()));
    for _ in 0..3 {
        // Integer keys in the same order: distance descending, then x and y ascending.
        let mut keyed: Vec<(u64, u64, u64, u32)> = order
            .iter()
            .map(|&i| {
                let p = points[i as usize];
                let (dx, dy) = (p[0] - centre[0], p[1] - centre[1]);
                (
                    !(dx * dx + dy * dy).to_bits(),
                    ordered(p[0]),
                    ordered(p[1]),
                    i,
                )
            })
            .collect();
        keyed.sort_unstable();
        order = keyed.into_iter().map(|k| k.3).collect();
        let again = mean(&mut order.iter().map(|&i| i as usize));
        if again == centre {
            break;
        }
        centre = again;
    }
    order
}

/// A key whose unsigned order is the total order of `v`.
#[inline]
fn ordered(v: f64) -> u64 {
    let bits = v.to_bits();
    if bits >> 63 == 1 {
        !bits
    } else {
        bits | 1 << 63
    }
}

/// The inner faces inside the rings and outside the outline (flood fill with parities).
fn keep_between(
    cdt: &Cdt,
    input: &CdtInput<'_>,
    marked: &[bool],
    original: impl Fn(FixedVertexHandle) -> u32,
) -> Vec<[u32; 3]> {
    let first = input.first_outline;
    let n = input.points.len() as u32;
    let is_outline = |a: u32, b: u32| a >= first && b >= first && a < n && b < n;
    // State per face (index 0 = outer): bit 0 inside polygon, bit 1 inside interior, bit 2 seen.
    let mut state = vec![0u8; cdt.num_inner_faces() + 1];
    let outer = cdt.outer_face();
    state[outer.fix().index()] = 4;
    let mut stack = vec![outer.fix()];
    let mut edges_of = Vec::with_capacity(8);
    while let Some(f) = stack.pop() {
        let face = cdt.face(f);
        edges_of.clear();
        match face.as_inner() {
            Some(inner) => edges_of.extend(inner.adjacent_edges()),
            None => edges_of.extend(cdt.convex_hull()),
        }
        let here = state[f.index()];
        for e in &edges_of {
            // Hull edges may come with either face on their left.
            let next = if e.face().fix() == f {
                e.rev().face()
            } else {
                e.face()
            };
            let n = next.fix().index();
            if state[n] & 4 != 0 {
                continue;
            }
            let mut s = here & 3;
            let undirected = e.as_undirected();
            if undirected.data().is_constraint_edge()
                || marked
                    .get(undirected.fix().index())
                    .copied()
                    .unwrap_or(false)
            {
                let [a, b] = e.vertices().map(|v| original(v.fix()));
                s ^= if is_outline(a, b) { 2 } else { 1 };
            }
            state[n] = s | 4;
            stack.push(next.fix());
        }
    }
    cdt.inner_faces()
        .filter(|f| state[f.fix().index()] & 3 == 1)
        .map(|f| f.vertices().map(|v| original(v.fix())))
        .collect()
}

#[cfg(test)]
mod tests {
    #![allow(clippy::unwrap_used)]
    use super::*;

    fn area(points: &[[f64; 2]], t: [u32; 3]) -> f64 {
        let [a, b, c] = t.map(|v| points[v as usize]);
        0.5 * ((b[0] - a[0]) * (c[1] - a[1]) - (c[0] - a[0]) * (b[1] - a[1]))
    }

    #[test]
    fn square_minus_square_hole() {
        let points = [
            [0.0, 0.0],
            [3.0, 0.0],
            [3.0, 3.0],
            [0.0, 3.0],
            [1.0, 1.0],
            [1.0, 2.0],
            [2.0, 2.0],
            [2.0, 1.0],
        ];
        let ring_edges = [
            [0, 1],
            [1, 2],
            [2, 3],
            [3, 0],
            [4, 5],
            [5, 6],
            [6, 7],
            [7, 4],
        ];
        let out = triangulate(&CdtInput {
            points: &points,
            ring_edges: &ring_edges,
            outline_edges: &[],
            first_outline: 8,
        })
        .unwrap();
        assert!(out.added.is_empty());
        let total: f64 = out.triangles.iter().map(|&t| area(&points, t)).sum();
        assert_eq!(total, 8.0);
        // The hole as an outline instead: the band is the same.
        let out = triangulate(&CdtInput {
            points: &points,
            ring_edges: &ring_edges[..4],
            outline_edges: &ring_edges[4..],
            first_outline: 4,
        })
        .unwrap();
        assert_eq!(
            out.triangles.iter().map(|&t| area(&points, t)).sum::<f64>(),
            8.0
        );
    }

    #[test]
    fn a_ring_that_crosses_itself_is_split_where_it_crosses() {
        // A figure eight: two triangles of area 1 meeting at (1, 1), even-odd inside.
        let points = [[0.0, 0.0], [2.0, 2.0], [2.0, 0.0], [0.0, 2.0]];
        let ring_edges = [[0, 1], [1, 2], [2, 3], [3, 0]];
        let out = triangulate(&CdtInput {
            points: &points,
            ring_edges: &ring_edges,
            outline_edges: &[],
            first_outline: 4,
        })
        .unwrap();
        assert_eq!(out.added.len(), 1);
        let mut all = points.to_vec();
        all.extend(&out.added);
        let total: f64 = out.triangles.iter().map(|&t| area(&all, t)).sum();
        assert!((total - 2.0).abs() < 1e-12, "{total}");
    }

    /// Every constraint handed to spade one after the other, conflicting ones split at
    /// the end: the triangles (each rotated to start at its smallest vertex, sorted) and
    /// the added points.
    fn spade_alone(input: &CdtInput<'_>) -> (Vec<[u32; 3]>, Vec<[u64; 2]>) {
        let vertices = input.points.iter().enumerate().map(|(i, p)| Vertex {
            position: Point2::new(p[0], p[1]),
            id: i as u32,
        });
        let order = bulk_load_order(input.points);
        let sorted: Vec<Vertex> = order
            .iter()
            .map(|&i| vertices.clone().nth(i as usize).unwrap())
            .collect();
        let delaunay = DelaunayTriangulation::<Vertex>::bulk_load(sorted).unwrap();
        let mut handle = vec![FixedVertexHandle::from_index(0); input.points.len()];
        for v in delaunay.vertices() {
            handle[v.data().id as usize] = v.fix();
        }
        let mut cdt = Cdt::from(delaunay);
        let mut conflicting = Vec::new();
        for e in input.ring_edges.iter().chain(input.outline_edges) {
            let [a, b] = e.map(|v| handle[v as usize]);
            if a != b && !cdt.exists_constraint(a, b) && cdt.try_add_constraint(a, b).is_empty() {
                conflicting.push([a, b]);
            }
        }
        for [a, b] in conflicting {
            cdt.add_constraint_and_split(a, b, |position| Vertex {
                position,
                id: ADDED,
            });
        }
        let n = input.points.len();
        let original = |v: FixedVertexHandle| match cdt.vertex(v).data().id {
            ADDED => v.index() as u32,
            id => id,
        };
        let none = vec![false; 0];
        let triangles = canonical(keep_between(&cdt, input, &none, original));
        let added = cdt
            .vertices()
            .skip(n)
            .map(|v| [v.position().x.to_bits(), v.position().y.to_bits()])
            .collect();
        (triangles, added)
    }

    fn canonical(mut triangles: Vec<[u32; 3]>) -> Vec<[u32; 3]> {
        for t in &mut triangles {
            let k = (0..3).min_by_key(|&k| t[k]).unwrap();
            t.rotate_left(k);
        }
        triangles.sort_unstable();
        triangles
    }

    #[test]
    fn constraints_marked_here_give_the_triangulation_of_spade_alone() {
        // Rings through random points, crossing themselves often, and a lattice outline
        // (cocircular points) inside: the constraints marked without spade, the hand-over
        // before a crossing and the splits must give spade's own result.
        let mut state = 0x9e37_79b9_7f4a_7c15u64;
        let mut uniform = || {
            state ^= state << 13;
            state ^= state >> 7;
            state ^= state << 17;
            (state >> 11) as f64 / (1u64 << 53) as f64
        };
        let mut handed_over = 0;
        for round in 0..60 {
            let ring_len = 4 + round % 20;
            let mut points: Vec<[f64; 2]> = (0..ring_len)
                .map(|k| {
                    // A star-shaped ring, jittered: crosses itself when the jitter is large.
                    let t = k as f64 / ring_len as f64 * std::f64::consts::TAU;
                    let r = 4.0 + uniform() * if round % 3 == 0 { 6.0 } else { 1.0 };
                    [r * t.cos(), r * t.sin() + 0.1 * uniform()]
                })
                .collect();
            let mut ring_edges: Vec<[u32; 2]> = (0..ring_len as u32)
                .map(|k| [k, (k + 1) % ring_len as u32])
                .collect();
            // A second ring (a hole) of random points, sometimes crossing the first.
            let hole = points.len() as u32;
            for _ in 0..5 {
                points.push([uniform() * 6.0 - 3.0, uniform() * 6.0 - 3.0]);
            }
            ring_edges.extend((0..5).map(|k| [hole + k, hole + (k + 1) % 5]));
            // A 3 × 3 lattice square outline in the middle.
            let first_outline = points.len() as u32;
            for (i, j) in [
                (0, 0),
                (1, 0),
                (2, 0),
                (2, 1),
                (2, 2),
                (1, 2),
                (0, 2),
                (0, 1),
            ] {
                points.push([f64::from(i) * 0.5 - 0.5, f64::from(j) * 0.5 - 0.5]);
            }
            let outline_edges: Vec<[u32; 2]> = (0..8)
                .map(|k| [first_outline + k, first_outline + (k + 1) % 8])
                .collect();
            let input = CdtInput {
                points: &points,
                ring_edges: &ring_edges,
                outline_edges: &outline_edges,
                first_outline,
            };
            let (triangles, added) = spade_alone(&input);
            handed_over += usize::from(!added.is_empty());
            let out = triangulate(&input).unwrap();
            assert_eq!(canonical(out.triangles), triangles, "round {round}");
            let ours: Vec<[u64; 2]> = out.added.iter().map(|p| p.map(f64::to_bits)).collect();
            assert_eq!(ours, added, "round {round}");
        }
        // Some rounds crossed themselves.
        assert!(handed_over > 5, "{handed_over}");
    }
}

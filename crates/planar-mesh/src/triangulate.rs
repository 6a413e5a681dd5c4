//! The three triangulations of a decimated segment: boundary-only (the paper's naive
//! baseline), point-based (§IV-B1) and polygon-based (§IV-B2).

use std::collections::HashMap;

use crate::PlanarMeshError;
use crate::cdt::{CdtInput, triangulate};
use crate::outline::outline_segments;
use crate::polygon::Polygon2;
use crate::quadtree::{Quadtree, unkey};
use crate::squares::node_triangles;

/// How a decimated segment is triangulated.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum Method {
    /// Point-based (§IV-B1): constrained Delaunay triangulation of the boundary and interior
    /// vertices, shell and hole edges as constraints. Conforming: no T-joints.
    Point,
    /// Polygon-based (§IV-B2): two right triangles per merged interior node, the band
    /// between their rectilinear outline and the boundary by constrained Delaunay
    /// triangulation. Fewer triangles; T-joints inside the interior (as in the paper), none
    /// on the outline.
    #[default]
    Polygon,
    /// The paper's naive baseline (Fig. 3, 8): constrained Delaunay triangulation of the
    /// boundary vertices only, no interior vertices.
    Boundary,
}

/// A triangulated segment in plane coordinates; the first `boundary` vertices are the
/// polygon's distinct ring vertices.
pub(crate) struct Triangulated {
    pub vertices: Vec<[f64; 2]>,
    pub triangles: Vec<[u32; 3]>,
    pub boundary: usize,
    /// Polygon-based: the leading triangles that split interior nodes.
    pub interior_triangles: usize,
}

/// The distinct ring vertices and the ring edges between them.
fn ring_graph(polygon: &Polygon2) -> (Vec<[f64; 2]>, Vec<[u32; 2]>) {
    let mut index: HashMap<[u64; 2], u32> = HashMap::with_capacity(polygon.num_vertices());
    let mut vertices = Vec::with_capacity(polygon.num_vertices());
    let mut edges = Vec::with_capacity(polygon.num_vertices());
    for ring in &polygon.rings {
        let ids: Vec<u32> = ring
            .iter()
            .map(|p| {
                *index
                    .entry([p[0].to_bits(), p[1].to_bits()])
                    .or_insert_with(|| {
                        vertices.push(*p);
                        (vertices.len() - 1) as u32
                    })
            })
            .collect();
        for k in 0..ids.len() {
            edges.push([ids[k], ids[(k + 1) % ids.len()]]);
        }
    }
    (vertices, edges)
}

/// Triangulates `polygon` decimated by `tree` (none for [`Method::Boundary`]) with
/// `method`; `conforming` splits every
/// polygon-based interior node with hanging vertices (else only those on the outline).
pub(crate) fn triangulate_segment(
    polygon: &Polygon2,
    tree: Option<&Quadtree>,
    method: Method,
    conforming: bool,
) -> Result<Triangulated, PlanarMeshError> {
    let (mut vertices, ring_edges) = ring_graph(polygon);
    let boundary = vertices.len();
    let mut interior_triangles = 0;
    let triangles = match (method, tree) {
        (Method::Boundary, _) | (_, None) => {
            let out = triangulate(&CdtInput {
                points: &vertices,
                ring_edges: &ring_edges,
                outline_edges: &[],
                first_outline: vertices.len() as u32,
            })?;
            vertices.extend(out.added);
            out.triangles
        }
        (Method::Point, Some(tree)) => {
            vertices.extend(tree.vertices.iter().map(|&k| {
                let (i, j) = unkey(k);
                tree.corner(i, j)
            }));
            let out = triangulate(&CdtInput {
                points: &vertices,
                ring_edges: &ring_edges,
                outline_edges: &[],
                first_outline: vertices.len() as u32,
            })?;
            vertices.extend(out.added);
            out.triangles
        }
        (Method::Polygon, Some(tree)) => {
            let (triangles, interior) =
                polygon_based(&mut vertices, &ring_edges, tree, conforming)?;
            interior_triangles = interior;
            triangles
        }
    };
    Ok(Triangulated {
        vertices,
        triangles,
        boundary,
        interior_triangles,
    })
}

/// Interior squares as right triangles plus the band by CDT; `vertices` holds the ring
/// vertices on entry and gains the interior vertices (and any split points).
fn polygon_based(
    vertices: &mut Vec<[f64; 2]>,
    ring_edges: &[[u32; 2]],
    tree: &Quadtree,
    conforming: bool,
) -> Result<(Vec<[u32; 3]>, usize), PlanarMeshError> {
    let boundary = vertices.len() as u32;
    let lattice = |k: u64| {
        let (i, j) = unkey(k);
        tree.corner(i, j)
    };
    vertices.extend(tree.vertices.iter().map(|&k| lattice(k)));
    // Final index of an interior vertex.
    let index = |k: u64| {
        tree.vertices
            .binary_search(&k)
            .map(|p| boundary + p as u32)
            .ok()
    };
    // The band's outline first: nodes with outline vertices on their sides must use them.
    let segments = outline_segments(tree);
    let mut outline_keys: Vec<u64> = segments.iter().flatten().copied().collect();
    outline_keys.sort_unstable();
    outline_keys.dedup();
    let mut triangles = Vec::with_capacity(2 * tree.interior.len() + 2 * boundary as usize);
    node_triangles(
        tree,
        |ring| conforming || ring.iter().any(|k| outline_keys.binary_search(k).is_ok()),
        |t| {
            if let [Some(a), Some(b), Some(c)] = t.map(index) {
                triangles.push([a, b, c]);
            }
        },
    );
    let interior = triangles.len();
    // The band: ring vertices, then the outline's vertices, with both sets of constraints.
    let mut band_points: Vec<[f64; 2]> = vertices[..boundary as usize].to_vec();
    band_points.extend(outline_keys.iter().map(|&k| lattice(k)));
    let band_index = |k: u64| {
        outline_keys
            .binary_search(&k)
            .map(|p| boundary + p as u32)
            .unwrap_or(boundary)
    };
    let outline_edges: Vec<[u32; 2]> = segments
        .iter()
        .map(|[a, b]| [band_index(*a), band_index(*b)])
        .collect();
    let out = triangulate(&CdtInput {
        points: &band_points,
        ring_edges,
        outline_edges: &outline_edges,
        first_outline: boundary,
    })?;
    // Band indices to final indices.
    let first_added = vertices.len() as u32;
    let band_points_len = band_points.len() as u32;
    let to_final = |v: u32| -> u32 {
        if v < boundary {
            v
        } else if v < band_points_len {
            index(outline_keys[(v - boundary) as usize]).unwrap_or(v)
        } else {
            first_added + (v - band_points_len)
        }
    };
    triangles.extend(out.triangles.iter().map(|t| t.map(to_final)));
    vertices.extend(out.added);
    Ok((triangles, interior))
}

//! Our own exact sweep-hull Delaunay triangulation (the Delaunator family of algorithms).
//!
//! 1. [`order`]: a seed triangle, the other points sorted by distance to its circumcentre,
//!    exact duplicates removed. Coordinates are copied in that order, so a point and its
//!    recent neighbours sit close in memory.
//! 2. Each point in turn is joined to the hull edges it sees (found through a hash of the
//!    pseudo-angle around the centre), then the edges opposite it are legalized with an
//!    explicit stack.
//! 3. A point that does not lie strictly outside the hull (possible only through rounding
//!    of the distance sort or inside the seed's circumcircle) is located by a visibility walk
//!    and inserted inside a triangle or on an edge, so no point is ever lost.
//!
//! Orientation and in-circle tests are exact ([`predicates`]); in-circle ties are broken by
//! a symbolic perturbation keyed on point ids, so the result is a unique Delaunay
//! triangulation whatever the insertion order: the property the α-complex strips rely on.
//! Triangles are counter-clockwise (y up); half-edge `3t + i` runs from corner `i` to
//! corner `i + 1` and its twin is stored directly.

pub(crate) mod alpha;
mod insert;
mod order;
pub(crate) mod predicates;

pub(crate) use order::Collinear;

/// A triangulation of a point set, indices into the caller's points.
#[derive(Debug, Clone)]
pub(crate) struct Triangulation {
    /// Counter-clockwise triangles.
    pub triangles: Vec<[u32; 3]>,
    /// Twin of every half-edge, [`NO_TWIN`](crate::NO_TWIN) on the hull.
    pub halfedges: Vec<u32>,
    /// The boundary vertices in counter-clockwise order, points lying on a hull edge
    /// included.
    pub hull: Vec<u32>,
    /// The distinct points triangulated (caller indices, insertion order).
    pub vertices: Vec<u32>,
    /// Points left out as exact duplicates of a point kept.
    pub duplicates: u32,
}

/// Delaunay triangulation of `points`. `ids` (one per point) are the global point ids
/// that break ties (duplicates keep the smallest id; cocircular ties are perturbed by id);
/// without them the index in `points` is the id.
///
/// # Errors
/// [`Collinear`] when fewer than three distinct points remain or all are collinear.
pub(crate) fn triangulate(
    points: &[[f64; 2]],
    ids: Option<&[u32]>,
) -> Result<Triangulation, Collinear> {
    let order = order::insertion_order(points, ids)?;
    let ranks: Vec<u32> = match ids {
        Some(ids) => order.input.iter().map(|&i| ids[i as usize]).collect(),
        None => order.input.clone(),
    };
    let mut sweep = insert::Sweep::new(&order.coords, &ranks, order.centre);
    for p in 3..order.coords.len() as u32 {
        sweep.insert(p);
    }
    let (triangles, halfedges, hull) = sweep.finish();
    let map = |v: u32| order.input[v as usize];
    Ok(Triangulation {
        triangles: triangles.iter().map(|t| t.map(map)).collect(),
        halfedges,
        hull: hull.into_iter().map(map).collect(),
        duplicates: order.duplicates,
        vertices: order.input,
    })
}

#[cfg(test)]
mod tests;

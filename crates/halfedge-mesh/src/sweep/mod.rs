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

/// A triangulation of a point set. Vertices are *positions*: indices into the distinct
/// points in insertion order (`coords`, `input`, `ranks`).
#[derive(Debug, Clone)]
pub(crate) struct Triangulation {
    /// Counter-clockwise triangles, three positions each.
    pub tris: Vec<u32>,
    /// Twin of every half-edge, [`NO_TWIN`](crate::NO_TWIN) on the hull.
    pub halfedges: Vec<u32>,
    /// The boundary positions in counter-clockwise order, points lying on a hull edge
    /// included.
    pub hull: Vec<u32>,
    /// Caller index of each position.
    pub input: Vec<u32>,
    /// Id of each position (the caller's `ids`, or its index).
    pub ranks: Vec<u32>,
    /// Coordinates of each position.
    pub coords: Vec<[f64; 2]>,
    /// Points left out as exact duplicates of a point kept.
    pub duplicates: u32,
}

impl Triangulation {
    /// The triangles as caller indices.
    pub fn caller_triangles(&self) -> Vec<[u32; 3]> {
        let map = |v: u32| self.input[v as usize];
        self.tris
            .chunks_exact(3)
            .map(|t| [map(t[0]), map(t[1]), map(t[2])])
            .collect()
    }
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
    let (tris, halfedges, hull) = sweep.finish();
    Ok(Triangulation {
        tris,
        halfedges,
        hull,
        input: order.input,
        ranks,
        coords: order.coords,
        duplicates: order.duplicates,
    })
}

#[cfg(test)]
mod tests;

//! Building a [`HalfEdgeMesh`] from user triangles: twin linking and the non-manifold
//! policies of the Polylidar3D paper (§4.3).

use rayon::prelude::*;

use crate::mesh::{NO_TWIN, cross_normal, next_halfedge, unit_normal};
use crate::{HalfEdgeMesh, MeshError};

/// What to do with an edge shared by more than two triangles (paper §4.3, condition 2).
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq, Hash)]
#[non_exhaustive]
pub enum NonManifoldPolicy {
    /// Link the first pair of opposite half-edges found (in half-edge order) and leave the
    /// others as border edges. The fastest; what the original implements.
    #[default]
    KeepFirst,
    /// Link the pair of opposite half-edges whose triangle normals are most alike.
    MostSimilarNormals,
    /// Link none of them: every half-edge on such an edge becomes a border edge. The safest:
    /// no planar segment can then cross a non-manifold edge.
    AllBorder,
}

/// What to do with a triangle that repeats a vertex, has zero area, or is so large that its
/// area overflows `f64`.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq, Hash)]
#[non_exhaustive]
pub enum DegeneratePolicy {
    /// Fail with [`MeshError::DegenerateTriangle`] naming the first such triangle.
    #[default]
    Error,
    /// Drop such triangles and count them in the [`BuildReport`].
    Drop,
}

/// Options for [`HalfEdgeMesh::from_triangles_with_options`].
///
/// ```
/// use halfedge_mesh::{DegeneratePolicy, MeshOptions, NonManifoldPolicy};
/// let options = MeshOptions::new()
///     .non_manifold(NonManifoldPolicy::AllBorder)
///     .degenerate(DegeneratePolicy::Drop);
/// assert_eq!(options.non_manifold, NonManifoldPolicy::AllBorder);
/// ```
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq, Hash)]
#[non_exhaustive]
pub struct MeshOptions {
    /// Handling of edges shared by more than two triangles.
    pub non_manifold: NonManifoldPolicy,
    /// Handling of degenerate triangles.
    pub degenerate: DegeneratePolicy,
}

impl MeshOptions {
    /// The defaults: [`NonManifoldPolicy::KeepFirst`], [`DegeneratePolicy::Error`].
    pub fn new() -> Self {
        Self::default()
    }

    /// Sets the non-manifold edge policy.
    pub fn non_manifold(mut self, policy: NonManifoldPolicy) -> Self {
        self.non_manifold = policy;
        self
    }

    /// Sets the degenerate triangle policy.
    pub fn degenerate(mut self, policy: DegeneratePolicy) -> Self {
        self.degenerate = policy;
        self
    }
}

/// What building a mesh from user triangles found along the way.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub struct BuildReport {
    /// Degenerate triangles dropped under [`DegeneratePolicy::Drop`].
    pub dropped_degenerate: usize,
    /// Edges shared by more than two triangles.
    pub non_manifold_edges: usize,
    /// Edges shared by exactly two triangles that run the same direction in both
    /// (inconsistent orientation); they are left as border edges.
    pub inconsistent_edges: usize,
    /// Half-edges without a twin in the result.
    pub border_halfedges: usize,
}

/// A triangle whose doubled area is at most this fraction of its longest edge squared is
/// treated as having zero area.
const ZERO_AREA_RATIO: f64 = 1e-14;

impl HalfEdgeMesh {
    /// Builds a mesh from vertices and triangles with the default [`MeshOptions`].
    ///
    /// ```
    /// use halfedge_mesh::HalfEdgeMesh;
    /// let vertices = vec![[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [1.0, 1.0, 0.5]];
    /// let mesh = HalfEdgeMesh::from_triangles(vertices, vec![[0, 1, 2], [1, 3, 2]])?;
    /// assert_eq!(mesh.twin(1), Some(5));
    /// # Ok::<(), halfedge_mesh::MeshError>(())
    /// ```
    ///
    /// # Errors
    /// See [`Self::from_triangles_with_options`].
    pub fn from_triangles(
        vertices: Vec<[f64; 3]>,
        triangles: Vec<[u32; 3]>,
    ) -> Result<Self, MeshError> {
        Self::from_triangles_with_options(vertices, triangles, MeshOptions::default())
            .map(|(mesh, _)| mesh)
    }

    /// Builds a mesh from vertices and triangles: checks the input, computes unit triangle
    /// normals and links twins.
    ///
    /// Twins are found by sorting the half-edges by their unordered vertex pair, which
    /// groups every edge's half-edges together without hashing; two half-edges become
    /// twins when they join the same vertices in opposite directions. Edges shared by more
    /// than two triangles follow `options.non_manifold`.
    ///
    /// # Errors
    /// [`MeshError::NoTriangles`], [`MeshError::TooLarge`], [`MeshError::IndexOutOfRange`],
    /// [`MeshError::NonFiniteVertex`], and [`MeshError::DegenerateTriangle`] under
    /// [`DegeneratePolicy::Error`].
    pub fn from_triangles_with_options(
        vertices: Vec<[f64; 3]>,
        mut triangles: Vec<[u32; 3]>,
        options: MeshOptions,
    ) -> Result<(Self, BuildReport), MeshError> {
        if vertices.len() > u32::MAX as usize {
            return Err(MeshError::TooLarge {
                what: "vertices",
                count: vertices.len(),
            });
        }
        if 3 * triangles.len() >= u32::MAX as usize {
            return Err(MeshError::TooLarge {
                what: "triangles",
                count: triangles.len(),
            });
        }
        let mut report = BuildReport::default();
        let before = triangles.len();
        let mut first_error = None;
        triangles.retain(|&tri| {
            if first_error.is_some() {
                return false;
            }
            match check_triangle(&vertices, tri) {
                Ok(()) => true,
                Err(MeshError::DegenerateTriangle { .. })
                    if options.degenerate == DegeneratePolicy::Drop =>
                {
                    false
                }
                Err(e) => {
                    first_error = Some(e);
                    false
                }
            }
        });
        if let Some(mut e) = first_error {
            // `retain` visits triangles in order, so the failing one is the next kept slot.
            let index = triangles.len();
            match &mut e {
                MeshError::IndexOutOfRange { triangle, .. }
                | MeshError::NonFiniteVertex { triangle, .. }
                | MeshError::DegenerateTriangle { triangle, .. } => *triangle = index,
                _ => {}
            }
            return Err(e);
        }
        report.dropped_degenerate = before - triangles.len();
        if triangles.is_empty() {
            return Err(MeshError::NoTriangles);
        }

        let normals: Vec<[f64; 3]> = triangles
            .par_iter()
            .map(|&tri| unit_normal(&vertices, tri))
            .collect();
        let halfedges = link_twins(&triangles, &normals, options.non_manifold, &mut report);
        report.border_halfedges = halfedges.iter().filter(|&&t| t == NO_TWIN).count();
        let mesh = Self::from_parts_trusted(vertices, triangles, halfedges, normals);
        debug_assert_eq!(mesh.sanity_check(), Ok(()));
        Ok((mesh, report))
    }
}

/// Checks one triangle's indices, finiteness and area. The triangle index in the error is
/// filled in by the caller.
fn check_triangle(vertices: &[[f64; 3]], tri: [u32; 3]) -> Result<(), MeshError> {
    for &v in &tri {
        let Some(p) = vertices.get(v as usize) else {
            return Err(MeshError::IndexOutOfRange {
                triangle: 0,
                vertex: v,
                num_vertices: vertices.len(),
            });
        };
        if !p.iter().all(|c| c.is_finite()) {
            return Err(MeshError::NonFiniteVertex {
                vertex: v,
                triangle: 0,
            });
        }
    }
    let degenerate = |reason| MeshError::DegenerateTriangle {
        triangle: 0,
        vertices: tri,
        reason,
    };
    if tri[0] == tri[1] || tri[1] == tri[2] || tri[0] == tri[2] {
        return Err(degenerate("repeated vertex"));
    }
    let [a, b, c] = tri.map(|v| vertices[v as usize]);
    let n = cross_normal(a, b, c);
    let area2 = (n[0] * n[0] + n[1] * n[1] + n[2] * n[2]).sqrt();
    let longest2 = [(a, b), (b, c), (c, a)]
        .iter()
        .map(|(p, q)| (0..3).map(|k| (p[k] - q[k]) * (p[k] - q[k])).sum::<f64>())
        .fold(0.0, f64::max);
    if !(area2.is_finite() && longest2.is_finite()) {
        return Err(degenerate(
            "too large: its edge lengths or area overflow f64",
        ));
    }
    if area2 <= ZERO_AREA_RATIO * longest2 {
        return Err(degenerate("zero area"));
    }
    Ok(())
}

/// Links twin half-edges by sorting half-edges on their unordered vertex pair.
fn link_twins(
    triangles: &[[u32; 3]],
    normals: &[[f64; 3]],
    policy: NonManifoldPolicy,
    report: &mut BuildReport,
) -> Vec<u32> {
    let origin = |h: u32| triangles[(h / 3) as usize][(h % 3) as usize];
    let key = |h: u32| {
        let (a, b) = (origin(h), origin(next_halfedge(h)));
        (u64::from(a.min(b)) << 32) | u64::from(a.max(b))
    };
    let mut keyed: Vec<(u64, u32)> = (0..3 * triangles.len() as u32)
        .into_par_iter()
        .map(|h| (key(h), h))
        .collect();
    keyed.par_sort_unstable();

    let mut halfedges = vec![NO_TWIN; keyed.len()];
    let opposite = |a: u32, b: u32| origin(a) != origin(b);
    for group in keyed.chunk_by(|x, y| x.0 == y.0) {
        match group {
            [_] => {}
            [(_, a), (_, b)] => {
                if opposite(*a, *b) {
                    halfedges[*a as usize] = *b;
                    halfedges[*b as usize] = *a;
                } else {
                    report.inconsistent_edges += 1;
                }
            }
            _ => {
                report.non_manifold_edges += 1;
                let pair = match policy {
                    NonManifoldPolicy::KeepFirst => first_opposite_pair(group, opposite),
                    NonManifoldPolicy::MostSimilarNormals => {
                        most_similar_pair(group, opposite, normals)
                    }
                    NonManifoldPolicy::AllBorder => None,
                };
                if let Some((a, b)) = pair {
                    halfedges[a as usize] = b;
                    halfedges[b as usize] = a;
                }
            }
        }
    }
    halfedges
}

/// The first half-edge of the group paired with the first later one running the other way.
fn first_opposite_pair(
    group: &[(u64, u32)],
    opposite: impl Fn(u32, u32) -> bool,
) -> Option<(u32, u32)> {
    group.iter().enumerate().find_map(|(i, &(_, a))| {
        group[i + 1..]
            .iter()
            .find(|&&(_, b)| opposite(a, b))
            .map(|&(_, b)| (a, b))
    })
}

/// The pair of opposite half-edges whose triangle normals have the largest dot product;
/// ties go to the lowest half-edge indices.
fn most_similar_pair(
    group: &[(u64, u32)],
    opposite: impl Fn(u32, u32) -> bool,
    normals: &[[f64; 3]],
) -> Option<(u32, u32)> {
    let mut best: Option<(f64, u32, u32)> = None;
    for (i, &(_, a)) in group.iter().enumerate() {
        for &(_, b) in &group[i + 1..] {
            if !opposite(a, b) {
                continue;
            }
            let (na, nb) = (normals[(a / 3) as usize], normals[(b / 3) as usize]);
            let dot = na[0] * nb[0] + na[1] * nb[1] + na[2] * nb[2];
            if best.is_none_or(|(d, _, _)| dot > d) {
                best = Some((dot, a, b));
            }
        }
    }
    best.map(|(_, a, b)| (a, b))
}

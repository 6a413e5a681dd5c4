//! Bilateral normal filtering of general meshes.

use halfedge_mesh::{HalfEdgeMesh, NO_TWIN, cross_normal};
use rayon::prelude::*;

use super::adjacency::Csr;
use super::{check_positive, check_vertices};
use crate::SmoothError;

/// Which triangles are a triangle's neighbours.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Default)]
pub enum TriangleNeighbourhood {
    /// The (up to three) triangles sharing an edge, through the twin half-edges.
    #[default]
    EdgeAdjacent,
    /// Every other triangle sharing a vertex.
    VertexRing,
}

/// Options of [`bilateral_normals`].
#[derive(Debug, Clone, Copy, PartialEq)]
#[non_exhaustive]
pub struct MeshBilateralOptions {
    /// σ_l, the spatial scale, in the mesh's length unit; finite, > 0. Default 0.1.
    pub sigma_length: f64,
    /// σ_a, the scale of the Euclidean distance between unit normals; finite, > 0.
    /// Default 0.1.
    pub sigma_angle: f64,
    /// Number of passes; 0 returns the input normals. Default 2.
    pub iterations: u32,
    /// Neighbour triangles. Default [`TriangleNeighbourhood::EdgeAdjacent`].
    pub neighbourhood: TriangleNeighbourhood,
}

impl Default for MeshBilateralOptions {
    fn default() -> Self {
        Self {
            sigma_length: 0.1,
            sigma_angle: 0.1,
            iterations: 2,
            neighbourhood: TriangleNeighbourhood::default(),
        }
    }
}

impl MeshBilateralOptions {
    /// The defaults (σ_l 0.1, σ_a 0.1, 2 iterations, edge-adjacent triangles).
    pub fn new() -> Self {
        Self::default()
    }

    /// Sets [`Self::sigma_length`].
    pub fn with_sigma_length(mut self, sigma_length: f64) -> Self {
        self.sigma_length = sigma_length;
        self
    }

    /// Sets [`Self::sigma_angle`].
    pub fn with_sigma_angle(mut self, sigma_angle: f64) -> Self {
        self.sigma_angle = sigma_angle;
        self
    }

    /// Sets [`Self::iterations`].
    pub fn with_iterations(mut self, iterations: u32) -> Self {
        self.iterations = iterations;
        self
    }

    /// Sets [`Self::neighbourhood`].
    pub fn with_neighbourhood(mut self, neighbourhood: TriangleNeighbourhood) -> Self {
        self.neighbourhood = neighbourhood;
        self
    }
}

/// Bilateral filtering of the triangle normals of `mesh` (its own normals if it has them,
/// else computed): `n' = normalize(Σ W_s W_r n_j)` over the neighbour triangles (the
/// triangle itself excluded) with `W_s = exp(−‖c − c_j‖² / σ_l²)` and
/// `W_r = exp(−‖n − n_j‖² / σ_a²)`. A triangle without neighbours, or whose weights all
/// underflow, keeps its normal. Returns one normal per triangle.
///
/// # Errors
/// Invalid sigmas, or a triangle using a missing or non-finite vertex.
pub fn bilateral_normals(
    mesh: &HalfEdgeMesh,
    options: &MeshBilateralOptions,
) -> Result<Vec<[f64; 3]>, SmoothError> {
    check_positive("sigma_length", options.sigma_length)?;
    check_positive("sigma_angle", options.sigma_angle)?;
    check_vertices(mesh)?;
    let vertices = mesh.vertices();
    let triangles = mesh.triangles();
    let mut normals: Vec<[f64; 3]> = match mesh.triangle_normals() {
        Some(normals) if normals.len() == triangles.len() => normals.to_vec(),
        _ => triangles
            .par_iter()
            .map(|&[a, b, c]| {
                let n = cross_normal(
                    vertices[a as usize],
                    vertices[b as usize],
                    vertices[c as usize],
                );
                let len = (n[0] * n[0] + n[1] * n[1] + n[2] * n[2]).sqrt();
                if len > 0.0 {
                    n.map(|x| x / len)
                } else {
                    [0.0; 3]
                }
            })
            .collect(),
    };
    if options.iterations == 0 {
        return Ok(normals);
    }
    let centroids: Vec<[f64; 3]> = triangles
        .par_iter()
        .map(|tri| {
            let [a, b, c] = tri.map(|v| vertices[v as usize]);
            [0, 1, 2].map(|k| (a[k] + b[k] + c[k]) / 3.0)
        })
        .collect();
    let neighbours = neighbour_lists(mesh, options.neighbourhood);
    let inv_l = 1.0 / (options.sigma_length * options.sigma_length);
    let inv_a = 1.0 / (options.sigma_angle * options.sigma_angle);
    let mut next = normals.clone();
    for _ in 0..options.iterations {
        next.par_iter_mut()
            .enumerate()
            .with_min_len(1024)
            .for_each(|(t, out)| {
                let (n, c) = (normals[t], centroids[t]);
                let mut acc = [0.0; 3];
                for &j in neighbours.get(t) {
                    let (nj, cj) = (normals[j as usize], centroids[j as usize]);
                    let w = (-dist2(c, cj) * inv_l - dist2(n, nj) * inv_a).exp();
                    for k in 0..3 {
                        acc[k] += w * nj[k];
                    }
                }
                let len = (acc[0] * acc[0] + acc[1] * acc[1] + acc[2] * acc[2]).sqrt();
                *out = if len > 0.0 { acc.map(|x| x / len) } else { n };
            });
        std::mem::swap(&mut normals, &mut next);
    }
    Ok(normals)
}

fn dist2(a: [f64; 3], b: [f64; 3]) -> f64 {
    let d = [a[0] - b[0], a[1] - b[1], a[2] - b[2]];
    d[0] * d[0] + d[1] * d[1] + d[2] * d[2]
}

/// The neighbour triangles of every triangle, without itself.
fn neighbour_lists(mesh: &HalfEdgeMesh, neighbourhood: TriangleNeighbourhood) -> Csr {
    let nt = mesh.num_triangles();
    match neighbourhood {
        TriangleNeighbourhood::EdgeAdjacent => Csr::from_lists(
            nt,
            mesh.halfedges()
                .par_iter()
                .enumerate()
                .filter(|&(_, &twin)| twin != NO_TWIN)
                .map(|(h, &twin)| ((h / 3) as u32, twin / 3))
                .collect(),
        ),
        TriangleNeighbourhood::VertexRing => {
            let around = Csr::vertex_triangles(mesh.num_vertices(), mesh.triangles());
            Csr::from_lists(
                nt,
                mesh.triangles()
                    .par_iter()
                    .enumerate()
                    .flat_map_iter(|(t, tri)| {
                        let around = &around;
                        tri.iter().flat_map(move |&v| {
                            around
                                .get(v as usize)
                                .iter()
                                .filter(move |&&u| u as usize != t)
                                .map(move |&u| (t as u32, u))
                        })
                    })
                    .collect(),
            )
        }
    }
}

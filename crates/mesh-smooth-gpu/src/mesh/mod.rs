//! Smoothing of general half-edge meshes (user meshes, Delaunay meshes), in `f64` with
//! rayon; results are identical at any thread count.
//!
//! * [`laplacian()`]: `v' = v + λ (Σ w_j v_j / Σ w_j − v)` over the 1-ring vertex neighbours,
//!   with uniform or inverse-distance weights ([`Weighting`]);
//! * [`taubin`]: alternating λ and μ Laplacian steps (λ > 0 > μ, |μ| > λ), which smooths
//!   without the shrinkage of repeated Laplacian steps;
//! * [`bilateral_normals`]: `n' = normalize(Σ W_s W_r n_j)` over edge-adjacent or
//!   vertex-ring triangles, the same weights as the organized-cloud filter.
//!
//! Vertex filters return new vertices (hand them to `HalfEdgeMesh::set_vertices`, which
//! also recomputes normals); the normal filter returns one unit normal per triangle
//! (`HalfEdgeMesh::set_triangle_normals`).
//!
//! ```
//! use halfedge_mesh::HalfEdgeMesh;
//! use mesh_smooth_gpu::mesh::{self, MeshBilateralOptions, TaubinOptions};
//!
//! let points: Vec<[f64; 3]> = (0..100)
//!     .map(|i| [(i % 10) as f64, (i / 10) as f64, if i == 55 { 0.5 } else { 0.0 }])
//!     .collect();
//! let mut surface = HalfEdgeMesh::delaunay_25d(&points, [0.0, 0.0, 1.0])?;
//! let smoothed = mesh::taubin(&surface, &TaubinOptions::new())?;
//! assert!(smoothed[55][2] < 0.5);
//! surface.set_vertices(smoothed)?;
//! let normals = mesh::bilateral_normals(&surface, &MeshBilateralOptions::new())?;
//! surface.set_triangle_normals(normals)?;
//! # Ok::<(), Box<dyn std::error::Error>>(())
//! ```

mod adjacency;
mod bilateral;
mod laplacian;

pub use bilateral::{MeshBilateralOptions, TriangleNeighbourhood, bilateral_normals};
pub use laplacian::{MeshLaplacianOptions, TaubinOptions, Weighting, laplacian, taubin};

use halfedge_mesh::HalfEdgeMesh;

use crate::SmoothError;

/// Checks that every triangle indexes existing, finite vertices.
fn check_vertices(mesh: &HalfEdgeMesh) -> Result<(), SmoothError> {
    let vertices = mesh.vertices();
    for (triangle, tri) in mesh.triangles().iter().enumerate() {
        for &vertex in tri {
            let Some(p) = vertices.get(vertex as usize) else {
                return Err(SmoothError::VertexOutOfRange {
                    triangle,
                    vertex,
                    num_vertices: vertices.len(),
                });
            };
            if !p.iter().all(|x| x.is_finite()) {
                return Err(SmoothError::NonFiniteVertex { vertex, triangle });
            }
        }
    }
    Ok(())
}

fn check_finite(name: &'static str, value: f64) -> Result<(), SmoothError> {
    if value.is_finite() {
        Ok(())
    } else {
        Err(SmoothError::InvalidParameter {
            name,
            value,
            reason: "must be finite",
        })
    }
}

fn check_positive(name: &'static str, value: f64) -> Result<(), SmoothError> {
    if value.is_finite() && value > 0.0 && (1.0 / (value * value)).is_finite() {
        Ok(())
    } else {
        Err(SmoothError::InvalidParameter {
            name,
            value,
            reason: "must be finite and > 0 (and not so small that 1/σ² overflows)",
        })
    }
}

//! Laplacian and Taubin vertex smoothing of general meshes.

use halfedge_mesh::{HalfEdgeMesh, NO_TWIN};
use rayon::prelude::*;

use super::adjacency::Csr;
use super::{check_finite, check_positive, check_vertices};
use crate::SmoothError;

/// How 1-ring neighbours are weighted.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Default)]
pub enum Weighting {
    /// Every neighbour counts the same (the umbrella operator).
    Uniform,
    /// `w_j = 1 / (‖v − v_j‖ + ε)`, as the organized-cloud filter.
    #[default]
    InverseDistance,
}

/// Options of [`laplacian`].
#[derive(Debug, Clone, Copy, PartialEq)]
#[non_exhaustive]
pub struct MeshLaplacianOptions {
    /// Step towards the weighted neighbour mean; finite. Default 0.5.
    pub lambda: f64,
    /// Number of passes. Default 2.
    pub iterations: u32,
    /// Neighbour weights. Default [`Weighting::InverseDistance`].
    pub weighting: Weighting,
    /// ε of inverse-distance weights, in the mesh's length unit; finite, > 0. Default 1e-6.
    pub epsilon: f64,
    /// Keep vertices on border edges (edges without a twin) fixed. Default `false`.
    pub pin_boundary: bool,
}

impl Default for MeshLaplacianOptions {
    fn default() -> Self {
        Self {
            lambda: 0.5,
            iterations: 2,
            weighting: Weighting::default(),
            epsilon: 1e-6,
            pin_boundary: false,
        }
    }
}

impl MeshLaplacianOptions {
    /// The defaults (λ 0.5, 2 iterations, inverse-distance weights, ε 1e-6, free boundary).
    pub fn new() -> Self {
        Self::default()
    }

    /// Sets [`Self::lambda`].
    pub fn with_lambda(mut self, lambda: f64) -> Self {
        self.lambda = lambda;
        self
    }

    /// Sets [`Self::iterations`].
    pub fn with_iterations(mut self, iterations: u32) -> Self {
        self.iterations = iterations;
        self
    }

    /// Sets [`Self::weighting`].
    pub fn with_weighting(mut self, weighting: Weighting) -> Self {
        self.weighting = weighting;
        self
    }

    /// Sets [`Self::epsilon`].
    pub fn with_epsilon(mut self, epsilon: f64) -> Self {
        self.epsilon = epsilon;
        self
    }

    /// Sets [`Self::pin_boundary`].
    pub fn with_pin_boundary(mut self, pin_boundary: bool) -> Self {
        self.pin_boundary = pin_boundary;
        self
    }
}

/// Options of [`taubin`].
#[derive(Debug, Clone, Copy, PartialEq)]
#[non_exhaustive]
pub struct TaubinOptions {
    /// The shrinking step, > 0. Default 0.5.
    pub lambda: f64,
    /// The inflating step, < 0 with |μ| > λ. Default −0.53.
    pub mu: f64,
    /// Number of λ | μ pairs. Default 10.
    pub iterations: u32,
    /// Neighbour weights. Default [`Weighting::Uniform`] (Taubin's choice).
    pub weighting: Weighting,
    /// ε of inverse-distance weights; finite, > 0. Default 1e-6.
    pub epsilon: f64,
    /// Keep vertices on border edges fixed. Default `false`.
    pub pin_boundary: bool,
}

impl Default for TaubinOptions {
    fn default() -> Self {
        Self {
            lambda: 0.5,
            mu: -0.53,
            iterations: 10,
            weighting: Weighting::Uniform,
            epsilon: 1e-6,
            pin_boundary: false,
        }
    }
}

impl TaubinOptions {
    /// The defaults (λ 0.5, μ −0.53, 10 pairs, uniform weights, free boundary).
    pub fn new() -> Self {
        Self::default()
    }

    /// Sets [`Self::lambda`] and [`Self::mu`].
    pub fn with_steps(mut self, lambda: f64, mu: f64) -> Self {
        self.lambda = lambda;
        self.mu = mu;
        self
    }

    /// Sets [`Self::iterations`].
    pub fn with_iterations(mut self, iterations: u32) -> Self {
        self.iterations = iterations;
        self
    }

    /// Sets [`Self::weighting`].
    pub fn with_weighting(mut self, weighting: Weighting) -> Self {
        self.weighting = weighting;
        self
    }

    /// Sets [`Self::pin_boundary`].
    pub fn with_pin_boundary(mut self, pin_boundary: bool) -> Self {
        self.pin_boundary = pin_boundary;
        self
    }
}

/// Laplacian smoothing of the vertices of `mesh` over their 1-ring neighbours; returns the
/// new vertices. Vertices no triangle uses (and, if pinned, border vertices) keep their
/// position.
///
/// # Errors
/// Invalid options, or a triangle using a missing or non-finite vertex.
pub fn laplacian(
    mesh: &HalfEdgeMesh,
    options: &MeshLaplacianOptions,
) -> Result<Vec<[f64; 3]>, SmoothError> {
    check_finite("lambda", options.lambda)?;
    check_positive("epsilon", options.epsilon)?;
    let smoother = Smoother::new(
        mesh,
        options.weighting,
        options.epsilon,
        options.pin_boundary,
    )?;
    let steps = vec![options.lambda; options.iterations as usize];
    Ok(smoother.run(mesh.vertices(), &steps))
}

/// Taubin λ | μ smoothing of the vertices of `mesh`; returns the new vertices.
///
/// # Errors
/// `lambda ≤ 0`, `mu ≥ 0`, `|mu| ≤ lambda`, non-finite values, or a triangle using a
/// missing or non-finite vertex.
pub fn taubin(mesh: &HalfEdgeMesh, options: &TaubinOptions) -> Result<Vec<[f64; 3]>, SmoothError> {
    let TaubinOptions { lambda, mu, .. } = *options;
    if !(lambda.is_finite() && lambda > 0.0) {
        return Err(SmoothError::InvalidParameter {
            name: "lambda",
            value: lambda,
            reason: "must be finite and > 0",
        });
    }
    if !(mu.is_finite() && mu < 0.0 && -mu > lambda) {
        return Err(SmoothError::InvalidParameter {
            name: "mu",
            value: mu,
            reason: "must be finite, < 0 and larger than lambda in magnitude",
        });
    }
    check_positive("epsilon", options.epsilon)?;
    let smoother = Smoother::new(
        mesh,
        options.weighting,
        options.epsilon,
        options.pin_boundary,
    )?;
    let steps: Vec<f64> = (0..options.iterations).flat_map(|_| [lambda, mu]).collect();
    Ok(smoother.run(mesh.vertices(), &steps))
}

struct Smoother {
    ring: Csr,
    pinned: Vec<bool>,
    weighting: Weighting,
    epsilon: f64,
}

impl Smoother {
    fn new(
        mesh: &HalfEdgeMesh,
        weighting: Weighting,
        epsilon: f64,
        pin_boundary: bool,
    ) -> Result<Self, SmoothError> {
        check_vertices(mesh)?;
        let n = mesh.num_vertices();
        let mut pinned = vec![false; n];
        if pin_boundary {
            for (h, &twin) in mesh.halfedges().iter().enumerate() {
                if twin == NO_TWIN {
                    let h = h as u32;
                    pinned[mesh.origin(h) as usize] = true;
                    pinned[mesh.destination(h) as usize] = true;
                }
            }
        }
        Ok(Self {
            ring: Csr::vertex_neighbours(n, mesh.triangles()),
            pinned,
            weighting,
            epsilon,
        })
    }

    /// One Jacobi pass per entry of `steps` (its λ).
    fn run(&self, vertices: &[[f64; 3]], steps: &[f64]) -> Vec<[f64; 3]> {
        let mut current = vertices.to_vec();
        let mut next = current.clone();
        for &lambda in steps {
            next.par_iter_mut()
                .enumerate()
                .with_min_len(1024)
                .for_each(|(v, out)| *out = self.vertex(&current, v, lambda));
            std::mem::swap(&mut current, &mut next);
        }
        current
    }

    fn vertex(&self, points: &[[f64; 3]], v: usize, lambda: f64) -> [f64; 3] {
        let p = points[v];
        let ring = self.ring.get(v);
        if self.pinned[v] || ring.is_empty() {
            return p;
        }
        let (mut sum, mut total) = ([0.0; 3], 0.0);
        for &j in ring {
            let q = points[j as usize];
            let w = match self.weighting {
                Weighting::Uniform => 1.0,
                Weighting::InverseDistance => {
                    let d = [p[0] - q[0], p[1] - q[1], p[2] - q[2]];
                    1.0 / ((d[0] * d[0] + d[1] * d[1] + d[2] * d[2]).sqrt() + self.epsilon)
                }
            };
            total += w;
            for k in 0..3 {
                sum[k] += w * q[k];
            }
        }
        [0, 1, 2].map(|k| p[k] + lambda * (sum[k] / total - p[k]))
    }
}

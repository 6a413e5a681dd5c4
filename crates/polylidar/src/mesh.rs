//! Planar simplification and texturing of the extracted planes (Ma et al. 2013, the
//! `planar-mesh` crate): each polygon's points and boundary → a light, optionally textured
//! mesh per plane, and all of them as one mesh.

use std::time::Instant;

use planar_mesh::{
    MergedMesh, Packing, PlanarMeshError, PlaneMesh, Segment, SimplifyOptions, merge, simplify_all,
};
use rayon::prelude::*;

use crate::Extraction;

/// A segment's points and their colours.
type Gathered = (Vec<[f64; 3]>, Option<Vec<[u8; 3]>>);

/// The simplified meshes of an extraction's planes.
#[derive(Debug, Clone)]
pub struct PlanarMeshes {
    /// `(polygon index, its mesh)` for every polygon that could be meshed, in polygon order.
    pub planes: Vec<(usize, PlaneMesh)>,
    /// `(polygon index, why)` for every polygon that could not.
    pub skipped: Vec<(usize, PlanarMeshError)>,
    /// Seconds from the extraction to the meshes: gathering each plane's points, then
    /// decimation, triangulation and textures.
    pub seconds: f64,
}

impl PlanarMeshes {
    /// All planes as one mesh, textures packed as `packing` says.
    pub fn merged(&self, packing: Packing) -> MergedMesh {
        let planes: Vec<(usize, &PlaneMesh)> = self.planes.iter().map(|(i, m)| (*i, m)).collect();
        merge(&planes, packing)
    }

    /// Triangles over all planes.
    pub fn num_triangles(&self) -> usize {
        self.planes.iter().map(|(_, m)| m.triangles.len()).sum()
    }
}

impl Extraction {
    /// The point indices (mesh vertices) of every polygon's triangles, sorted.
    pub fn polygon_vertices(&self) -> Vec<Vec<u32>> {
        let triangles = self.mesh.triangles();
        let words = self.mesh.num_vertices().div_ceil(64);
        self.polygons
            .par_iter()
            .map_init(
                || (Vec::new(), vec![0u64; words]),
                |(by_triangle, by_vertex), p| {
                    // The polygon's triangles in index order (a bitmap of their span), so
                    // that the triangle array is read front to back, not in the order
                    // region growing found them.
                    let (lo, hi) = p
                        .triangles
                        .iter()
                        .fold((u32::MAX, 0), |(lo, hi), &t| (lo.min(t), hi.max(t)));
                    if lo > hi {
                        return Vec::new();
                    }
                    let base = lo as usize / 64;
                    by_triangle.clear();
                    by_triangle.resize(hi as usize / 64 + 1 - base, 0u64);
                    for &t in &p.triangles {
                        by_triangle[t as usize / 64 - base] |= 1 << (t % 64);
                    }
                    take_each_bit(by_triangle, |t| {
                        for v in triangles[base * 64 + t] {
                            by_vertex[v as usize / 64] |= 1 << (v % 64);
                        }
                    });
                    // Read back in order, leaving the bitmap cleared for the next polygon.
                    let mut ids = Vec::with_capacity(p.triangles.len() / 2 + 8);
                    take_each_bit(by_vertex, |v| ids.push(v as u32));
                    ids
                },
            )
            .collect()
    }

    /// A simplified mesh of every polygon's plane (Ma et al. 2013): its points are the
    /// vertices of its triangles, its concave hull the polygon with holes. `colors`, one
    /// per vertex of [`Extraction::mesh`] (for an organized cloud: per pixel, row-major),
    /// are needed for textures. Planes run in parallel on rayon's current pool (see
    /// [`SimplifyOptions::parallel`]).
    ///
    /// ```
    /// use polylidar::{Config, Polylidar};
    /// use polylidar::planar_mesh::{SimplifyOptions, Packing};
    ///
    /// let points: Vec<[f64; 2]> = (0..900).map(|i| [(i % 30) as f64, (i / 30) as f64]).collect();
    /// let extraction = Polylidar::new(Config::new().with_alpha(1.0))?.extract_2d(&points)?;
    /// let meshes = extraction.planar_meshes(None, &SimplifyOptions::new())?;
    /// assert_eq!(meshes.planes.len(), 1);
    /// // The 29 × 29 square: far fewer triangles than the 1,682 of the full grid.
    /// assert!(meshes.num_triangles() < 400);
    /// assert_eq!(meshes.merged(Packing::Atlas).planes.len(), 1);
    /// # Ok::<(), Box<dyn std::error::Error>>(())
    /// ```
    ///
    /// # Errors
    /// [`PlanarMeshError::ColorCount`] when `colors` is not one per mesh vertex;
    /// [`PlanarMeshError::NoColors`] when the options ask for a texture without colours; bad
    /// options. A polygon that cannot be meshed is listed in [`PlanarMeshes::skipped`].
    pub fn planar_meshes(
        &self,
        colors: Option<&[[u8; 3]]>,
        options: &SimplifyOptions,
    ) -> Result<PlanarMeshes, PlanarMeshError> {
        let start = Instant::now();
        let vertices = self.mesh.vertices();
        if let Some(c) = colors
            && c.len() != vertices.len()
        {
            return Err(PlanarMeshError::ColorCount {
                colors: c.len(),
                points: vertices.len(),
            });
        }
        if options.texture.is_some() && colors.is_none() {
            return Err(PlanarMeshError::NoColors);
        }
        let ids = self.polygon_vertices();
        let gathered: Vec<Gathered> = ids
            .par_iter()
            .map(|ids| {
                let points = ids.iter().map(|&v| vertices[v as usize]).collect();
                let colors = colors.map(|c| ids.iter().map(|&v| c[v as usize]).collect());
                (points, colors)
            })
            .collect();
        let segments: Vec<Segment<'_>> = gathered
            .iter()
            .zip(&self.polygons)
            .map(|((points, colors), polygon)| {
                let segment = Segment::new(points, &polygon.shell_points, &polygon.hole_points);
                match colors {
                    Some(c) => segment.with_colors(c),
                    None => segment,
                }
            })
            .collect();
        let mut planes = Vec::new();
        let mut skipped = Vec::new();
        for (k, result) in simplify_all(&segments, options).into_iter().enumerate() {
            match result {
                Ok(mesh) => planes.push((k, mesh)),
                Err(e) => skipped.push((k, e)),
            }
        }
        Ok(PlanarMeshes {
            planes,
            skipped,
            seconds: start.elapsed().as_secs_f64(),
        })
    }
}

/// Calls `f` with the index of every set bit of `bits` (bit `k` of word `w` is `64 w + k`),
/// in increasing order, clearing each word as it is read.
fn take_each_bit(bits: &mut [u64], mut f: impl FnMut(usize)) {
    for (w, word) in bits.iter_mut().enumerate() {
        let mut b = std::mem::take(word);
        while b != 0 {
            f(w * 64 + b.trailing_zeros() as usize);
            b &= b - 1;
        }
    }
}

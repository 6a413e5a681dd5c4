//! Triangle-mesh export and uniform sampling of a scene's faces.

use rand::rngs::Xoshiro256PlusPlus;
use rand::{RngExt, SeedableRng};

use crate::error::SceneError;
use crate::face::Face;
use crate::scene::Scene;
use crate::triangulate::{Triangulation, refine, triangulate};
use crate::vec3::{V2, orient2};

/// Largest mesh [`Scene::to_mesh`] agrees to make.
pub const MAX_MESH_TRIANGLES: usize = 50_000_000;

/// A triangle mesh with one plane label per triangle: `(vertices, triangles, labels)`.
pub type LabelledMesh = (Vec<[f64; 3]>, Vec<[u32; 3]>, Vec<i32>);

/// Points sampled on a scene's faces, with the label of the face each came from.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct PointSample {
    /// Points in metres (world frame).
    pub points: Vec<[f64; 3]>,
    /// Plane label of each point.
    pub labels: Vec<i32>,
}

fn triangulate_face(index: usize, face: &Face) -> Result<Triangulation, SceneError> {
    triangulate(face.rings_2d()).map_err(|remaining| SceneError::TriangulationFailed {
        face: index,
        remaining,
    })
}

impl Scene {
    /// The scene as a triangle mesh with a plane label per triangle.
    ///
    /// Each face is triangulated on its own (ear clipping, holes bridged to the outer ring),
    /// then split by conforming longest-edge bisection until no edge is longer than
    /// `max_edge` metres (`f64::INFINITY`: no splitting). Within a face the mesh has no
    /// T-junctions, so its triangles are edge-connected; faces do not share vertices.
    /// Triangles are counter-clockwise seen from the face's front side (their normals are
    /// the face normals: outward for solids, up for floors, into the room for walls), and
    /// their areas add up to the face areas.
    ///
    /// # Errors
    /// `max_edge` not `> 0` (NaN included), a mesh that would exceed
    /// [`MAX_MESH_TRIANGLES`], or a numerically degenerate face.
    pub fn to_mesh(&self, max_edge: f64) -> Result<LabelledMesh, SceneError> {
        if max_edge.is_nan() || max_edge <= 0.0 {
            return Err(SceneError::InvalidParameter {
                name: "max_edge",
                value: max_edge,
                reason: "must be > 0 (f64::INFINITY for no splitting)",
            });
        }
        // Rough guard against huge meshes: refined triangles have their longest edge
        // above max_edge / 2 and bounded angles, so they average more area than this.
        let total_area: f64 = self.faces().iter().map(Face::area).sum();
        let estimate = total_area / (0.433 * 0.25 * max_edge * max_edge);
        if estimate > MAX_MESH_TRIANGLES as f64 {
            return Err(SceneError::InvalidParameter {
                name: "max_edge",
                value: max_edge,
                reason: "too small for this scene: the mesh would exceed MAX_MESH_TRIANGLES",
            });
        }
        let mut vertices = Vec::new();
        let mut triangles = Vec::new();
        let mut labels = Vec::new();
        for (i, face) in self.faces().iter().enumerate() {
            let mut t = triangulate_face(i, face)?;
            refine(&mut t, max_edge);
            let base = vertices.len() as u32;
            let frame = face.frame();
            vertices.extend(t.points.iter().map(|&q| frame.to_3d(q)));
            triangles.extend(t.triangles.iter().map(|tri| tri.map(|v| v + base)));
            labels.extend(std::iter::repeat_n(face.label(), t.triangles.len()));
        }
        Ok((vertices, triangles, labels))
    }

    /// `count` points drawn uniformly by area over the faces whose label is in `labels`
    /// (all faces when `labels` is `None`), deterministic by `seed`. For unorganized
    /// (2.5D) tests.
    ///
    /// # Errors
    /// A label in `labels` that no face has, or a numerically degenerate face.
    pub fn sample_uniform(
        &self,
        labels: Option<&[i32]>,
        count: usize,
        seed: u64,
    ) -> Result<PointSample, SceneError> {
        if let Some(ls) = labels
            && let Some(&label) = ls
                .iter()
                .find(|&&l| !self.faces().iter().any(|f| f.label() == l))
        {
            return Err(SceneError::UnknownLabel { label });
        }
        // Every triangle of every chosen face, with its cumulative area.
        let mut tris: Vec<([V2; 3], usize)> = Vec::new();
        let mut cumulative = Vec::new();
        let mut total = 0.0;
        for (i, face) in self.faces().iter().enumerate() {
            if labels.is_some_and(|ls| !ls.contains(&face.label())) {
                continue;
            }
            let t = triangulate_face(i, face)?;
            for tri in &t.triangles {
                let p = tri.map(|v| t.points[v as usize]);
                total += 0.5 * orient2(p[0], p[1], p[2]);
                tris.push((p, i));
                cumulative.push(total);
            }
        }
        let mut out = PointSample {
            points: Vec::with_capacity(count),
            labels: Vec::with_capacity(count),
        };
        if tris.is_empty() {
            return Ok(out);
        }
        let mut rng = Xoshiro256PlusPlus::seed_from_u64(seed);
        for _ in 0..count {
            let x = rng.random::<f64>() * total;
            let k = cumulative.partition_point(|&c| c <= x).min(tris.len() - 1);
            let (p, fi) = tris[k];
            let (mut a, mut b) = (rng.random::<f64>(), rng.random::<f64>());
            if a + b > 1.0 {
                (a, b) = (1.0 - a, 1.0 - b);
            }
            let q = [
                p[0][0] + a * (p[1][0] - p[0][0]) + b * (p[2][0] - p[0][0]),
                p[0][1] + a * (p[1][1] - p[0][1]) + b * (p[2][1] - p[0][1]),
            ];
            let face = &self.faces()[fi];
            out.points.push(face.frame().to_3d(q));
            out.labels.push(face.label());
        }
        Ok(out)
    }
}

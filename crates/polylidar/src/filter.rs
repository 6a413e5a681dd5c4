//! Triangle filtering: α (circumradius), `lmax` (longest edge) and, for 2.5D, the angle to
//! the up direction.

use halfedge_mesh::HalfEdgeMesh;
use rayon::prelude::*;

/// Triangles per parallel work item.
const CHUNK: usize = 8192;

/// How many triangles each test removed (a triangle is counted under the first test it
/// fails, in the order normal, `lmax`, α).
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub(crate) struct Dropped {
    pub normal: usize,
    pub lmax: usize,
    pub alpha: usize,
}

impl Dropped {
    fn add(self, other: Self) -> Self {
        Self {
            normal: self.normal + other.normal,
            lmax: self.lmax + other.lmax,
            alpha: self.alpha + other.alpha,
        }
    }
}

/// The tests to apply; a zero length or `None` disables a test.
#[derive(Debug, Clone, Copy)]
pub(crate) struct TriangleFilter {
    pub alpha: f64,
    pub lmax: f64,
    /// Unit up vector and minimum cosine between it and the triangle normal.
    pub normal: Option<([f64; 3], f64)>,
}

impl TriangleFilter {
    /// Marks the triangles that pass every test, in parallel.
    pub fn apply(&self, mesh: &HalfEdgeMesh) -> (Vec<bool>, Dropped) {
        let vertices = mesh.vertices();
        let normals = mesh.triangle_normals().unwrap_or(&[]);
        let mut keep = vec![false; mesh.num_triangles()];
        let dropped = keep
            .par_chunks_mut(CHUNK)
            .zip(mesh.triangles().par_chunks(CHUNK))
            .enumerate()
            .map(|(chunk, (keep, triangles))| {
                let mut dropped = Dropped::default();
                for (i, (k, tri)) in keep.iter_mut().zip(triangles).enumerate() {
                    let t = chunk * CHUNK + i;
                    match self.test(vertices, normals.get(t), *tri) {
                        Verdict::Keep => *k = true,
                        Verdict::Normal => dropped.normal += 1,
                        Verdict::Lmax => dropped.lmax += 1,
                        Verdict::Alpha => dropped.alpha += 1,
                    }
                }
                dropped
            })
            .reduce(Dropped::default, Dropped::add);
        (keep, dropped)
    }

    #[inline]
    fn test(&self, vertices: &[[f64; 3]], normal: Option<&[f64; 3]>, tri: [u32; 3]) -> Verdict {
        if let (Some((up, min_cos)), Some(n)) = (self.normal, normal)
            && n[0] * up[0] + n[1] * up[1] + n[2] * up[2] < min_cos
        {
            return Verdict::Normal;
        }
        if self.lmax <= 0.0 && self.alpha <= 0.0 {
            return Verdict::Keep;
        }
        let [a, b, c] = tri.map(|v| vertices[v as usize]);
        let d2 = |p: [f64; 3], q: [f64; 3]| {
            (p[0] - q[0]) * (p[0] - q[0])
                + (p[1] - q[1]) * (p[1] - q[1])
                + (p[2] - q[2]) * (p[2] - q[2])
        };
        let (ab, bc, ca) = (d2(a, b), d2(b, c), d2(c, a));
        if self.lmax > 0.0 && ab.max(bc).max(ca) > self.lmax * self.lmax {
            return Verdict::Lmax;
        }
        if self.alpha > 0.0 {
            // R = |ab| |bc| |ca| / (4 area) and |cross| = 2 area, so R² = ab·bc·ca / (4 |cross|²).
            let n = halfedge_mesh::cross_normal(a, b, c);
            let cross2 = n[0] * n[0] + n[1] * n[1] + n[2] * n[2];
            if ab * bc * ca > 4.0 * self.alpha * self.alpha * cross2 {
                return Verdict::Alpha;
            }
        }
        Verdict::Keep
    }
}

enum Verdict {
    Keep,
    Normal,
    Lmax,
    Alpha,
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn circumradius_and_edge_tests_match_the_formulas() {
        // Right triangle with legs 3, 4: hypotenuse 5, circumradius 2.5.
        let mesh = HalfEdgeMesh::from_triangles(
            vec![[0.0, 0.0, 0.0], [3.0, 0.0, 0.0], [0.0, 4.0, 0.0]],
            vec![[0, 1, 2]],
        )
        .unwrap();
        let run = |alpha, lmax| {
            TriangleFilter {
                alpha,
                lmax,
                normal: None,
            }
            .apply(&mesh)
        };
        assert_eq!(run(2.6, 0.0).0, [true]);
        assert_eq!(run(2.4, 0.0).1.alpha, 1);
        assert_eq!(run(0.0, 5.1).0, [true]);
        assert_eq!(run(0.0, 4.9).1.lmax, 1);
        let tilted = TriangleFilter {
            alpha: 0.0,
            lmax: 0.0,
            normal: Some(([0.0, 0.6, 0.8], 0.9)),
        };
        assert_eq!(tilted.apply(&mesh).1.normal, 1);
    }
}

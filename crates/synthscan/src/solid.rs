//! Convex solids (boxes, wedges, prisms) as closed sets of outward-facing polygons.

use crate::error::{SceneError, positive};
use crate::vec3::{V3, add, cross, normalize};

/// A closed convex solid: vertices in metres and faces as vertex loops, each
/// counter-clockwise seen from outside (so face normals point outward).
///
/// Solids are made at the origin with their base on `z = 0`, then rotated and
/// translated. Add one to a scene with [`Scene::add_solid`](crate::Scene::add_solid).
#[derive(Debug, Clone, PartialEq)]
pub struct Solid {
    vertices: Vec<V3>,
    faces: Vec<Vec<u32>>,
}

impl Solid {
    /// An axis-aligned box of size `[sx, sy, sz]` (metres), centred on the z axis, base on
    /// `z = 0`.
    ///
    /// # Errors
    /// A size that is not finite and `> 0`.
    pub fn cuboid(size: [f64; 3]) -> Result<Self, SceneError> {
        let hx = positive("size.x", size[0])? / 2.0;
        let hy = positive("size.y", size[1])? / 2.0;
        let sz = positive("size.z", size[2])?;
        let base = vec![[-hx, -hy], [hx, -hy], [hx, hy], [-hx, hy]];
        Ok(Self::extrude(&base, sz))
    }

    /// A wedge (ramp): a right-triangular prism `sx` long along x, `sy` wide along y, rising
    /// from height 0 at `x = -sx/2` to `sz` at `x = +sx/2`; base on `z = 0`, centred on the
    /// z axis. Its sloped face makes `atan(sz / sx)` with the floor.
    ///
    /// # Errors
    /// A size that is not finite and `> 0`.
    pub fn wedge(size: [f64; 3]) -> Result<Self, SceneError> {
        let hx = positive("size.x", size[0])? / 2.0;
        let hy = positive("size.y", size[1])? / 2.0;
        let sz = positive("size.z", size[2])?;
        let vertices = vec![
            [-hx, -hy, 0.0],
            [hx, -hy, 0.0],
            [hx, hy, 0.0],
            [-hx, hy, 0.0],
            [hx, -hy, sz],
            [hx, hy, sz],
        ];
        let faces = vec![
            vec![0, 3, 2, 1], // bottom
            vec![1, 2, 5, 4], // back (x = +hx)
            vec![0, 1, 4],    // side y = -hy
            vec![3, 5, 2],    // side y = +hy
            vec![0, 4, 5, 3], // slope
        ];
        Ok(Self { vertices, faces })
    }

    /// A right prism over a regular polygon with `sides` sides (`>= 3`) inscribed in a circle
    /// of radius `radius`, `height` tall; base on `z = 0`, axis on the z axis.
    ///
    /// # Errors
    /// Fewer than three sides, or a radius or height that is not finite and `> 0`.
    pub fn prism(sides: usize, radius: f64, height: f64) -> Result<Self, SceneError> {
        if sides < 3 {
            return Err(SceneError::InvalidParameter {
                name: "sides",
                value: sides as f64,
                reason: "a prism needs at least 3 sides",
            });
        }
        let r = positive("radius", radius)?;
        let h = positive("height", height)?;
        let base: Vec<[f64; 2]> = (0..sides)
            .map(|i| {
                let a = std::f64::consts::TAU * i as f64 / sides as f64;
                [r * a.cos(), r * a.sin()]
            })
            .collect();
        Ok(Self::extrude(&base, h))
    }

    /// Extrudes a counter-clockwise convex base polygon from `z = 0` to `z = h`.
    fn extrude(base: &[[f64; 2]], h: f64) -> Self {
        let n = base.len() as u32;
        let mut vertices: Vec<V3> = base.iter().map(|p| [p[0], p[1], 0.0]).collect();
        vertices.extend(base.iter().map(|p| [p[0], p[1], h]));
        let mut faces = vec![(0..n).rev().collect::<Vec<u32>>(), (n..2 * n).collect()];
        for i in 0..n {
            let j = (i + 1) % n;
            faces.push(vec![i, j, n + j, n + i]);
        }
        Self { vertices, faces }
    }

    /// Rotates by `degrees` about the world x axis through the origin (right-hand rule).
    pub fn rotated_x(self, degrees: f64) -> Self {
        let (s, c) = degrees.to_radians().sin_cos();
        self.map(|p| [p[0], c * p[1] - s * p[2], s * p[1] + c * p[2]])
    }

    /// Rotates by `degrees` about the world y axis through the origin (right-hand rule).
    pub fn rotated_y(self, degrees: f64) -> Self {
        let (s, c) = degrees.to_radians().sin_cos();
        self.map(|p| [c * p[0] + s * p[2], p[1], -s * p[0] + c * p[2]])
    }

    /// Rotates by `degrees` about the world z axis through the origin (right-hand rule).
    pub fn rotated_z(self, degrees: f64) -> Self {
        let (s, c) = degrees.to_radians().sin_cos();
        self.map(|p| [c * p[0] - s * p[1], s * p[0] + c * p[1], p[2]])
    }

    /// Translates by `t` (metres).
    pub fn translated(self, t: [f64; 3]) -> Self {
        self.map(|p| add(p, t))
    }

    fn map(mut self, f: impl Fn(V3) -> V3) -> Self {
        for p in &mut self.vertices {
            *p = f(*p);
        }
        self
    }

    /// Vertices in metres.
    pub fn vertices(&self) -> &[[f64; 3]] {
        &self.vertices
    }

    /// Faces as loops of vertex indices, counter-clockwise seen from outside.
    pub fn faces(&self) -> &[Vec<u32>] {
        &self.faces
    }

    /// The face rings in 3D, counter-clockwise seen from outside.
    pub fn face_rings(&self) -> impl Iterator<Item = Vec<[f64; 3]>> + '_ {
        self.faces
            .iter()
            .map(|f| f.iter().map(|&i| self.vertices[i as usize]).collect())
    }

    /// Lowest and highest z of the vertices (metres).
    pub fn z_range(&self) -> (f64, f64) {
        self.vertices
            .iter()
            .fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), p| {
                (lo.min(p[2]), hi.max(p[2]))
            })
    }

    /// Index of the face that faces straight down at the solid's lowest z, if any: the face
    /// that rests on a floor.
    pub fn bottom_face(&self) -> Option<usize> {
        let (zmin, zmax) = self.z_range();
        let tol = 1e-9 * (1.0 + (zmax - zmin).abs());
        self.face_rings().position(|ring| {
            let n = ring_normal(&ring);
            n.is_some_and(|n| n[2] < -1.0 + 1e-9) && ring.iter().all(|p| (p[2] - zmin).abs() <= tol)
        })
    }

    /// The bottom face's ring, counter-clockwise seen from above: the solid's footprint on
    /// the floor when it rests there.
    pub fn footprint(&self) -> Option<Vec<[f64; 3]>> {
        let f = self.bottom_face()?;
        let mut ring: Vec<V3> = self.faces[f]
            .iter()
            .map(|&i| self.vertices[i as usize])
            .collect();
        ring.reverse();
        Some(ring)
    }

    /// Horizontal bounding circle `(centre x, centre y, radius)` of the vertices (metres).
    pub(crate) fn bounding_circle_xy(&self) -> (f64, f64, f64) {
        let n = self.vertices.len() as f64;
        let cx = self.vertices.iter().map(|p| p[0]).sum::<f64>() / n;
        let cy = self.vertices.iter().map(|p| p[1]).sum::<f64>() / n;
        let r = self
            .vertices
            .iter()
            .map(|p| ((p[0] - cx).powi(2) + (p[1] - cy).powi(2)).sqrt())
            .fold(0.0, f64::max);
        (cx, cy, r)
    }
}

fn ring_normal(ring: &[V3]) -> Option<V3> {
    let mut n = [0.0; 3];
    for i in 0..ring.len() {
        n = add(n, cross(ring[i], ring[(i + 1) % ring.len()]));
    }
    normalize(n)
}

/// Checks that every face of `s` points away from its centroid (tests and debug builds).
#[cfg(test)]
pub(crate) fn faces_point_outward(s: &Solid) -> bool {
    use crate::vec3::{dot, sub};
    let c = s
        .vertices
        .iter()
        .fold([0.0; 3], |a, p| add(a, *p))
        .map(|x| x / s.vertices.len() as f64);
    s.face_rings()
        .all(|ring| ring_normal(&ring).is_some_and(|n| dot(n, sub(ring[0], c)) > 0.0))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn solids_have_outward_faces_after_rotation() -> Result<(), SceneError> {
        for s in [
            Solid::cuboid([1.0, 2.0, 3.0])?,
            Solid::wedge([2.0, 1.0, 0.5])?,
            Solid::prism(5, 0.4, 1.0)?,
        ] {
            assert!(faces_point_outward(&s));
            let r = s.rotated_x(20.0).rotated_y(-35.0).rotated_z(80.0);
            assert!(faces_point_outward(&r));
        }
        Ok(())
    }

    #[test]
    fn footprint_is_ccw_from_above() -> Result<(), SceneError> {
        let s = Solid::cuboid([1.0, 1.0, 1.0])?.translated([2.0, 0.0, 0.0]);
        let fp = s.footprint().ok_or(SceneError::Degenerate)?;
        let n = ring_normal(&fp).ok_or(SceneError::Degenerate)?;
        assert!(n[2] > 0.999);
        assert!(s.rotated_x(10.0).footprint().is_none());
        Ok(())
    }

    #[test]
    fn bad_sizes_are_rejected() {
        assert!(Solid::cuboid([1.0, -1.0, 1.0]).is_err());
        assert!(Solid::wedge([1.0, 1.0, f64::NAN]).is_err());
        assert!(Solid::prism(2, 1.0, 1.0).is_err());
    }
}

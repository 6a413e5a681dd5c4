//! A scene: labelled planar faces, and its ground truth.

use crate::error::SceneError;
use crate::face::Face;
use crate::solid::Solid;
use plane_geom::Polygon3;

/// A set of labelled planar faces in a right-handed world frame (metres).
///
/// Builders ([`Scene::room`], [`Scene::stairs`], [`Scene::ramps`],
/// [`Scene::random_polyhedra`]) use z up with the floor on `z = 0`. Faces with the same label
/// lie on one plane and face the same way; every other face has its own label.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct Scene {
    faces: Vec<Face>,
}

/// The ground truth for one plane label: the plane and the polygons on it.
#[derive(Debug, Clone, PartialEq)]
pub struct GroundTruthPlane {
    /// Plane label (`>= 0`), as in [`ScanResult::labels`](crate::ScanResult::labels).
    pub label: i32,
    /// Unit normal, pointing to the side the face is seen from.
    pub normal: [f64; 3],
    /// Offset `d` in metres: points `p` on the plane satisfy `normal · p = d`.
    pub offset: f64,
    /// The faces with this label (outer rings counter-clockwise seen from the front).
    pub polygons: Vec<Polygon3>,
}

impl Scene {
    /// An empty scene.
    pub fn new() -> Self {
        Self::default()
    }

    /// The faces, in the order they were added.
    pub fn faces(&self) -> &[Face] {
        &self.faces
    }

    /// One more than the largest label in use (0 for an empty scene).
    pub fn next_label(&self) -> i32 {
        self.faces.iter().map(|f| f.label() + 1).max().unwrap_or(0)
    }

    /// Adds a face and returns its index.
    ///
    /// # Errors
    /// [`SceneError::LabelPlaneMismatch`] when a face with the same label lies on another
    /// plane (normals must agree to `1e-9`, offsets to `1e-9 · (1 + |d|)` metres).
    pub fn add_face(&mut self, face: Face) -> Result<usize, SceneError> {
        if let Some(first) = self.faces.iter().find(|f| f.label() == face.label()) {
            let normal_dot = crate::vec3::dot(first.normal(), face.normal());
            let offset_diff = (first.offset() - face.offset()).abs();
            if normal_dot < 1.0 - 1e-9 || offset_diff > 1e-9 * (1.0 + first.offset().abs()) {
                return Err(SceneError::LabelPlaneMismatch {
                    face: self.faces.len(),
                    label: face.label(),
                    normal_dot,
                    offset_diff,
                });
            }
        }
        self.faces.push(face);
        Ok(self.faces.len() - 1)
    }

    /// Validates `polygon` as a face with `label` and adds it; returns its index.
    ///
    /// # Errors
    /// As [`Face::new`] and [`Scene::add_face`].
    pub fn add_polygon(&mut self, label: i32, polygon: Polygon3) -> Result<usize, SceneError> {
        self.add_face(Face::new(label, polygon)?)
    }

    /// Adds every face of `solid`, each with a new label, and returns the labels in the
    /// solid's face order. With `resting_on_floor`, the face that points straight down at
    /// the solid's lowest z (see [`Solid::bottom_face`]) is left out, as a floor hides it.
    ///
    /// # Errors
    /// As [`Face::new`] (only for numerically degenerate solids).
    pub fn add_solid(
        &mut self,
        solid: &Solid,
        resting_on_floor: bool,
    ) -> Result<Vec<i32>, SceneError> {
        let skip = if resting_on_floor {
            solid.bottom_face()
        } else {
            None
        };
        let mut labels = Vec::with_capacity(solid.faces().len());
        for (i, ring) in solid.face_rings().enumerate() {
            if Some(i) == skip {
                continue;
            }
            let label = self.next_label();
            self.add_polygon(label, Polygon3::from_shell(ring))?;
            labels.push(label);
        }
        Ok(labels)
    }

    /// The ground-truth planes, sorted by label.
    pub fn ground_truth(&self) -> Vec<GroundTruthPlane> {
        let mut planes: Vec<GroundTruthPlane> = Vec::new();
        let mut order: Vec<usize> = (0..self.faces.len()).collect();
        order.sort_by_key(|&i| (self.faces[i].label(), i));
        for i in order {
            let f = &self.faces[i];
            match planes.last_mut() {
                Some(p) if p.label == f.label() => p.polygons.push(f.polygon().clone()),
                _ => planes.push(GroundTruthPlane {
                    label: f.label(),
                    normal: f.normal(),
                    offset: f.offset(),
                    polygons: vec![f.polygon().clone()],
                }),
            }
        }
        planes
    }

    /// Total face area per label, sorted by label: `(label, m²)`.
    pub fn label_areas(&self) -> Vec<(i32, f64)> {
        let mut out: Vec<(i32, f64)> = Vec::new();
        for p in self.ground_truth() {
            let a = self
                .faces
                .iter()
                .filter(|f| f.label() == p.label)
                .map(Face::area)
                .sum();
            out.push((p.label, a));
        }
        out
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn shared_labels_must_be_coplanar() -> Result<(), SceneError> {
        let mut s = Scene::new();
        let a = vec![
            [0.0, 0.0, 0.0],
            [1.0, 0.0, 0.0],
            [1.0, 1.0, 0.0],
            [0.0, 1.0, 0.0],
        ];
        let b: Vec<[f64; 3]> = a.iter().map(|p| [p[0] + 2.0, p[1], p[2]]).collect();
        let c: Vec<[f64; 3]> = a.iter().map(|p| [p[0], p[1], p[2] + 0.5]).collect();
        s.add_polygon(0, Polygon3::from_shell(a))?;
        s.add_polygon(0, Polygon3::from_shell(b))?;
        assert!(matches!(
            s.add_polygon(0, Polygon3::from_shell(c.clone())),
            Err(SceneError::LabelPlaneMismatch {
                face: 2,
                label: 0,
                ..
            })
        ));
        s.add_polygon(1, Polygon3::from_shell(c))?;
        let gt = s.ground_truth();
        assert_eq!(gt.len(), 2);
        assert_eq!(gt[0].polygons.len(), 2);
        assert_eq!(s.label_areas(), vec![(0, 2.0), (1, 1.0)]);
        Ok(())
    }

    #[test]
    fn resting_solid_skips_bottom() -> Result<(), SceneError> {
        let mut s = Scene::new();
        let labels = s.add_solid(&Solid::cuboid([1.0, 1.0, 1.0])?, true)?;
        assert_eq!(labels, vec![0, 1, 2, 3, 4]);
        assert!(s.faces().iter().all(|f| f.normal()[2] > -0.5));
        Ok(())
    }
}

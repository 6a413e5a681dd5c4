//! 3D polygons (shell + holes as coordinates) and their measures.

use crate::vec3::{add, cross, norm, sub};

/// A polygon with holes in 3D: rings of points, each ring **open** (the first point is not
/// repeated at the end).
///
/// As input, a repeated closing point is tolerated and ignored. Polygons returned by
/// post-processing lie exactly on their plane (up to rounding), have a shell that runs
/// counter-clockwise seen from the side the plane normal points to, and clockwise holes.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct Polygon3 {
    /// Outer ring.
    pub shell: Vec<[f64; 3]>,
    /// Inner rings (holes).
    pub holes: Vec<Vec<[f64; 3]>>,
}

/// Measures of a [`Polygon3`].
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PolygonMetrics {
    /// Area of the shell minus the areas of the holes, in m². Computed with Newell's
    /// vector area, exact for planar rings; for a non-planar ring it is the area of its
    /// projection on its best-fitting plane direction.
    pub area: f64,
    /// Total length of all rings (shell and holes), in metres.
    pub perimeter: f64,
    /// Number of vertices over all rings.
    pub vertex_count: usize,
    /// Number of holes.
    pub hole_count: usize,
    /// Smallest x, y, z over the shell, in metres.
    pub bbox_min: [f64; 3],
    /// Largest x, y, z over the shell, in metres.
    pub bbox_max: [f64; 3],
}

impl Polygon3 {
    /// A polygon from a shell and holes.
    pub fn new(shell: Vec<[f64; 3]>, holes: Vec<Vec<[f64; 3]>>) -> Self {
        Self { shell, holes }
    }

    /// A polygon without holes.
    pub fn from_shell(shell: Vec<[f64; 3]>) -> Self {
        Self::new(shell, Vec::new())
    }

    /// The same polygon with one more hole.
    #[must_use]
    pub fn with_hole(mut self, hole: Vec<[f64; 3]>) -> Self {
        self.holes.push(hole);
        self
    }

    /// Area, perimeter, vertex count and bounding box. An empty shell gives zero area and
    /// perimeter and an infinite-inverted box (`min = +inf`, `max = -inf`).
    pub fn metrics(&self) -> PolygonMetrics {
        let mut bbox_min = [f64::INFINITY; 3];
        let mut bbox_max = [f64::NEG_INFINITY; 3];
        for p in &self.shell {
            for k in 0..3 {
                bbox_min[k] = bbox_min[k].min(p[k]);
                bbox_max[k] = bbox_max[k].max(p[k]);
            }
        }
        let holes_area: f64 = self.holes.iter().map(|h| ring_area(h)).sum();
        let perimeter =
            ring_length(&self.shell) + self.holes.iter().map(|h| ring_length(h)).sum::<f64>();
        PolygonMetrics {
            area: ring_area(&self.shell) - holes_area,
            perimeter,
            vertex_count: open_len(&self.shell)
                + self.holes.iter().map(|h| open_len(h)).sum::<usize>(),
            hole_count: self.holes.len(),
            bbox_min,
            bbox_max,
        }
    }
}

/// Number of distinct ring vertices (a repeated closing point not counted).
fn open_len(ring: &[[f64; 3]]) -> usize {
    match (ring.first(), ring.last()) {
        (Some(a), Some(b)) if ring.len() > 1 && a == b => ring.len() - 1,
        _ => ring.len(),
    }
}

/// Unsigned area of a 3D ring by Newell's method (vector area around the first point).
pub fn ring_area(ring: &[[f64; 3]]) -> f64 {
    let Some(&o) = ring.first() else {
        return 0.0;
    };
    let mut acc = [0.0; 3];
    for w in ring.windows(2) {
        acc = add(acc, cross(sub(w[0], o), sub(w[1], o)));
    }
    0.5 * norm(acc)
}

/// Length of a closed 3D ring (the closing edge included once).
pub fn ring_length(ring: &[[f64; 3]]) -> f64 {
    let n = open_len(ring);
    (0..n).map(|i| norm(sub(ring[(i + 1) % n], ring[i]))).sum()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn square_with_hole_metrics() {
        // A 2 × 2 square in the plane x = 1 with a 1 × 0.5 hole, closing point repeated.
        let shell = vec![
            [1.0, 0.0, 0.0],
            [1.0, 2.0, 0.0],
            [1.0, 2.0, 2.0],
            [1.0, 0.0, 2.0],
            [1.0, 0.0, 0.0],
        ];
        let hole = vec![
            [1.0, 0.5, 0.5],
            [1.0, 0.5, 1.0],
            [1.0, 1.5, 1.0],
            [1.0, 1.5, 0.5],
        ];
        let p = Polygon3::new(shell, vec![hole]);
        let m = p.metrics();
        assert!((m.area - 3.5).abs() < 1e-12);
        assert!((m.perimeter - 11.0).abs() < 1e-12);
        assert_eq!(m.vertex_count, 8);
        assert_eq!(m.hole_count, 1);
        assert_eq!(m.bbox_min, [1.0, 0.0, 0.0]);
        assert_eq!(m.bbox_max, [1.0, 2.0, 2.0]);
    }

    #[test]
    fn empty_polygon() {
        let m = Polygon3::default().metrics();
        assert_eq!(m.area, 0.0);
        assert_eq!(m.perimeter, 0.0);
        assert_eq!(m.vertex_count, 0);
    }
}

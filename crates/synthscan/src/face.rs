//! Planar polygons with holes and their ground-truth plane label.

use plane_geom::Polygon3;

use crate::error::SceneError;
use crate::vec3::{V2, V3, add, cross, dot, norm, normalize, orient2, ring_area, scale, sub};

/// A face of a scene: a validated planar polygon (convex or not, possibly with holes) and
/// the label of the ground-truth plane it lies on.
///
/// After [`Face::new`], the stored polygon has repeated and collinear vertices removed, the
/// outer ring counter-clockwise and the holes clockwise seen from the front side, and
/// [`Face::normal`] points to the front side.
#[derive(Debug, Clone, PartialEq)]
pub struct Face {
    label: i32,
    polygon: Polygon3,
    normal: V3,
    offset: f64,
    origin: V3,
    u: V3,
    v: V3,
    rings: Vec<Vec<V2>>,
    /// 2D bounding box `[xmin, xmax, ymin, ymax]` of each ring.
    ring_boxes: Vec<[f64; 4]>,
    area: f64,
    bbox_min: V3,
    bbox_max: V3,
}

impl Face {
    /// Validates `polygon` and makes a face with plane label `label` (`>= 0`).
    ///
    /// # Errors
    /// Negative label, non-finite coordinates, fewer than three usable vertices in a ring,
    /// a degenerate outer ring, vertices off the plane by more than `1e-9 · (1 + extent)`
    /// metres, rings that intersect or touch, or holes outside the outer ring.
    pub fn new(label: i32, polygon: Polygon3) -> Result<Self, SceneError> {
        if label < 0 {
            return Err(SceneError::NegativeLabel { label });
        }
        let rings3: Vec<&[V3]> = std::iter::once(polygon.shell.as_slice())
            .chain(polygon.holes.iter().map(Vec::as_slice))
            .collect();
        for (ring, pts) in rings3.iter().enumerate() {
            if let Some(vertex) = pts.iter().position(|p| p.iter().any(|c| !c.is_finite())) {
                return Err(SceneError::NonFinite { ring, vertex });
            }
        }
        if polygon.shell.len() < 3 {
            return Err(SceneError::TooFewVertices {
                ring: 0,
                count: polygon.shell.len(),
            });
        }
        let normal = normalize(newell(&polygon.shell)).ok_or(SceneError::Degenerate)?;
        let origin = polygon.shell[0];
        let u = polygon
            .shell
            .iter()
            .find_map(|p| {
                let d = sub(*p, origin);
                normalize(sub(d, scale(normal, dot(d, normal))))
            })
            .ok_or(SceneError::Degenerate)?;
        let v = cross(normal, u);

        let (bbox_min, bbox_max) = bbox(&polygon.shell);
        let extent = norm(sub(bbox_max, bbox_min));
        let tolerance = 1e-9 * (1.0 + extent);
        let offset =
            polygon.shell.iter().map(|p| dot(normal, *p)).sum::<f64>() / polygon.shell.len() as f64;
        for (ring, pts) in rings3.iter().enumerate() {
            for (vertex, p) in pts.iter().enumerate() {
                let distance = (dot(normal, *p) - offset).abs();
                if distance > tolerance {
                    return Err(SceneError::NonPlanar {
                        ring,
                        vertex,
                        distance,
                        tolerance,
                    });
                }
            }
        }

        let frame = Frame { origin, u, v };
        let mut rings = Vec::with_capacity(rings3.len());
        let mut clean3 = Vec::with_capacity(rings3.len());
        for (ring, pts) in rings3.iter().enumerate() {
            let mut r2: Vec<V2> = pts.iter().map(|p| frame.to_2d(*p)).collect();
            let mut r3: Vec<V3> = pts.to_vec();
            clean_ring(&mut r2, &mut r3, extent);
            if r2.len() < 3 {
                return Err(SceneError::TooFewVertices {
                    ring,
                    count: r2.len(),
                });
            }
            let a = ring_area(&r2);
            let reverse = if ring == 0 { a < 0.0 } else { a > 0.0 };
            if ring == 0 && a == 0.0 {
                return Err(SceneError::Degenerate);
            }
            if reverse {
                r2.reverse();
                r3.reverse();
            }
            rings.push(r2);
            clean3.push(r3);
        }
        check_intersections(&rings)?;
        for (h, hole) in rings.iter().enumerate().skip(1) {
            let p = hole[0];
            let outside = !point_in_ring(&rings[0], p);
            let nested = rings
                .iter()
                .enumerate()
                .skip(1)
                .any(|(o, other)| o != h && point_in_ring(other, p));
            if outside || nested {
                return Err(SceneError::HoleOutside { hole: h - 1 });
            }
        }
        let area = rings.iter().map(|r| ring_area(r)).sum();
        let ring_boxes = rings
            .iter()
            .map(|r| {
                r.iter().fold(
                    [
                        f64::INFINITY,
                        f64::NEG_INFINITY,
                        f64::INFINITY,
                        f64::NEG_INFINITY,
                    ],
                    |b, p| {
                        [
                            b[0].min(p[0]),
                            b[1].max(p[0]),
                            b[2].min(p[1]),
                            b[3].max(p[1]),
                        ]
                    },
                )
            })
            .collect();
        let mut clean3 = clean3.into_iter();
        let shell = clean3.next().unwrap_or_default();
        let polygon = Polygon3::new(shell, clean3.collect());
        Ok(Self {
            label,
            polygon,
            normal,
            offset,
            origin,
            u,
            v,
            rings,
            ring_boxes,
            area,
            bbox_min,
            bbox_max,
        })
    }

    /// Ground-truth plane label (`>= 0`).
    pub fn label(&self) -> i32 {
        self.label
    }

    /// The cleaned polygon (outer ring counter-clockwise, holes clockwise seen from the front).
    pub fn polygon(&self) -> &Polygon3 {
        &self.polygon
    }

    /// Unit normal, pointing to the front side.
    pub fn normal(&self) -> [f64; 3] {
        self.normal
    }

    /// Plane offset `d` in metres: points `p` of the plane satisfy `normal · p = d`.
    pub fn offset(&self) -> f64 {
        self.offset
    }

    /// Area in square metres (outer ring minus holes).
    pub fn area(&self) -> f64 {
        self.area
    }

    /// Axis-aligned bounding box `(min, max)` in metres.
    pub fn bounding_box(&self) -> ([f64; 3], [f64; 3]) {
        (self.bbox_min, self.bbox_max)
    }

    /// Signed distance of `p` from the face's plane, positive on the front side (metres).
    pub fn signed_distance(&self, p: [f64; 3]) -> f64 {
        dot(self.normal, p) - self.offset
    }

    pub(crate) fn frame(&self) -> Frame {
        Frame {
            origin: self.origin,
            u: self.u,
            v: self.v,
        }
    }

    /// 2D rings in the face frame: ring 0 outer (counter-clockwise), then holes (clockwise).
    pub(crate) fn rings_2d(&self) -> &[Vec<V2>] {
        &self.rings
    }

    pub(crate) fn bbox_contains(&self, p: V3, eps: f64) -> bool {
        (0..3).all(|k| p[k] >= self.bbox_min[k] - eps && p[k] <= self.bbox_max[k] + eps)
    }

    /// Whether a point given in the face frame is inside the outer ring and outside every
    /// hole (holes are disjoint and inside the outer ring, so this is the even-odd rule);
    /// ring bounding boxes skip most ring tests.
    pub(crate) fn contains_2d(&self, q: V2) -> bool {
        let in_box = |b: &[f64; 4]| q[0] >= b[0] && q[0] <= b[1] && q[1] >= b[2] && q[1] <= b[3];
        in_box(&self.ring_boxes[0])
            && point_in_ring(&self.rings[0], q)
            && !self
                .rings
                .iter()
                .zip(&self.ring_boxes)
                .skip(1)
                .any(|(r, b)| in_box(b) && point_in_ring(r, q))
    }
}

/// An orthonormal frame on a face's plane: `p = origin + x u + y v`.
#[derive(Debug, Clone, Copy)]
pub(crate) struct Frame {
    pub(crate) origin: V3,
    pub(crate) u: V3,
    pub(crate) v: V3,
}

impl Frame {
    #[inline]
    pub(crate) fn to_2d(self, p: V3) -> V2 {
        let d = sub(p, self.origin);
        [dot(d, self.u), dot(d, self.v)]
    }

    #[inline]
    pub(crate) fn to_3d(self, q: V2) -> V3 {
        add(add(self.origin, scale(self.u, q[0])), scale(self.v, q[1]))
    }
}

/// Newell's normal of a ring (length = twice the projected area).
fn newell(ring: &[V3]) -> V3 {
    let c = ring
        .iter()
        .fold([0.0; 3], |acc, p| add(acc, *p))
        .map(|x| x / ring.len() as f64);
    let mut n = [0.0; 3];
    for i in 0..ring.len() {
        let a = sub(ring[i], c);
        let b = sub(ring[(i + 1) % ring.len()], c);
        n = add(n, cross(a, b));
    }
    n
}

fn bbox(pts: &[V3]) -> (V3, V3) {
    let mut lo = [f64::INFINITY; 3];
    let mut hi = [f64::NEG_INFINITY; 3];
    for p in pts {
        for k in 0..3 {
            lo[k] = lo[k].min(p[k]);
            hi[k] = hi[k].max(p[k]);
        }
    }
    (lo, hi)
}

/// Drops repeated vertices and vertices collinear with their neighbours (including spikes).
fn clean_ring(r2: &mut Vec<V2>, r3: &mut Vec<V3>, extent: f64) {
    let len_eps = 1e-12 * (1.0 + extent);
    loop {
        let n = r2.len();
        if n < 3 {
            return;
        }
        let drop = (0..n).find(|&i| {
            let a = r2[(i + n - 1) % n];
            let b = r2[i];
            let c = r2[(i + 1) % n];
            let ab = ((b[0] - a[0]).powi(2) + (b[1] - a[1]).powi(2)).sqrt();
            let bc = ((c[0] - b[0]).powi(2) + (c[1] - b[1]).powi(2)).sqrt();
            ab <= len_eps || orient2(a, b, c).abs() <= 1e-12 * ab * bc
        });
        match drop {
            Some(i) => {
                r2.remove(i);
                r3.remove(i);
            }
            None => return,
        }
    }
}

/// Whether closed segments `ab` and `cd` share a point.
pub(crate) fn segments_intersect(a: V2, b: V2, c: V2, d: V2) -> bool {
    let d1 = orient2(c, d, a);
    let d2 = orient2(c, d, b);
    let d3 = orient2(a, b, c);
    let d4 = orient2(a, b, d);
    if ((d1 > 0.0 && d2 < 0.0) || (d1 < 0.0 && d2 > 0.0))
        && ((d3 > 0.0 && d4 < 0.0) || (d3 < 0.0 && d4 > 0.0))
    {
        return true;
    }
    let on = |p: V2, q: V2, r: V2| {
        r[0] >= p[0].min(q[0])
            && r[0] <= p[0].max(q[0])
            && r[1] >= p[1].min(q[1])
            && r[1] <= p[1].max(q[1])
    };
    (d1 == 0.0 && on(c, d, a))
        || (d2 == 0.0 && on(c, d, b))
        || (d3 == 0.0 && on(a, b, c))
        || (d4 == 0.0 && on(a, b, d))
}

fn check_intersections(rings: &[Vec<V2>]) -> Result<(), SceneError> {
    for (ra, ring_a) in rings.iter().enumerate() {
        let na = ring_a.len();
        for ea in 0..na {
            let (a0, a1) = (ring_a[ea], ring_a[(ea + 1) % na]);
            for (rb, ring_b) in rings.iter().enumerate().skip(ra) {
                let nb = ring_b.len();
                let start = if rb == ra { ea + 1 } else { 0 };
                for eb in start..nb {
                    // Adjacent edges of one ring share a vertex by construction.
                    if rb == ra && (eb == ea + 1 || (ea == 0 && eb == na - 1)) {
                        continue;
                    }
                    let (b0, b1) = (ring_b[eb], ring_b[(eb + 1) % nb]);
                    if segments_intersect(a0, a1, b0, b1) {
                        return Err(SceneError::RingsIntersect {
                            ring_a: ra,
                            edge_a: ea,
                            ring_b: rb,
                            edge_b: eb,
                        });
                    }
                }
            }
        }
    }
    Ok(())
}

/// Crossing-number test of `q` against one closed ring.
#[inline]
pub(crate) fn point_in_ring(ring: &[V2], q: V2) -> bool {
    let mut inside = false;
    let n = ring.len();
    let mut j = n - 1;
    for i in 0..n {
        let (a, b) = (ring[i], ring[j]);
        if (a[1] > q[1]) != (b[1] > q[1]) {
            let x = a[0] + (q[1] - a[1]) / (b[1] - a[1]) * (b[0] - a[0]);
            if q[0] < x {
                inside = !inside;
            }
        }
        j = i;
    }
    inside
}

#[cfg(test)]
mod tests {
    use super::*;

    fn square(z: f64, s: f64) -> Vec<V3> {
        vec![[0.0, 0.0, z], [s, 0.0, z], [s, s, z], [0.0, s, z]]
    }

    #[test]
    fn square_with_hole_area_and_orientation() -> Result<(), SceneError> {
        let hole = vec![
            [1.0, 1.0, 2.0],
            [2.0, 1.0, 2.0],
            [2.0, 2.0, 2.0],
            [1.0, 2.0, 2.0],
        ];
        let f = Face::new(3, Polygon3::from_shell(square(2.0, 4.0)).with_hole(hole))?;
        assert!((f.area() - 15.0).abs() < 1e-12);
        assert!((f.normal()[2] - 1.0).abs() < 1e-15);
        assert!((f.offset() - 2.0).abs() < 1e-15);
        assert!(ring_area(&f.rings_2d()[1]) < 0.0);
        assert!(f.contains_2d(f.frame().to_2d([0.5, 0.5, 2.0])));
        assert!(!f.contains_2d(f.frame().to_2d([1.5, 1.5, 2.0])));
        Ok(())
    }

    #[test]
    fn reversed_outer_flips_normal() -> Result<(), SceneError> {
        let mut r = square(0.0, 1.0);
        r.reverse();
        let f = Face::new(0, Polygon3::from_shell(r))?;
        assert!((f.normal()[2] + 1.0).abs() < 1e-15);
        Ok(())
    }

    #[test]
    fn collinear_and_repeated_vertices_are_dropped() -> Result<(), SceneError> {
        let r = vec![
            [0.0, 0.0, 0.0],
            [0.5, 0.0, 0.0],
            [1.0, 0.0, 0.0],
            [1.0, 0.0, 0.0],
            [1.0, 1.0, 0.0],
            [0.0, 1.0, 0.0],
        ];
        let f = Face::new(0, Polygon3::from_shell(r))?;
        assert_eq!(f.polygon().shell.len(), 4);
        Ok(())
    }

    #[test]
    fn bad_polygons_are_rejected() {
        let bowtie = vec![
            [0.0, 0.0, 0.0],
            [2.0, 0.0, 0.0],
            [2.0, 2.0, 0.0],
            [1.0, -1.0, 0.0],
            [0.0, 2.0, 0.0],
        ];
        assert!(matches!(
            Face::new(0, Polygon3::from_shell(bowtie)),
            Err(SceneError::RingsIntersect { .. })
        ));
        let bent = vec![
            [0.0, 0.0, 0.0],
            [1.0, 0.0, 0.0],
            [1.0, 1.0, 0.1],
            [0.0, 1.0, 0.0],
        ];
        assert!(matches!(
            Face::new(0, Polygon3::from_shell(bent)),
            Err(SceneError::NonPlanar { .. })
        ));
        let line = vec![[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [2.0, 0.0, 0.0]];
        assert!(Face::new(0, Polygon3::from_shell(line)).is_err());
        let nan = vec![[0.0, 0.0, 0.0], [f64::NAN, 0.0, 0.0], [0.0, 1.0, 0.0]];
        assert!(matches!(
            Face::new(0, Polygon3::from_shell(nan)),
            Err(SceneError::NonFinite { ring: 0, vertex: 1 })
        ));
        assert!(matches!(
            Face::new(-2, Polygon3::from_shell(square(0.0, 1.0))),
            Err(SceneError::NegativeLabel { label: -2 })
        ));
        let outside = Polygon3::from_shell(square(0.0, 1.0)).with_hole(vec![
            [2.0, 2.0, 0.0],
            [3.0, 2.0, 0.0],
            [3.0, 3.0, 0.0],
        ]);
        assert!(matches!(
            Face::new(0, outside),
            Err(SceneError::HoleOutside { hole: 0 })
        ));
        let touching = Polygon3::from_shell(square(0.0, 2.0)).with_hole(vec![
            [0.0, 0.5, 0.0],
            [1.0, 0.5, 0.0],
            [1.0, 1.0, 0.0],
        ]);
        assert!(matches!(
            Face::new(0, touching),
            Err(SceneError::RingsIntersect { .. })
        ));
    }
}

//! Random polygons with holes, embedded in random 3D planes, for the property tests.
#![allow(dead_code, clippy::unwrap_used, clippy::expect_used)]

use geo::{Coord, LineString, Polygon};

/// A polygon in 2D, its embedding into 3D and sample points inside it.
pub struct Case {
    pub shell: Vec<[f64; 2]>,
    pub holes: Vec<Vec<[f64; 2]>>,
    /// 3D point = origin + x · u + y · v.
    pub origin: [f64; 3],
    pub u: [f64; 3],
    pub v: [f64; 3],
}

impl Case {
    /// A star-shaped shell (radii `radii`, 3–5) with up to 6 small regular holes around
    /// the centre, in the plane through `origin` with unit normal from `tilt`.
    pub fn new(radii: &[f64], holes: &[(usize, f64)], tilt: [f64; 2], origin: [f64; 3]) -> Self {
        let n = radii.len();
        let shell = radii
            .iter()
            .enumerate()
            .map(|(k, r)| {
                let t = k as f64 / n as f64 * std::f64::consts::TAU;
                [r * t.cos(), r * t.sin()]
            })
            .collect();
        let m = holes.len();
        let holes = holes
            .iter()
            .enumerate()
            .map(|(k, &(sides, radius))| {
                let a = k as f64 / m.max(1) as f64 * std::f64::consts::TAU;
                let c = [1.5 * a.cos(), 1.5 * a.sin()];
                // Clockwise.
                (0..sides)
                    .map(|s| {
                        let t = -(s as f64) / sides as f64 * std::f64::consts::TAU + 0.3;
                        [c[0] + radius * t.cos(), c[1] + radius * t.sin()]
                    })
                    .collect()
            })
            .collect();
        let normal = normalize([tilt[0], tilt[1], 1.0]);
        let helper = if normal[0].abs() < 0.9 {
            [1.0, 0.0, 0.0]
        } else {
            [0.0, 1.0, 0.0]
        };
        let u = normalize(cross(helper, normal));
        let v = cross(normal, u);
        Self {
            shell,
            holes,
            origin,
            u,
            v,
        }
    }

    pub fn lift(&self, p: [f64; 2]) -> [f64; 3] {
        std::array::from_fn(|k| self.origin[k] + p[0] * self.u[k] + p[1] * self.v[k])
    }

    pub fn flatten(&self, p: [f64; 3]) -> [f64; 2] {
        let d = [
            p[0] - self.origin[0],
            p[1] - self.origin[1],
            p[2] - self.origin[2],
        ];
        [dot(d, self.u), dot(d, self.v)]
    }

    pub fn geo(&self) -> Polygon<f64> {
        let ring = |r: &Vec<[f64; 2]>| {
            LineString::from(
                r.iter()
                    .map(|p| Coord { x: p[0], y: p[1] })
                    .collect::<Vec<_>>(),
            )
        };
        Polygon::new(ring(&self.shell), self.holes.iter().map(ring).collect())
    }

    /// Points on a grid of spacing `step` inside the polygon (geo's containment), plus the
    /// ring vertices, lifted to 3D.
    pub fn points(&self, step: f64) -> Vec<[f64; 3]> {
        use geo::Contains;
        let poly = self.geo();
        let mut out: Vec<[f64; 3]> = self
            .shell
            .iter()
            .chain(self.holes.iter().flatten())
            .map(|p| self.lift(*p))
            .collect();
        let n = (10.0 / step) as i32;
        for i in -n..=n {
            for j in -n..=n {
                // A slight shear keeps points off the rings' vertices and lines.
                let p = [
                    f64::from(i) * step + 1e-4 * f64::from(j),
                    f64::from(j) * step,
                ];
                if poly.contains(&geo::Point::new(p[0], p[1])) {
                    out.push(self.lift(p));
                }
            }
        }
        out
    }

    pub fn shell3(&self) -> Vec<[f64; 3]> {
        self.shell.iter().map(|p| self.lift(*p)).collect()
    }

    pub fn holes3(&self) -> Vec<Vec<[f64; 3]>> {
        self.holes
            .iter()
            .map(|h| h.iter().map(|p| self.lift(*p)).collect())
            .collect()
    }
}

fn dot(a: [f64; 3], b: [f64; 3]) -> f64 {
    a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
}

fn cross(a: [f64; 3], b: [f64; 3]) -> [f64; 3] {
    [
        a[1] * b[2] - a[2] * b[1],
        a[2] * b[0] - a[0] * b[2],
        a[0] * b[1] - a[1] * b[0],
    ]
}

fn normalize(a: [f64; 3]) -> [f64; 3] {
    let n = dot(a, a).sqrt();
    a.map(|x| x / n)
}

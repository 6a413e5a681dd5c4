//! Mesh quality and an invariant checker: triangle angles (Fig. 8), skinny triangles,
//! covered area, and the defects a simplified mesh must not have.

use std::collections::HashMap;

/// The three interior angles of triangle `abc`, in degrees.
///
/// ```
/// let [a, b, c] = planar_mesh::quality::angles_deg([0.0, 0.0], [1.0, 0.0], [0.0, 1.0]);
/// assert!((a - 90.0).abs() < 1e-12 && (b - 45.0).abs() < 1e-12 && (c - 45.0).abs() < 1e-12);
/// ```
pub fn angles_deg(a: [f64; 2], b: [f64; 2], c: [f64; 2]) -> [f64; 3] {
    let angle = |p: [f64; 2], q: [f64; 2], r: [f64; 2]| {
        let (u, v) = ([q[0] - p[0], q[1] - p[1]], [r[0] - p[0], r[1] - p[1]]);
        let cross = u[0] * v[1] - u[1] * v[0];
        let dot = u[0] * v[0] + u[1] * v[1];
        cross.abs().atan2(dot).to_degrees()
    };
    [angle(a, b, c), angle(b, c, a), angle(c, a, b)]
}

/// The smallest angle of each triangle, in degrees.
pub fn min_angles_deg(vertices: &[[f64; 2]], triangles: &[[u32; 3]]) -> Vec<f64> {
    triangles
        .iter()
        .map(|t| {
            let [a, b, c] = t.map(|v| vertices[v as usize]);
            let [x, y, z] = angles_deg(a, b, c);
            x.min(y).min(z)
        })
        .collect()
}

/// The paper's skinny-triangle threshold: a minimum angle below 15°.
pub const SKINNY_DEG: f64 = 15.0;

/// Signed area of triangle `abc` (positive counter-clockwise).
#[inline]
pub fn signed_area(a: [f64; 2], b: [f64; 2], c: [f64; 2]) -> f64 {
    0.5 * ((b[0] - a[0]) * (c[1] - a[1]) - (c[0] - a[0]) * (b[1] - a[1]))
}

/// Something a simplified mesh must not contain.
#[derive(Debug, Clone, PartialEq)]
pub enum Defect {
    /// Two vertices at the same position.
    DuplicateVertex {
        /// The first vertex.
        first: u32,
        /// The later one.
        second: u32,
    },
    /// A triangle with an index out of range, a repeated vertex, or no positive area.
    BadTriangle {
        /// The triangle.
        triangle: usize,
    },
    /// A vertex in no triangle.
    UnusedVertex {
        /// The vertex.
        vertex: u32,
    },
    /// A vertex lying inside an edge of a triangle it does not belong to.
    TJoint {
        /// The vertex.
        vertex: u32,
        /// The triangle whose edge it lies on.
        triangle: usize,
    },
}

/// Checks `triangles` over `vertices` (plane coordinates): no duplicate vertices, every
/// triangle counter-clockwise with positive area, every vertex used, and no T-joint among
/// the triangles for which `check_t_joints(triangle)` is true (a vertex of the mesh lying
/// strictly inside one of their edges, within `1e-9` of the mesh's extent).
pub fn defects(
    vertices: &[[f64; 2]],
    triangles: &[[u32; 3]],
    check_t_joints: impl Fn(usize) -> bool,
) -> Vec<Defect> {
    let mut found = Vec::new();
    let mut seen: HashMap<[u64; 2], u32> = HashMap::with_capacity(vertices.len());
    for (v, p) in vertices.iter().enumerate() {
        if let Some(&first) = seen.get(&[p[0].to_bits(), p[1].to_bits()]) {
            found.push(Defect::DuplicateVertex {
                first,
                second: v as u32,
            });
        } else {
            seen.insert([p[0].to_bits(), p[1].to_bits()], v as u32);
        }
    }
    let mut used = vec![false; vertices.len()];
    for (k, t) in triangles.iter().enumerate() {
        let ok = t.iter().all(|&v| (v as usize) < vertices.len())
            && t[0] != t[1]
            && t[1] != t[2]
            && t[0] != t[2];
        if !ok
            || signed_area(
                vertices[t[0] as usize],
                vertices[t[1] as usize],
                vertices[t[2] as usize],
            ) <= 0.0
        {
            found.push(Defect::BadTriangle { triangle: k });
            continue;
        }
        for &v in t {
            used[v as usize] = true;
        }
    }
    found.extend(
        used.iter()
            .enumerate()
            .filter(|(_, u)| !**u)
            .map(|(v, _)| Defect::UnusedVertex { vertex: v as u32 }),
    );
    found.extend(t_joints(vertices, triangles, check_t_joints));
    found
}

/// Vertices strictly inside an edge of a checked triangle, found through a uniform grid.
fn t_joints(
    vertices: &[[f64; 2]],
    triangles: &[[u32; 3]],
    check: impl Fn(usize) -> bool,
) -> Vec<Defect> {
    if vertices.is_empty() || triangles.is_empty() {
        return Vec::new();
    }
    let mut lo = [f64::INFINITY; 2];
    let mut hi = [f64::NEG_INFINITY; 2];
    for p in vertices {
        for k in 0..2 {
            lo[k] = lo[k].min(p[k]);
            hi[k] = hi[k].max(p[k]);
        }
    }
    let extent = (hi[0] - lo[0]).max(hi[1] - lo[1]).max(f64::MIN_POSITIVE);
    let tol = extent * 1e-9;
    let n = ((vertices.len() as f64).sqrt().ceil() as usize).clamp(1, 1024);
    let cell = extent / n as f64;
    let at = |x: f64, k: usize| (((x - lo[k]) / cell).floor().max(0.0) as usize).min(n - 1);
    let mut grid: Vec<Vec<u32>> = vec![Vec::new(); n * n];
    for (v, p) in vertices.iter().enumerate() {
        grid[at(p[1], 1) * n + at(p[0], 0)].push(v as u32);
    }
    let mut found = Vec::new();
    for (k, t) in triangles.iter().enumerate() {
        if !check(k) || t.iter().any(|&v| v as usize >= vertices.len()) {
            continue;
        }
        for e in 0..3 {
            let (a, b) = (vertices[t[e] as usize], vertices[t[(e + 1) % 3] as usize]);
            let len2 = (b[0] - a[0]).powi(2) + (b[1] - a[1]).powi(2);
            if len2 == 0.0 {
                continue;
            }
            let (x0, x1) = (at(a[0].min(b[0]) - tol, 0), at(a[0].max(b[0]) + tol, 0));
            let (y0, y1) = (at(a[1].min(b[1]) - tol, 1), at(a[1].max(b[1]) + tol, 1));
            for gy in y0..=y1 {
                for gx in x0..=x1 {
                    for &v in &grid[gy * n + gx] {
                        if t.contains(&v) {
                            continue;
                        }
                        let p = vertices[v as usize];
                        let s =
                            ((p[0] - a[0]) * (b[0] - a[0]) + (p[1] - a[1]) * (b[1] - a[1])) / len2;
                        let cross = (b[0] - a[0]) * (p[1] - a[1]) - (b[1] - a[1]) * (p[0] - a[0]);
                        if s > 0.0 && s < 1.0 && cross.abs() <= tol * len2.sqrt() {
                            found.push(Defect::TJoint {
                                vertex: v,
                                triangle: k,
                            });
                        }
                    }
                }
            }
        }
    }
    found
}

//! Ramer–Douglas–Peucker simplification of closed rings, iterative and allocation-free
//! apart from the output.
//!
//! A ring `v0 … v(n−1)` (closed back to `v0`) is split at `v0` and at the vertex `vk`
//! farthest from it; both chains are simplified by RDP with point-to-segment distances.
//! Every removed vertex lies within `alpha` of the segment that replaces it, which is the
//! paper's meaning of α. A ring that would keep fewer than three vertices is returned
//! unchanged.

use geo::{Coord, LineString, Polygon};

/// Reusable buffers of [`simplify_polygon`].
#[derive(Debug, Default)]
pub(crate) struct SimplifyScratch {
    keep: Vec<bool>,
    stack: Vec<(usize, usize)>,
}

/// Simplifies every ring of `polygon` with tolerance `alpha` (metres).
pub(crate) fn simplify_polygon(
    polygon: &Polygon<f64>,
    alpha: f64,
    scratch: &mut SimplifyScratch,
) -> Polygon<f64> {
    let shell = simplify_ring(polygon.exterior(), alpha, scratch);
    let holes = polygon
        .interiors()
        .iter()
        .map(|h| simplify_ring(h, alpha, scratch))
        .collect();
    Polygon::new(shell, holes)
}

/// Squared distance from `p` to the closed segment `a b`.
fn dist2_to_segment(p: Coord<f64>, a: Coord<f64>, b: Coord<f64>) -> f64 {
    let (dx, dy) = (b.x - a.x, b.y - a.y);
    let (px, py) = (p.x - a.x, p.y - a.y);
    let len2 = dx * dx + dy * dy;
    let t = if len2 > 0.0 {
        ((px * dx + py * dy) / len2).clamp(0.0, 1.0)
    } else {
        0.0
    };
    let (ex, ey) = (px - t * dx, py - t * dy);
    ex * ex + ey * ey
}

/// `ring` is closed (`first == last`) as `geo` stores it.
fn simplify_ring(
    ring: &LineString<f64>,
    alpha: f64,
    scratch: &mut SimplifyScratch,
) -> LineString<f64> {
    let c = &ring.0;
    if c.len() < 5 {
        return ring.clone();
    }
    let n = c.len() - 1; // distinct vertices; c[n] == c[0]
    let v0 = c[0];
    let far = (1..n)
        .max_by(|&i, &j| {
            let di = (c[i].x - v0.x).powi(2) + (c[i].y - v0.y).powi(2);
            let dj = (c[j].x - v0.x).powi(2) + (c[j].y - v0.y).powi(2);
            di.total_cmp(&dj)
        })
        .unwrap_or(1);
    let keep = &mut scratch.keep;
    keep.clear();
    keep.resize(n + 1, false);
    keep[0] = true;
    keep[far] = true;
    keep[n] = true;
    let tol2 = alpha * alpha;
    let stack = &mut scratch.stack;
    stack.clear();
    stack.push((0, far));
    stack.push((far, n));
    while let Some((lo, hi)) = stack.pop() {
        if hi <= lo + 1 {
            continue;
        }
        let (a, b) = (c[lo], c[hi]);
        let mut best = (0.0, lo);
        for (k, &p) in c.iter().enumerate().take(hi).skip(lo + 1) {
            let d = dist2_to_segment(p, a, b);
            if d > best.0 {
                best = (d, k);
            }
        }
        if best.0 > tol2 {
            keep[best.1] = true;
            stack.push((lo, best.1));
            stack.push((best.1, hi));
        }
    }
    let kept = keep.iter().filter(|&&k| k).count();
    if kept < 4 {
        return ring.clone();
    }
    LineString(
        c.iter()
            .zip(keep.iter())
            .filter_map(|(&p, &k)| k.then_some(p))
            .collect(),
    )
}

#[cfg(test)]
mod tests {
    use super::*;

    fn ring(points: &[(f64, f64)]) -> LineString<f64> {
        let mut ls: LineString<f64> = points.to_vec().into();
        ls.close();
        ls
    }

    #[test]
    fn removes_near_collinear_vertices_only() {
        let r = ring(&[
            (0.0, 0.0),
            (1.0, 0.01),
            (2.0, 0.0),
            (2.0, 2.0),
            (1.0, 2.5),
            (0.0, 2.0),
        ]);
        let mut s = SimplifyScratch::default();
        let out = simplify_ring(&r, 0.1, &mut s);
        assert_eq!(
            out,
            ring(&[(0.0, 0.0), (2.0, 0.0), (2.0, 2.0), (1.0, 2.5), (0.0, 2.0)])
        );
        let out = simplify_ring(&r, 0.001, &mut s);
        assert_eq!(out, r);
    }

    #[test]
    fn never_collapses_below_a_triangle() {
        let r = ring(&[(0.0, 0.0), (1.0, 0.001), (2.0, 0.0), (1.0, -0.001)]);
        let mut s = SimplifyScratch::default();
        assert_eq!(simplify_ring(&r, 1.0, &mut s), r);
    }

    #[test]
    fn matches_brute_force_tolerance() {
        // Oracle: every input vertex is within alpha of the output ring.
        let n = 300;
        let r: Vec<(f64, f64)> = (0..n)
            .map(|i| {
                let t = std::f64::consts::TAU * i as f64 / n as f64;
                let rr = 2.0 + 0.03 * ((i * 7919) % 13) as f64 / 13.0;
                (rr * t.cos(), rr * t.sin())
            })
            .collect();
        let r = ring(&r);
        let mut s = SimplifyScratch::default();
        for alpha in [0.005, 0.02, 0.1, 0.5] {
            let out = simplify_ring(&r, alpha, &mut s);
            assert!(out.0.len() < r.0.len());
            for &p in &r.0 {
                let d = out
                    .0
                    .windows(2)
                    .map(|w| dist2_to_segment(p, w[0], w[1]))
                    .fold(f64::INFINITY, f64::min)
                    .sqrt();
                assert!(d <= alpha * (1.0 + 1e-12), "alpha {alpha}: {d}");
            }
        }
    }
}

//! Ear clipping of polygons with holes (holes bridged to the outer ring) and conforming
//! longest-edge bisection to bound edge lengths.

use std::collections::HashMap;

use crate::face::segments_intersect;
use crate::vec3::{V2, orient2};

/// A triangulation in 2D: points and counter-clockwise triangles.
#[derive(Debug, Clone, Default)]
pub(crate) struct Triangulation {
    pub(crate) points: Vec<V2>,
    pub(crate) triangles: Vec<[u32; 3]>,
}

/// Triangulates a polygon with holes (ring 0 counter-clockwise, holes clockwise, rings
/// simple and disjoint). Returns `Err(remaining)` if clipping gets stuck (numerically
/// degenerate input).
pub(crate) fn triangulate(rings: &[Vec<V2>]) -> Result<Triangulation, usize> {
    let points: Vec<V2> = rings.iter().flatten().copied().collect();
    let mut starts = Vec::with_capacity(rings.len());
    let mut s = 0u32;
    for r in rings {
        starts.push(s);
        s += r.len() as u32;
    }
    let ring_indices =
        |r: usize| -> Vec<u32> { (starts[r]..starts[r] + rings[r].len() as u32).collect() };

    let mut poly = ring_indices(0);
    // Holes by decreasing largest x, each bridged from its rightmost vertex.
    let mut holes: Vec<(usize, u32)> = (1..rings.len())
        .map(|r| {
            let m = ring_indices(r)
                .into_iter()
                .max_by(|&a, &b| {
                    let (pa, pb) = (points[a as usize], points[b as usize]);
                    pa[0].total_cmp(&pb[0]).then(pb[1].total_cmp(&pa[1]))
                })
                .unwrap_or(starts[r]);
            (r, m)
        })
        .collect();
    holes.sort_by(|a, b| {
        points[b.1 as usize][0]
            .total_cmp(&points[a.1 as usize][0])
            .then(a.0.cmp(&b.0))
    });
    for (pos, &(r, m)) in holes.iter().enumerate() {
        let pending: Vec<usize> = holes[pos..].iter().map(|h| h.0).collect();
        let k = bridge(&points, &poly, rings, &starts, &pending, r, m).ok_or(poly.len())?;
        let ring = ring_indices(r);
        let mi = (m - starts[r]) as usize;
        let mut merged = Vec::with_capacity(poly.len() + ring.len() + 2);
        merged.extend_from_slice(&poly[..=k]);
        merged.extend((0..=ring.len()).map(|i| ring[(mi + i) % ring.len()]));
        merged.push(poly[k]);
        merged.extend_from_slice(&poly[k + 1..]);
        poly = merged;
    }
    let triangles = clip_ears(&points, poly)?;
    Ok(Triangulation { points, triangles })
}

/// Position in `poly` of the vertex to bridge hole vertex `m` to, or `None`.
fn bridge(
    points: &[V2],
    poly: &[u32],
    rings: &[Vec<V2>],
    starts: &[u32],
    pending: &[usize],
    hole: usize,
    m: u32,
) -> Option<usize> {
    let pm = points[m as usize];
    let n = poly.len();
    let hole_len = rings[hole].len() as u32;
    let hm = m - starts[hole];
    let m_prev = points[(starts[hole] + (hm + hole_len - 1) % hole_len) as usize];
    let m_next = points[(starts[hole] + (hm + 1) % hole_len) as usize];
    let mut best: Option<(f64, usize)> = None;
    for k in 0..n {
        let vi = poly[k];
        let pv = points[vi as usize];
        let d2 = (pv[0] - pm[0]).powi(2) + (pv[1] - pm[1]).powi(2);
        if best.is_some_and(|(bd, _)| d2 >= bd) {
            continue;
        }
        let prev = points[poly[(k + n - 1) % n] as usize];
        let next = points[poly[(k + 1) % n] as usize];
        if !in_cone(prev, pv, next, pm) || !in_cone(m_prev, pm, m_next, pv) {
            continue;
        }
        let blocked_poly = (0..n).any(|e| {
            let (a, b) = (poly[e], poly[(e + 1) % n]);
            a != vi && b != vi && segments_intersect(pm, pv, points[a as usize], points[b as usize])
        });
        let blocked_holes = || {
            pending.iter().any(|&r| {
                let len = rings[r].len() as u32;
                (0..len).any(|i| {
                    let a = starts[r] + i;
                    let b = starts[r] + (i + 1) % len;
                    a != m
                        && b != m
                        && segments_intersect(pm, pv, points[a as usize], points[b as usize])
                })
            })
        };
        if !blocked_poly && !blocked_holes() {
            best = Some((d2, k));
        }
    }
    best.map(|(_, k)| k)
}

/// Whether point `p` lies strictly inside the interior angle at `v` between `prev` and
/// `next` (interior on the left of `prev → v → next`).
fn in_cone(prev: V2, v: V2, next: V2, p: V2) -> bool {
    let left_of_in = orient2(prev, v, p) > 0.0;
    let left_of_out = orient2(v, next, p) > 0.0;
    if orient2(prev, v, next) > 0.0 {
        left_of_in && left_of_out
    } else {
        left_of_in || left_of_out
    }
}

/// Clips ears from a weakly simple counter-clockwise ring of point indices, choosing at
/// each step the best-shaped ear.
fn clip_ears(points: &[V2], mut v: Vec<u32>) -> Result<Vec<[u32; 3]>, usize> {
    let mut out = Vec::with_capacity(v.len().saturating_sub(2));
    let p = |i: u32| points[i as usize];
    while v.len() > 3 {
        let n = v.len();
        let mut best: Option<(f64, usize)> = None;
        for i in 0..n {
            let (a, b, c) = (v[(i + n - 1) % n], v[i], v[(i + 1) % n]);
            let (pa, pb, pc) = (p(a), p(b), p(c));
            let area2 = orient2(pa, pb, pc);
            if area2 <= 0.0 {
                continue;
            }
            let blocked = v.iter().any(|&j| {
                j != a && j != b && j != c && {
                    let q = p(j);
                    orient2(pa, pb, q) >= 0.0
                        && orient2(pb, pc, q) >= 0.0
                        && orient2(pc, pa, q) >= 0.0
                }
            });
            if blocked {
                continue;
            }
            let longest = [dist2(pa, pb), dist2(pb, pc), dist2(pc, pa)]
                .into_iter()
                .fold(0.0, f64::max);
            let quality = area2 / longest;
            if best.is_none_or(|(q, _)| quality > q) {
                best = Some((quality, i));
            }
        }
        let Some((_, i)) = best else {
            return Err(n);
        };
        out.push([v[(i + n - 1) % n], v[i], v[(i + 1) % n]]);
        v.remove(i);
    }
    if v.len() == 3 && orient2(p(v[0]), p(v[1]), p(v[2])) > 0.0 {
        out.push([v[0], v[1], v[2]]);
    }
    Ok(out)
}

#[inline]
fn dist2(a: V2, b: V2) -> f64 {
    (a[0] - b[0]).powi(2) + (a[1] - b[1]).powi(2)
}

const NONE: u32 = u32::MAX;

/// Conforming longest-edge bisection (Rivara's LEPP): splits triangles until no edge is
/// longer than `max_edge`. Edges shared by two triangles are split in both, so the result
/// has no T-junctions; orientation is kept.
pub(crate) fn refine(t: &mut Triangulation, max_edge: f64) {
    if !(max_edge.is_finite() && max_edge > 0.0) {
        return;
    }
    let max2 = max_edge * max_edge;
    let mut edges: HashMap<(u32, u32), [u32; 2]> = HashMap::with_capacity(t.triangles.len() * 3);
    for (ti, tri) in t.triangles.iter().enumerate() {
        for k in 0..3 {
            let e = key(tri[k], tri[(k + 1) % 3]);
            let slot = edges.entry(e).or_insert([NONE, NONE]);
            if slot[0] == NONE {
                slot[0] = ti as u32;
            } else {
                slot[1] = ti as u32;
            }
        }
    }
    let mut r = Refiner {
        t,
        edges,
        path: Vec::new(),
    };
    let mut i = 0;
    while i < r.t.triangles.len() {
        if r.longest(i as u32).1 > max2 {
            r.lepp_bisect(i as u32);
        } else {
            i += 1;
        }
    }
}

#[inline]
fn key(a: u32, b: u32) -> (u32, u32) {
    if a < b { (a, b) } else { (b, a) }
}

struct Refiner<'a> {
    t: &'a mut Triangulation,
    edges: HashMap<(u32, u32), [u32; 2]>,
    path: Vec<u32>,
}

impl Refiner<'_> {
    /// The longest edge of triangle `ti` as its local index `k` (edge `k → k+1`) and its
    /// squared length. Ties go to the smaller vertex-index key, so both triangles on an
    /// edge agree on the order of edges.
    fn longest(&self, ti: u32) -> (usize, f64) {
        let tri = self.t.triangles[ti as usize];
        let mut best = (0, -1.0, (0, 0));
        for k in 0..3 {
            let (a, b) = (tri[k], tri[(k + 1) % 3]);
            let l = dist2(self.t.points[a as usize], self.t.points[b as usize]);
            let kk = key(a, b);
            if l > best.1 || (l == best.1 && kk < best.2) {
                best = (k, l, kk);
            }
        }
        (best.0, best.1)
    }

    fn neighbour(&self, ti: u32, k: usize) -> Option<u32> {
        let tri = self.t.triangles[ti as usize];
        let slot = self.edges.get(&key(tri[k], tri[(k + 1) % 3]))?;
        let other = if slot[0] == ti { slot[1] } else { slot[0] };
        (other != NONE).then_some(other)
    }

    /// Bisects `start` along its longest edge, first bisecting along the longest-edge
    /// propagation path until that edge is the longest of both its triangles.
    fn lepp_bisect(&mut self, start: u32) {
        self.path.clear();
        self.path.push(start);
        while let Some(&cur) = self.path.last() {
            let (k, _) = self.longest(cur);
            match self.neighbour(cur, k) {
                None => {
                    self.split(cur, k, None);
                    self.path.pop();
                }
                Some(nb) => {
                    let tri = self.t.triangles[cur as usize];
                    let e = key(tri[k], tri[(k + 1) % 3]);
                    let (kn, _) = self.longest(nb);
                    let tn = self.t.triangles[nb as usize];
                    if key(tn[kn], tn[(kn + 1) % 3]) == e {
                        self.split(cur, k, Some((nb, kn)));
                        self.path.pop();
                    } else {
                        self.path.push(nb);
                    }
                }
            }
        }
    }

    /// Splits edge `k` of triangle `ti` (and of its neighbour `nb` at local edge `kn`) at
    /// its midpoint.
    fn split(&mut self, ti: u32, k: usize, nb: Option<(u32, usize)>) {
        let tri = self.t.triangles[ti as usize];
        let (a, b, c) = (tri[k], tri[(k + 1) % 3], tri[(k + 2) % 3]);
        let (pa, pb) = (self.t.points[a as usize], self.t.points[b as usize]);
        let m = self.t.points.len() as u32;
        self.t
            .points
            .push([0.5 * (pa[0] + pb[0]), 0.5 * (pa[1] + pb[1])]);
        self.edges.remove(&key(a, b));

        // ti = (a, b, c) becomes (a, m, c); new t2 = (m, b, c).
        let t2 = self.t.triangles.len() as u32;
        self.t.triangles[ti as usize] = [a, m, c];
        self.t.triangles.push([m, b, c]);
        self.replace(key(b, c), ti, t2);
        self.edges.insert(key(m, c), [ti, t2]);
        let (mut am, mut mb) = ([ti, NONE], [t2, NONE]);

        if let Some((n, kn)) = nb {
            // n = (b, a, d) becomes (b, m, d); new n2 = (m, a, d).
            let tn = self.t.triangles[n as usize];
            let d = tn[(kn + 2) % 3];
            let n2 = self.t.triangles.len() as u32;
            self.t.triangles[n as usize] = [b, m, d];
            self.t.triangles.push([m, a, d]);
            self.replace(key(a, d), n, n2);
            self.edges.insert(key(m, d), [n, n2]);
            am[1] = n2;
            mb[1] = n;
        }
        self.edges.insert(key(a, m), am);
        self.edges.insert(key(m, b), mb);
    }

    fn replace(&mut self, e: (u32, u32), old: u32, new: u32) {
        if let Some(slot) = self.edges.get_mut(&e) {
            for s in slot.iter_mut() {
                if *s == old {
                    *s = new;
                }
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::vec3::ring_area;

    fn area(t: &Triangulation) -> f64 {
        t.triangles
            .iter()
            .map(|tri| {
                0.5 * orient2(
                    t.points[tri[0] as usize],
                    t.points[tri[1] as usize],
                    t.points[tri[2] as usize],
                )
            })
            .sum()
    }

    fn square(x0: f64, y0: f64, s: f64, ccw: bool) -> Vec<V2> {
        let mut r = vec![[x0, y0], [x0 + s, y0], [x0 + s, y0 + s], [x0, y0 + s]];
        if !ccw {
            r.reverse();
        }
        r
    }

    /// No directed edge is used twice, and the edges without a reverse twin (the mesh
    /// boundary) add up to the rings' perimeter: no T-junctions.
    fn conforming(t: &Triangulation, rings: &[Vec<V2>]) -> bool {
        let mut dir: HashMap<(u32, u32), usize> = HashMap::new();
        for tri in &t.triangles {
            for k in 0..3 {
                *dir.entry((tri[k], tri[(k + 1) % 3])).or_default() += 1;
            }
        }
        let boundary: f64 = dir
            .keys()
            .filter(|(a, b)| !dir.contains_key(&(*b, *a)))
            .map(|&(a, b)| dist2(t.points[a as usize], t.points[b as usize]).sqrt())
            .sum();
        let perimeter: f64 = rings
            .iter()
            .map(|r| {
                (0..r.len())
                    .map(|i| dist2(r[i], r[(i + 1) % r.len()]).sqrt())
                    .sum::<f64>()
            })
            .sum();
        dir.values().all(|&c| c == 1) && (boundary - perimeter).abs() < 1e-9
    }

    #[test]
    fn square_with_two_holes() -> Result<(), usize> {
        let rings = vec![
            square(0.0, 0.0, 10.0, true),
            square(1.0, 1.0, 2.0, false),
            square(6.0, 5.0, 3.0, false),
        ];
        let expected: f64 = rings.iter().map(|r| ring_area(r)).sum();
        let mut t = triangulate(&rings)?;
        assert_eq!(t.triangles.len(), 12 - 2 + 2 * 2);
        assert!((area(&t) - expected).abs() < 1e-9);
        assert!(conforming(&t, &rings));
        refine(&mut t, 0.7);
        assert!((area(&t) - expected).abs() < 1e-9);
        assert!(conforming(&t, &rings));
        for tri in &t.triangles {
            let p = tri.map(|i| t.points[i as usize]);
            assert!(orient2(p[0], p[1], p[2]) > 0.0);
            for k in 0..3 {
                assert!(dist2(p[k], p[(k + 1) % 3]) <= 0.49 + 1e-12);
            }
        }
        Ok(())
    }

    #[test]
    fn staircase_profile() -> Result<(), usize> {
        let mut ring = vec![[0.0, 0.0]];
        for i in 0..5 {
            let (x, y) = (i as f64 * 0.3, (i + 1) as f64 * 0.2);
            ring.push([x, y]);
            ring.push([x + 0.3, y]);
        }
        ring.push([1.5, 0.0]);
        // Profile runs up and right, which is clockwise; make it counter-clockwise.
        ring.reverse();
        let a = ring_area(&ring);
        assert!(a > 0.0);
        let rings = [ring];
        let mut t = triangulate(&rings)?;
        assert!((area(&t) - a).abs() < 1e-12);
        refine(&mut t, 0.05);
        assert!((area(&t) - a).abs() < 1e-12);
        assert!(conforming(&t, &rings));
        Ok(())
    }
}

//! Validity checking: a fast sufficient test with exact predicates, backed by
//! `geo::Validation` as the authority when the fast test cannot decide.
//!
//! The fast test accepts a polygon only when all of these hold: every ring has at least
//! three distinct vertices, no repeated consecutive vertex and only finite coordinates;
//! no two segments of the polygon touch or cross except consecutive segments of one ring
//! at their shared vertex, and those do not fold back onto each other; every hole's first
//! vertex lies strictly inside the shell and outside every other hole. With exact
//! orientation predicates (Shewchuk's, via `geo`'s `RobustKernel`) this implies what
//! `geo::Validation` checks for a polygon, at `O(n log n)` cost for ordinary shapes
//! instead of its `O(n²)` ring self-intersection scan. Anything the fast test does not
//! accept goes to `geo::Validation`, so "valid" here always means valid for `geo`.

use geo::kernels::{Kernel, Orientation, RobustKernel};
use geo::{Coord, LineString, Polygon, Validation};

/// One segment of a ring, with its bounding box and place in the ring.
#[derive(Debug, Clone, Copy)]
struct Seg {
    a: Coord<f64>,
    b: Coord<f64>,
    min: Coord<f64>,
    max: Coord<f64>,
    ring: u32,
    index: u32,
}

/// Reusable buffers of the fast validity test.
#[derive(Debug, Default)]
pub(crate) struct ValidityScratch {
    segs: Vec<Seg>,
    /// `(min x, segment index)`, sorted: a compact sort key instead of moving `Seg`s.
    order: Vec<(f64, u32)>,
    ring_lens: Vec<u32>,
}

/// `Ok(())` if `polygon` is valid for `geo::Validation`; otherwise the first reason `geo`
/// gives.
pub(crate) fn check_valid(
    polygon: &Polygon<f64>,
    scratch: &mut ValidityScratch,
) -> Result<(), String> {
    if fast_valid(polygon, scratch) {
        return Ok(());
    }
    let mut first = None;
    // `visit_validation` stops at the first `Err` the handler returns.
    let _ = polygon.visit_validation(Box::new(|e| {
        first = Some(e.to_string());
        Err::<(), ()>(())
    }));
    match first {
        None if polygon.exterior().0.is_empty() => Err("the shell is empty".to_string()),
        None => Ok(()),
        Some(reason) => Err(reason),
    }
}

fn orient(p: Coord<f64>, q: Coord<f64>, r: Coord<f64>) -> Orientation {
    RobustKernel::orient2d(p, q, r)
}

/// A sufficient condition for validity; `false` means "not proven", not "invalid".
pub(crate) fn fast_valid(polygon: &Polygon<f64>, scratch: &mut ValidityScratch) -> bool {
    scratch.segs.clear();
    scratch.ring_lens.clear();
    let rings = std::iter::once(polygon.exterior()).chain(polygon.interiors());
    for (ring_idx, ring) in rings.enumerate() {
        if !push_ring(ring, ring_idx as u32, scratch) {
            return false;
        }
    }
    let segs = &scratch.segs;
    if u32::try_from(segs.len()).is_err() {
        return false;
    }
    let order = &mut scratch.order;
    order.clear();
    order.extend(segs.iter().enumerate().map(|(i, s)| (s.min.x, i as u32)));
    order.sort_unstable_by(|a, b| a.0.total_cmp(&b.0));
    for (i, &(_, si)) in order.iter().enumerate() {
        let s = segs[si as usize];
        for &(min_x, ti) in &order[i + 1..] {
            if min_x > s.max.x {
                break;
            }
            let t = &segs[ti as usize];
            if t.min.y > s.max.y || t.max.y < s.min.y {
                continue;
            }
            if s.ring == t.ring {
                let n = scratch.ring_lens[s.ring as usize];
                if (s.index + 1) % n == t.index {
                    if folds_back(s.a, s.b, t.b) {
                        return false;
                    }
                    continue;
                }
                if (t.index + 1) % n == s.index {
                    if folds_back(t.a, t.b, s.b) {
                        return false;
                    }
                    continue;
                }
            }
            if segments_touch(s.a, s.b, t.a, t.b) {
                return false;
            }
        }
    }
    holes_placed_properly(polygon)
}

/// Appends the ring's segments; `false` if the ring alone already fails the fast test.
fn push_ring(ring: &LineString<f64>, ring_idx: u32, scratch: &mut ValidityScratch) -> bool {
    let c = &ring.0;
    // Closed, at least 3 distinct vertices (4 coordinates), all finite.
    if c.len() < 4 || c.first() != c.last() {
        return false;
    }
    if !c.iter().all(|p| p.x.is_finite() && p.y.is_finite()) {
        return false;
    }
    let Ok(n) = u32::try_from(c.len() - 1) else {
        return false;
    };
    for (k, w) in c.windows(2).enumerate() {
        let (a, b) = (w[0], w[1]);
        if a == b {
            return false;
        }
        scratch.segs.push(Seg {
            a,
            b,
            min: Coord {
                x: a.x.min(b.x),
                y: a.y.min(b.y),
            },
            max: Coord {
                x: a.x.max(b.x),
                y: a.y.max(b.y),
            },
            ring: ring_idx,
            index: k as u32,
        });
    }
    scratch.ring_lens.push(n);
    true
}

/// Whether consecutive segments `p→q`, `q→r` overlap beyond their shared vertex `q`.
fn folds_back(p: Coord<f64>, q: Coord<f64>, r: Coord<f64>) -> bool {
    orient(p, q, r) == Orientation::Collinear
        && (q.x - p.x) * (r.x - q.x) + (q.y - p.y) * (r.y - q.y) <= 0.0
}

/// Exact closed-segment intersection test (touching counts).
fn segments_touch(a: Coord<f64>, b: Coord<f64>, c: Coord<f64>, d: Coord<f64>) -> bool {
    let o1 = orient(a, b, c);
    let o2 = orient(a, b, d);
    let o3 = orient(c, d, a);
    let o4 = orient(c, d, b);
    if o1 != o2 && o3 != o4 {
        return true;
    }
    (o1 == Orientation::Collinear && in_box(a, b, c))
        || (o2 == Orientation::Collinear && in_box(a, b, d))
        || (o3 == Orientation::Collinear && in_box(c, d, a))
        || (o4 == Orientation::Collinear && in_box(c, d, b))
}

/// For `r` collinear with `p`, `q`: whether it lies on the closed segment `p q`.
fn in_box(p: Coord<f64>, q: Coord<f64>, r: Coord<f64>) -> bool {
    r.x >= p.x.min(q.x) && r.x <= p.x.max(q.x) && r.y >= p.y.min(q.y) && r.y <= p.y.max(q.y)
}

/// Winding number of the closed ring around `p` (exact; `p` must not be on the ring).
fn winding_number(ring: &[Coord<f64>], p: Coord<f64>) -> i64 {
    let mut wn = 0i64;
    for w in ring.windows(2) {
        let (a, b) = (w[0], w[1]);
        if a.y <= p.y {
            if b.y > p.y && orient(a, b, p) == Orientation::CounterClockwise {
                wn += 1;
            }
        } else if b.y <= p.y && orient(a, b, p) == Orientation::Clockwise {
            wn -= 1;
        }
    }
    wn
}

fn bbox(ring: &[Coord<f64>]) -> (Coord<f64>, Coord<f64>) {
    let mut lo = Coord {
        x: f64::INFINITY,
        y: f64::INFINITY,
    };
    let mut hi = Coord {
        x: f64::NEG_INFINITY,
        y: f64::NEG_INFINITY,
    };
    for p in ring {
        lo.x = lo.x.min(p.x);
        lo.y = lo.y.min(p.y);
        hi.x = hi.x.max(p.x);
        hi.y = hi.y.max(p.y);
    }
    (lo, hi)
}

/// With no ring contacts (checked before), each hole is inside the shell and outside the
/// other holes iff its first vertex is.
fn holes_placed_properly(polygon: &Polygon<f64>) -> bool {
    let holes = polygon.interiors();
    if holes.is_empty() {
        return true;
    }
    let shell = &polygon.exterior().0;
    if holes.iter().any(|h| winding_number(shell, h.0[0]) == 0) {
        return false;
    }
    let boxes: Vec<_> = holes.iter().map(|h| bbox(&h.0)).collect();
    for (i, h) in holes.iter().enumerate() {
        let p = h.0[0];
        for (j, other) in holes.iter().enumerate() {
            let (lo, hi) = boxes[j];
            if i != j
                && p.x >= lo.x
                && p.x <= hi.x
                && p.y >= lo.y
                && p.y <= hi.y
                && winding_number(&other.0, p) != 0
            {
                return false;
            }
        }
    }
    true
}

#[cfg(test)]
mod tests {
    use super::*;
    use geo::wkt;

    fn both(p: &Polygon<f64>) -> (bool, bool) {
        let mut s = ValidityScratch::default();
        (fast_valid(p, &mut s), p.is_valid())
    }

    #[test]
    fn fast_test_accepts_simple_polygons() {
        let p = wkt!(POLYGON((0. 0., 10. 0., 10. 10., 0. 10., 0. 0.),(2. 2., 2. 4., 4. 4., 4. 2., 2. 2.),(6. 6., 6. 8., 8. 8., 6. 6.)));
        assert_eq!(both(&p), (true, true));
        let tri = wkt!(POLYGON((0. 0., 1. 0., 0. 1., 0. 0.)));
        assert_eq!(both(&tri), (true, true));
    }

    #[test]
    fn fast_test_rejects_what_geo_rejects() {
        let cases = [
            // bow-tie
            wkt!(POLYGON((0. 0., 10. 10., 10. 0., 0. 10., 0. 0.))),
            // hole outside the shell
            wkt!(POLYGON((0. 0., 1. 0., 1. 1., 0. 1., 0. 0.),(2. 2., 2. 3., 3. 3., 2. 2.))),
            // nested holes
            wkt!(POLYGON((0. 0., 10. 0., 10. 10., 0. 10., 0. 0.),(1. 1., 1. 9., 9. 9., 9. 1., 1. 1.),(2. 2., 2. 3., 3. 3., 2. 2.))),
            // hole crossing the shell
            wkt!(POLYGON((0. 0., 10. 0., 10. 10., 0. 10., 0. 0.),(5. 5., 5. 15., 6. 15., 6. 5., 5. 5.))),
            // collinear spike
            wkt!(POLYGON((0. 0., 10. 0., 15. 0., 10. 0., 10. 10., 0. 10., 0. 0.))),
            // two distinct points only
            wkt!(POLYGON((0. 0., 1. 0., 0. 0., 1. 0., 0. 0.))),
        ];
        for p in &cases {
            assert!(!both(p).0, "fast test accepted {p:?}");
        }
        let mut s = ValidityScratch::default();
        assert!(check_valid(&cases[0], &mut s).is_err());
    }

    #[test]
    fn touching_hole_goes_to_geo_and_is_accepted() {
        // A hole touching the shell at one point is OGC-valid; the fast test defers.
        let p =
            wkt!(POLYGON((0. 0., 4. 1., 4. 4., 0. 4., 0. 0.),(0. 2., 2. 1., 3. 2., 2. 3., 0. 2.)));
        let mut s = ValidityScratch::default();
        assert!(!fast_valid(&p, &mut s));
        assert!(check_valid(&p, &mut s).is_ok());
    }
}

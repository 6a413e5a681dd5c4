//! Exact geometric predicates (Shewchuk's adaptive arithmetic from the `robust` crate) and a
//! symbolic perturbation that breaks in-circle ties consistently.

use robust::{Coord, incircle, orient2d};

#[inline(always)]
fn coord(p: [f64; 2]) -> Coord<f64> {
    Coord { x: p[0], y: p[1] }
}

/// Positive if `a, b, c` turn counter-clockwise (y up), negative if clockwise, zero if
/// collinear; the sign is exact.
#[inline(always)]
pub(crate) fn orient(a: [f64; 2], b: [f64; 2], c: [f64; 2]) -> f64 {
    orient2d(coord(a), coord(b), coord(c))
}

/// Whether `d` lies inside the circle through the counter-clockwise triangle `a, b, c`.
///
/// Exact, with ties (four cocircular points) broken by simulation of simplicity: each point
/// is lifted to the paraboloid with an extra infinitesimal height that is larger the smaller
/// its rank. Ranks are global point ids, so every caller triangulating any subset of the
/// points resolves a tie the same way, and the triangulation is unique: the regular
/// triangulation of the perturbed lifted points, which refines the Delaunay subdivision.
/// `ranks` is only called on a tie.
#[inline(always)]
pub(crate) fn in_circle(pts: [[f64; 2]; 4], ranks: impl FnOnce() -> [u32; 4]) -> bool {
    let [a, b, c, d] = pts;
    let det = incircle(coord(a), coord(b), coord(c), coord(d));
    if det != 0.0 {
        return det > 0.0;
    }
    perturbed_in_circle(pts, ranks())
}

/// Shewchuk's relative error bound of the floating-point in-circle determinant,
/// `(10 + 96 ε) ε` with `ε = 2⁻⁵³`.
const INCIRCLE_ERROR: f64 = (10.0 + 96.0 * f64::EPSILON / 2.0) * f64::EPSILON / 2.0;

/// A semi-static filter for [`in_circle`] over points whose coordinates all lie in a box
/// of the given extent: when the float determinant exceeds [`Self::bound`] its sign is
/// certain, without the per-call error bound of the adaptive test.
#[derive(Debug, Clone, Copy)]
pub(crate) struct InCircleFilter {
    bound: f64,
}

impl InCircleFilter {
    /// For points within a box of width and height at most `extent`.
    pub fn new(extent: f64) -> Self {
        // Every coordinate difference is at most `extent` (rounded up a little), so the
        // adaptive test's "permanent" is at most 12 extent⁴.
        let m = extent * (1.0 + 4.0 * f64::EPSILON);
        let m2 = m * m;
        Self {
            bound: 12.0 * INCIRCLE_ERROR * (m2 * m2) * (1.0 + 1e-12),
        }
    }

    /// [`in_circle`], deciding most cases from the float determinant alone.
    #[inline(always)]
    pub fn in_circle(
        self,
        a: [f64; 2],
        b: [f64; 2],
        c: [f64; 2],
        d: [f64; 2],
        ranks: impl FnOnce() -> [u32; 4],
    ) -> bool {
        let (adx, ady) = (a[0] - d[0], a[1] - d[1]);
        let (bdx, bdy) = (b[0] - d[0], b[1] - d[1]);
        let (cdx, cdy) = (c[0] - d[0], c[1] - d[1]);
        let alift = adx * adx + ady * ady;
        let blift = bdx * bdx + bdy * bdy;
        let clift = cdx * cdx + cdy * cdy;
        let det = alift * (bdx * cdy - cdx * bdy)
            + blift * (cdx * ady - adx * cdy)
            + clift * (adx * bdy - bdx * ady);
        if det > self.bound {
            true
        } else if -det > self.bound {
            false
        } else {
            in_circle([a, b, c, d], ranks)
        }
    }
}

/// The tie rule of [`in_circle`] for four exactly cocircular points.
///
/// Heights `z_p = |p|² + ε_p`; `d` is inside iff `z_d < Σ λ_i z_i` with `λ` the barycentric
/// coordinates of `d` in `abc`. At a tie only the largest `ε` counts: `d`'s own pushes it
/// out, a vertex's pulls `d` in iff its barycentric weight is positive. No three of four
/// distinct cocircular points are collinear, so that weight is never zero.
#[cold]
fn perturbed_in_circle(pts: [[f64; 2]; 4], ranks: [u32; 4]) -> bool {
    let [a, b, c, d] = pts;
    let top = (0..4).min_by_key(|&i| ranks[i]).unwrap_or(3);
    match top {
        0 => orient(b, c, d) > 0.0,
        1 => orient(c, a, d) > 0.0,
        2 => orient(a, b, d) > 0.0,
        _ => false,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn orientation_signs() {
        assert!(orient([0.0, 0.0], [1.0, 0.0], [0.0, 1.0]) > 0.0);
        assert!(orient([0.0, 0.0], [0.0, 1.0], [1.0, 0.0]) < 0.0);
        assert_eq!(orient([0.0, 0.0], [1.0, 1.0], [3.0, 3.0]), 0.0);
    }

    #[test]
    fn strict_cases_ignore_ranks() {
        let tri = [[0.0, 0.0], [2.0, 0.0], [0.0, 2.0]];
        let inside = [tri[0], tri[1], tri[2], [0.5, 0.5]];
        let outside = [tri[0], tri[1], tri[2], [3.0, 3.0]];
        assert!(in_circle(inside, || [0, 1, 2, 3]));
        assert!(in_circle(inside, || [3, 2, 1, 0]));
        assert!(!in_circle(outside, || [0, 1, 2, 3]));
    }

    /// The filter agrees with the adaptive test, on easy and on nearly cocircular cases.
    #[test]
    fn filter_agrees_with_exact_test() {
        let filter = InCircleFilter::new(10.0);
        let tri = [[0.0, 0.0], [2.0, 0.0], [0.0, 2.0]];
        for d in [
            [0.5, 0.5],
            [3.0, 3.0],
            [2.0, 2.0],
            [2.0, 2.0 + 1e-15],
            [1.0 + 1e-16, -1e-15],
        ] {
            let pts = [tri[0], tri[1], tri[2], d];
            let fast = filter.in_circle(tri[0], tri[1], tri[2], d, || [0, 1, 2, 3]);
            assert_eq!(fast, in_circle(pts, || [0, 1, 2, 3]));
        }
    }

    /// On a cocircular square exactly one of the two diagonals must be legal, whatever the
    /// ranks: the test from either side of a diagonal agrees.
    #[test]
    fn ties_pick_exactly_one_diagonal() {
        let [a, b, c, d] = [[0.0, 0.0], [1.0, 0.0], [1.0, 1.0], [0.0, 1.0]];
        for ranks in [[0, 1, 2, 3], [3, 2, 1, 0], [2, 0, 3, 1], [1, 3, 0, 2]] {
            let [ra, rb, rc, rd] = ranks;
            // Diagonal a–c: triangles (a, b, c) and (a, c, d); flip if d is inside (a, b, c).
            let flip_ac = in_circle([a, b, c, d], || [ra, rb, rc, rd]);
            let flip_ac_other_side = in_circle([c, d, a, b], || [rc, rd, ra, rb]);
            assert_eq!(flip_ac, flip_ac_other_side, "ranks {ranks:?}");
            // Diagonal b–d: triangles (b, c, d) and (b, d, a).
            let flip_bd = in_circle([b, c, d, a], || [rb, rc, rd, ra]);
            let flip_bd_other_side = in_circle([d, a, b, c], || [rd, ra, rb, rc]);
            assert_eq!(flip_bd, flip_bd_other_side, "ranks {ranks:?}");
            assert_ne!(flip_ac, flip_bd, "ranks {ranks:?}");
        }
    }
}

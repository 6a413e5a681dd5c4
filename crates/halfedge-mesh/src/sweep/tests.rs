//! Unit tests of the sweep against brute force: exact empty circumcircles, twin links,
//! the triangle count of a triangulation and hull membership.

use proptest::prelude::*;

use super::predicates::{in_circle, orient};
use super::*;
use crate::mesh::NO_TWIN;

/// Checks every invariant of `tri` against brute force; returns nothing, panics on failure.
pub(super) fn check(points: &[[f64; 2]], tri: &Triangulation) {
    let xy = |v: u32| points[v as usize];
    let triangles = tri.caller_triangles();
    let hull: Vec<u32> = tri.hull.iter().map(|&p| tri.input[p as usize]).collect();
    for (p, &i) in tri.input.iter().enumerate() {
        assert_eq!(tri.coords[p], points[i as usize]);
    }
    let n_distinct = {
        let mut p: Vec<(u64, u64)> = points
            .iter()
            .map(|p| (p[0].to_bits(), p[1].to_bits()))
            .collect();
        p.sort_unstable();
        p.dedup();
        p.len()
    };
    assert_eq!(points.len() - tri.duplicates as usize, n_distinct);
    // Triangle count of any triangulation: 2n − 2 − h.
    assert_eq!(triangles.len(), 2 * n_distinct - 2 - hull.len());
    let mut used = vec![false; points.len()];
    for (t, v) in triangles.iter().enumerate() {
        assert!(
            orient(xy(v[0]), xy(v[1]), xy(v[2])) > 0.0,
            "triangle {t} {v:?} not CCW"
        );
        for &w in v {
            used[w as usize] = true;
        }
        for (i, &d) in points.iter().enumerate() {
            if v.contains(&(i as u32)) {
                continue;
            }
            let ranks = [v[0], v[1], v[2], i as u32];
            let strictly = robust::incircle(
                robust::Coord {
                    x: xy(v[0])[0],
                    y: xy(v[0])[1],
                },
                robust::Coord {
                    x: xy(v[1])[0],
                    y: xy(v[1])[1],
                },
                robust::Coord {
                    x: xy(v[2])[0],
                    y: xy(v[2])[1],
                },
                robust::Coord { x: d[0], y: d[1] },
            );
            assert!(strictly <= 0.0, "point {i} inside circumcircle of {v:?}");
            let dup = points[..i].contains(&d) || d == xy(v[0]) || d == xy(v[1]) || d == xy(v[2]);
            if !dup {
                assert!(
                    !in_circle([xy(v[0]), xy(v[1]), xy(v[2]), d], || ranks),
                    "point {i} inside the perturbed circumcircle of {v:?}"
                );
            }
        }
    }
    assert_eq!(used.iter().filter(|u| **u).count(), n_distinct);
    for (h, &twin) in tri.halfedges.iter().enumerate() {
        let org = |h: usize| triangles[h / 3][h % 3];
        let dst = |h: usize| triangles[h / 3][(h + 1) % 3];
        if twin == NO_TWIN {
            continue;
        }
        let twin = twin as usize;
        assert_eq!(tri.halfedges[twin] as usize, h);
        assert_eq!((org(h), dst(h)), (dst(twin), org(twin)));
    }
    let border = tri.halfedges.iter().filter(|t| **t == NO_TWIN).count();
    assert_eq!(border, hull.len());
    // The hull is convex (weakly: collinear points on its edges stay) and counter-clockwise.
    let h = hull.len();
    for i in 0..h {
        let [a, b, c] = [i, (i + 1) % h, (i + 2) % h].map(|k| xy(hull[k]));
        assert!(
            orient(a, b, c) >= 0.0,
            "hull turns right at {}",
            hull[(i + 1) % h]
        );
    }
}

fn grid(n: usize, step: f64) -> Vec<[f64; 2]> {
    (0..n * n)
        .map(|i| [(i % n) as f64 * step, (i / n) as f64 * step])
        .collect()
}

#[test]
fn small_cases() {
    let square = [[0.0, 0.0], [1.0, 0.0], [1.0, 1.0], [0.0, 1.0]];
    check(&square, &triangulate(&square, None).unwrap());
    let with_dups = [[0.0, 0.0], [1.0, 0.0], [0.0, 0.0], [0.0, 1.0], [1.0, 0.0]];
    let tri = triangulate(&with_dups, None).unwrap();
    assert_eq!(tri.duplicates, 2);
    assert_eq!(tri.tris.len(), 3);
    // The smallest index of each group of duplicates is kept.
    let mut v = tri.caller_triangles()[0];
    v.sort_unstable();
    assert_eq!(v, [0, 1, 3]);
    assert!(triangulate(&[[1.0, 1.0]; 4], None).is_err());
    assert!(triangulate(&[[0.0, 0.0], [1.0, 1.0], [2.0, 2.0], [0.0, 0.0]], None).is_err());
}

#[test]
fn cocircular_grids() {
    for (n, step) in [(2, 1.0), (3, 1.0), (7, 0.1), (20, 0.3)] {
        let points = grid(n, step);
        let tri = triangulate(&points, None).unwrap();
        check(&points, &tri);
        assert_eq!(tri.tris.len(), 6 * (n - 1) * (n - 1));
    }
}

#[test]
fn points_on_a_circle_and_collinear_runs() {
    let circle: Vec<[f64; 2]> = (0..64)
        .map(|i| {
            let a = i as f64 * std::f64::consts::TAU / 64.0;
            [a.cos(), a.sin()]
        })
        .collect();
    check(&circle, &triangulate(&circle, None).unwrap());
    // Exactly cocircular: the 8 compass points and the 4 + 4 Pythagorean (3, 4) points.
    let mut exact = vec![[5.0, 0.0], [0.0, 5.0], [-5.0, 0.0], [0.0, -5.0]];
    for (x, y) in [(3.0, 4.0), (4.0, 3.0)] {
        exact.extend([[x, y], [-x, y], [x, -y], [-x, -y]]);
    }
    exact.push([0.0, 0.0]);
    check(&exact, &triangulate(&exact, None).unwrap());
    let mut line: Vec<[f64; 2]> = (0..30).map(|i| [i as f64, 2.0 * i as f64]).collect();
    line.push([3.0, -1.0]);
    line.extend((0..10).map(|i| [i as f64 * 0.5, -1.0]));
    check(&line, &triangulate(&line, None).unwrap());
}

fn point() -> impl Strategy<Value = [f64; 2]> {
    (-8i32..8, -8i32..8).prop_map(|(x, y)| [f64::from(x) * 0.25, f64::from(y) * 0.25])
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(200))]

    /// Points on a coarse lattice: many duplicates, collinear runs and cocircular sets.
    #[test]
    fn lattice_points(points in proptest::collection::vec(point(), 3..60)) {
        match triangulate(&points, None) {
            Ok(tri) => check(&points, &tri),
            Err(Collinear) => {
                let a = points[0];
                let b = points.iter().find(|p| **p != a).copied().unwrap_or(a);
                prop_assert!(points.iter().all(|p| orient(a, b, *p) == 0.0));
            }
        }
    }

    #[test]
    fn random_points(points in proptest::collection::vec((-1e3f64..1e3, -1e3f64..1e3), 3..150)) {
        let points: Vec<[f64; 2]> = points.into_iter().map(|(x, y)| [x, y]).collect();
        check(&points, &triangulate(&points, None).unwrap());
    }

    /// Tiny perturbations of a grid: nearly cocircular everywhere.
    #[test]
    fn perturbed_grid(noise in proptest::collection::vec(-4i32..4, 100)) {
        let points: Vec<[f64; 2]> = grid(10, 1.0)
            .into_iter()
            .zip(&noise)
            .map(|(p, &e)| [p[0] + f64::from(e) * 1e-15, p[1] - f64::from(e) * 2e-16])
            .collect();
        check(&points, &triangulate(&points, None).unwrap());
    }
}

/// Sorted vertex triples of a triangulation, in caller indices.
fn triangle_set(triangles: &[[u32; 3]]) -> Vec<[u32; 3]> {
    let mut set: Vec<[u32; 3]> = triangles
        .iter()
        .map(|t| {
            let mut t = *t;
            t.sort_unstable();
            t
        })
        .collect();
    set.sort_unstable();
    set
}

/// Inserting in input order (most points inside the hull: the located-insertion fallback)
/// gives the same unique triangulation as the sorted sweep.
fn any_order_same_result(points: &[[f64; 2]]) {
    let mut distinct: Vec<[f64; 2]> = Vec::new();
    for p in points {
        if !distinct.contains(p) {
            distinct.push(*p);
        }
    }
    let Some(k) =
        (2..distinct.len()).find(|&k| orient(distinct[0], distinct[1], distinct[k]) != 0.0)
    else {
        return;
    };
    distinct.swap(2, k);
    if orient(distinct[0], distinct[1], distinct[2]) < 0.0 {
        distinct.swap(1, 2);
    }
    let ranks: Vec<u32> = (0..distinct.len() as u32).collect();
    let mut sweep = insert::Sweep::new(&distinct, &ranks, distinct[0]);
    for p in 3..distinct.len() as u32 {
        sweep.insert(p);
    }
    let (tris, halfedges, hull) = sweep.finish();
    let unordered = Triangulation {
        tris,
        halfedges,
        hull,
        input: ranks.clone(),
        ranks: ranks.clone(),
        coords: distinct.clone(),
        duplicates: 0,
    };
    check(&distinct, &unordered);
    let sorted = triangulate(&distinct, None).unwrap();
    assert_eq!(
        triangle_set(&unordered.caller_triangles()),
        triangle_set(&sorted.caller_triangles())
    );
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(200))]

    #[test]
    fn insertion_order_does_not_matter(points in proptest::collection::vec(point(), 3..50)) {
        any_order_same_result(&points);
    }
}

#[test]
fn insertion_order_does_not_matter_on_a_grid() {
    let mut points = grid(9, 0.5);
    // A scrambled order, deterministic.
    for i in 0..points.len() {
        let j = (i * 37 + 11) % points.len();
        points.swap(i, j);
    }
    any_order_same_result(&points);
}

//! Oracles for the exact sweep-hull Delaunay triangulation and the parallel α-complex:
//! brute-force empty circumcircles with exact in-circle tests, the delaunator crate, exact
//! tilings of cocircular grids, near-degenerate inputs, and the α-complex against the full
//! triangulation filtered by circumradius at several strip and thread counts.

#![allow(clippy::expect_used, clippy::unwrap_used, clippy::panic)]

use halfedge_mesh::{AlphaComplexOptions, HalfEdgeMesh, MeshError, NO_TWIN};
use proptest::prelude::*;
use rand::{RngExt, SeedableRng};
use rand_chacha::ChaCha8Rng;
use robust::{Coord, incircle, orient2d};

fn c(p: [f64; 3]) -> Coord<f64> {
    Coord { x: p[0], y: p[1] }
}

fn orient(a: [f64; 3], b: [f64; 3], p: [f64; 3]) -> f64 {
    orient2d(c(a), c(b), c(p))
}

/// Every triangle is counter-clockwise and no input point lies strictly inside its
/// circumcircle (exact test); every distinct point is used; the mesh is sane.
fn assert_exactly_delaunay(points: &[[f64; 2]], mesh: &HalfEdgeMesh) {
    mesh.sanity_check().unwrap();
    let v = mesh.vertices();
    let mut used = vec![false; points.len()];
    for tri in mesh.triangles() {
        let [a, b, cc] = tri.map(|i| v[i as usize]);
        assert!(orient(a, b, cc) > 0.0, "{tri:?} is not counter-clockwise");
        for &i in tri {
            used[i as usize] = true;
        }
        for p in v {
            assert!(
                incircle(c(a), c(b), c(cc), c(*p)) <= 0.0,
                "{p:?} inside the circumcircle of {tri:?}"
            );
        }
    }
    let mut distinct: Vec<(u64, u64)> = points
        .iter()
        .map(|p| (p[0].to_bits(), p[1].to_bits()))
        .collect();
    distinct.sort_unstable();
    distinct.dedup();
    assert_eq!(used.iter().filter(|u| **u).count(), distinct.len());
}

/// Sorted vertex triples.
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

/// Sorted (origin, destination) pairs of the twinned half-edges.
fn twin_pairs(mesh: &HalfEdgeMesh) -> Vec<(u32, u32)> {
    let mut pairs: Vec<(u32, u32)> = (0..mesh.halfedges().len() as u32)
        .filter(|&h| mesh.halfedges()[h as usize] != NO_TWIN)
        .map(|h| (mesh.origin(h), mesh.destination(h)))
        .collect();
    pairs.sort_unstable();
    pairs
}

fn delaunator_set(points: &[[f64; 2]]) -> Vec<[u32; 3]> {
    let input: Vec<delaunator::Point> = points
        .iter()
        .map(|p| delaunator::Point { x: p[0], y: p[1] })
        .collect();
    let result = delaunator::triangulate(&input);
    let triangles: Vec<[u32; 3]> = result
        .triangles
        .chunks_exact(3)
        .map(|t| [t[0] as u32, t[1] as u32, t[2] as u32])
        .collect();
    triangle_set(&triangles)
}

fn area(mesh: &HalfEdgeMesh) -> f64 {
    let v = mesh.vertices();
    mesh.triangles()
        .iter()
        .map(|t| 0.5 * orient(v[t[0] as usize], v[t[1] as usize], v[t[2] as usize]))
        .sum()
}

fn random_points(n: usize, seed: u64, side: f64) -> Vec<[f64; 2]> {
    let mut rng = ChaCha8Rng::seed_from_u64(seed);
    (0..n)
        .map(|_| [rng.random::<f64>() * side, rng.random::<f64>() * side])
        .collect()
}

fn grid(nx: usize, ny: usize, step: f64) -> Vec<[f64; 2]> {
    (0..nx * ny)
        .map(|i| [(i % nx) as f64 * step, (i / nx) as f64 * step])
        .collect()
}

/// The Polylidar filter's α test, from the triangle's smallest vertex.
fn within_alpha(v: &[[f64; 3]], tri: [u32; 3], alpha: f64) -> bool {
    let r = (0..3).min_by_key(|&k| tri[k]).unwrap();
    let [a, b, cc] = [0, 1, 2].map(|k| v[tri[(r + k) % 3] as usize]);
    let d2 = |p: [f64; 3], q: [f64; 3]| (p[0] - q[0]).powi(2) + (p[1] - q[1]).powi(2);
    let cross = (b[0] - a[0]) * (cc[1] - a[1]) - (b[1] - a[1]) * (cc[0] - a[0]);
    d2(a, b) * d2(b, cc) * d2(cc, a) <= 4.0 * alpha * alpha * (cross * cross)
}

/// The α-complex at several strip and thread counts equals the full triangulation filtered
/// by circumradius; counts agree; the output is identical for every thread count.
fn assert_alpha_complex_matches(points: &[[f64; 2]], alpha: f64) {
    let (full, full_report) = HalfEdgeMesh::delaunay_2d_with_report(points).unwrap();
    let v = full.vertices();
    let kept: Vec<[u32; 3]> = full
        .triangles()
        .iter()
        .copied()
        .filter(|t| within_alpha(v, *t, alpha))
        .collect();
    let expected = triangle_set(&kept);
    for strips in [0, 1, 2, 3, 4, 7] {
        let options = AlphaComplexOptions::new().strips(strips);
        let mut first: Option<HalfEdgeMesh> = None;
        for threads in [1, 2, 4] {
            let pool = rayon::ThreadPoolBuilder::new()
                .num_threads(threads)
                .build()
                .unwrap();
            let (mesh, report) = pool
                .install(|| HalfEdgeMesh::alpha_complex_2d_with_options(points, alpha, &options))
                .unwrap();
            mesh.sanity_check().unwrap();
            assert_eq!(triangle_set(mesh.triangles()), expected, "strips {strips}");
            assert_eq!(report.duplicate_points, full_report.duplicate_points);
            assert_eq!(report.delaunay_triangles, full.num_triangles());
            assert_eq!(report.dropped_alpha, full.num_triangles() - kept.len());
            // Twins: exactly the edges shared by two kept triangles.
            let mut shared: Vec<(u32, u32)> = Vec::new();
            for (t, tri) in full.triangles().iter().enumerate() {
                for k in 0..3 {
                    let h = (3 * t + k) as u32;
                    if let Some(twin) = full.twin(h)
                        && within_alpha(v, *tri, alpha)
                        && within_alpha(v, full.triangles()[twin as usize / 3], alpha)
                    {
                        shared.push((full.origin(h), full.destination(h)));
                    }
                }
            }
            shared.sort_unstable();
            assert_eq!(twin_pairs(&mesh), shared, "strips {strips}");
            // Smallest vertex first, so the Polylidar filter keeps every triangle again.
            assert!(
                mesh.triangles()
                    .iter()
                    .all(|t| t[0] < t[1] && t[0] < t[2] && within_alpha(v, *t, alpha))
            );
            match &first {
                None => first = Some(mesh),
                Some(m) => assert_eq!(&mesh, m, "strips {strips}, threads {threads}"),
            }
        }
    }
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(64))]

    #[test]
    fn random_points_are_exactly_delaunay(
        pts in proptest::collection::vec((-1e3f64..1e3, -1e3f64..1e3), 3..120),
    ) {
        let points: Vec<[f64; 2]> = pts.into_iter().map(|(x, y)| [x, y]).collect();
        let mesh = HalfEdgeMesh::delaunay_2d(&points).unwrap();
        assert_exactly_delaunay(&points, &mesh);
        // Random floats are never four cocircular: the triangulation is unique.
        prop_assert_eq!(triangle_set(mesh.triangles()), delaunator_set(&points));
    }

    /// Points on a small lattice: duplicates, collinear runs and cocircular sets.
    #[test]
    fn lattice_points_are_exactly_delaunay(
        pts in proptest::collection::vec((0i32..6, 0i32..6), 3..50),
    ) {
        let points: Vec<[f64; 2]> =
            pts.into_iter().map(|(x, y)| [f64::from(x), f64::from(y)]).collect();
        match HalfEdgeMesh::delaunay_2d(&points) {
            Ok(mesh) => assert_exactly_delaunay(&points, &mesh),
            Err(MeshError::Collinear { .. }) => {}
            Err(e) => panic!("{e}"),
        }
    }

    #[test]
    fn alpha_complex_equals_filtered_delaunay(
        seed in 0u64..1000,
        n in 3usize..400,
        alpha in 0.5f64..40.0,
    ) {
        assert_alpha_complex_matches(&random_points(n, seed, 100.0), alpha);
    }

    #[test]
    fn alpha_complex_on_lattices(
        pts in proptest::collection::vec((0i32..40, 0i32..12), 3..200),
        alpha in 0.6f64..3.0,
    ) {
        let points: Vec<[f64; 2]> =
            pts.into_iter().map(|(x, y)| [f64::from(x), f64::from(y)]).collect();
        if HalfEdgeMesh::delaunay_2d(&points).is_ok() {
            assert_alpha_complex_matches(&points, alpha);
        }
    }
}

#[test]
fn larger_random_set_matches_delaunator() {
    let points = random_points(if cfg!(debug_assertions) { 3000 } else { 30_000 }, 5, 1.0);
    let mesh = HalfEdgeMesh::delaunay_2d(&points).unwrap();
    mesh.sanity_check().unwrap();
    assert_eq!(triangle_set(mesh.triangles()), delaunator_set(&points));
}

#[test]
fn cocircular_grids_tile_exactly() {
    for (nx, ny, step) in [(2, 2, 1.0), (5, 3, 0.1), (40, 25, 0.3), (17, 17, 1e-3)] {
        let points = grid(nx, ny, step);
        let mesh = HalfEdgeMesh::delaunay_2d(&points).unwrap();
        assert_exactly_delaunay(&points, &mesh);
        assert_eq!(mesh.num_triangles(), 2 * (nx - 1) * (ny - 1));
        let hull_area = (nx - 1) as f64 * step * (ny - 1) as f64 * step;
        assert!((area(&mesh) - hull_area).abs() <= 1e-12 * hull_area.max(1.0));
    }
}

#[test]
fn near_degenerate_inputs() {
    // Points on a circle (rounded: nearly cocircular), plus its centre.
    let mut circle: Vec<[f64; 2]> = (0..200)
        .map(|i| {
            let a = i as f64 * std::f64::consts::TAU / 200.0;
            [1e3 * a.cos(), 1e3 * a.sin()]
        })
        .collect();
    circle.push([0.0, 0.0]);
    assert_exactly_delaunay(&circle, &HalfEdgeMesh::delaunay_2d(&circle).unwrap());

    // Exactly cocircular points: (±5, 0), (0, ±5), (±3, ±4), (±4, ±3).
    let mut exact = vec![[5.0, 0.0], [0.0, 5.0], [-5.0, 0.0], [0.0, -5.0]];
    for (x, y) in [(3.0, 4.0), (4.0, 3.0)] {
        exact.extend([[x, y], [-x, y], [x, -y], [-x, -y]]);
    }
    let mesh = HalfEdgeMesh::delaunay_2d(&exact).unwrap();
    assert_exactly_delaunay(&exact, &mesh);
    assert_eq!(mesh.num_triangles(), exact.len() - 2);

    // A grid moved by a few ulps: nearly cocircular everywhere.
    let mut rng = ChaCha8Rng::seed_from_u64(3);
    let jittered: Vec<[f64; 2]> = grid(30, 30, 1.0)
        .into_iter()
        .map(|p| {
            let e = |rng: &mut ChaCha8Rng| f64::from(rng.random_range(-3i32..=3)) * 1e-15;
            [p[0] + e(&mut rng), p[1] + e(&mut rng)]
        })
        .collect();
    assert_exactly_delaunay(&jittered, &HalfEdgeMesh::delaunay_2d(&jittered).unwrap());

    // Duplicates: the first of each group is kept and counted once.
    let mut dups = random_points(300, 9, 10.0);
    dups.extend_from_within(0..100);
    dups.extend_from_within(0..50);
    let (mesh, report) = HalfEdgeMesh::delaunay_2d_with_report(&dups).unwrap();
    assert_eq!(report.duplicate_points, 150);
    assert!(mesh.triangles().iter().flatten().all(|&v| v < 300));
    assert_exactly_delaunay(&dups, &mesh);

    // Collinear runs along the hull and through the interior.
    let mut runs: Vec<[f64; 2]> = (0..50).map(|i| [i as f64 * 0.5, 0.0]).collect();
    runs.extend((0..50).map(|i| [0.0, i as f64 * 0.25]));
    runs.extend((0..50).map(|i| [i as f64 * 0.3, i as f64 * 0.2]));
    runs.push([20.0, 12.0]);
    assert_exactly_delaunay(&runs, &HalfEdgeMesh::delaunay_2d(&runs).unwrap());

    // All collinear: an error, not an empty mesh.
    let line: Vec<[f64; 2]> = (0..20).map(|i| [i as f64, 3.0 * i as f64 - 1.0]).collect();
    assert_eq!(
        HalfEdgeMesh::delaunay_2d(&line),
        Err(MeshError::Collinear { count: 20 })
    );
}

#[test]
fn alpha_complex_on_grids_and_near_duplicates() {
    // Cocircular cells cut by strip boundaries.
    assert_alpha_complex_matches(&grid(40, 10, 1.0), 0.75);
    assert_alpha_complex_matches(&grid(40, 10, 1.0), 3.0);
    // Points 1e-14 α apart: the float radius test is unreliable there, so the strips give
    // way to a single one.
    let mut points = random_points(400, 11, 100.0);
    let p = points[7];
    points.push([p[0] + 1e-13, p[1]]);
    assert_alpha_complex_matches(&points, 10.0);
    let options = AlphaComplexOptions::new().strips(4);
    let (_, report) = HalfEdgeMesh::alpha_complex_2d_with_options(&points, 10.0, &options).unwrap();
    assert_eq!(report.strips, 1);
    let (_, report) =
        HalfEdgeMesh::alpha_complex_2d_with_options(&points[..400], 10.0, &options).unwrap();
    assert_eq!(report.strips, 4);
}

#[test]
fn alpha_complex_extremes_and_errors() {
    let points = random_points(200, 1, 10.0);
    let full = HalfEdgeMesh::delaunay_2d(&points).unwrap();
    let (all, report) = HalfEdgeMesh::alpha_complex_2d(&points, f64::INFINITY).unwrap();
    assert_eq!(
        triangle_set(all.triangles()),
        triangle_set(full.triangles())
    );
    assert_eq!(report.dropped_alpha, 0);
    for alpha in [0.0, -1.0, f64::NAN] {
        let (none, report) = HalfEdgeMesh::alpha_complex_2d(&points, alpha).unwrap();
        assert_eq!(none.num_triangles(), 0);
        assert_eq!(report.dropped_alpha, full.num_triangles());
    }
    assert_eq!(
        HalfEdgeMesh::alpha_complex_2d(&[[0.0, 0.0], [1.0, 1.0]], 1.0).err(),
        Some(MeshError::TooFewPoints { found: 2 })
    );
    assert_eq!(
        HalfEdgeMesh::alpha_complex_2d(&[[0.0, 0.0], [1.0, f64::NAN], [2.0, 0.0]], 1.0).err(),
        Some(MeshError::NonFinitePoint { index: 1 })
    );
    // Two parallel lines: every strip of them may be collinear, the whole set is not.
    let lines: Vec<[f64; 2]> = (0..200)
        .map(|i| [(i / 2) as f64, (i % 2) as f64 * 50.0])
        .collect();
    assert_alpha_complex_matches(&lines, 30.0);
    let line: Vec<[f64; 2]> = (0..20).map(|i| [i as f64, 2.0]).collect();
    assert_eq!(
        HalfEdgeMesh::alpha_complex_2d(&line, 1.0).err(),
        Some(MeshError::Collinear { count: 20 })
    );
}

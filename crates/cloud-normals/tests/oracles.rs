//! The crate against independent oracles: brute-force neighbours, nalgebra's symmetric
//! eigen-decomposition, known planes, and a brute-force voxel grouping.

use cloud_normals::{
    Neighbours, NormalsError, Orientation, estimate_normals, neighbourhood_noise, orient,
    plane_normal, smallest_eigenvector, voxel_downsample,
};
use nalgebra::{Matrix3, SymmetricEigen};
use proptest::prelude::*;
use rand::{RngExt, SeedableRng};
use rand_chacha::ChaCha8Rng;

fn d2(a: [f64; 3], b: [f64; 3]) -> f64 {
    (0..3).map(|i| (a[i] - b[i]).powi(2)).sum()
}

fn random_cloud(n: usize, seed: u64) -> Vec<[f64; 3]> {
    let mut rng = ChaCha8Rng::seed_from_u64(seed);
    (0..n)
        .map(|_| {
            [
                rng.random_range(-5.0..5.0),
                rng.random_range(-5.0..5.0),
                rng.random_range(-5.0..5.0),
            ]
        })
        .collect()
}

#[test]
fn neighbours_match_brute_force_distances() {
    let points = random_cloud(500, 1);
    let k = 9;
    let knn = Neighbours::new(&points, k).unwrap();
    for (i, p) in points.iter().enumerate() {
        let mut all: Vec<f64> = points.iter().map(|q| d2(*p, *q)).collect();
        all.sort_by(f64::total_cmp);
        let found: Vec<f64> = knn
            .of(i)
            .iter()
            .map(|&j| d2(*p, points[j as usize]))
            .collect();
        for (a, b) in found.iter().zip(&all[..k]) {
            assert!(
                (a - b).abs() < 1e-12,
                "point {i}: {found:?} vs {:?}",
                &all[..k]
            );
        }
        assert_eq!(knn.of(i)[0] as usize, i);
    }
}

/// Brute force: the `k` nearest of `points[i]`, by (squared distance, index).
fn brute_force(points: &[[f64; 3]], i: usize, k: usize) -> Vec<u32> {
    let mut all: Vec<(f64, u32)> = points
        .iter()
        .enumerate()
        .map(|(j, q)| (d2(points[i], *q), j as u32))
        .collect();
    all.sort_by(|a, b| a.0.total_cmp(&b.0).then(a.1.cmp(&b.1)));
    all[..k].iter().map(|&(_, j)| j).collect()
}

#[test]
fn neighbours_on_surfaces_with_duplicates_and_outliers_are_the_brute_force_ones() {
    // Two faces of a box on a grid (many equal distances), some points repeated, a
    // sparse scatter of far points (their neighbours lie beyond the 27 cells).
    let mut rng = ChaCha8Rng::seed_from_u64(7);
    let mut points = Vec::new();
    for i in 0..20 {
        for j in 0..20 {
            let (u, v) = (0.1 * f64::from(i), 0.1 * f64::from(j));
            points.push([u, v, 0.0]);
            points.push([u, 0.0, v + rng.random_range(0.0..0.01)]);
        }
    }
    for i in 0..50 {
        points.push(points[i * 7]);
    }
    for _ in 0..20 {
        points.push([
            rng.random_range(-20.0..20.0),
            rng.random_range(-20.0..20.0),
            rng.random_range(5.0..20.0),
        ]);
    }
    for k in [1, 13] {
        let knn = Neighbours::new(&points, k).unwrap();
        for i in 0..points.len() {
            assert_eq!(knn.of(i), brute_force(&points, i, k), "point {i}, k {k}");
        }
    }
}

#[test]
fn neighbours_among_many_copies_and_far_outliers_are_the_brute_force_ones() {
    // A random cloud with long runs of one position (longer than k, so capped in the
    // grid), far outliers on every side (beyond the grid's robust extent, clamped into
    // its border cells) and a near-overflow one.
    let mut rng = ChaCha8Rng::seed_from_u64(11);
    for seed in 0..3 {
        let mut points = random_cloud(1000, seed);
        for copies in [40, 13, 300] {
            let at = rng.random_range(0..points.len());
            let p = points[at];
            for _ in 0..copies {
                let at = rng.random_range(0..points.len());
                points.insert(at, p);
            }
        }
        for far in [4.2e19, -3.0e12, 1.0e150, 8.0e3] {
            let axis = rng.random_range(0..3);
            let mut p = points[rng.random_range(0..points.len())];
            p[axis] = far;
            points.insert(rng.random_range(0..points.len()), p);
        }
        let ks = [1, 12, 40];
        let found: Vec<Neighbours> = ks
            .iter()
            .map(|&k| Neighbours::new(&points, k).unwrap())
            .collect();
        for i in 0..points.len() {
            let all = brute_force(&points, i, 40);
            for (knn, k) in found.iter().zip(ks) {
                assert_eq!(knn.of(i), &all[..k], "seed {seed}, point {i}, k {k}");
            }
        }
    }
}

#[test]
fn pca_normals_of_a_noisy_tilted_plane_match_it() {
    // The plane through c with normal n, sampled on a jittered grid with 1 mm noise.
    let n = {
        let v: [f64; 3] = [0.3, -0.5, 0.8];
        let l = v.iter().map(|c| c * c).sum::<f64>().sqrt();
        v.map(|c| c / l)
    };
    let e1 = {
        let v = [n[1], -n[0], 0.0];
        let l = (v[0] * v[0] + v[1] * v[1]).sqrt();
        v.map(|c| c / l)
    };
    let e2 = [
        n[1] * e1[2] - n[2] * e1[1],
        n[2] * e1[0] - n[0] * e1[2],
        n[0] * e1[1] - n[1] * e1[0],
    ];
    let mut rng = ChaCha8Rng::seed_from_u64(3);
    let points: Vec<[f64; 3]> = (0..2500)
        .map(|i| {
            let (u, v) = (0.02 * (i % 50) as f64, 0.02 * (i / 50) as f64);
            let w = rng.random_range(-0.001..0.001);
            std::array::from_fn(|a| 1.0 + u * e1[a] + v * e2[a] + w * n[a])
        })
        .collect();
    let mut normals = estimate_normals(&points, &Neighbours::new(&points, 16).unwrap());
    orient(
        &points,
        &mut normals,
        Orientation::Towards([10.0 * n[0], 10.0 * n[1], 10.0 * n[2]]),
    )
    .unwrap();
    for normal in &normals {
        let cos = normal.iter().zip(&n).map(|(a, b)| a * b).sum::<f64>();
        assert!(cos > 0.995, "normal {normal:?} vs {n:?}");
    }
}

#[test]
fn degenerate_neighbourhoods_have_no_normal() {
    let line: Vec<[f64; 3]> = (0..5).map(|i| [i as f64, 2.0 * i as f64, 0.0]).collect();
    assert_eq!(plane_normal(line.iter().copied()), None);
    assert_eq!(plane_normal([[1.0, 1.0, 1.0]; 4].into_iter()), None);
    assert_eq!(plane_normal([[0.0; 3], [1.0, 0.0, 0.0]].into_iter()), None);
}

#[test]
fn orientation_along_up_makes_walls_agree() {
    let points = [[0.0; 3]; 4];
    let mut normals = [
        [0.0, 0.0, -1.0],
        [-1.0, 0.0, 0.0],
        [1.0, 0.0, 0.05],
        [0.0, -1.0, 0.0],
    ];
    orient(&points, &mut normals, Orientation::Along([0.0, 0.0, 1.0])).unwrap();
    assert_eq!(normals[0], [0.0, 0.0, 1.0]);
    assert_eq!(normals[1], [1.0, 0.0, 0.0]);
    assert_eq!(normals[2], [1.0, 0.0, 0.05]);
    assert_eq!(normals[3], [0.0, 1.0, 0.0]);
    assert!(orient(&points, &mut normals, Orientation::Along([0.0; 3])).is_err());
}

#[test]
fn bad_clouds_are_errors() {
    assert_eq!(Neighbours::new(&[], 5), Err(NormalsError::Empty));
    assert!(matches!(
        Neighbours::new(&[[0.0, f64::NAN, 0.0]], 5),
        Err(NormalsError::NonFinite { index: 0, .. })
    ));
    assert!(matches!(
        voxel_downsample(&[[0.0; 3]], 0.0),
        Err(NormalsError::BadVoxelSize { .. })
    ));
    assert!(matches!(
        voxel_downsample(&[[0.0; 3], [1e9, 0.0, 0.0]], 1e-3),
        Err(NormalsError::TooManyVoxels { .. })
    ));
}

/// A tilted 60 × 60 plane on a grid of step `h` with uniform noise of `±amplitude` along
/// its normal, moved by a rotation and a far offset.
fn noisy_plane(h: f64, amplitude: f64, seed: u64) -> Vec<[f64; 3]> {
    let mut rng = ChaCha8Rng::seed_from_u64(seed);
    let (c, s) = (0.6f64, 0.8f64);
    (0..3600)
        .map(|i| {
            let (u, v) = (h * (i % 60) as f64, h * (i / 60) as f64);
            let w = amplitude * rng.random_range(-1.0..1.0);
            // Rotated about x by the angle of cos 0.6, then offset.
            [u + 1e3, c * v - s * w + 2e3, s * v + c * w - 5e2]
        })
        .collect()
}

/// The noise estimate from its definition with nalgebra's eigenvalues: the median over
/// every point of `√λ₀ / (λ₁λ₂)^¼` of its neighbourhood.
fn noise_by_nalgebra(points: &[[f64; 3]], knn: &Neighbours) -> f64 {
    let mut values: Vec<f64> = (0..points.len())
        .map(|i| {
            let around: Vec<[f64; 3]> = knn.of(i).iter().map(|&v| points[v as usize]).collect();
            let n = around.len() as f64;
            let mean: [f64; 3] =
                std::array::from_fn(|a| around.iter().map(|p| p[a]).sum::<f64>() / n);
            let mut m = Matrix3::zeros();
            for p in &around {
                let d = nalgebra::Vector3::new(p[0] - mean[0], p[1] - mean[1], p[2] - mean[2]);
                m += d * d.transpose() / n;
            }
            let mut e: Vec<f64> = SymmetricEigen::new(m).eigenvalues.iter().copied().collect();
            e.sort_by(f64::total_cmp);
            e[0].max(0.0).sqrt() / (e[1] * e[2]).sqrt().sqrt()
        })
        .collect();
    values.sort_by(f64::total_cmp);
    values[values.len() / 2]
}

#[test]
fn noise_estimate_matches_its_definition_and_grows_with_the_noise() {
    let mut last = 0.0;
    for (step, amplitude) in [0.0, 0.002, 0.005, 0.01, 0.02].into_iter().enumerate() {
        let points = noisy_plane(0.01, amplitude, step as u64);
        let knn = Neighbours::new(&points, 12).unwrap();
        // 3600 points: every one is sampled.
        let estimate = neighbourhood_noise(&points, &knn).unwrap();
        let oracle = noise_by_nalgebra(&points, &knn);
        assert!(
            (estimate - oracle).abs() <= 1e-6 * oracle.max(1e-3),
            "{estimate} vs {oracle}"
        );
        if amplitude == 0.0 {
            assert!(estimate < 1e-5, "noise-free: {estimate}");
        } else {
            assert!(estimate > last, "{amplitude}: {estimate} after {last}");
        }
        last = estimate;
    }
}

#[test]
fn noise_estimate_does_not_depend_on_the_unit_or_the_spacing() {
    // The same plane in metres and in millimetres, and sampled twice as densely with the
    // noise scaled alike: one estimate.
    let metres = noisy_plane(0.01, 0.004, 7);
    let millimetres: Vec<[f64; 3]> = metres.iter().map(|p| p.map(|c| c * 1e3)).collect();
    let dense = noisy_plane(0.005, 0.002, 7);
    let e = |points: &[[f64; 3]]| {
        neighbourhood_noise(points, &Neighbours::new(points, 12).unwrap()).unwrap()
    };
    let (a, b, c) = (e(&metres), e(&millimetres), e(&dense));
    assert!((a - b).abs() < 1e-9 * a, "{a} vs {b}");
    assert!((a - c).abs() < 1e-9 * a, "{a} vs {c}");
}

#[test]
fn noise_estimate_of_a_line_is_none() {
    let line: Vec<[f64; 3]> = (0..50).map(|i| [i as f64, 2.0 * i as f64, 0.0]).collect();
    assert_eq!(
        neighbourhood_noise(&line, &Neighbours::new(&line, 6).unwrap()),
        None
    );
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(200))]

    /// The closed form against nalgebra's symmetric eigen-decomposition.
    #[test]
    fn smallest_eigenvector_matches_nalgebra(c in prop::array::uniform6(-1.0f64..1.0)) {
        // A covariance: M Mᵀ is symmetric positive semi-definite.
        let m = Matrix3::new(c[0], c[1], c[2], c[3], c[4], c[5], c[1] * c[4], c[0] - c[5], 0.5);
        let a = m * m.transpose();
        let eigen = SymmetricEigen::new(a);
        let mut order = [0usize, 1, 2];
        order.sort_by(|&i, &j| eigen.eigenvalues[i].total_cmp(&eigen.eigenvalues[j]));
        let gap = eigen.eigenvalues[order[1]] - eigen.eigenvalues[order[0]];
        prop_assume!(gap > 1e-6 * a.trace());
        let entries = [a[(0, 0)], a[(1, 1)], a[(2, 2)], a[(0, 1)], a[(0, 2)], a[(1, 2)]];
        let (v, ratio) = smallest_eigenvector(entries).unwrap();
        let expected = eigen.eigenvectors.column(order[0]);
        let cos = (v[0] * expected[0] + v[1] * expected[1] + v[2] * expected[2]).abs();
        prop_assert!(cos > 1.0 - 1e-6, "{v:?} vs {expected:?}");
        prop_assert!((ratio - eigen.eigenvalues[order[0]].max(0.0) / a.trace()).abs() < 1e-8);
    }

    /// Voxels against a direct grouping of the points by their cell.
    #[test]
    fn voxels_group_points_by_cell(seed in 0u64..1000, size in 0.2f64..3.0) {
        let points = random_cloud(300, seed);
        let voxels = voxel_downsample(&points, size).unwrap();
        let min: [f64; 3] = std::array::from_fn(|a| points.iter().map(|p| p[a]).fold(f64::INFINITY, f64::min));
        let cell = |p: &[f64; 3]| -> [i64; 3] { std::array::from_fn(|a| ((p[a] - min[a]) / size).floor() as i64) };
        let mut cells: Vec<[i64; 3]> = points.iter().map(cell).collect();
        cells.sort();
        cells.dedup();
        prop_assert_eq!(voxels.representatives.len(), cells.len());
        for (i, p) in points.iter().enumerate() {
            let rep = voxels.representatives[voxels.voxel_of[i] as usize];
            prop_assert_eq!(cell(p), cell(&points[rep as usize]));
        }
    }
}

//! Shared helpers of the integration tests: seeded clouds and independent `f64` oracles.
#![allow(dead_code, clippy::expect_used)] // each test binary uses a different subset

use opc_mesh::OrganizedPointCloud;
use rand::{RngExt, SeedableRng};
use rand_chacha::ChaCha8Rng;

/// A wavy surface seen as a range image (`spacing` between pixels), with Gaussian-ish
/// noise of amplitude `noise`, a random fraction `holes` of NaN pixels and one NaN block.
pub fn wavy_cloud(
    rows: usize,
    cols: usize,
    seed: u64,
    noise: f64,
    holes: f64,
) -> OrganizedPointCloud {
    let mut rng = ChaCha8Rng::seed_from_u64(seed);
    let spacing = 0.02;
    let mut points = Vec::with_capacity(rows * cols);
    for r in 0..rows {
        for c in 0..cols {
            let (x, y) = (c as f64 * spacing, r as f64 * spacing);
            let z = 2.0 + 0.3 * (3.0 * x).sin() * (2.0 * y).cos();
            let jitter = |rng: &mut ChaCha8Rng| noise * (rng.random::<f64>() - 0.5) * 2.0;
            let p = [
                x + jitter(&mut rng),
                y + jitter(&mut rng),
                z + jitter(&mut rng),
            ];
            points.push(if rng.random::<f64>() < holes {
                [f64::NAN; 3]
            } else {
                p
            });
        }
    }
    if rows > 8 && cols > 8 {
        let (r0, c0) = (rng.random_range(0..rows - 4), rng.random_range(0..cols - 4));
        for r in r0..r0 + 3 {
            for c in c0..c0 + 4 {
                points[r * cols + c] = [f64::NAN; 3];
            }
        }
    }
    OrganizedPointCloud::new(rows, cols, points).expect("rows × cols points")
}

/// The plane `z = 1 + 0.1 x + 0.2 y` sampled on a regular grid.
pub fn planar_grid(rows: usize, cols: usize) -> OrganizedPointCloud {
    let points = (0..rows * cols)
        .map(|i| {
            let (x, y) = ((i % cols) as f64 * 0.05, (i / cols) as f64 * 0.05);
            [x, y, 1.0 + 0.1 * x + 0.2 * y]
        })
        .collect();
    OrganizedPointCloud::new(rows, cols, points).expect("rows × cols points")
}

fn valid(p: &[f64; 3]) -> bool {
    p.iter().all(|v| v.is_finite())
}

fn sub(a: [f64; 3], b: [f64; 3]) -> [f64; 3] {
    [a[0] - b[0], a[1] - b[1], a[2] - b[2]]
}

fn norm2(a: [f64; 3]) -> f64 {
    a[0] * a[0] + a[1] * a[1] + a[2] * a[2]
}

/// Brute-force `f64` Laplacian straight from the formula, skipping NaN neighbours.
pub fn laplacian_oracle(
    cloud: &OrganizedPointCloud,
    kernel: usize,
    lambda: f64,
    iterations: u32,
    eps: f64,
) -> Vec<[f64; 3]> {
    let (rows, cols) = (cloud.rows(), cloud.cols());
    let h = kernel / 2;
    let mut cur = cloud.points().to_vec();
    for _ in 0..iterations {
        let mut next = cur.clone();
        for r in h..rows.saturating_sub(h) {
            for c in h..cols.saturating_sub(h) {
                let v = cur[r * cols + c];
                if !valid(&v) {
                    continue;
                }
                let (mut s, mut sw) = ([0.0; 3], 0.0);
                for rr in r - h..=r + h {
                    for cc in c - h..=c + h {
                        let q = cur[rr * cols + cc];
                        if (rr, cc) == (r, c) || !valid(&q) {
                            continue;
                        }
                        let w = 1.0 / (norm2(sub(v, q)).sqrt() + eps);
                        sw += w;
                        for k in 0..3 {
                            s[k] += w * q[k];
                        }
                    }
                }
                if sw > 0.0 {
                    next[r * cols + c] = [0, 1, 2].map(|k| v[k] + lambda * (s[k] / sw - v[k]));
                }
            }
        }
        cur = next;
    }
    cur
}

/// Brute-force `f64` bilateral filter on the implicit mesh, straight from the formula and
/// `grid::slot_vertices`; missing slots are `None`.
pub fn bilateral_oracle(
    cloud: &OrganizedPointCloud,
    kernel: usize,
    sigma_l: f64,
    sigma_a: f64,
    iterations: u32,
) -> Vec<Option<[f64; 3]>> {
    let (rows, cols) = (cloud.rows(), cloud.cols());
    let (cr, cc) = (rows - 1, cols - 1);
    let pts = cloud.points();
    let mut normals = vec![None; 2 * cr * cc];
    let mut centroids = vec![[0.0; 3]; 2 * cr * cc];
    for r in 0..cr {
        for c in 0..cc {
            for k in 0..2 {
                let s = mesh_smooth_gpu::grid::slot(cols, r, c, k);
                let [a, b, d] =
                    mesh_smooth_gpu::grid::slot_vertices(cols, r, c, k).map(|i| pts[i as usize]);
                if !(valid(&a) && valid(&b) && valid(&d)) {
                    continue;
                }
                let n = halfedge_mesh::cross_normal(a, b, d);
                let len = norm2(n).sqrt();
                normals[s] = Some(if len > 0.0 {
                    n.map(|x| x / len)
                } else {
                    [0.0; 3]
                });
                centroids[s] = [0, 1, 2].map(|i| (a[i] + b[i] + d[i]) / 3.0);
            }
        }
    }
    let h = kernel / 2;
    for _ in 0..iterations {
        let mut next = normals.clone();
        for r in h..cr.saturating_sub(h) {
            for c in h..cc.saturating_sub(h) {
                for k in 0..2 {
                    let s = 2 * (r * cc + c) + k;
                    let Some(n) = normals[s] else { continue };
                    let mut acc = [0.0; 3];
                    for rr in r - h..=r + h {
                        for c2 in c - h..=c + h {
                            if (rr, c2) == (r, c) {
                                continue;
                            }
                            for k2 in 0..2 {
                                let j = 2 * (rr * cc + c2) + k2;
                                let Some(nj) = normals[j] else { continue };
                                let w = (-norm2(sub(centroids[s], centroids[j]))
                                    / (sigma_l * sigma_l))
                                    .exp()
                                    * (-norm2(sub(n, nj)) / (sigma_a * sigma_a)).exp();
                                for i in 0..3 {
                                    acc[i] += w * nj[i];
                                }
                            }
                        }
                    }
                    let len = norm2(acc).sqrt();
                    if len > 0.0 {
                        next[s] = Some(acc.map(|x| x / len));
                    }
                }
            }
        }
        normals = next;
    }
    normals
}

/// Largest difference between two clouds relative to `1 + |coordinate|`; NaN must match NaN.
pub fn max_relative_difference(a: &[[f64; 3]], b: &[[f64; 3]]) -> f64 {
    assert_eq!(a.len(), b.len());
    let mut worst = 0.0f64;
    for (i, (p, q)) in a.iter().zip(b).enumerate() {
        for k in 0..3 {
            if p[k].is_nan() || q[k].is_nan() {
                assert!(p[k].is_nan() && q[k].is_nan(), "point {i}: {p:?} vs {q:?}");
                continue;
            }
            worst = worst.max((p[k] - q[k]).abs() / (1.0 + q[k].abs()));
        }
    }
    worst
}

/// Largest component-wise difference between two sets of slot normals; missing must
/// match missing.
pub fn max_normal_difference(a: &[[f32; 3]], b: &[[f32; 3]]) -> f64 {
    assert_eq!(a.len(), b.len());
    let mut worst = 0.0f64;
    for (i, (p, q)) in a.iter().zip(b).enumerate() {
        assert_eq!(p[0].is_nan(), q[0].is_nan(), "slot {i}: {p:?} vs {q:?}");
        if p[0].is_nan() {
            continue;
        }
        for k in 0..3 {
            worst = worst.max(f64::from((p[k] - q[k]).abs()));
        }
    }
    worst
}

/// Bit patterns of a cloud, for exact comparison (NaN == NaN).
pub fn bits(points: &[[f64; 3]]) -> Vec<[u64; 3]> {
    points.iter().map(|p| p.map(f64::to_bits)).collect()
}

/// Bit patterns of slot normals.
pub fn normal_bits(normals: &[[f32; 3]]) -> Vec<[u32; 3]> {
    normals.iter().map(|n| n.map(f32::to_bits)).collect()
}

//! Group assignment against a brute-force scan over all dominant normals.
#![allow(clippy::expect_used, clippy::unwrap_used, clippy::panic)]

use halfedge_mesh::HalfEdgeMesh;
use planeseg::{NO_GROUP, SegmentationConfig, assign_groups};
use proptest::prelude::*;

fn unit(v: [f64; 3]) -> [f64; 3] {
    let len = (v[0] * v[0] + v[1] * v[1] + v[2] * v[2]).sqrt();
    v.map(|c| c / len)
}

/// One small triangle per normal, each with exactly that (unit) normal.
fn triangles_with_normals(normals: &[[f64; 3]]) -> HalfEdgeMesh {
    let mut vertices = Vec::new();
    let mut triangles = Vec::new();
    for (i, &n) in normals.iter().enumerate() {
        // Two unit vectors spanning the plane orthogonal to n, right-handed with n.
        let helper = if n[0].abs() < 0.9 {
            [1.0, 0.0, 0.0]
        } else {
            [0.0, 1.0, 0.0]
        };
        let cross = |a: [f64; 3], b: [f64; 3]| {
            [
                a[1] * b[2] - a[2] * b[1],
                a[2] * b[0] - a[0] * b[2],
                a[0] * b[1] - a[1] * b[0],
            ]
        };
        let e1 = unit(cross(helper, n));
        let e2 = cross(n, e1);
        let o = [10.0 * i as f64, 0.0, 0.0];
        vertices.push(o);
        vertices.push([0, 1, 2].map(|k| o[k] + e1[k]));
        vertices.push([0, 1, 2].map(|k| o[k] + e2[k]));
        let b = 3 * i as u32;
        triangles.push([b, b + 1, b + 2]);
    }
    HalfEdgeMesh::from_triangles(vertices, triangles).unwrap()
}

fn direction() -> impl Strategy<Value = [f64; 3]> {
    (-1.0f64..1.0, -1.0f64..1.0, -1.0f64..1.0)
        .prop_filter("not too short", |(x, y, z)| x * x + y * y + z * z > 0.01)
        .prop_map(|(x, y, z)| unit([x, y, z]))
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(64))]

    #[test]
    fn nearest_dominant_normal_matches_brute_force(
        dominant in proptest::collection::vec(direction(), 1..40),
        // Some dominant normals nudged slightly off others: near ties and close pairs.
        nudges in proptest::collection::vec((0usize..40, -0.02f64..0.02, -0.02f64..0.02), 0..8),
        normals in proptest::collection::vec(direction(), 1..400),
        norm_thresh in -1.0f64..1.0,
        // Few dominant normals (at most 4), some tens, or more than the kernel scans
        // (its cube-map table then answers).
        size in 0u8..3,
        more in proptest::collection::vec(direction(), 70),
    ) {
        let (mut dominant, mut nudges) = (dominant, nudges);
        match size {
            0 => {
                dominant.truncate(2);
                nudges.truncate(2);
            }
            1 => {}
            _ => dominant.extend(more),
        }
        for (i, dx, dy) in nudges {
            let d = dominant[i % dominant.len()];
            dominant.push(unit([d[0] + dx, d[1] + dy, d[2]]));
        }
        // Triangle normals near the dominant ones too, where the choice is hardest.
        let mut normals = normals;
        for (i, d) in dominant.iter().enumerate() {
            normals.push(unit([d[0] + 1e-3 * (i % 3) as f64, d[1], d[2] - 1e-3]));
        }
        let mesh = triangles_with_normals(&normals);
        let config = SegmentationConfig::new().with_lmax(0.0).with_norm_thresh(norm_thresh);
        let (groups, counts) = assign_groups(&mesh, &dominant, &config).unwrap();
        let got_normals = mesh.triangle_normals().unwrap();
        for (t, n) in got_normals.iter().enumerate() {
            let mut best = (NO_GROUP, f64::NEG_INFINITY);
            for (j, d) in dominant.iter().enumerate() {
                let dot = n[0] * d[0] + n[1] * d[1] + n[2] * d[2];
                if dot > best.1 {
                    best = (j as u32, dot);
                }
            }
            let expected = if best.1 >= norm_thresh { best.0 } else { NO_GROUP };
            prop_assert_eq!(groups[t], expected, "triangle {} normal {:?}", t, n);
        }
        prop_assert_eq!(counts.grouped + counts.dropped_normal, normals.len());
    }
}

/// The normal test comes first: a triangle far from every dominant normal counts as
/// dropped by the normal whatever its edges; `lmax` counts only the others.
#[test]
fn counts_attribute_each_dropped_triangle_to_one_test() {
    // Triangle legs are 1 long (hypotenuse √2): lmax 1.2 drops every triangle by length.
    let normals = [[0.0, 0.0, 1.0], [1.0, 0.0, 0.0], [0.0, 0.0, 1.0]];
    let mesh = triangles_with_normals(&normals);
    let config = SegmentationConfig::new()
        .with_lmax(1.2)
        .with_norm_thresh(0.9);
    let (groups, counts) = assign_groups(&mesh, &[[0.0, 0.0, 1.0]], &config).unwrap();
    assert_eq!(groups, vec![NO_GROUP; 3]);
    assert_eq!(
        (counts.dropped_normal, counts.dropped_lmax, counts.grouped),
        (1, 2, 0)
    );
    let config = config.with_lmax(1.5);
    let (groups, counts) = assign_groups(&mesh, &[[0.0, 0.0, 1.0]], &config).unwrap();
    assert_eq!(groups, vec![0, NO_GROUP, 0]);
    assert_eq!(
        (counts.dropped_normal, counts.dropped_lmax, counts.grouped),
        (1, 0, 2)
    );
}

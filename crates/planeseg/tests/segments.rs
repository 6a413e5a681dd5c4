//! Segmentation against a serial brute-force oracle, on scenes with known planes, with
//! many dominant normals, at several thread counts, and with bad input.
#![allow(clippy::expect_used, clippy::unwrap_used, clippy::panic)]

use halfedge_mesh::{HalfEdgeMesh, NO_TWIN};
use planeseg::{
    NO_GROUP, SegmentError, SegmentationConfig, Segmenter, assign_groups, geometric_plane, segment,
};
use proptest::prelude::*;

/// A height field on an `n × n` grid of unit cells, triangulated as a user mesh.
fn terrain(n: usize, height: impl Fn(usize, usize) -> f64) -> HalfEdgeMesh {
    terrain_at(n, [0.0; 3], height)
}

/// [`terrain`] moved by `origin`.
fn terrain_at(n: usize, origin: [f64; 3], height: impl Fn(usize, usize) -> f64) -> HalfEdgeMesh {
    let vertices = (0..=n)
        .flat_map(|r| (0..=n).map(move |c| (r, c)))
        .map(|(r, c)| [c as f64, r as f64, height(r, c)])
        .map(|p| [0, 1, 2].map(|k| origin[k] + p[k]))
        .collect();
    HalfEdgeMesh::from_triangles(vertices, test_fixtures::grid_triangles(n)).unwrap()
}

/// The serial oracle: Alg. 4 and 5 written as plainly as possible.
fn oracle(
    mesh: &HalfEdgeMesh,
    dominant: &[[f64; 3]],
    config: &SegmentationConfig,
) -> Vec<(u32, Vec<u32>)> {
    let (groups, _) = assign_groups(mesh, dominant, config).unwrap();
    let v = mesh.vertices();
    let centroid = |t: usize| {
        let [a, b, c] = mesh.triangles()[t].map(|i| v[i as usize]);
        [0, 1, 2].map(|k| (a[k] + b[k] + c[k]) / 3.0)
    };
    let mut label = vec![false; groups.len()];
    let mut segments = Vec::new();
    for seed in 0..groups.len() {
        let g = groups[seed];
        if g == NO_GROUP || label[seed] {
            continue;
        }
        let n = dominant[g as usize];
        let off = |t: usize| {
            let c = centroid(t);
            n[0] * c[0] + n[1] * c[1] + n[2] * c[2]
        };
        let mut segment = vec![seed as u32];
        label[seed] = true;
        let mut i = 0;
        while i < segment.len() {
            let t = segment[i] as usize;
            i += 1;
            for h in 3 * t..3 * t + 3 {
                let twin = mesh.halfedges()[h];
                if twin == NO_TWIN {
                    continue;
                }
                let m = (twin / 3) as usize;
                if groups[m] == g
                    && !label[m]
                    && (config.z_thresh == 0.0 || (off(m) - off(seed)).abs() <= config.z_thresh)
                {
                    label[m] = true;
                    segment.push(m as u32);
                }
            }
        }
        if segment.len() >= config.min_triangles.max(1) {
            segments.push((g, segment));
        }
    }
    segments.sort_by_key(|(g, s)| (*g, s[0]));
    segments
}

#[test]
fn a_raised_block_is_a_hole_in_the_floor_and_a_segment_of_its_own() {
    let mesh = terrain(20, |r, c| {
        if (8..=12).contains(&r) && (8..=12).contains(&c) {
            0.5
        } else {
            0.0
        }
    });
    let config = SegmentationConfig::new()
        .with_lmax(2.0)
        .with_min_triangles(10)
        .with_norm_thresh(0.95);
    let found = segment(&mesh, &[[0.0, 0.0, 1.0]], &config).unwrap();
    assert_eq!(found.segments.len(), 2);
    let floor = &found.segments[0];
    assert_eq!(floor.polygon.holes.len(), 1);
    assert_eq!(floor.polygon.shell.len(), 80);
    let top = &found.segments[1];
    assert_eq!(top.triangles.len(), 2 * 4 * 4);
    assert!((top.centroid[2] - 0.5).abs() < 1e-12);
    assert!((top.normal[2] - 1.0).abs() < 1e-12);
}

#[test]
fn z_thresh_splits_a_gentle_step() {
    // A 0.05 step over one cell: its triangles are nearly flat, so only z_thresh splits.
    let mesh = terrain(20, |_, c| if c >= 10 { 0.05 } else { 0.0 });
    let base = SegmentationConfig::new()
        .with_min_triangles(10)
        .with_norm_thresh(0.99);
    assert_eq!(
        segment(&mesh, &[[0.0, 0.0, 1.0]], &base)
            .unwrap()
            .segments
            .len(),
        1
    );
    let split = segment(&mesh, &[[0.0, 0.0, 1.0]], &base.with_z_thresh(0.02)).unwrap();
    assert_eq!(split.segments.len(), 2);
    assert_eq!(
        split.segments,
        segment(&mesh, &[[0.0, 0.0, 1.0]], &base.with_z_thresh(0.02))
            .unwrap()
            .segments
    );
}

#[test]
fn more_than_254_dominant_normals() {
    // 300 separate quads, each facing its own direction on a Fibonacci sphere.
    let count = 300;
    let golden = std::f64::consts::PI * (3.0 - 5f64.sqrt());
    let mut normals = Vec::new();
    let mut vertices = Vec::new();
    let mut triangles = Vec::new();
    for i in 0..count {
        let z = 1.0 - 2.0 * (i as f64 + 0.5) / count as f64;
        let r = (1.0 - z * z).sqrt();
        let n = [
            r * (golden * i as f64).cos(),
            r * (golden * i as f64).sin(),
            z,
        ];
        let a = if n[0].abs() < 0.9 {
            [1.0, 0.0, 0.0]
        } else {
            [0.0, 1.0, 0.0]
        };
        let d = a[0] * n[0] + a[1] * n[1] + a[2] * n[2];
        let e1 = [a[0] - d * n[0], a[1] - d * n[1], a[2] - d * n[2]];
        let l = (e1[0] * e1[0] + e1[1] * e1[1] + e1[2] * e1[2]).sqrt();
        let e1 = e1.map(|x| x / l);
        let e2 = [
            n[1] * e1[2] - n[2] * e1[1],
            n[2] * e1[0] - n[0] * e1[2],
            n[0] * e1[1] - n[1] * e1[0],
        ];
        let center = [10.0 * i as f64, 0.0, 0.0];
        let base = vertices.len() as u32;
        for (u, v) in [(0.0, 0.0), (1.0, 0.0), (1.0, 1.0), (0.0, 1.0)] {
            vertices.push([0, 1, 2].map(|k| center[k] + u * e1[k] + v * e2[k]));
        }
        triangles.extend([[base, base + 1, base + 2], [base, base + 2, base + 3]]);
        normals.push(n);
    }
    let mesh = HalfEdgeMesh::from_triangles(vertices, triangles).unwrap();
    let config = SegmentationConfig::new()
        .with_min_triangles(2)
        .with_norm_thresh(0.999);
    let found = segment(&mesh, &normals, &config).unwrap();
    assert_eq!(found.segments.len(), count);
    for (i, s) in found.segments.iter().enumerate() {
        assert_eq!(s.group as usize, i);
        assert_eq!(s.polygon.shell.len(), 4);
    }
}

/// A segmenter reused over meshes of different sizes and dominant normals, and after a
/// failed call, gives what fresh calls give.
#[test]
fn a_reused_segmenter_matches_fresh_calls() {
    let config = SegmentationConfig::new()
        .with_lmax(2.0)
        .with_min_triangles(3)
        .with_z_thresh(0.2);
    let block = |r: usize, c: usize| f64::from(u8::from((4..9).contains(&r) && c > 6));
    let len = (0.3f64 * 0.3 * 2.0 + 1.0).sqrt();
    let ramp = [-0.3 / len, -0.3 / len, 1.0 / len];
    let cases = [
        (terrain(20, block), vec![[0.0, 0.0, 1.0]]),
        (
            terrain(7, |r, c| 0.3 * (r + c) as f64),
            vec![[0.0, 0.0, 1.0], ramp],
        ),
        (
            terrain(20, block),
            vec![[0.0, 0.0, 1.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]],
        ),
    ];
    let mut segmenter = Segmenter::new();
    for (mesh, dominant) in cases.iter().chain(&cases) {
        let reused = segmenter.segment(mesh, dominant, &config).unwrap();
        assert!(!reused.segments.is_empty());
        assert_eq!(reused, segment(mesh, dominant, &config).unwrap());
        assert!(
            segmenter
                .segment(mesh, &[[0.0, 0.0, 2.0]], &config)
                .is_err()
        );
    }
}

#[test]
fn bad_input_is_an_error() {
    let mesh = terrain(3, |_, _| 0.0);
    let config = SegmentationConfig::new();
    assert!(matches!(
        segment(&mesh, &[[0.0, 0.0, 2.0]], &config),
        Err(SegmentError::BadDominantNormal { index: 0, .. })
    ));
    assert!(matches!(
        segment(&mesh, &[[f64::NAN, 0.0, 1.0]], &config),
        Err(SegmentError::BadDominantNormal { .. })
    ));
    assert!(matches!(
        segment(&mesh, &[[0.0, 0.0, 1.0]], &config.with_z_thresh(-1.0)),
        Err(SegmentError::Config {
            field: "z_thresh",
            ..
        })
    ));
    let (v, t, h, _) = mesh.into_parts();
    let bare = HalfEdgeMesh::from_parts(v, t, h, Vec::new()).unwrap();
    assert_eq!(
        segment(&bare, &[[0.0, 0.0, 1.0]], &config),
        Err(SegmentError::MissingNormals)
    );
    // No dominant normal: nothing to grow, no error.
    let mesh = terrain(3, |_, _| 0.0);
    let none = segment(&mesh, &[], &config).unwrap();
    assert!(none.segments.is_empty());
    assert_eq!(none.counts.groups.dropped_normal, mesh.num_triangles());
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(32))]

    #[test]
    fn matches_the_serial_oracle_at_any_thread_count(
        heights in proptest::collection::vec(0.0f64..1.0, 17 * 17),
        roughness in 0.0f64..2.0,
        z_thresh in prop_oneof![Just(0.0), 0.05f64..0.5],
        norm_thresh in 0.7f64..0.99,
    ) {
        let mesh = terrain(16, |r, c| roughness * heights[r * 17 + c]);
        let dominant = [[0.0, 0.0, 1.0], [0.6, 0.0, 0.8], [0.0, -0.6, 0.8], [-0.48, 0.36, 0.8]];
        let config = SegmentationConfig::new().with_lmax(1.6).with_min_triangles(3).with_z_thresh(z_thresh).with_norm_thresh(norm_thresh);
        let expected = oracle(&mesh, &dominant, &config);
        for threads in [1, 2, 4] {
            let pool = rayon::ThreadPoolBuilder::new().num_threads(threads).build().unwrap();
            let found = pool.install(|| segment(&mesh, &dominant, &config)).unwrap();
            let got: Vec<(u32, Vec<u32>)> = found.segments.iter().map(|s| (s.group, s.triangles.clone())).collect();
            prop_assert_eq!(&got, &expected);
        }
    }

    /// Segments compute their plane from their boundary and one number per triangle; it is
    /// the plane `geometric_plane` computes from all their triangles, also far from the
    /// origin (georeferenced coordinates).
    #[test]
    fn segment_planes_match_geometric_plane(
        heights in proptest::collection::vec(0.0f64..1.0, 25 * 25),
        roughness in 0.0f64..1.5,
        far in proptest::bool::ANY,
    ) {
        let origin = if far { [4.5e5, 5.2e6, 310.0] } else { [0.0; 3] };
        let mesh = terrain_at(24, origin, |r, c| roughness * heights[r * 25 + c]);
        let dominant = [[0.0, 0.0, 1.0], [0.6, 0.0, 0.8], [0.0, -0.6, 0.8]];
        let config = SegmentationConfig::new().with_min_triangles(3).with_z_thresh(0.3).with_norm_thresh(0.8);
        for s in segment(&mesh, &dominant, &config).unwrap().segments {
            let (normal, centroid) = geometric_plane(&mesh, &s.triangles);
            for k in 0..3 {
                prop_assert!((s.normal[k] - normal[k]).abs() < 1e-9, "{:?} vs {:?}", s.normal, normal);
                prop_assert!((s.centroid[k] - centroid[k]).abs() < 1e-6, "{:?} vs {:?}", s.centroid, centroid);
            }
        }
    }
}

//! Refinement on scenes with known planes: planes that are no dominant normal, a plane cut
//! into bands by `z_thresh`, noisy triangles left out by `norm_thresh`, and one plane seen
//! in two pieces.
#![allow(clippy::unwrap_used)]

use halfedge_mesh::HalfEdgeMesh;
use planeseg::{NO_GROUP, PlanarSegment, SegmentationConfig, segment};

/// An `n × n` grid of unit cells over `x, y`, lifted by `height`, two triangles a cell.
fn height_field(n: usize, height: impl Fn(f64, f64) -> f64) -> HalfEdgeMesh {
    let vertices = (0..(n + 1) * (n + 1))
        .map(|i| {
            let (x, y) = ((i % (n + 1)) as f64, (i / (n + 1)) as f64);
            [x, y, height(x, y)]
        })
        .collect();
    let triangles = test_fixtures::grid_triangles(n);
    let mut mesh = HalfEdgeMesh::from_triangles(vertices, triangles).unwrap();
    mesh.compute_triangle_normals();
    mesh
}

/// The triangles whose three corners satisfy `inside`, sorted.
fn triangles_where(mesh: &HalfEdgeMesh, inside: impl Fn([f64; 3]) -> bool) -> Vec<u32> {
    let v = mesh.vertices();
    (0..mesh.num_triangles() as u32)
        .filter(|&t| {
            mesh.triangles()[t as usize]
                .iter()
                .all(|&i| inside(v[i as usize]))
        })
        .collect()
}

fn sorted(segment: &PlanarSegment) -> Vec<u32> {
    let mut t = segment.triangles.clone();
    t.sort_unstable();
    t
}

fn config(refine: bool) -> SegmentationConfig {
    SegmentationConfig::new()
        .with_norm_thresh(0.95)
        .with_z_thresh(0.3)
        .with_min_triangles(10)
        .with_refine(refine)
}

const UP: [f64; 3] = [0.0, 0.0, 1.0];

#[test]
fn planes_that_are_no_dominant_normal_are_grown() {
    // Floor for x ≤ 10, a 30° ramp up to x = 20, a 20° ramp down to x = 30; the only
    // dominant normal is the floor's.
    let (t30, t20) = (30f64.to_radians().tan(), 20f64.to_radians().tan());
    let mesh = height_field(30, |x, _| {
        if x <= 10.0 {
            0.0
        } else if x <= 20.0 {
            (x - 10.0) * t30
        } else {
            10.0 * t30 - (x - 20.0) * t20
        }
    });
    let paper = segment(&mesh, &[UP], &config(false)).unwrap();
    assert_eq!(
        paper.segments.len(),
        1,
        "the paper's growth finds the floor only"
    );

    let refined = segment(&mesh, &[UP], &config(true)).unwrap();
    assert_eq!(refined.segments.len(), 3);
    let floor = triangles_where(&mesh, |p| p[0] <= 10.0);
    let up = triangles_where(&mesh, |p| (10.0..=20.0).contains(&p[0]));
    let down = triangles_where(&mesh, |p| p[0] >= 20.0);
    let found: Vec<Vec<u32>> = refined.segments.iter().map(sorted).collect();
    assert_eq!(found, vec![floor, up, down]);
    assert_eq!(refined.segments[0].group, 0);
    for (s, degrees) in refined.segments[1..].iter().zip([30f64, -20.0]) {
        assert_eq!(s.group, NO_GROUP);
        let (sin, cos) = degrees.to_radians().sin_cos();
        let expected = [-sin, 0.0, cos];
        for (got, want) in s.normal.iter().zip(expected) {
            assert!((got - want).abs() < 1e-9, "{:?}", s.normal);
        }
    }
}

#[test]
fn a_bevel_strip_along_a_crease_is_no_plane() {
    // A floor for x ≤ 14, a 60° ramp for x ≥ 17, and between them a 30° bevel three cells
    // wide and thirty long: what smoothing makes of a sharp crease. It is too thin and too
    // elongated to be a plane, though it has enough triangles and no dominant normal
    // explains it.
    let (t30, t60) = (30f64.to_radians().tan(), 60f64.to_radians().tan());
    let mesh = height_field(30, |x, _| {
        if x <= 14.0 {
            0.0
        } else if x <= 17.0 {
            (x - 14.0) * t30
        } else {
            3.0 * t30 + (x - 17.0) * t60
        }
    });
    let bevel = triangles_where(&mesh, |p| (14.0..=17.0).contains(&p[0]));
    assert!(bevel.len() >= 10 * config(true).min_triangles);

    let refined = segment(&mesh, &[UP], &config(true)).unwrap();
    let found: Vec<Vec<u32>> = refined.segments.iter().map(sorted).collect();
    let floor = triangles_where(&mesh, |p| p[0] <= 14.0);
    let ramp = triangles_where(&mesh, |p| p[0] >= 17.0);
    assert_eq!(found, vec![floor, ramp]);
}

#[test]
fn a_plane_cut_into_bands_by_z_thresh_is_merged() {
    // A plane 10° off the dominant normal: along x its offset drifts by 0.18 a cell, so
    // the paper's growth (within 0.3 of the seed) cuts it into narrow bands.
    let slope = 10f64.to_radians().tan();
    let mesh = height_field(30, |x, _| x * slope);
    let paper = segment(&mesh, &[UP], &config(false)).unwrap();
    assert!(paper.segments.len() > 5, "{} bands", paper.segments.len());

    let refined = segment(&mesh, &[UP], &config(true)).unwrap();
    assert_eq!(refined.segments.len(), 1);
    assert_eq!(refined.segments[0].triangles.len(), mesh.num_triangles());
    assert!(refined.segments[0].polygon.holes.is_empty());
}

#[test]
fn noisy_triangles_on_a_plane_are_absorbed() {
    // A floor with every seventh vertex raised by 0.45: the triangles around it tilt by
    // more than norm_thresh allows (24°), yet lie within z_thresh = 0.5 of the floor.
    let mesh = height_field(30, |x, y| {
        if (x as usize * 31 + y as usize).is_multiple_of(7)
            && x > 0.0
            && y > 0.0
            && x < 30.0
            && y < 30.0
        {
            0.45
        } else {
            0.0
        }
    });
    let config = |refine| config(refine).with_z_thresh(0.5);
    let paper = segment(&mesh, &[UP], &config(false)).unwrap();
    let paper_triangles: usize = paper.segments.iter().map(|s| s.triangles.len()).sum();
    assert!(
        paper_triangles < mesh.num_triangles() * 3 / 4,
        "{paper_triangles}"
    );

    let refined = segment(&mesh, &[UP], &config(true)).unwrap();
    assert_eq!(refined.segments.len(), 1);
    assert_eq!(refined.segments[0].triangles.len(), mesh.num_triangles());
}

#[test]
fn pieces_of_one_plane_share_a_plane_id() {
    // A floor cut in two by a trench 5 deep across 12 ≤ x ≤ 18; the trench's bottom is
    // parallel to the floor but another plane.
    let mesh = height_field(30, |x, _| {
        if (12.0..=18.0).contains(&x) {
            -5.0
        } else {
            0.0
        }
    });
    let refined = segment(&mesh, &[UP], &config(true)).unwrap();
    let left = triangles_where(&mesh, |p| p[0] <= 12.0 && p[2] == 0.0);
    let right = triangles_where(&mesh, |p| p[0] >= 18.0 && p[2] == 0.0);
    let bottom = triangles_where(&mesh, |p| p[2] == -5.0);
    let index_of = |triangles: &[u32]| {
        refined
            .segments
            .iter()
            .position(|s| sorted(s) == triangles)
            .unwrap()
    };
    let (l, r, b) = (index_of(&left), index_of(&right), index_of(&bottom));
    let plane = |i: usize| refined.segments[i].plane;
    assert_eq!(plane(l), plane(r));
    assert_eq!(plane(l), l.min(r) as u32);
    assert_ne!(plane(b), plane(l));
    assert_eq!(plane(b), b as u32);

    // Without refinement every segment is its own plane.
    let paper = segment(&mesh, &[UP], &config(false)).unwrap();
    for (i, s) in paper.segments.iter().enumerate() {
        assert_eq!(s.plane, i as u32);
    }
}

#[test]
fn a_small_piece_joins_the_plane_it_lies_in_despite_a_noisy_normal() {
    // A floor for x ≤ 20 and, beyond a trench 5 deep, a 6 × 6 plateau tilted by 7° about
    // the floor's level (as noise tilts a patch of a wall seen between two objects): more
    // than COPLANAR_COS allows, but within norm_thresh, and its points lie within a
    // quarter of z_thresh of the floor's plane. Raised by half of z_thresh it is a plane of
    // its own.
    let tilt = 7f64.to_radians().tan();
    let plateau = |x: f64, y: f64| (23.0..=29.0).contains(&x) && (10.0..=16.0).contains(&y);
    let scene = |lift: f64| {
        height_field(30, move |x, y| {
            if x <= 20.0 {
                0.0
            } else if plateau(x, y) {
                lift + (x - 26.0) * tilt
            } else {
                -5.0
            }
        })
    };
    let config = config(true).with_z_thresh(1.0).with_min_triangles(20);
    for (lift, same) in [(0.0, true), (0.5, false)] {
        let mesh = scene(lift);
        let refined = segment(&mesh, &[UP], &config).unwrap();
        let index_of = |inside: &dyn Fn([f64; 3]) -> bool| {
            let triangles = triangles_where(&mesh, inside);
            refined
                .segments
                .iter()
                .position(|s| sorted(s) == triangles)
                .unwrap()
        };
        let floor = index_of(&|p| p[0] <= 20.0);
        let piece = index_of(&|p| plateau(p[0], p[1]));
        let plane = |i: usize| refined.segments[i].plane;
        assert_eq!(plane(piece) == plane(floor), same, "lift {lift}");
    }
}

#[test]
fn refinement_does_not_depend_on_the_thread_count() {
    let mesh = height_field(40, |x, y| ((x * 0.37).sin() + (y * 0.23).cos()) * 0.8);
    let run = |threads| {
        rayon::ThreadPoolBuilder::new()
            .num_threads(threads)
            .build()
            .unwrap()
            .install(|| segment(&mesh, &[UP, [0.6, 0.0, 0.8]], &config(true)).unwrap())
    };
    let one = run(1);
    assert!(!one.segments.is_empty());
    assert_eq!(one, run(3));
}

/// Two flat `n × n` grids side by side, z = 0: one of `coarse` cells, one of `fine` cells,
/// far apart.
fn two_grids(n: usize, coarse: f64, fine: f64) -> HalfEdgeMesh {
    let mut vertices = Vec::new();
    let mut triangles = Vec::new();
    for (cell, x0) in [(coarse, 0.0), (fine, 1000.0)] {
        let first = vertices.len() as u32;
        for i in 0..(n + 1) * (n + 1) {
            let (x, y) = ((i % (n + 1)) as f64, (i / (n + 1)) as f64);
            vertices.push([x0 + x * cell, y * cell, 0.0]);
        }
        triangles.extend(
            test_fixtures::grid_triangles(n)
                .into_iter()
                .map(|t| t.map(|v| first + v)),
        );
    }
    let mut mesh = HalfEdgeMesh::from_triangles(vertices, triangles).unwrap();
    mesh.compute_triangle_normals();
    mesh
}

#[test]
fn a_far_plane_with_few_triangles_but_a_large_area_is_kept() {
    // 6 × 6 cells each: 72 triangles, below min_triangles 100; the coarse grid covers
    // 144 square units (a far wall seen by few pixels), the fine one 0.36.
    let mesh = two_grids(6, 2.0, 0.1);
    let per_grid = mesh.num_triangles() / 2;
    let config = config(true).with_min_triangles(100);
    let by_count = segment(&mesh, &[UP], &config).unwrap();
    assert!(by_count.segments.is_empty());

    let by_area = segment(&mesh, &[UP], &config.with_min_area(5.0)).unwrap();
    assert_eq!(by_area.segments.len(), 1);
    let expected: Vec<u32> = (0..per_grid as u32).collect();
    assert_eq!(sorted(&by_area.segments[0]), expected);

    // Without refinement min_area does not apply (the paper's Alg. 5).
    let paper = segment(&mesh, &[UP], &config.with_refine(false).with_min_area(5.0)).unwrap();
    assert!(paper.segments.is_empty());
}

#[test]
fn a_small_tilted_patch_grown_for_another_normal_merges_into_its_plane() {
    // A floor with a 4 × 10 patch tilted by 25° about its own centre line (heights ±0.93),
    // as smoothing tilts a patch of a far, noisy wall towards another dominant normal.
    // Growth gives the patch its own segment (its normal is the second dominant normal);
    // its normal is beyond norm_thresh (18°) of the floor's but within ABSORB_COS (45°),
    // and its points lie within ADJACENT_FLOOR · z_thresh = 1 of the floor's plane (RMS
    // 0.54), so the patch is part of the floor. Lifted by 3 it is a plane of its own.
    let angle = 25f64.to_radians();
    let tilted = [-angle.sin(), 0.0, angle.cos()];
    let patch = |x: f64, y: f64| (13.0..=17.0).contains(&x) && (10.0..=20.0).contains(&y);
    let config = config(true).with_z_thresh(2.0).with_min_triangles(20);
    for (lift, merged) in [(0.0, true), (3.0, false)] {
        let mesh = height_field(30, move |x, y| {
            if patch(x, y) {
                lift + (x - 15.0) * angle.tan()
            } else {
                0.0
            }
        });
        let refined = segment(&mesh, &[UP, tilted], &config).unwrap();
        let patch_triangles = triangles_where(&mesh, |p| patch(p[0], p[1]));
        assert!(patch_triangles.len() >= 20);
        let floor = refined
            .segments
            .iter()
            .max_by_key(|s| s.triangles.len())
            .unwrap();
        let in_floor = patch_triangles.iter().all(|t| floor.triangles.contains(t));
        assert_eq!(in_floor, merged, "lift {lift}");
        if !merged {
            assert!(
                refined
                    .segments
                    .iter()
                    .any(|s| patch_triangles.iter().all(|t| s.triangles.contains(t))),
                "the lifted patch is a segment"
            );
        }
    }
}

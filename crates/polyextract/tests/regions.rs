//! Oracle tests: for random regions of grids and Delaunay meshes, every extracted polygon
//! is OGC-valid (geo's `Validation`) and its area (shell minus holes) equals the summed area
//! of the region's triangles.
#![allow(clippy::expect_used, clippy::unwrap_used, clippy::panic)]

use geo::{Area, LineString, Polygon as GeoPolygon, Validation, Winding};
use halfedge_mesh::{HalfEdgeMesh, NO_TWIN};
use polyextract::{ExtractError, Extractor, Polygon, extract_polygon};
use proptest::prelude::*;

/// A `w × h` grid of unit cells; cell (r, c) has triangles 2k and 2k + 1, k = r·w + c,
/// split along the diagonal chosen by `diag`.
fn grid_mesh(w: usize, h: usize, diag: impl Fn(usize, usize) -> bool) -> HalfEdgeMesh {
    let vid = |r: usize, c: usize| (r * (w + 1) + c) as u32;
    let vertices = (0..=h)
        .flat_map(|r| (0..=w).map(move |c| [c as f64, r as f64, 0.0]))
        .collect();
    let mut triangles = Vec::new();
    for r in 0..h {
        for c in 0..w {
            let (a, b, cc, d) = (vid(r, c), vid(r, c + 1), vid(r + 1, c + 1), vid(r + 1, c));
            if diag(r, c) {
                triangles.extend([[a, b, cc], [a, cc, d]]);
            } else {
                triangles.extend([[a, b, d], [b, cc, d]]);
            }
        }
    }
    HalfEdgeMesh::from_triangles(vertices, triangles).unwrap()
}

/// Edge-connected components of the triangles with `keep[t]`, in triangle order.
fn components(mesh: &HalfEdgeMesh, keep: &[bool]) -> Vec<Vec<u32>> {
    let mut label = vec![u32::MAX; keep.len()];
    let mut regions = Vec::new();
    for seed in 0..keep.len() {
        if !keep[seed] || label[seed] != u32::MAX {
            continue;
        }
        let id = regions.len() as u32;
        let mut region = vec![seed as u32];
        label[seed] = id;
        let mut i = 0;
        while i < region.len() {
            let t = region[i];
            for h in 3 * t..3 * t + 3 {
                if let Some(twin) = mesh.twin(h) {
                    let n = (twin / 3) as usize;
                    if keep[n] && label[n] == u32::MAX {
                        label[n] = id;
                        region.push(n as u32);
                    }
                }
            }
            i += 1;
        }
        regions.push(region);
    }
    regions
}

fn to_geo(mesh: &HalfEdgeMesh, polygon: &Polygon) -> GeoPolygon<f64> {
    let ring = |r: &[u32]| {
        LineString::from(
            r.iter()
                .map(|&i| {
                    let p = mesh.vertices()[i as usize];
                    (p[0], p[1])
                })
                .collect::<Vec<_>>(),
        )
    };
    GeoPolygon::new(
        ring(&polygon.shell),
        polygon.holes.iter().map(|h| ring(h)).collect(),
    )
}

fn triangle_area(mesh: &HalfEdgeMesh, t: u32) -> f64 {
    let [a, b, c] = mesh.triangles()[t as usize].map(|v| mesh.vertices()[v as usize]);
    0.5 * ((b[0] - a[0]) * (c[1] - a[1]) - (b[1] - a[1]) * (c[0] - a[0]))
}

/// Extracts every component and checks validity, orientation and area.
fn check_all(mesh: &HalfEdgeMesh, keep: &[bool]) -> usize {
    let mut holes = 0;
    for region in components(mesh, keep) {
        let members: std::collections::HashSet<u32> = region.iter().copied().collect();
        let polygon = extract_polygon(
            mesh,
            &region,
            |t| members.contains(&t),
            |i| {
                let p = mesh.vertices()[i as usize];
                [p[0], p[1]]
            },
        )
        .unwrap();
        // The same region given by its boundary half-edges, listed backwards, must give
        // the same polygon.
        let twins = mesh.halfedges();
        let boundary: Vec<u32> = region
            .iter()
            .rev()
            .flat_map(|&t| (3 * t..3 * t + 3).rev())
            .filter(|&h| {
                let twin = twins[h as usize];
                twin == NO_TWIN || !members.contains(&(twin / 3))
            })
            .collect();
        let from_boundary = Extractor::new()
            .extract_boundary(mesh, &boundary, |i| {
                let p = mesh.vertices()[i as usize];
                [p[0], p[1]]
            })
            .unwrap();
        assert_eq!(from_boundary, polygon);
        let geo_polygon = to_geo(mesh, &polygon);
        assert!(
            geo_polygon.is_valid(),
            "invalid polygon {:?}: {:?}",
            polygon,
            geo_polygon.validation_errors()
        );
        let expected: f64 = region.iter().map(|&t| triangle_area(mesh, t)).sum();
        let got = geo_polygon.unsigned_area();
        assert!(
            (got - expected).abs() <= 1e-9 * expected.max(1.0),
            "area {got} vs {expected}"
        );
        assert!(geo_polygon.exterior().is_ccw());
        assert!(geo_polygon.interiors().iter().all(|h| h.is_cw()));
        holes += polygon.holes.len();
    }
    holes
}

#[test]
fn full_grid_is_one_square() {
    let mesh = grid_mesh(4, 3, |_, _| true);
    let region: Vec<u32> = (0..mesh.num_triangles() as u32).collect();
    let polygon = extract_polygon(
        &mesh,
        &region,
        |_| true,
        |i| {
            let p = mesh.vertices()[i as usize];
            [p[0], p[1]]
        },
    )
    .unwrap();
    assert_eq!(polygon.shell.len(), 14);
    assert!(polygon.holes.is_empty());
    // The shell starts after the extreme point: largest x, then largest y = (4, 3).
    assert_eq!(*polygon.shell.last().unwrap(), 19);
}

#[test]
fn hole_touching_shell_and_holes_touching_each_other() {
    // 6 × 6 grid (cells (row, col)). Cells (2, 2) and (3, 3): two holes meeting at a vertex.
    // Corner cell (5, 0) is a notch of the shell and interior cell (4, 1) touches it at one
    // vertex: a hole touching the shell. Cells (0, 4) and (1, 5) leave cell (0, 5) attached
    // by a single vertex only: a region of its own.
    let mesh = grid_mesh(6, 6, |r, c| (r + c) % 2 == 0);
    let mut keep = vec![true; mesh.num_triangles()];
    for (r, c) in [(2, 2), (3, 3), (5, 0), (4, 1), (0, 4), (1, 5)] {
        let k = 2 * (r * 6 + c);
        keep[k] = false;
        keep[k + 1] = false;
    }
    let holes = check_all(&mesh, &keep);
    assert_eq!(holes, 3, "rings touching at a vertex stay separate rings");
    assert_eq!(components(&mesh, &keep).len(), 2);
}

#[test]
fn checkerboard_pinches_split_into_valid_polygons() {
    let mesh = grid_mesh(5, 5, |_, _| true);
    let keep: Vec<bool> = (0..mesh.num_triangles())
        .map(|t| ((t / 2) % 5 + (t / 2) / 5) % 2 == 0)
        .collect();
    check_all(&mesh, &keep);
}

#[test]
fn errors_are_reported() {
    let mesh = grid_mesh(2, 2, |_, _| true);
    let project = |i: u32| {
        let p = mesh.vertices()[i as usize];
        [p[0], p[1]]
    };
    assert_eq!(
        extract_polygon(&mesh, &[], |_| true, project),
        Err(ExtractError::EmptyRegion)
    );
    assert!(matches!(
        extract_polygon(&mesh, &[99], |_| true, project),
        Err(ExtractError::TriangleOutOfRange { triangle: 99, .. })
    ));
    assert!(matches!(
        extract_polygon(&mesh, &[0], |_| true, |_| [f64::NAN, 0.0]),
        Err(ExtractError::NonFinitePoint { .. })
    ));
    let mut extractor = Extractor::new();
    assert_eq!(
        extractor.extract_boundary(&mesh, &[], project),
        Err(ExtractError::NoBoundary)
    );
    assert!(matches!(
        extractor.extract_boundary(&mesh, &[3 * 99], project),
        Err(ExtractError::TriangleOutOfRange { triangle: 99, .. })
    ));
    // Half of a boundary: the ring cannot close.
    assert!(matches!(
        extractor.extract_boundary(&mesh, &[0], project),
        Err(ExtractError::BrokenBoundary { .. })
    ));
}

#[test]
fn mirrored_frame_is_undone() {
    let mesh = grid_mesh(3, 3, |_, _| true);
    let region: Vec<u32> = (0..mesh.num_triangles() as u32).collect();
    let direct = extract_polygon(
        &mesh,
        &region,
        |_| true,
        |i| {
            let p = mesh.vertices()[i as usize];
            [p[0], p[1]]
        },
    )
    .unwrap();
    let mirrored = extract_polygon(
        &mesh,
        &region,
        |_| true,
        |i| {
            let p = mesh.vertices()[i as usize];
            [-p[0], p[1]]
        },
    )
    .unwrap();
    assert_eq!(direct, mirrored);
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(64))]

    #[test]
    fn random_grid_regions_give_valid_polygons(
        w in 2usize..12,
        h in 2usize..12,
        seed_keep in proptest::collection::vec(any::<bool>(), 0..300),
        diag_bits in any::<u64>(),
    ) {
        let mesh = grid_mesh(w, h, |r, c| diag_bits >> ((r * w + c) % 64) & 1 == 1);
        let keep: Vec<bool> = (0..mesh.num_triangles())
            .map(|t| seed_keep.get(t / 2).copied().unwrap_or(true))
            .collect();
        check_all(&mesh, &keep);
    }

    #[test]
    fn random_delaunay_regions_give_valid_polygons(
        points in proptest::collection::vec((0.0f64..100.0, 0.0f64..100.0), 3..200),
        keep_bits in proptest::collection::vec(any::<bool>(), 400),
    ) {
        let points: Vec<[f64; 2]> = points.into_iter().map(|(x, y)| [x, y]).collect();
        let Ok(mesh) = HalfEdgeMesh::delaunay_2d(&points) else { return Ok(()) };
        let keep: Vec<bool> = (0..mesh.num_triangles()).map(|t| keep_bits[t % 400]).collect();
        check_all(&mesh, &keep);
    }
}

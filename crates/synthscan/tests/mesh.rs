//! Mesh export and sampling: triangles on their planes, areas adding up to the faces',
//! orientation, edge bounds, no T-junctions inside a face; sampled points on their faces.

use std::collections::HashMap;

use proptest::prelude::*;
use synthscan::{
    Face, Polygon3, RampsConfig, RandomPolyhedraConfig, RoomConfig, Scene, SceneError, StairsConfig,
};

fn sub(a: [f64; 3], b: [f64; 3]) -> [f64; 3] {
    [a[0] - b[0], a[1] - b[1], a[2] - b[2]]
}
fn cross(a: [f64; 3], b: [f64; 3]) -> [f64; 3] {
    [
        a[1] * b[2] - a[2] * b[1],
        a[2] * b[0] - a[0] * b[2],
        a[0] * b[1] - a[1] * b[0],
    ]
}
fn dot(a: [f64; 3], b: [f64; 3]) -> f64 {
    a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
}
fn len(a: [f64; 3]) -> f64 {
    dot(a, a).sqrt()
}

/// Polygon area from the 3D rings alone (Newell), independent of the face's own frame.
fn polygon_area(p: &Polygon3) -> f64 {
    let ring_area = |r: &[[f64; 3]]| {
        let mut n = [0.0; 3];
        for i in 0..r.len() {
            let c = cross(r[i], r[(i + 1) % r.len()]);
            n = [n[0] + c[0], n[1] + c[1], n[2] + c[2]];
        }
        0.5 * len(n)
    };
    ring_area(&p.shell) - p.holes.iter().map(|h| ring_area(h)).sum::<f64>()
}

fn perimeter(p: &Polygon3) -> f64 {
    std::iter::once(&p.shell)
        .chain(&p.holes)
        .map(|r| {
            (0..r.len())
                .map(|i| len(sub(r[(i + 1) % r.len()], r[i])))
                .sum::<f64>()
        })
        .sum()
}

/// Checks the mesh of `scene` against its faces; one label per face assumed.
fn check_mesh(scene: &Scene, max_edge: f64) -> Result<usize, SceneError> {
    let (v, tris, labels) = scene.to_mesh(max_edge)?;
    assert_eq!(tris.len(), labels.len());
    let faces: HashMap<i32, &Face> = scene.faces().iter().map(|f| (f.label(), f)).collect();
    assert_eq!(
        faces.len(),
        scene.faces().len(),
        "test assumes one face per label"
    );
    let mut area: HashMap<i32, f64> = HashMap::new();
    let mut directed: HashMap<(u32, u32), (i32, usize)> = HashMap::new();
    for (t, &l) in tris.iter().zip(&labels) {
        let f = faces[&l];
        let p = t.map(|i| v[i as usize]);
        for q in p {
            assert!(f.signed_distance(q).abs() < 1e-9, "vertex off its plane");
        }
        let n = cross(sub(p[1], p[0]), sub(p[2], p[0]));
        assert!(
            dot(n, f.normal()) > 0.0,
            "triangle not counter-clockwise from the front"
        );
        *area.entry(l).or_default() += 0.5 * len(n);
        for k in 0..3 {
            if max_edge.is_finite() {
                assert!(len(sub(p[(k + 1) % 3], p[k])) <= max_edge * (1.0 + 1e-12));
            }
            let e = (t[k], t[(k + 1) % 3]);
            assert!(
                directed.insert(e, (l, 0)).is_none(),
                "directed edge used twice"
            );
        }
    }
    // Edges without a reverse twin form each face's boundary: their length must equal the
    // polygon's perimeter (a T-junction would add an inner edge to it).
    let mut boundary: HashMap<i32, f64> = HashMap::new();
    for (&(a, b), &(l, _)) in &directed {
        if !directed.contains_key(&(b, a)) {
            *boundary.entry(l).or_default() += len(sub(v[b as usize], v[a as usize]));
        }
    }
    for f in scene.faces() {
        let want = polygon_area(f.polygon());
        assert!((want - f.area()).abs() < 1e-9 * (1.0 + want));
        let got = area.get(&f.label()).copied().unwrap_or(0.0);
        assert!(
            (got - want).abs() < 1e-9 * (1.0 + want),
            "label {}: {got} vs {want}",
            f.label()
        );
        let b = boundary.get(&f.label()).copied().unwrap_or(0.0);
        let per = perimeter(f.polygon());
        assert!(
            (b - per).abs() < 1e-9 * (1.0 + per),
            "label {}: boundary {b} vs {per}",
            f.label()
        );
    }
    Ok(tris.len())
}

#[test]
fn builder_meshes_are_exact() -> Result<(), SceneError> {
    let scenes = [
        Scene::room(&RoomConfig::default())?,
        Scene::stairs(&StairsConfig::default())?,
        Scene::ramps(&RampsConfig::default())?,
        Scene::random_polyhedra(&RandomPolyhedraConfig::default().with_seed(4))?,
    ];
    for scene in &scenes {
        let coarse = check_mesh(scene, f64::INFINITY)?;
        let fine = check_mesh(scene, 0.2)?;
        assert!(fine > 2 * coarse);
    }
    Ok(())
}

#[test]
fn max_edge_gives_enough_triangles_for_min_triangles_filters() -> Result<(), SceneError> {
    let scene = Scene::room(&RoomConfig::default())?;
    let (_, _, labels) = scene.to_mesh(0.1)?;
    let floor = labels.iter().filter(|&&l| l == 0).count();
    // 30 m² of floor in triangles with edges of at most 0.1 m.
    assert!(floor > 3000, "{floor}");
    assert!(scene.to_mesh(0.0).is_err());
    assert!(scene.to_mesh(f64::NAN).is_err());
    assert!(scene.to_mesh(1e-6).is_err(), "absurd meshes are refused");
    Ok(())
}

#[test]
fn sampling_stays_on_faces_and_follows_area() -> Result<(), SceneError> {
    let scene = Scene::stairs(&StairsConfig::default())?;
    let treads = [2, 4, 6, 8];
    let s = scene.sample_uniform(Some(&treads), 4000, 3)?;
    assert_eq!(s.points.len(), 4000);
    let faces: HashMap<i32, &Face> = scene.faces().iter().map(|f| (f.label(), f)).collect();
    for (p, l) in s.points.iter().zip(&s.labels) {
        assert!(treads.contains(l));
        assert!(faces[l].signed_distance(*p).abs() < 1e-9);
        let (lo, hi) = faces[l].bounding_box();
        assert!((0..3).all(|k| p[k] >= lo[k] - 1e-9 && p[k] <= hi[k] + 1e-9));
    }
    // Equal treads get about a quarter each (binomial σ ≈ 27).
    for t in treads {
        let n = s.labels.iter().filter(|&&l| l == t).count() as f64;
        assert!((n - 1000.0).abs() < 150.0, "tread {t}: {n}");
    }
    assert_eq!(s, scene.sample_uniform(Some(&treads), 4000, 3)?);
    assert_ne!(s, scene.sample_uniform(Some(&treads), 4000, 4)?);
    // The floor (with its hole) gets points only outside the stairs' footprint.
    let floor = scene.sample_uniform(Some(&[0]), 2000, 1)?;
    assert!(floor.points.iter().all(|p| {
        let inside = p[0] > 1e-9 && p[0] < 1.2 - 1e-9 && p[1] > 1e-9 && p[1] < 1.0 - 1e-9;
        !inside && p[2].abs() < 1e-12
    }));
    assert!(matches!(
        scene.sample_uniform(Some(&[99]), 10, 0),
        Err(SceneError::UnknownLabel { label: 99 })
    ));
    assert_eq!(scene.sample_uniform(None, 10, 0)?.points.len(), 10);
    Ok(())
}

/// A star-shaped polygon (simple by construction) with a square hole around its centre.
fn star(radii: &[f64], hole: f64) -> Polygon3 {
    let n = radii.len();
    let outer = radii
        .iter()
        .enumerate()
        .map(|(i, r)| {
            let a = std::f64::consts::TAU * i as f64 / n as f64;
            [r * a.cos(), r * a.sin(), 0.5]
        })
        .collect();
    let h = hole / 2.0;
    Polygon3::from_shell(outer).with_hole(vec![
        [-h, -h, 0.5],
        [h, -h, 0.5],
        [h, h, 0.5],
        [-h, h, 0.5],
    ])
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(48))]

    #[test]
    fn random_star_polygons_mesh_exactly(
        radii in prop::collection::vec(1.0f64..4.0, 5..24),
        hole in 0.2f64..1.0,
        max_edge in 0.3f64..3.0,
        tilt in 0.0f64..80.0,
    ) {
        // Tilt the polygon so the face frame is not axis-aligned.
        let (s, c) = tilt.to_radians().sin_cos();
        let mut p = star(&radii, hole);
        for q in p.shell.iter_mut().chain(p.holes.iter_mut().flatten()) {
            *q = [q[0], c * q[1] - s * q[2], s * q[1] + c * q[2]];
        }
        let mut scene = Scene::new();
        scene.add_polygon(0, p).map_err(|e| TestCaseError::fail(e.to_string()))?;
        check_mesh(&scene, max_edge).map_err(|e| TestCaseError::fail(e.to_string()))?;
    }
}

//! Scans checked against an independent ray caster (Möller–Trumbore on the exported mesh),
//! noise statistics, and determinism.

use synthscan::{
    FLOOR_LABEL, Noise, PinholeCamera, Polygon3, Pose, RoomConfig, ScanResult, Scene, SceneError,
    Sensor, SphericalSensor, synpeb_like,
};

fn dot(a: [f64; 3], b: [f64; 3]) -> f64 {
    a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
}
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

/// Nearest hit of a ray on a triangle soup: `(range, triangle)`.
fn moller_trumbore(
    v: &[[f64; 3]],
    tris: &[[u32; 3]],
    o: [f64; 3],
    d: [f64; 3],
) -> Option<(f64, usize)> {
    let mut best: Option<(f64, usize)> = None;
    for (i, t) in tris.iter().enumerate() {
        let (a, b, c) = (v[t[0] as usize], v[t[1] as usize], v[t[2] as usize]);
        let (e1, e2) = (sub(b, a), sub(c, a));
        let p = cross(d, e2);
        let det = dot(e1, p);
        if det.abs() < 1e-14 {
            continue;
        }
        let s = sub(o, a);
        let u = dot(s, p) / det;
        let q = cross(s, e1);
        let w = dot(d, q) / det;
        let range = dot(e2, q) / det;
        let eps = 1e-12;
        let inside = u >= -eps && w >= -eps && u + w <= 1.0 + eps && range > 1e-9;
        if inside && best.is_none_or(|(r, _)| range < r) {
            best = Some((range, i));
        }
    }
    best
}

fn plane_distance(scan: &ScanResult, i: usize) -> f64 {
    let plane = &scan.planes[scan.labels[i] as usize];
    assert_eq!(plane.label, scan.labels[i]);
    dot(plane.normal, scan.points[i]) - plane.offset
}

/// Every pixel agrees with the mesh ray caster: same hit or miss, the same range, and the
/// same label unless the hit point lies on both labels' planes (a ray through an edge).
fn check_against_oracle(scene: &Scene, sensor: &impl Sensor) -> Result<(), SceneError> {
    let scan = scene.scan(sensor, &Noise::none())?;
    let (v, tris, tri_labels) = scene.to_mesh(f64::INFINITY)?;
    let o = sensor.pose().translation();
    let mut hits = 0;
    for r in 0..sensor.rows() {
        for c in 0..sensor.cols() {
            let i = r * sensor.cols() + c;
            let d = sensor.pose().rotate(sensor.direction(r, c));
            let oracle = moller_trumbore(&v, &tris, o, d);
            match oracle {
                None => {
                    assert_eq!(scan.labels[i], -1, "pixel {r},{c}");
                    assert!(scan.points[i].iter().all(|x| x.is_nan()));
                }
                Some((range, t)) => {
                    hits += 1;
                    assert!(
                        scan.labels[i] >= 0,
                        "pixel {r},{c}: oracle hit, scan missed"
                    );
                    let ours = dot(sub(scan.points[i], o), d);
                    assert!(
                        (ours - range).abs() < 1e-9,
                        "pixel {r},{c}: {ours} vs {range}"
                    );
                    assert!(plane_distance(&scan, i).abs() < 1e-9);
                    if scan.labels[i] != tri_labels[t] {
                        let other = &scan.planes[tri_labels[t] as usize];
                        let dist = dot(other.normal, scan.points[i]) - other.offset;
                        assert!(
                            dist.abs() < 1e-9,
                            "pixel {r},{c}: label mismatch off an edge"
                        );
                    }
                }
            }
        }
    }
    assert!(hits > 0);
    Ok(())
}

#[test]
fn room_scans_match_mesh_ray_caster() -> Result<(), SceneError> {
    let scene = Scene::room(&RoomConfig::default())?;
    let pose = Pose::look_at([0.3, 0.4, 1.7], [3.5, 2.5, 0.3], [0.0, 0.0, 1.0])?;
    check_against_oracle(
        &scene,
        &PinholeCamera::new(30, 40, 25.0, 25.0)?.with_pose(pose),
    )?;
    let pose = Pose::look_at([5.5, 4.5, 1.2], [2.0, 2.5, 0.5], [0.0, 0.0, 1.0])?;
    check_against_oracle(
        &scene,
        &SphericalSensor::new(24, 48, 200.0, 120.0)?.with_pose(pose),
    )
}

#[test]
fn random_polyhedra_and_stairs_match_mesh_ray_caster() -> Result<(), SceneError> {
    let (scene, _) = synpeb_like(3)?;
    let pose = Pose::look_at([0.5, 2.5, 1.0], [6.0, 2.5, 1.0], [0.0, 0.0, 1.0])?;
    check_against_oracle(
        &scene,
        &SphericalSensor::new(30, 30, 70.0, 60.0)?.with_pose(pose),
    )?;
    let stairs = Scene::stairs(&Default::default())?;
    let pose = Pose::look_at([-1.5, -1.0, 1.5], [0.6, 0.5, 0.3], [0.0, 0.0, 1.0])?;
    check_against_oracle(
        &stairs,
        &PinholeCamera::new(30, 30, 20.0, 20.0)?.with_pose(pose),
    )
}

#[test]
fn open_rays_miss() -> Result<(), SceneError> {
    let scene = Scene::room(&RoomConfig::default().with_ceiling(false))?;
    let pose = Pose::look_at([3.0, 2.5, 1.0], [3.0, 2.5, 5.0], [0.0, 1.0, 0.0])?;
    let scan = scene.scan(
        &PinholeCamera::new(10, 10, 50.0, 50.0)?.with_pose(pose),
        &Noise::none(),
    )?;
    assert_eq!(scan.num_valid(), 0);
    assert!(scan.points.iter().flatten().all(|x| x.is_nan()));
    Ok(())
}

#[test]
fn obstacle_cuts_a_hole_in_the_floor_labels() -> Result<(), SceneError> {
    let config = RoomConfig::default().with_table(None);
    let obstacle = config.obstacle.ok_or(SceneError::Degenerate)?;
    let scene = Scene::room(&config)?;
    let [cx, cy] = obstacle.center;
    // Straight down over the obstacle, from 2.5 m.
    let pose = Pose::look_at([cx, cy, 2.5], [cx, cy, 0.0], [0.0, 1.0, 0.0])?;
    let cam = PinholeCamera::new(61, 61, 60.0, 60.0)?.with_pose(pose);
    let scan = scene.scan(&cam, &Noise::none())?;
    let top = scan
        .planes
        .iter()
        .find(|p| p.normal[2] > 0.999 && (p.offset - obstacle.size[2]).abs() < 1e-9)
        .map(|p| p.label)
        .ok_or(SceneError::Degenerate)?;
    let label = |r: usize, c: usize| scan.labels[r * 61 + c];
    assert_eq!(label(30, 30), top);
    // Along each image axis from the centre: obstacle top, then its sides or floor,
    // and floor at the border: the floor is seen all around the obstacle but not under it.
    for (dr, dc) in [(0i64, 1i64), (0, -1), (1, 0), (-1, 0)] {
        let line: Vec<i32> = (0..=30)
            .map(|k| label((30 + dr * k) as usize, (30 + dc * k) as usize))
            .collect();
        assert_eq!(line[30], FLOOR_LABEL);
        let first_floor = line.iter().position(|&l| l == FLOOR_LABEL).unwrap_or(0);
        assert!(first_floor > 3);
        assert!(line[..first_floor].iter().all(|&l| l != FLOOR_LABEL));
        assert!(line[first_floor..].iter().all(|&l| l == FLOOR_LABEL));
    }
    // No floor point lies inside the obstacle's footprint.
    let (hx, hy) = (obstacle.size[0] / 2.0, obstacle.size[1] / 2.0);
    for (p, &l) in scan.points.iter().zip(&scan.labels) {
        if l == FLOOR_LABEL {
            assert!((p[0] - cx).abs() >= hx - 1e-9 || (p[1] - cy).abs() >= hy - 1e-9);
        }
    }
    // The floor polygon itself has the footprint as a hole.
    assert_eq!(scan.planes[FLOOR_LABEL as usize].polygons[0].holes.len(), 1);
    Ok(())
}

/// A single 20 × 20 m plane tilted 30° from the xy plane, seen from 3 m.
fn tilted_plane() -> Result<(Scene, PinholeCamera, [f64; 3], f64), SceneError> {
    let a = 30f64.to_radians();
    let n = [0.0, -a.sin(), a.cos()];
    let (u, v) = ([1.0, 0.0, 0.0], [0.0, a.cos(), a.sin()]);
    let corner = |s: f64, t: f64| {
        [
            s * u[0] + t * v[0],
            s * u[1] + t * v[1],
            s * u[2] + t * v[2],
        ]
    };
    let ring = vec![
        corner(-10.0, -10.0),
        corner(10.0, -10.0),
        corner(10.0, 10.0),
        corner(-10.0, 10.0),
    ];
    let mut scene = Scene::new();
    scene.add_polygon(0, Polygon3::from_shell(ring))?;
    let pose = Pose::look_at([0.0, 0.0, 3.0], [0.0, 0.0, 0.0], [0.0, 1.0, 0.0])?;
    let cam = PinholeCamera::new(100, 100, 60.0, 60.0)?.with_pose(pose);
    Ok((scene, cam, n, 0.0))
}

fn mean_std(x: &[f64]) -> (f64, f64) {
    let m = x.iter().sum::<f64>() / x.len() as f64;
    let v = x.iter().map(|y| (y - m).powi(2)).sum::<f64>() / (x.len() - 1) as f64;
    (m, v.sqrt())
}

#[test]
fn radial_noise_statistics() -> Result<(), SceneError> {
    let (scene, cam, n, offset) = tilted_plane()?;
    let sigma = 0.01;
    let scan = scene.scan(&cam, &Noise::new(sigma, 0.0, 42))?;
    let o = cam.pose().translation();
    // Signed distance from the point to the true plane, measured along the ray.
    let residuals: Vec<f64> = (0..scan.points.len())
        .map(|i| {
            let d = cam.pose().rotate(cam.direction(i / 100, i % 100));
            let range = (offset - dot(n, o)) / dot(n, d);
            dot(sub(scan.points[i], o), d) - range
        })
        .collect();
    let (m, s) = mean_std(&residuals);
    assert!(m.abs() < 0.1 * sigma, "mean {m}");
    assert!((s / sigma - 1.0).abs() < 0.1, "std {s}");
    Ok(())
}

#[test]
fn tangential_noise_statistics() -> Result<(), SceneError> {
    // A beam tilted by δ₁e₁ + δ₂e₂ moves the point off the plane by r (n · δ), whose
    // standard deviation is r σ sin(incidence); normalised, it must have unit spread.
    let (scene, cam, n, offset) = tilted_plane()?;
    let sigma_mdeg = 4.0;
    let sigma = (sigma_mdeg * 1e-3f64).to_radians();
    let scan = scene.scan(&cam, &Noise::new(0.0, sigma_mdeg, 9))?;
    let o = cam.pose().translation();
    let z: Vec<f64> = (0..scan.points.len())
        .map(|i| {
            let d = cam.pose().rotate(cam.direction(i / 100, i % 100));
            let range = (offset - dot(n, o)) / dot(n, d);
            let sin_inc = (1.0 - dot(n, d).powi(2)).sqrt();
            (dot(n, scan.points[i]) - offset) / (range * sigma * sin_inc)
        })
        .collect();
    let (m, s) = mean_std(&z);
    assert!(m.abs() < 0.1, "mean {m}");
    assert!((s - 1.0).abs() < 0.1, "std {s}");
    Ok(())
}

#[test]
fn zero_noise_is_exact_and_negative_sigma_is_rejected() -> Result<(), SceneError> {
    let (scene, cam, _, _) = tilted_plane()?;
    let a = scene.scan(&cam, &Noise::none())?;
    let b = scene.scan(&cam, &Noise::new(0.0, 0.0, 1234))?;
    assert_eq!(a, b);
    assert!((0..a.points.len()).all(|i| plane_distance(&a, i).abs() < 1e-9));
    assert!(matches!(
        scene.scan(&cam, &Noise::new(-0.1, 0.0, 0)),
        Err(SceneError::InvalidParameter {
            name: "radial_sigma",
            ..
        })
    ));
    assert!(scene.scan(&cam, &Noise::new(0.0, f64::NAN, 0)).is_err());
    Ok(())
}

fn bits(s: &ScanResult) -> Vec<u64> {
    s.points.iter().flatten().map(|x| x.to_bits()).collect()
}

#[test]
fn deterministic_by_seed_and_thread_count() -> Result<(), Box<dyn std::error::Error>> {
    let (scene, _) = synpeb_like(11)?;
    let pose = Pose::look_at([0.5, 2.5, 1.0], [6.0, 2.5, 1.0], [0.0, 0.0, 1.0])?;
    let sensor = SphericalSensor::new(60, 80, 70.0, 60.0)?.with_pose(pose);
    let noise = Noise::new(0.005, 2.0, 5);
    let run = |threads: usize| -> Result<ScanResult, Box<dyn std::error::Error>> {
        let pool = rayon::ThreadPoolBuilder::new()
            .num_threads(threads)
            .build()?;
        Ok(pool.install(|| scene.scan(&sensor, &noise))?)
    };
    let one = run(1)?;
    let four = run(4)?;
    assert_eq!(bits(&one), bits(&four));
    assert_eq!(one.labels, four.labels);
    let again = scene.scan(&sensor, &noise)?;
    assert_eq!(bits(&one), bits(&again));
    let other = scene.scan(&sensor, &noise.with_seed(6))?;
    assert_ne!(bits(&one), bits(&other));
    // Same seed, same scene; another seed, another scene.
    assert_eq!(synpeb_like(11)?.0, scene);
    assert_ne!(synpeb_like(12)?.0, scene);
    Ok(())
}

#[test]
fn synpeb_like_frame_sees_many_planes() -> Result<(), SceneError> {
    let (scene, sensor) = synpeb_like(1)?;
    // A quarter-resolution version of the 500 × 500 sensor keeps the debug test fast.
    let small = SphericalSensor::new(125, 125, 70.0, 60.0)?.with_pose(*sensor.pose());
    let scan = scene.scan(&small, &Noise::new(0.002, 1.0, 1))?;
    assert_eq!(
        scan.num_valid(),
        125 * 125,
        "a closed room returns every ray"
    );
    let seen = scan.label_counts().iter().filter(|&&c| c > 0).count();
    assert!(seen >= 15, "only {seen} planes seen");
    assert!(scan.label_counts()[FLOOR_LABEL as usize] > 0);
    Ok(())
}

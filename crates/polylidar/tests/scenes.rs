//! Generated scenes with known planes through the 3D pipeline: organized scans and meshes
//! of the same scenes, recovered with the right normals, counts and holes.
#![allow(clippy::expect_used, clippy::unwrap_used, clippy::panic)]

use polylidar::{
    BilateralConfig, Config, DecimateConfig, DecimateFactor, DominantNormalsConfig,
    ExtractedPolygon, Extraction, FillConfig, LaplacianConfig, OrganizedPointCloud, Polylidar,
    PolylidarError,
};
use synthscan::{
    FLOOR_LABEL, Noise, PinholeCamera, Pose, RampsConfig, RoomConfig, ScanResult, Scene,
    StairsConfig,
};

/// Parameters for noise-free scenes: no smoothing; FastGA at level 5 (ramps 10° apart)
/// keeps weak peaks (small planes next to a large floor), like the synpeb preset.
fn config() -> Config {
    Config::new()
        .with_fastga(
            DominantNormalsConfig::default()
                .with_level(5)
                .with_value_threshold(3.0)
                .with_min_cluster_weight(0.01),
        )
        .with_lmax(0.15)
        .with_min_triangles(150)
        .with_norm_thresh(0.98)
        .with_min_hole_vertices(6)
        .with_z_thresh(0.03)
}

fn scan(scene: &Scene, eye: [f64; 3], target: [f64; 3], noise: &Noise) -> ScanResult {
    let pose = Pose::look_at(eye, target, [0.0, 0.0, 1.0]).expect("valid pose");
    let camera = PinholeCamera::new(240, 320, 160.0, 160.0)
        .expect("valid camera")
        .with_pose(pose);
    scene.scan(&camera, noise).expect("scan")
}

fn cloud(scan: &ScanResult) -> OrganizedPointCloud {
    OrganizedPointCloud::new(scan.rows, scan.cols, scan.points.clone()).expect("cloud")
}

/// The default room scanned from the corner the tests look from.
fn room_scan(noise: &Noise) -> ScanResult {
    let scene = Scene::room(&RoomConfig::default()).expect("room");
    scan(&scene, [3.0, 0.3, 2.6], [3.2, 3.0, 0.0], noise)
}

/// [`config`] with both filters at their defaults, for noisy scans.
fn smoothed_config() -> Config {
    config()
        .with_z_thresh(0.05)
        .with_norm_thresh(0.95)
        .with_laplacian(Some(LaplacianConfig::default()))
        .with_bilateral(Some(BilateralConfig::default()))
}

/// Per polygon: the ground-truth label most of its items carry and that share, where
/// `items` gives each polygon's item ids and `truth` their labels.
fn majorities(items: Vec<Vec<usize>>, truth: &[i32]) -> Vec<(i32, f64)> {
    items
        .into_iter()
        .map(|ids| {
            let mut labels: Vec<i32> = ids.iter().map(|&i| truth[i]).collect();
            labels.sort_unstable();
            let mut best = (labels[0], 0);
            for run in labels.chunk_by(|a, b| a == b) {
                if run.len() > best.1 {
                    best = (run[0], run.len());
                }
            }
            (best.0, best.1 as f64 / ids.len() as f64)
        })
        .collect()
}

/// Majority labels of each polygon's points (organized input: vertex = pixel).
fn point_majorities(extraction: &Extraction, truth: &[i32]) -> Vec<(i32, f64)> {
    let labels = extraction.point_labels();
    let items = (0..extraction.polygons.len())
        .map(|p| {
            (0..labels.len())
                .filter(|&v| labels[v] == p as i32)
                .collect()
        })
        .collect();
    majorities(items, truth)
}

/// Runs the organized pipeline on a scan; the majority label of each polygon's points.
fn extract_scan(scan: &ScanResult, config: Config) -> (Extraction, Vec<(i32, f64)>) {
    let extraction = Polylidar::new(config)
        .expect("config")
        .extract_organized(&cloud(scan))
        .expect("extraction");
    let majorities = point_majorities(&extraction, &scan.labels);
    (extraction, majorities)
}

/// Majority labels of each polygon's triangles (mesh input, one label per triangle).
fn triangle_majorities(extraction: &Extraction, truth: &[i32]) -> Vec<(i32, f64)> {
    let items = extraction
        .polygons
        .iter()
        .map(|p| p.triangles.iter().map(|&t| t as usize).collect())
        .collect();
    majorities(items, truth)
}

fn angle_deg(a: [f64; 3], b: [f64; 3]) -> f64 {
    let d: f64 = (0..3).map(|k| a[k] * b[k]).sum();
    d.clamp(-1.0, 1.0).acos().to_degrees()
}

/// Every polygon is one ground-truth plane (≥ `share` of its items), with that plane's
/// normal within `degrees` and its centroid on it; no plane but `may_split` is found
/// twice. Returns the labels found.
fn check_planes(
    extraction: &Extraction,
    majorities: &[(i32, f64)],
    planes: &[synthscan::GroundTruthPlane],
    share: f64,
    degrees: f64,
    may_split: Option<i32>,
) -> Vec<i32> {
    let mut found = Vec::new();
    for (polygon, &(label, s)) in extraction.polygons.iter().zip(majorities) {
        assert!(s >= share, "polygon of plane {label} is only {s:.3} pure");
        let truth = &planes[label as usize];
        let angle = angle_deg(polygon.plane.normal, truth.normal);
        assert!(angle <= degrees, "plane {label}: normal off by {angle:.3}°");
        let c = polygon.plane.centroid;
        let off: f64 = (0..3).map(|k| truth.normal[k] * c[k]).sum::<f64>() - truth.offset;
        assert!(
            off.abs() < 0.01,
            "plane {label}: centroid {off:.4} m off the plane"
        );
        found.push(label);
    }
    let mut unique = found.clone();
    unique.sort_unstable();
    unique.dedup();
    let split = found
        .iter()
        .filter(|&&l| Some(l) == may_split)
        .count()
        .saturating_sub(1);
    assert_eq!(
        unique.len() + split,
        found.len(),
        "a plane was split: {found:?}"
    );
    unique
}

/// The polygon whose points are mostly of plane `label`.
fn polygon_of<'a>(
    extraction: &'a Extraction,
    majorities: &[(i32, f64)],
    label: i32,
) -> &'a ExtractedPolygon {
    let index = majorities.iter().position(|&(l, _)| l == label);
    &extraction.polygons[index.unwrap_or_else(|| panic!("plane {label} not found"))]
}

/// Every label of `wanted` is among the `found` ones.
fn assert_found(found: &[i32], wanted: impl IntoIterator<Item = i32>) {
    for label in wanted {
        assert!(
            found.contains(&label),
            "plane {label} missed; found {found:?}"
        );
    }
}

/// Ray-casting point-in-ring test in xy.
fn inside_xy(ring: &[[f64; 3]], p: [f64; 2]) -> bool {
    let mut inside = false;
    let mut j = ring.len() - 1;
    for i in 0..ring.len() {
        let (a, b) = (ring[i], ring[j]);
        if (a[1] > p[1]) != (b[1] > p[1])
            && p[0] < (b[0] - a[0]) * (p[1] - a[1]) / (b[1] - a[1]) + a[0]
        {
            inside = !inside;
        }
        j = i;
    }
    inside
}

/// Ground-truth labels with at least `min` points.
fn visible(scan: &ScanResult, min: usize) -> Vec<i32> {
    let counts = scan.label_counts();
    (0..counts.len() as i32)
        .filter(|&l| counts[l as usize] >= min)
        .collect()
}

#[test]
fn room_scan_finds_floor_with_obstacle_hole_table_and_walls() {
    let room = RoomConfig::default();
    let scene = Scene::room(&room).expect("room");
    let scan = scan(&scene, [3.0, 0.3, 2.6], [3.2, 3.0, 0.0], &Noise::none());
    let (extraction, majorities) = extract_scan(&scan, config());
    let found = check_planes(&extraction, &majorities, &scan.planes, 0.98, 1.0, None);

    // Every plane seen by at least 3 × min_triangles pixels is found.
    assert_found(&found, visible(&scan, 450));
    // The floor: one polygon whose holes include the obstacle's footprint, while a free
    // floor spot is inside the shell and in no hole.
    let floor = polygon_of(&extraction, &majorities, FLOOR_LABEL);
    let obstacle = room.obstacle.expect("default room has an obstacle").center;
    assert!(inside_xy(&floor.shell_points, obstacle));
    assert!(floor.hole_points.iter().any(|h| inside_xy(h, obstacle)));
    let free = [4.5, 3.5];
    assert!(inside_xy(&floor.shell_points, free));
    assert!(!floor.hole_points.iter().any(|h| inside_xy(h, free)));
    // The table top is a horizontal plane at its height.
    let table = room.table.expect("default room has a table");
    let top = extraction
        .polygons
        .iter()
        .find(|p| inside_xy(&p.shell_points, table.center) && p.plane.centroid[2] > 0.5)
        .expect("table top found");
    assert!((top.plane.centroid[2] - table.height).abs() < 0.01);

    let c = &extraction.diagnostics.counts;
    assert_eq!(c.polygons, extraction.polygons.len());
    assert_eq!(c.points, scan.num_valid());
    assert!(c.dominant_normals >= 3);
}

#[test]
fn room_mesh_gives_the_same_planes_as_its_scan_without_occlusion() {
    let room = RoomConfig::default();
    let scene = Scene::room(&room).expect("room");
    let (vertices, triangles, labels) = scene.to_mesh(0.1).expect("mesh");
    let extraction = Polylidar::new(config().with_min_triangles(20).with_min_hole_vertices(3))
        .expect("config")
        .extract_mesh(vertices, triangles)
        .expect("extraction");
    let majorities = triangle_majorities(&extraction, &labels);
    let found = check_planes(
        &extraction,
        &majorities,
        &scene.ground_truth(),
        1.0,
        1e-6,
        None,
    );
    // Floor, four walls, ceiling, table top and the obstacle's top are all large.
    assert_found(&found, 0..=6);
    // Seen whole, the floor has one hole per leg and one for the obstacle.
    let floor = polygon_of(&extraction, &majorities, FLOOR_LABEL);
    assert_eq!(floor.holes.len(), 5);
    let obstacle = room.obstacle.expect("obstacle").center;
    assert!(floor.hole_points.iter().any(|h| inside_xy(h, obstacle)));
}

#[test]
fn stairs_scan_finds_every_tread_and_riser() {
    let scene = Scene::stairs(&StairsConfig::default()).expect("stairs");
    // From the front and above, looking up the stairs.
    let scan = scan(&scene, [-1.2, 0.5, 1.6], [0.8, 0.5, 0.2], &Noise::none());
    let config = config().with_lmax(0.1).with_min_triangles(100);
    let (extraction, majorities) = extract_scan(&scan, config);
    // The treads are small and seen edge-on: a row of riser pixels just below each nosing
    // lies within a pixel of the tread's plane and joins it.
    let found = check_planes(&extraction, &majorities, &scan.planes, 0.85, 1.0, None);
    // Floor plus 4 risers and 4 treads.
    assert_found(&found, 0..9);
}

#[test]
fn ramps_scan_finds_each_tilted_plane() {
    let ramps = RampsConfig::default();
    let scene = Scene::ramps(&ramps).expect("ramps");
    let scan = scan(&scene, [-1.5, 2.0, 2.5], [1.0, 2.0, 0.0], &Noise::none());
    // cos 8° between the floor and the 10° ramp, so the two stay apart.
    let (extraction, majorities) = extract_scan(&scan, config().with_norm_thresh(0.99));
    // Pixels along the ramps' edges lie within a pixel of the neighbouring plane; the
    // ramps' shadows cut the floor behind them off from the floor in front.
    let found = check_planes(
        &extraction,
        &majorities,
        &scan.planes,
        0.9,
        1.0,
        Some(FLOOR_LABEL),
    );
    for (i, angle) in ramps.angles_deg.iter().enumerate() {
        let slope = 4 * i as i32 + 4;
        assert!(
            found.contains(&slope),
            "ramp at {angle}° missed; found {found:?}"
        );
    }
    assert!(found.contains(&FLOOR_LABEL));
}

/// A noisy scan through the whole stack (Laplacian, bilateral, FastGA, planes).
fn noisy_room(threads: usize) -> (ScanResult, Extraction) {
    let scan = room_scan(&Noise::new(0.004, 0.0, 7));
    let config = smoothed_config()
        .with_laplacian(Some(
            LaplacianConfig::default()
                .with_kernel(5)
                .with_iterations(4.into()),
        ))
        .with_threads(threads);
    let extraction = Polylidar::new(config)
        .expect("config")
        .extract_organized(&cloud(&scan))
        .expect("extraction");
    (scan, extraction)
}

#[test]
fn noisy_scan_with_smoothing_recovers_the_large_planes() {
    let (scan, extraction) = noisy_room(0);
    let majorities = point_majorities(&extraction, &scan.labels);
    // Floor, far wall, table top, obstacle top: each found once, within 2°.
    for label in [FLOOR_LABEL, 3, 7, 28] {
        let truth = &scan.planes[label as usize];
        let good = extraction
            .polygons
            .iter()
            .zip(&majorities)
            .filter(|(p, m)| m.0 == label && angle_deg(p.plane.normal, truth.normal) <= 2.0)
            .count();
        assert_eq!(good, 1, "plane {label}");
    }
    // Smoothing across depth edges (a table leg in front of the floor) bends a few floor
    // pixels toward the camera; such spurious pieces stay small.
    let total: usize = extraction.polygons.iter().map(|p| p.triangles.len()).sum();
    let off: usize = extraction
        .polygons
        .iter()
        .zip(&majorities)
        .filter(|(p, m)| angle_deg(p.plane.normal, scan.planes[m.0 as usize].normal) > 5.0)
        .map(|(p, _)| p.triangles.len())
        .sum();
    assert!(
        off * 100 < total,
        "{off} of {total} triangles in off-normal polygons"
    );
    let timings = &extraction.diagnostics.timings;
    for stage in [
        "laplacian",
        "mesh",
        "bilateral",
        "fastga",
        "planes_polygons",
    ] {
        assert!(timings.get(stage).is_some(), "no timing for {stage}");
    }
}

#[test]
fn same_output_at_any_thread_count() {
    let (_, one) = noisy_room(1);
    for threads in [2, 3] {
        let (_, many) = noisy_room(threads);
        assert_eq!(one.polygons, many.polygons, "{threads} threads");
        assert_eq!(one.diagnostics.counts, many.diagnostics.counts);
    }
}

#[test]
fn bad_3d_input_gives_errors() {
    let polylidar = Polylidar::new(config()).expect("config");
    let nan = OrganizedPointCloud::new(2, 2, vec![[f64::NAN; 3]; 4]).expect("cloud");
    assert!(matches!(
        polylidar.extract_organized(&nan),
        Err(PolylidarError::Organized(_))
    ));
    let vertices = vec![[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]];
    assert!(matches!(
        polylidar.extract_mesh(vertices.clone(), vec![[0, 1, 3]]),
        Err(PolylidarError::Mesh(_))
    ));
    let mut bad = vertices;
    bad[1][2] = f64::NAN;
    assert!(matches!(
        polylidar.extract_mesh(bad, vec![[0, 1, 2]]),
        Err(PolylidarError::Mesh(_))
    ));
}

#[test]
fn a_reused_pipeline_gives_the_same_output_as_a_fresh_one() {
    let scene = Scene::room(&RoomConfig::default()).expect("room");
    let near = scan(
        &scene,
        [3.0, 0.3, 2.6],
        [3.2, 3.0, 0.0],
        &Noise::new(0.002, 0.0, 3),
    );
    let far = scan(
        &scene,
        [5.5, 4.5, 2.8],
        [1.0, 1.0, 0.0],
        &Noise::new(0.002, 0.0, 4),
    );
    let reused = Polylidar::new(config()).expect("config");
    for s in [&near, &far, &near] {
        let fresh = Polylidar::new(config()).expect("config");
        let a = reused.extract_organized(&cloud(s)).expect("extraction");
        let b = fresh.extract_organized(&cloud(s)).expect("extraction");
        assert_eq!(a.polygons, b.polygons);
        assert_eq!(a.diagnostics.counts, b.diagnostics.counts);
    }
}

#[test]
fn a_pipeline_can_be_shared_between_threads() {
    fn shareable<T: Send + Sync>() {}
    shareable::<Polylidar>();
    let room = cloud(&room_scan(&Noise::none()));
    let shared = Polylidar::new(config()).expect("config");
    let alone = shared.extract_organized(&room).expect("extraction");
    std::thread::scope(|s| {
        let runs: Vec<_> = (0..3)
            .map(|_| s.spawn(|| shared.extract_organized(&room).expect("extraction")))
            .collect();
        for run in runs {
            assert_eq!(run.join().expect("no panic").polygons, alone.polygons);
        }
    });
}

/// Many runs at once on one pipeline, with both filters and with its own pool or rayon's
/// global one: every run finishes with the output of a run alone. A worker that waited
/// inside one run while another run's start waited for the first run's state would
/// deadlock here.
#[test]
fn concurrent_runs_on_one_pipeline_all_finish() {
    let room = cloud(&room_scan(&Noise::new(0.004, 0.0, 7)));
    for threads in [2, 0] {
        let shared = Polylidar::new(smoothed_config().with_threads(threads)).expect("config");
        let alone = shared.extract_organized(&room).expect("extraction");
        std::thread::scope(|s| {
            let runs: Vec<_> = (0..4)
                .map(|_| {
                    s.spawn(|| {
                        (0..6)
                            .map(|_| shared.extract_organized(&room).expect("extraction"))
                            .collect::<Vec<_>>()
                    })
                })
                .collect();
            for run in runs {
                for got in run.join().expect("no panic") {
                    assert_eq!(got.polygons, alone.polygons);
                }
            }
        });
    }
}

/// Frames meshed into a recycled extraction's arrays (and the previous triangle map)
/// give the extraction of a fresh run, through a stream whose shape changes (the arrays
/// grow and shrink), with both filters on and without them, with missing returns filled
/// (a copy of the caller's cloud) and from a view of the frame (a copy too).
#[test]
fn recycled_extractions_give_the_results_of_fresh_runs() {
    let scene = Scene::room(&RoomConfig::default()).expect("room");
    let frame = |rows: usize, cols: usize, seed: u64| {
        let pose = Pose::look_at([3.0, 0.3, 2.6], [3.2, 3.0, 0.0], [0.0, 0.0, 1.0]);
        let camera = PinholeCamera::new(rows, cols, 0.5 * cols as f64, 0.5 * cols as f64)
            .expect("valid camera")
            .with_pose(pose.expect("valid pose"));
        cloud(
            &scene
                .scan(&camera, &Noise::new(0.004, 0.0, seed))
                .expect("scan"),
        )
    };
    let frames = [
        frame(120, 160, 1),
        frame(150, 200, 2),
        frame(90, 130, 3),
        frame(120, 160, 4),
    ];
    let smoothed = smoothed_config();
    let decimated = smoothed.clone().with_decimate(Some(
        DecimateConfig::default().with_factor(DecimateFactor::Fixed(2)),
    ));
    let filled = smoothed
        .clone()
        .with_fill_missing(Some(FillConfig::default()));
    let runs = [
        (config(), false),
        (smoothed.clone(), false),
        (smoothed, true),
        (decimated, false),
        (filled.clone(), false),
        (filled, true),
    ];
    for (config, view) in runs {
        let recycling = Polylidar::new(config.clone()).expect("config");
        let extract = |p: &Polylidar, cloud: &OrganizedPointCloud| {
            if view {
                p.extract_organized_view(cloud.view())
            } else {
                p.extract_organized(cloud)
            }
            .expect("extraction")
        };
        for cloud in &frames {
            let fresh = extract(&Polylidar::new(config.clone()).expect("config"), cloud);
            let got = extract(&recycling, cloud);
            assert_eq!(got.mesh, fresh.mesh);
            assert_eq!(got.polygons, fresh.polygons);
            assert_eq!(got.dominant_normals, fresh.dominant_normals);
            assert!(!got.polygons.is_empty());
            recycling.recycle(got);
        }
        // A frame of the last one's size: its normals refill the recycled allocation,
        // and so do its points, which become the mesh's vertices: copied (to fill
        // missing returns in, or from a view), smoothed from the caller's cloud, or
        // decimated.
        let normals_at = |e: &polylidar::Extraction| e.mesh.triangle_normals().map(<[_]>::as_ptr);
        let vertices_at = |e: &polylidar::Extraction| e.mesh.vertices().as_ptr();
        let again = extract(&recycling, &frames[0]);
        let before = (normals_at(&again), vertices_at(&again));
        recycling.recycle(again);
        let again = extract(&recycling, &frames[0]);
        assert!(before.0.is_some());
        assert_eq!(normals_at(&again), before.0);
        assert_eq!(vertices_at(&again), before.1);
        assert_eq!(again.decimation.is_some(), config.decimate.is_some());
    }
}

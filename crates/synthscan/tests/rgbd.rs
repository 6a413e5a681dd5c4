//! The RGB-D depth cameras checked against their model: noise statistics, disparity
//! quantisation, missing returns (grazing, baseline shadow, depth edges, range), labels,
//! determinism, and the `rgbd_like` frames.

use synthscan::{
    DepthCameraKind, DepthModel, PinholeCamera, Polygon3, Pose, ScanResult, Scene, SceneError,
    Sensor, SimulatedDepthCamera, rgbd_like,
};

fn dot(a: [f64; 3], b: [f64; 3]) -> f64 {
    a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
}

/// A square of half-size `h` in the plane `x = x0`, facing `−x` (towards the origin),
/// centred on `(x0, cy, cz)`.
fn plate(x0: f64, cy: f64, cz: f64, h: f64) -> Polygon3 {
    Polygon3::from_shell(vec![
        [x0, cy - h, cz - h],
        [x0, cy - h, cz + h],
        [x0, cy + h, cz + h],
        [x0, cy + h, cz - h],
    ])
}

/// A camera at the origin looking along world `+x` (camera right = world `−y`).
fn camera(
    rows: usize,
    cols: usize,
    f: f64,
    model: DepthModel,
) -> Result<SimulatedDepthCamera, SceneError> {
    let pose = Pose::look_at([0.0; 3], [1.0, 0.0, 0.0], [0.0, 0.0, 1.0])?;
    Ok(SimulatedDepthCamera::new(PinholeCamera::new(rows, cols, f, f)?, model)?.with_pose(pose))
}

/// Depth along the camera's optical axis of every pixel (NaN where none).
fn depths(scan: &ScanResult, camera: &SimulatedDepthCamera) -> Vec<f64> {
    let pose = camera.pose();
    let forward = pose.rotate([0.0, 0.0, 1.0]);
    let o = pose.translation();
    scan.points
        .iter()
        .map(|p| dot([p[0] - o[0], p[1] - o[1], p[2] - o[2]], forward))
        .collect()
}

fn mean_std(values: &[f64]) -> (f64, f64) {
    let n = values.len() as f64;
    let mean = values.iter().sum::<f64>() / n;
    let var = values.iter().map(|v| (v - mean) * (v - mean)).sum::<f64>() / (n - 1.0);
    (mean, var.sqrt())
}

/// The measured depth noise on a fronto-parallel wall at `distance`.
fn wall_noise(model: DepthModel, distance: f64) -> Result<(f64, f64, usize), SceneError> {
    let mut scene = Scene::new();
    scene.add_polygon(0, plate(distance, 0.0, 0.0, 50.0))?;
    let cam = camera(120, 160, 100.0, model)?;
    let scan = scene.scan_depth(&cam, 11)?;
    let errors: Vec<f64> = depths(&scan, &cam)
        .into_iter()
        .filter(|z| z.is_finite())
        .map(|z| z - distance)
        .collect();
    let (mean, std) = mean_std(&errors);
    Ok((mean, std, errors.len()))
}

#[test]
fn depth_noise_follows_a_plus_b_z_squared() -> Result<(), SceneError> {
    // Without quantisation and rounding, the depth error is N(0, (a + b z²)²).
    for model in [
        DepthModel {
            disparity_step: 0.0,
            depth_unit: 0.0,
            ..DepthModel::kinect_v1().without_dropouts()
        },
        DepthModel {
            disparity_step: 0.0,
            depth_unit: 0.0,
            sigma_floor: 0.002,
            sigma_quadratic: 0.001,
            ..DepthModel::d435().without_dropouts()
        },
    ] {
        let mut sigmas = Vec::new();
        for z in [1.0, 3.0] {
            let (mean, std, n) = wall_noise(model, z)?;
            assert_eq!(n, 120 * 160);
            let want = model.sigma(z);
            assert!(
                (std / want - 1.0).abs() < 0.05,
                "σ at {z} m: measured {std}, model {want}"
            );
            assert!(
                mean.abs() < 4.0 * want / (n as f64).sqrt(),
                "bias {mean} at {z} m"
            );
            sigmas.push(std);
        }
        let ratio = sigmas[1] / sigmas[0];
        let want = model.sigma(3.0) / model.sigma(1.0);
        assert!((ratio / want - 1.0).abs() < 0.07, "ratio {ratio} vs {want}");
    }
    // The Kinect's noise is purely quadratic: 3 m is 9 times as noisy as 1 m.
    let kinect = DepthModel {
        disparity_step: 0.0,
        depth_unit: 0.0,
        ..DepthModel::kinect_v1().without_dropouts()
    };
    let ratio = wall_noise(kinect, 3.0)?.1 / wall_noise(kinect, 1.0)?.1;
    assert!((ratio / 9.0 - 1.0).abs() < 0.07, "ratio {ratio}");
    Ok(())
}

#[test]
fn depth_is_quantised_in_disparity() -> Result<(), SceneError> {
    let model = DepthModel {
        depth_unit: 0.0,
        ..DepthModel::kinect_v1().without_dropouts()
    };
    let fb = model.disparity_focal * model.baseline;
    let mut scene = Scene::new();
    scene.add_polygon(0, plate(3.0, 0.0, 0.0, 50.0))?;
    let cam = camera(120, 160, 100.0, model)?;
    let z = depths(&scene.scan_depth(&cam, 3)?, &cam);
    assert!(z.iter().all(|z| z.is_finite()));
    // Every depth is f·B / (k · step) for an integer k.
    for &v in &z {
        let k = fb / (v * model.disparity_step);
        assert!(
            (k - k.round()).abs() < 1e-6,
            "depth {v} is not on a level (k = {k})"
        );
    }
    // The histogram has isolated peaks one quantisation step apart.
    let mut levels: Vec<f64> = z.clone();
    levels.sort_by(f64::total_cmp);
    levels.dedup_by(|a, b| (*a - *b).abs() < 1e-9);
    assert!(
        levels.len() >= 3 && levels.len() < 20,
        "{} levels",
        levels.len()
    );
    for pair in levels.windows(2) {
        let step = model.depth_step(pair[0]);
        let gap = pair[1] - pair[0];
        assert!((gap / step - 1.0).abs() < 0.05, "gap {gap} vs step {step}");
    }
    let bins = |v: f64| (v * 1000.0).floor() as i64;
    let span = bins(levels[levels.len() - 1]) - bins(levels[0]) + 1;
    let mut used: Vec<i64> = z.iter().map(|&v| bins(v)).collect();
    used.sort_unstable();
    used.dedup();
    assert!(
        (used.len() as f64) < 0.2 * span as f64,
        "{} of {span} 1 mm bins used",
        used.len()
    );

    // With the 1 mm depth unit every depth is a whole number of millimetres.
    let cam = camera(40, 40, 100.0, DepthModel::kinect_v1().without_dropouts())?;
    for v in depths(&scene.scan_depth(&cam, 3)?, &cam) {
        assert!((v * 1000.0 - (v * 1000.0).round()).abs() < 1e-6, "{v}");
    }
    Ok(())
}

#[test]
fn returns_go_missing_at_grazing_incidence() -> Result<(), SceneError> {
    let mut scene = Scene::new();
    scene.add_polygon(
        0,
        Polygon3::from_shell(vec![
            [-50.0, -50.0, 0.0],
            [50.0, -50.0, 0.0],
            [50.0, 50.0, 0.0],
            [-50.0, 50.0, 0.0],
        ]),
    )?;
    let model = DepthModel {
        grazing_start_deg: 70.0,
        grazing_end_deg: 85.0,
        ..DepthModel::ideal()
    };
    // 1 m above the floor, pitched down 20°: incidence from about 50° to beyond 90°.
    let pose = Pose::look_at(
        [0.0, 0.0, 1.0],
        [1.0, 0.0, 1.0 - 20f64.to_radians().tan()],
        [0.0, 0.0, 1.0],
    )?;
    let cam = SimulatedDepthCamera::new(PinholeCamera::new(120, 160, 130.0, 130.0)?, model)?
        .with_pose(pose);
    let scan = scene.scan_depth(&cam, 5)?;
    let (mut low, mut high) = ([0usize; 2], [0usize; 2]); // [kept, dropped]
    for row in 0..cam.rows() {
        for col in 0..cam.cols() {
            let d = pose.rotate(cam.direction(row, col));
            let kept = scan.labels[row * cam.cols() + col] >= 0;
            if d[2] >= 0.0 {
                assert!(!kept, "a ray above the horizon has depth");
                continue;
            }
            let incidence = (-d[2]).acos().to_degrees();
            if incidence < 70.0 {
                assert!(kept, "dropped at {incidence:.1}°");
            } else if incidence > 85.0 {
                assert!(!kept, "kept at {incidence:.1}°");
            } else {
                let bin = if incidence < 77.5 {
                    &mut low
                } else {
                    &mut high
                };
                bin[usize::from(!kept)] += 1;
            }
        }
    }
    let frac = |b: [usize; 2]| b[1] as f64 / (b[0] + b[1]).max(1) as f64;
    assert!(low[0] + low[1] > 100 && high[0] + high[1] > 100);
    // Smoothstep: under half dropped in the first half of the ramp, over half in the second.
    assert!(frac(low) > 0.02 && frac(low) < 0.5, "low {low:?}");
    assert!(frac(high) > 0.5 && frac(high) < 0.98, "high {high:?}");
    Ok(())
}

/// A plate 1.5 m away in front of a wall 3 m away.
fn plate_before_wall() -> Result<Scene, SceneError> {
    let mut scene = Scene::new();
    scene.add_polygon(0, plate(3.0, 0.0, 0.0, 50.0))?;
    scene.add_polygon(1, plate(1.5, 0.0, 0.0, 0.3))?;
    Ok(scene)
}

#[test]
fn near_objects_cast_a_shadow_as_wide_as_the_disparity_difference() -> Result<(), SceneError> {
    let scene = plate_before_wall()?;
    let model = DepthModel {
        shadows: true,
        ..DepthModel::ideal()
    };
    let (rows, cols, f) = (60, 200, 200.0);
    let reference = scene.scan_depth(&camera(rows, cols, f, DepthModel::ideal())?, 0)?;
    let scan = scene.scan_depth(&camera(rows, cols, f, model)?, 0)?;
    let width = f * model.baseline * (1.0 / 1.5 - 1.0 / 3.0);
    let row = rows / 2;
    let line = |s: &ScanResult| s.labels[row * cols..(row + 1) * cols].to_vec();
    let (want, got) = (line(&reference), line(&scan));
    let first = want
        .iter()
        .position(|&l| l == 1)
        .ok_or(SceneError::UnknownLabel { label: 1 })?;
    let last = want
        .iter()
        .rposition(|&l| l == 1)
        .ok_or(SceneError::UnknownLabel { label: 1 })?;
    // The plate itself and everything right of it are seen.
    assert_eq!(&got[first..], &want[first..]);
    // Left of it, a band of the wall as wide as the disparity difference is missing.
    let band = got[..first].iter().rev().take_while(|&&l| l < 0).count();
    assert!(
        (band as f64 - width).abs() <= 1.0,
        "shadow {band} px, expected {width:.1}"
    );
    assert!(got[..first - band].iter().all(|&l| l == 0));
    assert!(last + 1 < cols);
    // Every dropped pixel in the whole image is wall.
    for (g, w) in scan.labels.iter().zip(&reference.labels) {
        assert!(*g == *w || (*g == -1 && *w == 0));
    }
    Ok(())
}

#[test]
fn pixels_next_to_depth_jumps_are_dropped() -> Result<(), SceneError> {
    let scene = plate_before_wall()?;
    let (rows, cols) = (60, 80);
    let reference = camera(rows, cols, 60.0, DepthModel::ideal())?;
    let z = depths(&scene.scan_depth(&reference, 0)?, &reference);
    // An independent edge map: 4-neighbours differing by more than 5 %, dilated by 1 px.
    let mut edge = vec![false; rows * cols];
    for r in 0..rows {
        for c in 0..cols {
            let i = r * cols + c;
            let mut jump = false;
            for (dr, dc) in [(0i64, 1i64), (0, -1), (1, 0), (-1, 0)] {
                let (rr, cc) = (r as i64 + dr, c as i64 + dc);
                if rr >= 0 && cc >= 0 && (rr as usize) < rows && (cc as usize) < cols {
                    let j = rr as usize * cols + cc as usize;
                    jump |= (z[i] - z[j]).abs() > 0.05 * z[i].min(z[j]);
                }
            }
            edge[i] = jump;
        }
    }
    let near = |r: usize, c: usize| {
        (r.saturating_sub(1)..=(r + 1).min(rows - 1))
            .any(|rr| (c.saturating_sub(1)..=(c + 1).min(cols - 1)).any(|cc| edge[rr * cols + cc]))
    };
    let always = DepthModel {
        edge_drop: 1.0,
        edge_band: 1,
        ..DepthModel::ideal()
    };
    let scan = scene.scan_depth(&camera(rows, cols, 60.0, always)?, 4)?;
    let mut at_risk = 0;
    for r in 0..rows {
        for c in 0..cols {
            let dropped = scan.labels[r * cols + c] < 0;
            assert_eq!(dropped, near(r, c), "pixel ({r}, {c})");
            at_risk += usize::from(near(r, c));
        }
    }
    assert!(at_risk > 50);
    // With probability 0.5, about half of them.
    let half = DepthModel {
        edge_drop: 0.5,
        ..always
    };
    let scan = scene.scan_depth(&camera(rows, cols, 60.0, half)?, 4)?;
    let dropped = scan.labels.iter().filter(|&&l| l < 0).count();
    let frac = dropped as f64 / at_risk as f64;
    assert!((0.3..0.7).contains(&frac), "{dropped} of {at_risk}");
    Ok(())
}

#[test]
fn depth_outside_the_range_is_missing() -> Result<(), SceneError> {
    let model = DepthModel {
        min_depth: 1.5,
        max_depth: 3.0,
        ..DepthModel::ideal()
    };
    // A wall tilted so that its depth runs from about 1.3 to 5.7 m across the image.
    let mut scene = Scene::new();
    scene.add_polygon(
        0,
        Polygon3::from_shell(vec![
            [0.2, 3.0, -10.0],
            [0.2, 3.0, 10.0],
            [4.0, -3.0, 10.0],
            [4.0, -3.0, -10.0],
        ]),
    )?;
    let reference = camera(20, 120, 60.0, DepthModel::ideal())?;
    let cam = camera(20, 120, 60.0, model)?;
    let want = depths(&scene.scan_depth(&reference, 0)?, &reference);
    let got = depths(&scene.scan_depth(&cam, 0)?, &cam);
    let (mut inside, mut outside) = (0, 0);
    for (w, g) in want.iter().zip(&got) {
        if (1.5..=3.0).contains(w) {
            assert_eq!(w.to_bits(), g.to_bits());
            inside += 1;
        } else {
            assert!(g.is_nan(), "depth {w} kept");
            outside += 1;
        }
    }
    assert!(inside > 100 && outside > 100);
    Ok(())
}

fn bits(scan: &ScanResult) -> Vec<[u64; 3]> {
    scan.points.iter().map(|p| p.map(f64::to_bits)).collect()
}

#[test]
fn scans_are_deterministic_by_seed_and_thread_count() -> Result<(), Box<dyn std::error::Error>> {
    let (scene, camera) = rgbd_like(3, DepthCameraKind::KinectHalf)?;
    let run = |threads: usize, seed: u64| -> Result<ScanResult, Box<dyn std::error::Error>> {
        let pool = rayon::ThreadPoolBuilder::new()
            .num_threads(threads)
            .build()?;
        Ok(pool.install(|| scene.scan_depth(&camera, seed))?)
    };
    let one = run(1, 5)?;
    let three = run(3, 5)?;
    assert_eq!(bits(&one), bits(&three));
    assert_eq!(one.labels, three.labels);
    assert_eq!(bits(&one), bits(&run(2, 5)?));
    let other = run(2, 6)?;
    assert_ne!(bits(&one), bits(&other));
    // The same seed builds the same room.
    let (again, camera_again) = rgbd_like(3, DepthCameraKind::KinectHalf)?;
    assert_eq!(again, scene);
    assert_eq!(camera_again, camera);
    Ok(())
}

#[test]
fn labels_agree_with_points() -> Result<(), SceneError> {
    for seed in [1, 2] {
        for kind in [DepthCameraKind::KinectHalf, DepthCameraKind::D435Half] {
            let (scene, camera) = rgbd_like(seed, kind)?;
            let ideal = camera.clone().with_model(DepthModel::ideal())?;
            let exact = scene.scan_depth(&ideal, seed)?;
            // Error-free points lie on the plane of their label.
            for (p, &l) in exact.points.iter().zip(&exact.labels) {
                if l >= 0 {
                    let plane = &exact.planes[l as usize];
                    let d = dot(plane.normal, *p) - plane.offset;
                    assert!(d.abs() < 1e-9, "{d}");
                }
            }
            // With errors, a pixel keeps the label of the face its ray hit, and its depth
            // stays within the noise, a quantisation step and the depth unit of the truth.
            let noisy = scene.scan_depth(&camera, seed)?;
            let model = camera.model();
            let (zt, zn) = (depths(&exact, &ideal), depths(&noisy, &camera));
            let mut kept = 0;
            for i in 0..zt.len() {
                if noisy.labels[i] >= 0 {
                    assert_eq!(noisy.labels[i], exact.labels[i]);
                    let bound =
                        6.0 * model.sigma(zt[i]) + 2.0 * model.depth_step(zt[i]) + model.depth_unit;
                    assert!((zn[i] - zt[i]).abs() < bound, "{} vs {}", zn[i], zt[i]);
                    kept += 1;
                }
            }
            assert!(kept > zt.len() / 2);
        }
    }
    Ok(())
}

#[test]
fn rgbd_like_frames_have_enough_sizeable_planes() -> Result<(), SceneError> {
    for kind in DepthCameraKind::ALL {
        let (rows, cols) = kind.size();
        let pixels = (rows * cols) as f64;
        let seeds = if matches!(kind, DepthCameraKind::Kinect | DepthCameraKind::D435) {
            0..2
        } else {
            0..8
        };
        for seed in seeds {
            let (scene, camera) = rgbd_like(seed, kind)?;
            assert_eq!((camera.rows(), camera.cols()), (rows, cols));
            assert_eq!(camera.camera().intrinsics()[0], kind.focal());
            let scan = scene.scan_depth(&camera, seed)?;
            let counts = scan.label_counts();
            let seen = counts.iter().filter(|&&c| c > 0).count();
            let tiny = counts
                .iter()
                .filter(|&&c| c > 0 && (c as f64) < 1e-3 * pixels)
                .count();
            assert!((10..=35).contains(&seen), "{seen} planes, seed {seed}");
            assert!(3 * tiny < seen, "{tiny} of {seen} planes tiny, seed {seed}");
            assert!(scan.num_valid() as f64 > 0.8 * pixels);
        }
    }
    Ok(())
}

#[test]
fn presets_and_validation() -> Result<(), SceneError> {
    for (full, half) in [
        (DepthCameraKind::Kinect, DepthCameraKind::KinectHalf),
        (DepthCameraKind::D435, DepthCameraKind::D435Half),
    ] {
        assert_eq!(full.size().0, 2 * half.size().0);
        assert_eq!(full.size().1, 2 * half.size().1);
        assert_eq!(full.focal(), 2.0 * half.focal());
        assert_eq!(full.model(), half.model());
        SimulatedDepthCamera::preset(full)?;
    }
    // Khoshelham & Elberink: about 7 cm between depth levels at 5 m for the Kinect.
    assert!((DepthModel::kinect_v1().depth_step(5.0) - 0.07).abs() < 0.005);
    let cam = PinholeCamera::new(4, 4, 10.0, 10.0)?;
    for bad in [
        DepthModel {
            sigma_quadratic: -1.0,
            ..DepthModel::ideal()
        },
        DepthModel {
            grazing_start_deg: 80.0,
            grazing_end_deg: 70.0,
            ..DepthModel::ideal()
        },
        DepthModel {
            edge_drop: 1.5,
            ..DepthModel::ideal()
        },
        DepthModel {
            min_depth: 2.0,
            max_depth: 1.0,
            ..DepthModel::ideal()
        },
        DepthModel {
            baseline: 0.0,
            ..DepthModel::ideal()
        },
    ] {
        assert!(matches!(
            SimulatedDepthCamera::new(cam.clone(), bad),
            Err(SceneError::InvalidParameter { .. })
        ));
    }
    Ok(())
}

//! The real fixtures of `../shared/fixtures` end to end with the papers' presets.
#![allow(clippy::expect_used, clippy::unwrap_used, clippy::panic)]

use polylidar::{Config, Extraction, OrganizedPointCloud, Polylidar};
use polylidar_io::{InputKind, read_input};

fn organized(rel: &str) -> Option<OrganizedPointCloud> {
    let path = test_fixtures::fixture(rel)?;
    let InputKind::Cloud(cloud) = read_input(&path).expect("readable fixture") else {
        panic!("{rel} is not a point cloud");
    };
    assert!(cloud.is_organized(), "{rel} is organized");
    Some(OrganizedPointCloud::new(cloud.rows, cloud.cols, cloud.points).expect("valid cloud"))
}

fn run(cloud: &OrganizedPointCloud, preset: &str) -> Extraction {
    let config = Config::preset(preset).expect("known preset");
    Polylidar::new(config)
        .expect("valid preset")
        .extract_organized(cloud)
        .expect("extraction")
}

/// Every polygon is planar: its points lie near its plane, and its normal is unit.
fn check_planarity(extraction: &Extraction, tolerance: f64) {
    for (i, p) in extraction.polygons.iter().enumerate() {
        let n = p.plane.normal;
        assert!(((n[0] * n[0] + n[1] * n[1] + n[2] * n[2]).sqrt() - 1.0).abs() < 1e-9);
        let worst = p
            .shell_points
            .iter()
            .map(|q| (n[0] * q[0] + n[1] * q[1] + n[2] * q[2] + p.plane.offset).abs())
            .fold(0.0, f64::max);
        assert!(
            worst < tolerance,
            "polygon {i}: a shell point is {worst:.3} m off its plane"
        );
    }
}

#[test]
fn synpeb_scans_give_dozens_of_planes() {
    for rel in ["synpeb/pc_01.pcd", "synpeb/pc_02.pcd"] {
        let Some(cloud) = organized(rel) else { return };
        let extraction = run(&cloud, "synpeb");
        let c = &extraction.diagnostics.counts;
        eprintln!("{rel}: {c:?}");
        // The original reports 47 planes on pc_01.
        assert!(
            (20..=90).contains(&c.polygons),
            "{rel}: {} polygons",
            c.polygons
        );
        assert!(c.dominant_normals >= 3);
        check_planarity(&extraction, 0.25);
        // Planes are large: min_triangles 1000.
        assert!(
            extraction
                .polygons
                .iter()
                .all(|p| p.triangles.len() >= 1000)
        );
    }
}

#[test]
fn realsense_frame_with_rgbd_preset_gives_valid_postprocessed_polygons() {
    let Some(cloud) = organized("realsense/rgbd_opc.npy") else {
        return;
    };
    let extraction = run(&cloud, "rgbd");
    let c = &extraction.diagnostics.counts;
    eprintln!("rgbd_opc: {c:?}");
    assert!(
        c.polygons >= 1,
        "a RealSense frame of a floor has at least one plane"
    );
    assert_eq!(c.postprocessed_polygons, extraction.postprocessed.len());
    check_planarity(&extraction, 0.2);
    // Post-processed polygons stay on their source plane.
    for p in &extraction.postprocessed {
        let plane = extraction.polygons[p.source].plane;
        for q in p.shell.iter().chain(p.holes.iter().flatten()) {
            let d: f64 = (0..3).map(|k| plane.normal[k] * q[k]).sum::<f64>() + plane.offset;
            assert!(d.abs() < 1e-9);
        }
    }
}

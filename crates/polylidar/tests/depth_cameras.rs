//! Every source of depth-camera intrinsics (numbers, Open3D camera JSON, RealSense CSV
//! beside the image) gives the cloud that back-projecting the shared ICL-NUIM and TUM
//! frames by hand gives; missing or mismatched intrinsics are errors that say so.
#![cfg(feature = "io")]
#![allow(clippy::expect_used, clippy::unwrap_used, clippy::panic)]

use std::path::Path;

use polylidar::io::{CameraSource, DepthCamera, Input, Limits, is_missing_intrinsics};
use polylidar::{Intrinsics, OrganizedPointCloud};

/// The PrimeSense intrinsics of `rgbd/camera_primesense.json`, which Open3D uses for both
/// data sets.
const PRIMESENSE: [f64; 4] = [525.0, 525.0, 319.5, 239.5];

/// The oracle: `z = d / units`, `x = (u − cx) z / fx`, `y = (v − cy) z / fy`, NaN for 0.
fn by_hand(path: &Path, units_per_metre: f64) -> Vec<[f64; 3]> {
    let image = polylidar_io::read_depth_png(path).unwrap();
    let [fx, fy, cx, cy] = PRIMESENSE;
    (0..image.height)
        .flat_map(|v| (0..image.width).map(move |u| (u, v)))
        .map(|(u, v)| {
            let d = image.data[v * image.width + u];
            if d == 0 {
                return [f64::NAN; 3];
            }
            let z = f64::from(d) / units_per_metre;
            [(u as f64 - cx) * z / fx, (v as f64 - cy) * z / fy, z]
        })
        .collect()
}

fn assert_same(cloud: &OrganizedPointCloud, expected: &[[f64; 3]], what: &str) {
    assert_eq!((cloud.rows(), cloud.cols()), (480, 640), "{what}");
    assert_eq!(cloud.points().len(), expected.len(), "{what}");
    for (i, (p, q)) in cloud.points().iter().zip(expected).enumerate() {
        for k in 0..3 {
            let same = (p[k].is_nan() && q[k].is_nan()) || (p[k] - q[k]).abs() <= 1e-12;
            assert!(same, "{what}: point {i} is {p:?}, by hand {q:?}");
        }
    }
}

/// A fresh temporary folder for one test.
fn temp_dir(name: &str) -> test_fixtures::ScratchDir {
    test_fixtures::scratch_dir("polylidar-cameras", name)
}

/// A RealSense Viewer metadata CSV with the PrimeSense intrinsics.
fn realsense_csv(depth_units: Option<f64>) -> String {
    let [fx, fy, cx, cy] = PRIMESENSE;
    let mut text = format!(
        "Type,Depth\nResolution x,640\nResolution y,480\nFx,{fx}\nFy,{fy}\nPPx,{cx}\nPPy,{cy}\n"
    );
    if let Some(units) = depth_units {
        text.push_str(&format!("Depth Units,{units}\n"));
    }
    text
}

#[test]
fn every_source_gives_the_hand_made_cloud() {
    let Some(json) = test_fixtures::fixture("rgbd/camera_primesense.json") else {
        return;
    };
    let frames = [
        ("rgbd/icl_living_depth_00000.png", 1000.0),
        ("rgbd/icl_living_depth_00004.png", 1000.0),
        ("rgbd/tum_depth.png", 5000.0),
    ];
    for (name, units) in frames {
        let Some(png) = test_fixtures::fixture(name) else {
            return;
        };
        let expected = by_hand(&png, units);
        let [fx, fy, cx, cy] = PRIMESENSE;
        let numbers = DepthCamera::new(CameraSource::Pinhole(Intrinsics::new(fx, fy, cx, cy)))
            .with_units_per_metre(units);
        assert_same(
            &numbers.read(&png).unwrap(),
            &expected,
            &format!("{name}, numbers"),
        );
        let from_json =
            DepthCamera::new(CameraSource::File(json.clone())).with_units_per_metre(units);
        assert_same(
            &from_json.read(&png).unwrap(),
            &expected,
            &format!("{name}, JSON"),
        );

        // The RealSense CSV beside a copy of the frame: its Depth Units, or the flag.
        let dir = temp_dir(name.trim_start_matches("rgbd/").trim_end_matches(".png"));
        let copy = dir.join("frame_depth.png");
        std::fs::copy(&png, &copy).unwrap();
        std::fs::write(
            dir.join("frame_depth_metadata.csv"),
            realsense_csv(Some(1.0 / units)),
        )
        .unwrap();
        let Input::Organized(beside) = Input::read(&copy).unwrap() else {
            panic!("a depth PNG is organized input")
        };
        assert_same(&beside, &expected, &format!("{name}, CSV beside"));
        std::fs::write(dir.join("frame_depth_metadata.csv"), realsense_csv(None)).unwrap();
        let flagged = DepthCamera::default().with_units_per_metre(units);
        let Input::Organized(with_flag) =
            Input::read_with_camera(&copy, &flagged, &Limits::default())
                .unwrap()
                .0
        else {
            panic!("a depth PNG is organized input")
        };
        assert_same(
            &with_flag,
            &expected,
            &format!("{name}, CSV beside + units"),
        );
        std::fs::remove_dir_all(&dir).unwrap();
    }
}

#[test]
fn missing_and_mismatched_intrinsics_are_errors() {
    let Some(png) = test_fixtures::fixture("rgbd/icl_living_depth_00000.png") else {
        return;
    };
    let Some(json) = test_fixtures::fixture("rgbd/camera_primesense.json") else {
        return;
    };
    let dir = temp_dir("missing");
    let copy = dir.join("alone.png");
    std::fs::copy(&png, &copy).unwrap();
    let e = DepthCamera::default().read(&copy).unwrap_err();
    assert!(is_missing_intrinsics(&e), "{e}");
    let text = e.to_string();
    assert!(
        text.contains("alone.png") && text.contains("no camera intrinsics"),
        "{text}"
    );
    assert!(
        text.contains("alone_metadata.csv"),
        "the paths tried are named: {text}"
    );

    // A camera for 640 × 480 on a 320 × 240 image.
    let image = polylidar_io::read_depth_png(&png).unwrap();
    let half: Vec<u16> = (0..240)
        .flat_map(|v| (0..320).map(move |u| (u, v)))
        .map(|(u, v)| image.data[2 * v * 640 + 2 * u])
        .collect();
    let e = DepthCamera::new(CameraSource::File(json.clone()))
        .cloud(&half, 240, 320, None)
        .unwrap_err();
    assert!(
        e.to_string().contains("640 × 480") && e.to_string().contains("320 × 240"),
        "{e}"
    );

    let e = DepthCamera::new(CameraSource::File(json))
        .with_units_per_metre(0.0)
        .read(&png)
        .unwrap_err();
    assert!(e.to_string().contains("depth_scale"), "{e}");
    std::fs::remove_dir_all(&dir).unwrap();
}

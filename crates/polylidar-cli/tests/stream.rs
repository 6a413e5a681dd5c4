//! `polylidar stream` over the shared RGB-D frames: one record per frame, each equal to
//! what `polylidar extract` gives on that frame alone, with each source of intrinsics;
//! colours per polygon; errors naming what is missing.
#![allow(clippy::expect_used, clippy::unwrap_used, clippy::panic)]

mod common;

use std::path::{Path, PathBuf};

use common::{polylidar_in as polylidar, succeeded};
use serde_json::Value;

fn temp_dir(name: &str) -> test_fixtures::ScratchDir {
    common::scratch("stream", name)
}

fn read_json(path: &Path) -> Value {
    serde_json::from_str(&std::fs::read_to_string(path).unwrap()).unwrap()
}

/// `polylidar extract FRAME CAMERA… -o single.geojson`'s features.
fn extract_alone(dir: &Path, frame: &Path, camera: &[&str]) -> Value {
    let frame = frame.display().to_string();
    let mut args = vec!["extract", &frame, "--preset", "rgbd-auto", "--stride", "2"];
    args.extend_from_slice(camera);
    args.extend_from_slice(&["-o", "single.geojson"]);
    succeeded(&polylidar(dir, &args));
    read_json(&dir.join("single.geojson"))["features"].clone()
}

#[test]
fn stream_of_icl_frames_equals_each_frame_alone() {
    let (Some(first), Some(_), Some(camera)) = (
        test_fixtures::fixture("rgbd/icl_living_depth_00000.png"),
        test_fixtures::fixture("rgbd/icl_living_depth_00004.png"),
        test_fixtures::fixture("rgbd/camera_primesense.json"),
    ) else {
        return;
    };
    let dir = temp_dir("icl");
    let folder = first.parent().unwrap();
    let glob = folder.join("icl_living_depth_*.png").display().to_string();
    let colors = folder.join("icl_living_color_*.jpg").display().to_string();
    let camera = camera.display().to_string();
    let out = polylidar(
        &dir,
        &[
            "stream",
            &glob,
            "--intrinsics",
            &camera,
            "--preset",
            "rgbd-auto",
            "--stride",
            "2",
            "-o",
            "frames.geojsonl",
            "--json",
        ],
    );
    succeeded(&out);
    let report: Value = serde_json::from_slice(&out.stdout).unwrap();
    assert_eq!(report["failed"], 0, "{report}");
    assert_eq!(report["frames"].as_array().unwrap().len(), 2, "{report}");
    assert!(report["period_ms"].as_f64().unwrap() > 0.0, "{report}");
    let stages: Vec<&str> = report["summary"]
        .as_array()
        .unwrap()
        .iter()
        .map(|s| s["stage"].as_str().unwrap())
        .collect();
    assert!(
        stages.contains(&"bilateral") && stages.contains(&"pipeline"),
        "{stages:?}"
    );

    let text = std::fs::read_to_string(dir.join("frames.geojsonl")).unwrap();
    let lines: Vec<Value> = text
        .lines()
        .map(|l| serde_json::from_str(l).unwrap())
        .collect();
    assert_eq!(lines.len(), 2);
    for (line, name) in lines
        .iter()
        .zip(["icl_living_depth_00000", "icl_living_depth_00004"])
    {
        assert_eq!(line["type"], "FeatureCollection");
        let frame = PathBuf::from(line["frame"].as_str().unwrap());
        assert!(frame.ends_with(format!("{name}.png")), "{frame:?}");
        let alone = extract_alone(&dir, &frame, &["--intrinsics", &camera]);
        assert!(
            !alone.as_array().unwrap().is_empty(),
            "{name}: planes found"
        );
        assert_eq!(line["features"], alone, "{name}: stream and extract agree");
    }

    // With the colour pictures, each polygon gets its mean colour.
    let out = polylidar(
        &dir,
        &[
            "stream",
            &glob,
            "--color",
            &colors,
            "--intrinsics",
            &camera,
            "--preset",
            "rgbd-auto",
            "--stride",
            "2",
            "--prefetch",
            "0",
            "--in-flight",
            "1",
            "-o",
            "colored.geojsonl",
        ],
    );
    succeeded(&out);
    let text = std::fs::read_to_string(dir.join("colored.geojsonl")).unwrap();
    for (line, plain) in text.lines().zip(&lines) {
        let line: Value = serde_json::from_str(line).unwrap();
        let features = line["features"].as_array().unwrap();
        assert_eq!(features.len(), plain["features"].as_array().unwrap().len());
        for feature in features {
            let color = feature["properties"]["color"].as_array().unwrap();
            assert_eq!(color.len(), 3);
            assert!(color.iter().all(|c| c.as_u64().unwrap() <= 255));
        }
    }
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn tum_frame_with_numbers_into_a_folder() {
    let Some(tum) = test_fixtures::fixture("rgbd/tum_depth.png") else {
        return;
    };
    let dir = temp_dir("tum");
    let glob = tum.display().to_string();
    let camera = [
        "--intrinsics",
        "525,525,319.5,239.5",
        "--depth-scale",
        "5000",
    ];
    let mut args = vec!["stream", &glob, "--preset", "rgbd-auto", "--stride", "2"];
    args.extend_from_slice(&camera);
    args.extend_from_slice(&["--out-dir", "frames"]);
    let stderr = succeeded(&polylidar(&dir, &args));
    assert!(stderr.contains("1 of 1 frames ran"), "{stderr}");
    let streamed = read_json(&dir.join("frames/tum_depth.geojson"));
    assert_eq!(streamed["frame"].as_str(), Some(glob.as_str()));
    let alone = extract_alone(&dir, &tum, &camera);
    assert!(!alone.as_array().unwrap().is_empty());
    assert_eq!(streamed["features"], alone);
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn missing_intrinsics_name_the_ways_to_give_them() {
    let Some(png) = test_fixtures::fixture("rgbd/icl_living_depth_00000.png") else {
        return;
    };
    let dir = temp_dir("missing");
    std::fs::create_dir_all(dir.join("frames")).unwrap();
    std::fs::copy(&png, dir.join("frames/depth_0.png")).unwrap();
    let expected = "depth_0.png: no camera intrinsics: pass --intrinsics fx,fy,cx,cy and \
                    --depth-scale, or an Open3D camera JSON, or put the RealSense \
                    _metadata.csv beside it";
    let out = polylidar(&dir, &["extract", "frames/depth_0.png"]);
    assert!(!out.status.success());
    assert!(
        String::from_utf8_lossy(&out.stderr).contains(expected),
        "{out:?}"
    );
    let out = polylidar(&dir, &["stream", "frames", "-o", "x.geojsonl"]);
    assert!(!out.status.success());
    assert!(
        String::from_utf8_lossy(&out.stderr).contains(expected),
        "{out:?}"
    );
    let out = polylidar(
        &dir,
        &["extract", "frames/depth_0.png", "--intrinsics", "1,2,3"],
    );
    assert!(
        String::from_utf8_lossy(&out.stderr).contains("four numbers"),
        "{out:?}"
    );
    let out = polylidar(&dir, &["stream", "nothing_*.png", "-o", "x.geojsonl"]);
    assert!(
        String::from_utf8_lossy(&out.stderr).contains("no frames found"),
        "{out:?}"
    );
    std::fs::remove_dir_all(&dir).unwrap();
}

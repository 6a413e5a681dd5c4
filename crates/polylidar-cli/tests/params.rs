//! How `polylidar extract` chooses and reports parameters: units, lengths from the point
//! spacing, explanations of empty results and `--strict`, flag forms and warnings.
#![allow(clippy::expect_used, clippy::unwrap_used, clippy::panic)]

mod common;

use std::path::{Path, PathBuf};

use common::{json, polylidar};

fn scratch(name: &str) -> test_fixtures::ScratchDir {
    common::scratch("params", name)
}

/// A flat `n × n` grid of 3D points `spacing` apart, with a small tilt so no three are
/// exactly collinear along the diagonals, as CSV.
fn flat_cloud(dir: &Path, n: usize, spacing: f64) -> PathBuf {
    let mut text = String::from("x,y,z\n");
    for i in 0..n {
        for j in 0..n {
            let (x, y) = (i as f64 * spacing, j as f64 * spacing);
            text.push_str(&format!("{x},{y},{}\n", 0.001 * x));
        }
    }
    let path = dir.join(format!("cloud-{n}-{spacing}.csv"));
    std::fs::write(&path, text).unwrap();
    path
}

#[test]
fn lmax_comes_from_the_spacing_when_not_given() {
    let dir = scratch("spacing");
    let cloud = flat_cloud(&dir, 30, 0.5);
    let out = json(&polylidar(&["extract", cloud.to_str().unwrap(), "--json"]));
    let params = &out["parameters"];
    assert_eq!(params["spacing"], 0.5);
    assert_eq!(params["lmax"], 4.0 * 0.5);
    assert_eq!(params["unit_source"], "assumed");
    assert_eq!(out["counts"]["polygons"], 1);
    // Given explicitly, it is kept.
    let out = json(&polylidar(&[
        "extract",
        cloud.to_str().unwrap(),
        "--json",
        "--lmax",
        "0.75",
    ]));
    assert_eq!(out["parameters"]["lmax"], 0.75);
}

#[test]
fn min_triangles_comes_from_the_extent_when_not_given() {
    // A 100 × 100 grid of spacing 1 and one point far away: the cloud spans 3000 × 3000,
    // so the smallest region is 900 square units, 1800 triangles of half a unit.
    let dir = scratch("extent");
    let mut text = String::from("x,y,z\n");
    for i in 0..100 {
        for j in 0..100 {
            text.push_str(&format!("{i},{j},{}\n", 0.001 * i as f64));
        }
    }
    text.push_str("3000,3000,0\n");
    let cloud = dir.join("extent.csv");
    std::fs::write(&cloud, text).unwrap();
    let out = json(&polylidar(&["extract", cloud.to_str().unwrap(), "--json"]));
    assert_eq!(out["parameters"]["min_triangles"], 1800);
    assert_eq!(out["counts"]["polygons"], 1);
    // Given explicitly, or by a preset, it is kept.
    let out = json(&polylidar(&[
        "extract",
        cloud.to_str().unwrap(),
        "--json",
        "--min-triangles",
        "5",
    ]));
    assert_eq!(out["parameters"]["min_triangles"], 5);
}

#[test]
fn presets_are_converted_into_the_units() {
    let dir = scratch("units");
    // Spacing 0.05: four spacings stay below rooftop's lmax in either unit.
    let cloud = flat_cloud(&dir, 40, 0.05);
    let lmax = |units: &str| {
        let out = json(&polylidar(&[
            "extract",
            cloud.to_str().unwrap(),
            "--preset",
            "rooftop",
            "--units",
            units,
            "--json",
        ]));
        assert_eq!(out["parameters"]["unit"], units);
        out["parameters"]["lmax"].as_f64().unwrap()
    };
    assert_eq!(lmax("m"), 0.9);
    assert!((lmax("ft") - 0.9 / 0.3048).abs() < 1e-12);
    assert!((lmax("us-ft") - 0.9 * 3937.0 / 1200.0).abs() < 1e-12);
    assert!(
        !polylidar(&["extract", cloud.to_str().unwrap(), "--units", "yd"])
            .status
            .success()
    );
}

#[test]
fn an_empty_result_is_explained_and_strict_exits_3() {
    let dir = scratch("strict");
    let cloud = flat_cloud(&dir, 20, 1.0);
    let args = ["extract", cloud.to_str().unwrap(), "--lmax", "0.5"];
    let out = polylidar(&args);
    assert_eq!(out.status.code(), Some(0));
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(stderr.contains("lmax dropped"), "{stderr}");
    assert!(stderr.contains("try --lmax 4"), "{stderr}");
    let strict = polylidar(&[&args[..], &["--strict"]].concat());
    assert_eq!(strict.status.code(), Some(3));
    // The suggested value brings the polygon back.
    let fixed = polylidar(&[
        "extract",
        cloud.to_str().unwrap(),
        "--lmax",
        "4",
        "--strict",
    ]);
    assert_eq!(fixed.status.code(), Some(0));
    let stderr = String::from_utf8_lossy(&fixed.stderr);
    assert!(stderr.contains("1 polygon,"), "{stderr}");
}

#[test]
fn up_takes_commas_or_spaces_and_needs_three_numbers() {
    let dir = scratch("up");
    let cloud = flat_cloud(&dir, 15, 1.0);
    let path = cloud.to_str().unwrap();
    let commas = json(&polylidar(&["extract", path, "--json", "--up", "0,0,1"]));
    let spaces = json(&polylidar(&[
        "extract", path, "--json", "--up", "0", "0", "1",
    ]));
    assert_eq!(commas["counts"], spaces["counts"]);
    assert_eq!(commas["counts"]["polygons"], 1);
    let short = polylidar(&["extract", path, "--up", "0", "1"]);
    assert_eq!(short.status.code(), Some(1));
    assert!(String::from_utf8_lossy(&short.stderr).contains("three numbers"));
}

#[test]
fn norm_thresh_takes_a_cosine_or_degrees() {
    let dir = scratch("norm");
    let cloud = flat_cloud(&dir, 15, 1.0);
    let path = cloud.to_str().unwrap();
    let run = |value: &str| {
        json(&polylidar(&[
            "extract",
            path,
            "--json",
            "--norm-thresh",
            value,
        ]))
    };
    let cosine = run("0.5");
    for degrees in ["60deg", "60 deg", "60°"] {
        let out = run(degrees);
        let got = out["parameters"]["norm_thresh"].as_f64().unwrap();
        assert!((got - 0.5).abs() < 1e-12, "{degrees}: {got}");
        assert_eq!(out["counts"], cosine["counts"]);
    }
    let bad = polylidar(&["extract", path, "--norm-thresh", "200deg"]);
    assert_eq!(bad.status.code(), Some(2));
    assert!(String::from_utf8_lossy(&bad.stderr).contains("neither a cosine"));
}

#[test]
fn flags_that_do_not_apply_are_reported() {
    let dir = scratch("warn");
    let (rows, cols) = (20, 30);
    let grid: Vec<f64> = (0..rows * cols)
        .flat_map(|i| [(i % cols) as f64 * 0.01, (i / cols) as f64 * 0.01, 1.0])
        .collect();
    let npy = dir.join("organized.npy");
    polylidar_io::write_npy_f64(&npy, &[rows, cols, 3], &grid).unwrap();
    let out = polylidar(&[
        "extract",
        npy.to_str().unwrap(),
        "--alpha",
        "1",
        "--up",
        "0,1,0",
    ]);
    assert!(out.status.success());
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(
        stderr.contains("warning: --alpha does not apply"),
        "{stderr}"
    );
    assert!(stderr.contains("warning: --up does not apply"), "{stderr}");
}

#[test]
fn organized_input_gets_the_adaptive_preset_of_its_sensor() {
    let (Some(depth), Some(camera)) = (
        test_fixtures::fixture("rgbd/tum_depth.png"),
        test_fixtures::fixture("rgbd/camera_primesense.json"),
    ) else {
        return;
    };
    let (depth, camera) = (depth.to_str().unwrap(), camera.to_str().unwrap());
    let base = [
        "extract",
        depth,
        "--intrinsics",
        camera,
        "--stride",
        "4",
        "--json",
    ];
    let preset = |extra: &[&str]| {
        let args: Vec<&str> = base.iter().chain(extra).copied().collect();
        json(&polylidar(&args))["parameters"]["preset"].clone()
    };
    // A depth image without --preset runs the depth cameras' adaptive preset.
    assert_eq!(preset(&[]), "rgbd-auto");
    // --preset wins, and a config file is the whole base: no preset is added under it.
    assert_eq!(preset(&["--preset", "rgbd"]), "rgbd");
    let dir = scratch("default-preset");
    let toml = dir.join("params.toml");
    std::fs::write(&toml, "min_triangles = 100\n").unwrap();
    assert_eq!(
        preset(&["--config", toml.to_str().unwrap()]),
        serde_json::Value::Null
    );

    // Any other organized cloud (a range scan) runs the range scanners' one.
    let cloud = dir.join("scan.npy");
    let labels = dir.join("labels.npy");
    let out = polylidar(&[
        "generate",
        "-o",
        cloud.to_str().unwrap(),
        "--labels-out",
        labels.to_str().unwrap(),
    ]);
    assert!(out.status.success(), "{out:?}");
    let out = json(&polylidar(&[
        "extract",
        cloud.to_str().unwrap(),
        "--stride",
        "5",
        "--json",
    ]));
    assert_eq!(out["parameters"]["preset"], "synpeb-auto");
}

#[test]
fn decimate_is_checked_and_reported_where_it_does_not_apply() {
    let dir = scratch("decimate");
    let csv = dir.join("points.csv");
    let rows: String = (0..100)
        .map(|i| format!("{},{}\n", i % 10, i / 10))
        .collect();
    std::fs::write(&csv, format!("x,y\n{rows}")).unwrap();
    let out = polylidar(&["extract", csv.to_str().unwrap(), "--decimate", "2"]);
    assert!(out.status.success());
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(
        stderr.contains("warning: --decimate does not apply"),
        "{stderr}"
    );
    for bad in ["0", "17", "half"] {
        let out = polylidar(&["extract", csv.to_str().unwrap(), "--decimate", bad]);
        assert_eq!(out.status.code(), Some(2), "--decimate {bad}");
        let stderr = String::from_utf8_lossy(&out.stderr);
        assert!(stderr.contains("a block side 1 to 16"), "{stderr}");
    }
    std::fs::remove_dir_all(&dir).ok();
}

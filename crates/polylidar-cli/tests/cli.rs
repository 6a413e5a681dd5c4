//! End-to-end tests of the `polylidar` binary.

use std::path::PathBuf;
use std::process::{Command, Output};

fn polylidar(args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_polylidar"))
        .args(args)
        .output()
        .expect("the binary runs")
}

fn scratch(name: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("polylidar-cli-{}-{name}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    dir
}

/// A 30 × 30 grid of points with a 6 × 6 hole, as CSV with a header.
fn grid_csv(dir: &std::path::Path) -> PathBuf {
    let mut text = String::from("x,y\n");
    for i in 0..30 {
        for j in 0..30 {
            if !((12..18).contains(&i) && (12..18).contains(&j)) {
                text.push_str(&format!("{i},{j}\n"));
            }
        }
    }
    let path = dir.join("grid.csv");
    std::fs::write(&path, text).unwrap();
    path
}

fn json(output: &Output) -> serde_json::Value {
    assert!(
        output.status.success(),
        "{}",
        String::from_utf8_lossy(&output.stderr)
    );
    serde_json::from_slice(&output.stdout).expect("stdout is one JSON object")
}

#[test]
fn demo_writes_geojson_and_png() {
    let dir = scratch("demo");
    let (geojson, png) = (dir.join("demo.geojson"), dir.join("demo.png"));
    let out = polylidar(&[
        "extract",
        "--demo",
        "-o",
        geojson.to_str().unwrap(),
        "--plot",
        png.to_str().unwrap(),
    ]);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let collection: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(&geojson).unwrap()).unwrap();
    assert_eq!(collection["type"], "FeatureCollection");
    let features = collection["features"].as_array().unwrap();
    assert_eq!(features.len(), 1);
    let rings = features[0]["geometry"]["coordinates"].as_array().unwrap();
    assert_eq!(rings.len(), 4, "a shell and the demo's three holes");
    let shell = rings[0].as_array().unwrap();
    assert_eq!(shell.first(), shell.last(), "GeoJSON rings are closed");
    assert_eq!(&std::fs::read(&png).unwrap()[..8], b"\x89PNG\r\n\x1a\n");
}

#[test]
fn json_report_has_the_documented_shape() {
    let dir = scratch("json");
    let csv = grid_csv(&dir);
    let report = json(&polylidar(&[
        "extract",
        csv.to_str().unwrap(),
        "--lmax",
        "1.5",
        "--json",
        "--repeat",
        "3",
    ]));
    assert_eq!(report["input"]["kind"], "points_2d");
    assert_eq!(report["input"]["points"], 900 - 36);
    assert_eq!(report["input"]["runs"], 3);
    assert_eq!(report["counts"]["polygons"], 1);
    assert_eq!(report["counts"]["holes"], 1);
    let timings = report["timings_ms"].as_object().unwrap();
    let keys: Vec<&str> = timings.keys().map(String::as_str).collect();
    assert_eq!(keys, ["mesh", "regions", "polygons", "total"]);
    assert!(
        timings
            .values()
            .all(|v| v.as_f64().is_some_and(|ms| ms >= 0.0))
    );
}

#[test]
fn flags_win_over_the_config_file() {
    let dir = scratch("config");
    let csv = grid_csv(&dir);
    let config = dir.join("params.toml");
    std::fs::write(&config, "lmax = 1.5\nmin_triangles = 100000\n").unwrap();
    let args = [
        "extract",
        csv.to_str().unwrap(),
        "--config",
        config.to_str().unwrap(),
        "--json",
    ];
    let from_file = json(&polylidar(&args));
    assert_eq!(from_file["counts"]["polygons"], 0);
    assert_eq!(from_file["counts"]["regions_too_small"], 1);
    let mut with_flag = args.to_vec();
    with_flag.extend(["--min-triangles", "10"]);
    assert_eq!(json(&polylidar(&with_flag))["counts"]["polygons"], 1);
}

#[test]
fn bad_input_gives_clear_errors() {
    let dir = scratch("errors");
    let missing = polylidar(&["extract", dir.join("nope.csv").to_str().unwrap()]);
    assert!(!missing.status.success());
    assert!(String::from_utf8_lossy(&missing.stderr).contains("nope.csv"));

    let config = dir.join("bad.toml");
    std::fs::write(&config, "alpah = 1.0\n").unwrap();
    let bad_key = polylidar(&["extract", "--demo", "--config", config.to_str().unwrap()]);
    assert!(!bad_key.status.success());
    let message = String::from_utf8_lossy(&bad_key.stderr);
    assert!(message.contains("alpah"), "{message}");

    let negative = polylidar(&["extract", "--demo", "--alpha", "-1"]);
    assert!(!negative.status.success());
    assert!(String::from_utf8_lossy(&negative.stderr).contains("alpha"));

    let collinear = dir.join("line.csv");
    std::fs::write(&collinear, "0,0\n1,1\n2,2\n3,3\n").unwrap();
    let out = polylidar(&["extract", collinear.to_str().unwrap()]);
    assert!(!out.status.success());
    assert!(String::from_utf8_lossy(&out.stderr).contains("collinear"));
}

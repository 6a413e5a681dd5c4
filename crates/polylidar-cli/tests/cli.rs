//! End-to-end tests of the `polylidar` binary.
#![allow(clippy::expect_used, clippy::unwrap_used, clippy::panic)]

mod common;

use std::path::PathBuf;

use common::{json, polylidar};

fn scratch(name: &str) -> test_fixtures::ScratchDir {
    common::scratch("cli", name)
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

#[test]
fn shape_demo_writes_geojson_and_png() {
    let dir = scratch("demo-shape");
    let (geojson, png) = (dir.join("demo.geojson"), dir.join("demo.png"));
    let out = polylidar(&[
        "extract",
        "--demo",
        "shape",
        "-o",
        geojson.to_str().unwrap(),
        "--plot",
        png.to_str().unwrap(),
    ]);
    common::succeeded(&out);
    let collection: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(&geojson).unwrap()).unwrap();
    assert_eq!(collection["type"], "FeatureCollection");
    let features = collection["features"].as_array().unwrap();
    assert_eq!(features.len(), 1);
    let rings = features[0]["geometry"]["coordinates"].as_array().unwrap();
    assert_eq!(rings.len(), 4, "a shell and the demo's three holes");
    let shell = rings[0].as_array().unwrap();
    assert_eq!(shell.first(), shell.last(), "GeoJSON rings are closed");
    assert_eq!(
        shell[0].as_array().unwrap().len(),
        2,
        "2D input, 2D coordinates"
    );
    assert_eq!(&std::fs::read(&png).unwrap()[..8], b"\x89PNG\r\n\x1a\n");
}

#[test]
fn scene_demo_runs_the_3d_pipeline_and_scores_it() {
    let dir = scratch("demo-scene");
    let (geojson, png) = (dir.join("scene.geojson"), dir.join("scene.png"));
    let report = json(&polylidar(&[
        "extract",
        "--demo",
        "-o",
        geojson.to_str().unwrap(),
        "--plot",
        png.to_str().unwrap(),
        "--json",
    ]));
    assert_eq!(report["input"]["kind"], "organized");
    assert_eq!(report["input"]["rows"], 500);
    let keys: Vec<&str> = report["timings_ms"]
        .as_object()
        .unwrap()
        .keys()
        .map(String::as_str)
        .collect();
    assert_eq!(
        keys,
        [
            "laplacian",
            "mesh",
            "bilateral",
            "fastga",
            "planes_polygons",
            "total"
        ]
    );
    let metrics = &report["metrics"];
    assert!(metrics["f"].as_f64().unwrap() > 0.0);
    assert!(metrics["truth_planes"].as_u64().unwrap() > 10);

    let collection: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(&geojson).unwrap()).unwrap();
    let features = collection["features"].as_array().unwrap();
    assert_eq!(
        features.len() as u64,
        report["counts"]["polygons"].as_u64().unwrap()
    );
    assert!(features.len() >= 10);
    for feature in features {
        let p = &feature["properties"];
        let n: Vec<f64> = p["normal"]
            .as_array()
            .unwrap()
            .iter()
            .map(|v| v.as_f64().unwrap())
            .collect();
        assert!((n.iter().map(|c| c * c).sum::<f64>() - 1.0).abs() < 1e-9);
        assert!(p["area"].as_f64().unwrap() > 0.0);
        assert!(
            p["triangles"].as_u64().unwrap() >= 250 || p["area"].as_f64().unwrap() >= 0.015,
            "the demo's synpeb-auto preset: min_triangles 250, else min_area 0.015 m²"
        );
        assert!(p["points"].as_u64().unwrap() > 0);
        let first = &feature["geometry"]["coordinates"][0][0];
        assert_eq!(first.as_array().unwrap().len(), 3, "3D coordinates");
    }
    assert_eq!(&std::fs::read(&png).unwrap()[..8], b"\x89PNG\r\n\x1a\n");
}

#[test]
fn generated_scan_round_trips_through_extract_and_evaluate() {
    let dir = scratch("generate");
    let (scan, truth, predicted) = (
        dir.join("scan.pcd"),
        dir.join("truth.npy"),
        dir.join("pred.npy"),
    );
    let out = polylidar(&[
        "generate",
        "--seed",
        "2",
        "-o",
        scan.to_str().unwrap(),
        "--labels-out",
        truth.to_str().unwrap(),
    ]);
    common::succeeded(&out);
    let extracted = json(&polylidar(&[
        "extract",
        scan.to_str().unwrap(),
        "--preset",
        "synpeb",
        "--labels-out",
        predicted.to_str().unwrap(),
        "--json",
    ]));
    assert_eq!(extracted["input"]["rows"], 500);
    let halved = json(&polylidar(&[
        "extract",
        scan.to_str().unwrap(),
        "--preset",
        "synpeb",
        "--stride",
        "2",
        "--json",
    ]));
    assert_eq!(halved["input"]["rows"], 250);
    assert_eq!(halved["input"]["cols"], 250);
    assert!(extracted["counts"]["polygons"].as_u64().unwrap() >= 10);

    // Scoring the saved prediction and scoring a fresh run agree.
    let saved = json(&polylidar(&[
        "evaluate",
        scan.to_str().unwrap(),
        "--labels",
        truth.to_str().unwrap(),
        "--predicted",
        predicted.to_str().unwrap(),
        "--json",
    ]));
    let fresh = json(&polylidar(&[
        "evaluate",
        scan.to_str().unwrap(),
        "--labels",
        truth.to_str().unwrap(),
        "--preset",
        "synpeb",
        "--json",
    ]));
    assert_eq!(saved["metrics"], fresh["metrics"]);
    // Every missed and every spurious plane is explained, and the causes add up.
    let metrics = &fresh["metrics"];
    let causes = &fresh["causes"];
    let explained = causes["planes"].as_array().unwrap().len() as u64;
    let counted: u64 = causes["counts"]
        .as_object()
        .unwrap()
        .values()
        .map(|n| n.as_u64().unwrap())
        .sum();
    assert_eq!(explained, counted);
    let (missed, spurious) = (
        metrics["missed"].as_u64().unwrap(),
        metrics["spurious"].as_u64().unwrap(),
    );
    assert!(explained >= missed + spurious, "{causes}");
    let output = polylidar(&[
        "evaluate",
        scan.to_str().unwrap(),
        "--labels",
        truth.to_str().unwrap(),
        "--preset",
        "synpeb",
    ]);
    let text = String::from_utf8_lossy(&output.stdout);
    assert!(
        text.contains("causes:") && text.contains("ground-truth planes"),
        "{text}"
    );
    // Without smoothing, the smoothing stages are absent.
    let raw = json(&polylidar(&[
        "extract",
        scan.to_str().unwrap(),
        "--preset",
        "synpeb",
        "--no-smoothing",
        "--json",
    ]));
    let stages = raw["timings_ms"].as_object().unwrap();
    assert!(!stages.contains_key("laplacian") && !stages.contains_key("bilateral"));
    assert_eq!(raw["counts"]["laplacian_iterations"], 0);
    assert_eq!(
        saved["metrics"]["predicted_planes"],
        extracted["counts"]["polygons"]
    );
    // The ground truth scored against itself is perfect.
    let perfect = json(&polylidar(&[
        "evaluate",
        scan.to_str().unwrap(),
        "--labels",
        truth.to_str().unwrap(),
        "--predicted",
        truth.to_str().unwrap(),
        "--json",
    ]));
    assert_eq!(perfect["metrics"]["f"], 100.0);
    assert_eq!(perfect["metrics"]["k"], 100.0);
}

#[test]
fn mesh_input_gives_planes_and_post_processing_is_optional() {
    let dir = scratch("mesh");
    // Two 10 × 10 grids of unit squares: one at z = 0, one at z = 5 (a separate plane).
    let mut obj = String::new();
    for z in [0.0, 5.0] {
        for i in 0..=10 {
            for j in 0..=10 {
                obj.push_str(&format!("v {i} {j} {z}\n"));
            }
        }
    }
    for layer in 0..2 {
        for i in 0..10 {
            for j in 0..10 {
                let v = |a: usize, b: usize| layer * 121 + a * 11 + b + 1;
                obj.push_str(&format!(
                    "f {} {} {}\n",
                    v(i, j),
                    v(i + 1, j),
                    v(i + 1, j + 1)
                ));
                obj.push_str(&format!(
                    "f {} {} {}\n",
                    v(i, j),
                    v(i + 1, j + 1),
                    v(i, j + 1)
                ));
            }
        }
    }
    let mesh = dir.join("two_planes.obj");
    std::fs::write(&mesh, obj).unwrap();
    let config = dir.join("post.toml");
    std::fs::write(
        &config,
        "lmax = 2.0\nmin_triangles = 10\n[postprocess]\nmin_area = 1.0\n",
    )
    .unwrap();
    let run = |extra: &[&str]| -> serde_json::Value {
        let geojson = dir.join("out.geojson");
        let mut args = vec![
            "extract",
            mesh.to_str().unwrap(),
            "--config",
            config.to_str().unwrap(),
            "-o",
            geojson.to_str().unwrap(),
        ];
        args.extend(extra);
        let out = polylidar(&args);
        common::succeeded(&out);
        serde_json::from_str(&std::fs::read_to_string(&geojson).unwrap()).unwrap()
    };
    let processed = run(&[]);
    let raw = run(&["--raw"]);
    for collection in [&processed, &raw] {
        let features = collection["features"].as_array().unwrap();
        assert_eq!(features.len(), 2);
        for f in features {
            assert!((f["properties"]["area"].as_f64().unwrap() - 100.0).abs() < 1e-9);
            assert_eq!(f["properties"]["triangles"], 200);
            assert_eq!(f["properties"]["points"], 121);
        }
    }
    assert!(processed["features"][0]["properties"]["source"].is_u64());
    assert!(raw["features"][0]["properties"]["source"].is_null());
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
    let bad_key = polylidar(&[
        "extract",
        "--demo",
        "shape",
        "--config",
        config.to_str().unwrap(),
    ]);
    assert!(!bad_key.status.success());
    let message = String::from_utf8_lossy(&bad_key.stderr);
    assert!(message.contains("alpah"), "{message}");

    let preset = polylidar(&["extract", "--demo", "--preset", "lidar"]);
    assert!(!preset.status.success());
    assert!(String::from_utf8_lossy(&preset.stderr).contains("synpeb"));

    let stride = polylidar(&["extract", "--demo", "shape", "--stride", "2"]);
    assert!(!stride.status.success());
    assert!(String::from_utf8_lossy(&stride.stderr).contains("organized"));

    let negative = polylidar(&["extract", "--demo", "shape", "--alpha", "-1"]);
    assert!(!negative.status.success());
    assert!(String::from_utf8_lossy(&negative.stderr).contains("alpha"));

    let collinear = dir.join("line.csv");
    std::fs::write(&collinear, "0,0\n1,1\n2,2\n3,3\n").unwrap();
    let out = polylidar(&["extract", collinear.to_str().unwrap()]);
    assert!(!out.status.success());
    assert!(String::from_utf8_lossy(&out.stderr).contains("collinear"));
}

/// `extract --help` names every preset the library knows, so that the list written in the
/// flag's help cannot fall behind `polylidar::Preset`.
#[test]
fn the_preset_help_names_every_preset() {
    let out = polylidar(&["extract", "--help"]);
    assert!(out.status.success());
    let help = String::from_utf8(out.stdout).unwrap();
    let start = help.find("--preset <NAME>").expect("the --preset flag");
    let end = help[start..]
        .find("--units")
        .map_or(help.len(), |e| start + e);
    let words: Vec<&str> = help[start..end]
        .split(|c: char| !(c.is_ascii_alphanumeric() || c == '-'))
        .collect();
    for preset in polylidar::Preset::all() {
        let name = preset.to_string();
        assert!(
            words.contains(&name.as_str()),
            "`{name}` missing from the --preset help"
        );
    }
}

/// The 3D path's picture shows a floor whose normals point down (against `--up`): it is
/// seen from the side its triangles face, not from behind (where they were culled and the
/// picture was empty).
#[test]
fn a_floor_with_downward_normals_is_drawn() {
    let dir = scratch("floor-down");
    let (pcd, png) = (dir.join("floor.pcd"), dir.join("floor.png"));
    let side = 50;
    let mut text = format!(
        "VERSION 0.7\nFIELDS x y z normal_x normal_y normal_z\nSIZE 4 4 4 4 4 4\n\
         TYPE F F F F F F\nCOUNT 1 1 1 1 1 1\nWIDTH {n}\nHEIGHT 1\nVIEWPOINT 0 0 0 1 0 0 0\n\
         POINTS {n}\nDATA ascii\n",
        n = side * side
    );
    for i in 0..side {
        for j in 0..side {
            // A slight ripple: no exactly cocircular grid.
            let z = 0.001 * ((i * 7 + j * 3) % 5) as f64;
            text.push_str(&format!(
                "{} {} {z} 0 0 -1\n",
                0.02 * i as f64,
                0.02 * j as f64
            ));
        }
    }
    std::fs::write(&pcd, text).unwrap();
    let out = polylidar(&[
        "extract",
        pcd.to_str().unwrap(),
        "--preset",
        "room",
        "--plot",
        png.to_str().unwrap(),
    ]);
    common::succeeded(&out);
    let image = polylidar_io::read_color_image(&png).unwrap();
    let coloured = image
        .rgb
        .iter()
        .filter(|p| p.iter().any(|&c| c < 200))
        .count();
    assert!(
        coloured * 5 > image.rgb.len(),
        "{coloured} of {} pixels drawn",
        image.rgb.len()
    );
}

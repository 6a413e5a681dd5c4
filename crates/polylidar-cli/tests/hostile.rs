//! Careless and hostile command lines (issue 22): outputs checked before the pipeline
//! runs and never left half written, flags out of range refused with the rule, messages
//! that name the file and say what to do, each printed once.

#![allow(clippy::expect_used, clippy::unwrap_used, clippy::panic)]

mod common;

use std::path::{Path, PathBuf};
use std::process::Output;

use common::{json, polylidar};

fn scratch(name: &str) -> test_fixtures::ScratchDir {
    common::scratch("hostile", name)
}

/// A 20 × 20 grid of 2D points as CSV.
fn grid_csv(dir: &Path) -> PathBuf {
    let mut text = String::from("x,y\n");
    for i in 0..20 {
        for j in 0..20 {
            text.push_str(&format!("{i},{j}\n"));
        }
    }
    let path = dir.join("grid.csv");
    std::fs::write(&path, text).unwrap();
    path
}

/// An ASCII PLY mesh with the given vertices and triangles.
fn ply(dir: &Path, name: &str, vertices: &[[f64; 3]], faces: &[[u32; 3]]) -> PathBuf {
    let mut text = format!(
        "ply\nformat ascii 1.0\nelement vertex {}\nproperty double x\nproperty double y\n\
         property double z\nelement face {}\nproperty list uchar int vertex_indices\nend_header\n",
        vertices.len(),
        faces.len()
    );
    for v in vertices {
        text.push_str(&format!("{:e} {:e} {:e}\n", v[0], v[1], v[2]));
    }
    for f in faces {
        text.push_str(&format!("3 {} {} {}\n", f[0], f[1], f[2]));
    }
    let path = dir.join(name);
    std::fs::write(&path, text).unwrap();
    path
}

fn stderr(out: &Output) -> String {
    String::from_utf8_lossy(&out.stderr).into_owned()
}

/// The run failed with exit code 1 and its stderr.
fn failed(out: &Output) -> String {
    assert_eq!(out.status.code(), Some(1), "{}", stderr(out));
    stderr(out)
}

fn names(dir: &Path) -> Vec<String> {
    let mut names: Vec<String> = std::fs::read_dir(dir)
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .collect();
    names.sort();
    names
}

fn s(path: &Path) -> &str {
    path.to_str().unwrap()
}

#[test]
fn output_equal_to_the_input_is_refused_and_the_input_kept() {
    let dir = scratch("same-as-input");
    let input = grid_csv(&dir);
    let before = std::fs::read(&input).unwrap();
    let spelled = dir.join(".").join("grid.csv");
    let err = failed(&polylidar(&["extract", s(&input), "-o", s(&spelled)]));
    assert!(err.contains("-o is the input"), "{err}");
    assert!(err.contains("grid.csv"), "{err}");
    assert_eq!(std::fs::read(&input).unwrap(), before);
    let err = failed(&polylidar(&["extract", s(&input), "--plot", s(&input)]));
    assert!(err.contains("--plot is the input"), "{err}");
    assert_eq!(names(&dir), ["grid.csv"]);
}

#[test]
fn outputs_are_checked_before_the_pipeline_and_old_files_kept() {
    let dir = scratch("checked-first");
    let input = grid_csv(&dir);
    let geojson = dir.join("planes.geojson");
    std::fs::write(&geojson, b"a good old result").unwrap();
    // Two outputs on one file.
    let err = failed(&polylidar(&[
        "extract",
        s(&input),
        "-o",
        s(&geojson),
        "--plot",
        s(&geojson),
    ]));
    assert!(err.contains("--plot and -o name the same file"), "{err}");
    // A later output that cannot be written: the earlier one is not touched either.
    let blocker = dir.join("blocker");
    std::fs::write(&blocker, b"a file, not a directory").unwrap();
    let err = failed(&polylidar(&[
        "extract",
        s(&input),
        "-o",
        s(&geojson),
        "--plot",
        s(&blocker.join("plot.png")),
    ]));
    assert!(err.contains("is not a directory"), "{err}");
    assert!(err.contains("plot.png"), "{err}");
    // An output that is a directory.
    let err = failed(&polylidar(&["extract", s(&input), "-o", s(&dir)]));
    assert!(err.contains("is a directory"), "{err}");
    // --labels-out on input without a grid, before any output is written.
    let err = failed(&polylidar(&[
        "extract",
        s(&input),
        "-o",
        s(&geojson),
        "--labels-out",
        s(&dir.join("labels.npy")),
    ]));
    assert!(err.contains("--labels-out needs organized input"), "{err}");
    assert_eq!(std::fs::read(&geojson).unwrap(), b"a good old result");
    assert_eq!(names(&dir), ["blocker", "grid.csv", "planes.geojson"]);
    // And a run that works replaces it, leaving no temporary file.
    let report = json(&polylidar(&[
        "extract",
        s(&input),
        "-o",
        s(&geojson),
        "--json",
    ]));
    assert_eq!(report["counts"]["polygons"], 1);
    assert!(
        std::fs::read_to_string(&geojson)
            .unwrap()
            .contains("FeatureCollection")
    );
    assert_eq!(names(&dir), ["blocker", "grid.csv", "planes.geojson"]);
}

#[cfg(unix)]
#[test]
fn a_write_over_the_file_size_limit_keeps_the_old_file() {
    let dir = scratch("ulimit");
    let input = grid_csv(&dir);
    let geojson = dir.join("planes.geojson");
    let old = "x".repeat(3000);
    std::fs::write(&geojson, &old).unwrap();
    // 1 block of 512 bytes: the GeoJSON of the grid is larger.
    let script = format!(
        "ulimit -f 1; exec '{}' extract '{}' -o '{}'",
        env!("CARGO_BIN_EXE_polylidar"),
        s(&input),
        s(&geojson)
    );
    let out = std::process::Command::new("sh")
        .args(["-c", &script])
        .output()
        .unwrap();
    let err = failed(&out);
    assert!(err.contains("planes.geojson"), "{err}");
    assert_eq!(std::fs::read_to_string(&geojson).unwrap(), old);
    assert_eq!(names(&dir), ["grid.csv", "planes.geojson"]);
}

#[test]
fn negative_values_parse_and_are_range_checked() {
    let dir = scratch("negative");
    let input = grid_csv(&dir);
    for (flag, field) in [
        ("--z-thresh", "z_thresh"),
        ("--min-area", "min_area"),
        ("--lmax", "lmax"),
    ] {
        let err = failed(&polylidar(&["extract", s(&input), flag, "-1"]));
        assert!(!err.contains("unexpected argument"), "{flag}: {err}");
        assert!(err.contains(&format!("{field} = -1")), "{flag}: {err}");
    }
    let out = polylidar(&["extract", s(&input), "--min-triangles", "-1"]);
    assert_eq!(out.status.code(), Some(2));
    assert!(
        stderr(&out).contains("invalid value '-1'"),
        "{}",
        stderr(&out)
    );
}

#[test]
fn threads_are_bounded_with_the_limit_stated() {
    let dir = scratch("threads");
    let input = grid_csv(&dir);
    let err = failed(&polylidar(&["extract", s(&input), "--threads", "100000"]));
    assert!(err.contains("100000 worker threads"), "{err}");
    assert!(err.contains("at most"), "{err}");
    assert!(err.contains("per core"), "{err}");
}

#[test]
fn meaningless_smoothing_and_fastga_values_are_refused_with_the_config() {
    let dir = scratch("ranges");
    let input = grid_csv(&dir);
    for (toml, field) in [
        ("[laplacian]\nlambda = 2.0\n", "laplacian.lambda"),
        ("[laplacian]\nlambda = -1e30\n", "laplacian.lambda"),
        (
            "[laplacian]\niterations = 4294967295\n",
            "laplacian.iterations",
        ),
        ("[laplacian]\nkernel = 4\n", "laplacian.kernel"),
        ("[bilateral]\nkernel = 999\n", "bilateral.kernel"),
        ("[bilateral]\nsigma_angle = 0.0\n", "bilateral.sigma_angle"),
        ("[fastga]\nsample_fraction = 0.0\n", "sample_fraction"),
    ] {
        let config = dir.join("bad.toml");
        std::fs::write(&config, toml).unwrap();
        let err = failed(&polylidar(&["extract", s(&input), "--config", s(&config)]));
        assert!(err.contains(field), "{toml}: {err}");
    }
}

#[test]
fn a_smoothing_kernel_wider_than_the_image_is_refused() {
    let dir = scratch("kernel");
    let cloud = dir.join("tiny.npy");
    let points: Vec<f64> = (0..16)
        .flat_map(|i| [f64::from(i % 4), f64::from(i / 4), 1.0])
        .collect();
    polylidar_io::write_npy_f64(&cloud, &[4, 4, 3], &points).unwrap();
    let err = failed(&polylidar(&["extract", s(&cloud), "--preset", "synpeb"]));
    assert!(
        err.contains("tiny.npy: laplacian.kernel 5 is wider than the image's 4 × 4 pixels"),
        "{err}"
    );
    assert!(
        err.contains("at most 3 (in --config) or --no-smoothing"),
        "{err}"
    );
    let out = polylidar(&["extract", s(&cloud), "--preset", "synpeb", "--no-smoothing"]);
    assert!(out.status.success(), "{}", stderr(&out));
}

#[test]
fn errors_are_printed_once() {
    let dir = scratch("once");
    let missing = dir.join("missing.csv");
    let err = failed(&polylidar(&["extract", s(&missing)]));
    assert!(err.contains("missing.csv"), "{err}");
    assert_eq!(err.matches("No such file").count(), 1, "{err}");
}

#[test]
fn pipeline_errors_name_the_input() {
    let dir = scratch("names");
    let input = dir.join("two.csv");
    std::fs::write(&input, "0,0\n1,1\n").unwrap();
    let err = failed(&polylidar(&["extract", s(&input)]));
    assert!(err.contains("two.csv: "), "{err}");
    let square = [
        [0.0, 0.0, 0.0],
        [1.0, 0.0, 0.0],
        [1.0, 1.0, 0.0],
        [0.0, 1.0, 0.0],
    ];
    let flat = ply(&dir, "flat.ply", &square, &[[0, 1, 2], [0, 2, 0]]);
    let err = failed(&polylidar(&["extract", s(&flat)]));
    assert!(err.contains("flat.ply: triangle 1"), "{err}");
    assert!(err.contains("repeated vertex"), "{err}");
    assert!(err.contains("remove them"), "{err}");
    assert!(!err.contains("DegeneratePolicy"), "{err}");
    let mut huge = square;
    huge[2] = [1e300, 1e300, 0.0];
    let big = ply(&dir, "huge.ply", &huge, &[[0, 1, 3], [1, 2, 3]]);
    let err = failed(&polylidar(&["extract", s(&big)]));
    assert!(err.contains("huge.ply: triangle 1"), "{err}");
    assert!(err.contains("too large"), "{err}");
    assert!(!err.contains("zero area"), "{err}");
}

#[test]
fn generate_checks_both_outputs_first() {
    let dir = scratch("generate");
    let cloud = dir.join("scan.pcd");
    let err = failed(&polylidar(&[
        "generate",
        "-o",
        s(&cloud),
        "--labels-out",
        s(&cloud),
    ]));
    assert!(
        err.contains("--labels-out and -o name the same file"),
        "{err}"
    );
    assert_eq!(names(&dir), Vec::<String>::new());
}

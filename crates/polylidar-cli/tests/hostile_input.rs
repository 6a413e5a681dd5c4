//! The `polylidar` binary on hostile input (issue 22): an input past the memory budget is a
//! clear error naming the file and `--max-memory`, reached before anything is allocated;
//! NaN points of an unorganized PCD are skipped with a note.

// Test helpers fail loudly by design.
#![allow(clippy::unwrap_used, clippy::expect_used)]

mod common;

use common::{json, polylidar};

fn scratch(name: &str) -> test_fixtures::ScratchDir {
    common::scratch("hostile", name)
}

/// An unorganized ascii PCD: a 20 × 20 grid of points on z = 0, `nan` of them NaN.
fn grid_pcd(dir: &std::path::Path, nan: usize) -> std::path::PathBuf {
    let mut lines = Vec::new();
    for i in 0..20 {
        for j in 0..20 {
            lines.push(format!("{i} {j} 0"));
        }
    }
    for line in lines.iter_mut().step_by(7).take(nan) {
        *line = "nan nan nan".to_owned();
    }
    let text = format!(
        "VERSION 0.7\nFIELDS x y z\nSIZE 4 4 4\nTYPE F F F\nCOUNT 1 1 1\nWIDTH {n}\nHEIGHT 1\n\
         POINTS {n}\nDATA ascii\n{}\n",
        lines.join("\n"),
        n = lines.len()
    );
    let path = dir.join("grid.pcd");
    std::fs::write(&path, text).unwrap();
    path
}

#[test]
fn an_input_past_the_budget_is_refused_with_the_way_out() {
    let dir = scratch("budget");
    let path = grid_pcd(&dir, 0);
    let out = polylidar(&["extract", path.to_str().unwrap(), "--max-memory", "64K"]);
    assert_eq!(out.status.code(), Some(1));
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(stderr.contains("grid.pcd"), "{stderr}");
    assert!(stderr.contains("memory budget of 64.0 KiB"), "{stderr}");
    assert!(stderr.contains("--max-memory"), "{stderr}");
    assert!(!stderr.contains("panicked"), "{stderr}");
    // Within the default budget it runs.
    let report = json(&polylidar(&["extract", path.to_str().unwrap(), "--json"]));
    assert_eq!(report["input"]["points"], 400);
    let out = polylidar(&["extract", path.to_str().unwrap(), "--max-memory", "lots"]);
    assert_eq!(out.status.code(), Some(2));
    assert!(String::from_utf8_lossy(&out.stderr).contains("not a memory size"));
}

#[test]
fn nan_points_of_an_unorganized_pcd_are_skipped_and_counted() {
    let dir = scratch("nan");
    let path = grid_pcd(&dir, 5);
    let out = polylidar(&["extract", path.to_str().unwrap(), "--json"]);
    let stderr = String::from_utf8_lossy(&out.stderr).into_owned();
    let report = json(&out);
    assert_eq!(report["input"]["points"], 395);
    assert!(stderr.contains("5 invalid points skipped"), "{stderr}");
}

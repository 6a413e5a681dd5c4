//! `polylidar stream`'s outputs (issue 22): checked before the first frame is read,
//! distinct from the frames and from each other, written atomically, and nothing left
//! behind when a frame or a write fails.

#![allow(clippy::expect_used, clippy::unwrap_used, clippy::panic)]

mod common;

use std::path::Path;
use std::process::Output;

use common::{json, polylidar};

/// A fresh, empty folder.
fn scratch(name: &str) -> test_fixtures::ScratchDir {
    common::scratch("stream-outputs", name)
}

/// Writes `count` organized clouds `frames/f_K.npy` (a 24 × 24 tilted plane each) into
/// `dir`; returns the glob that lists them.
fn frames(dir: &Path, count: usize) -> String {
    let frames = dir.join("frames");
    std::fs::create_dir_all(&frames).unwrap();
    for k in 0..count {
        let points: Vec<f64> = (0..24 * 24)
            .flat_map(|i| {
                let (r, c) = (f64::from(i / 24), f64::from(i % 24));
                [c * 0.05, r * 0.05, 1.0 + 0.01 * r + 0.001 * k as f64]
            })
            .collect();
        polylidar_io::write_npy_f64(frames.join(format!("f_{k}.npy")), &[24, 24, 3], &points)
            .unwrap();
    }
    format!("{}/f_*.npy", frames.display())
}

fn stream(glob: &str, extra: &[&str]) -> Output {
    let mut args = vec![
        "stream",
        glob,
        "--no-smoothing",
        "--min-triangles",
        "20",
        "--prefetch",
        "0",
    ];
    args.extend_from_slice(extra);
    polylidar(&args)
}

fn stderr(out: &Output) -> String {
    String::from_utf8_lossy(&out.stderr).into_owned()
}

/// The run failed with exit code 1 and its stderr.
fn failed(out: &Output) -> String {
    assert_eq!(out.status.code(), Some(1), "{}", stderr(out));
    stderr(out)
}

/// The sorted names in `dir`.
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
fn lines_and_folder_outputs_are_written_whole() {
    let dir = scratch("written");
    let glob = frames(&dir, 2);
    let lines = dir.join("out/polygons.geojsonl");
    let report = json(&stream(&glob, &["-o", s(&lines), "--json"]));
    assert_eq!(report["failed"], 0, "{report}");
    let text = std::fs::read_to_string(&lines).unwrap();
    assert_eq!(text.lines().count(), 2, "{text}");
    for line in text.lines() {
        let v: serde_json::Value = serde_json::from_str(line).unwrap();
        assert_eq!(v["type"], "FeatureCollection");
    }
    assert_eq!(names(&dir.join("out")), ["polygons.geojsonl"]);
    let folder = dir.join("per_frame");
    let out = stream(&glob, &["--out-dir", s(&folder)]);
    assert!(out.status.success(), "{}", stderr(&out));
    assert_eq!(names(&folder), ["f_0.geojson", "f_1.geojson"]);
}

#[test]
fn an_output_that_is_a_frame_is_refused_before_any_frame_runs() {
    let dir = scratch("frame");
    let glob = frames(&dir, 2);
    let frame = dir.join("frames/f_1.npy");
    let before = std::fs::read(&frame).unwrap();
    let err = failed(&stream(&glob, &["-o", s(&frame)]));
    assert!(err.contains("-o is a frame"), "{err}");
    assert!(err.contains("f_1.npy"), "{err}");
    assert!(!err.contains("frames ran"), "ran before refusing: {err}");
    assert_eq!(std::fs::read(&frame).unwrap(), before);
    assert_eq!(names(&dir.join("frames")), ["f_0.npy", "f_1.npy"]);
}

#[test]
fn a_frame_file_blocked_by_a_directory_is_refused_first() {
    let dir = scratch("blocked");
    let glob = frames(&dir, 2);
    let folder = dir.join("per_frame");
    std::fs::create_dir_all(folder.join("f_1.geojson")).unwrap();
    let err = failed(&stream(&glob, &["--out-dir", s(&folder)]));
    assert!(err.contains("f_1.geojson"), "{err}");
    assert!(err.contains("is a directory"), "{err}");
    assert!(!err.contains("frames ran"), "ran before refusing: {err}");
    assert_eq!(names(&folder), ["f_1.geojson"]);
    let err = failed(&stream(&glob, &["-o", s(&folder)]));
    assert!(err.contains("-o is a directory"), "{err}");
}

#[test]
fn a_failing_frame_keeps_the_previous_outputs_and_leaves_no_temporary() {
    let dir = scratch("failing");
    let glob = frames(&dir, 3);
    // The last frame is corrupt: the first two run, then the stream fails.
    std::fs::write(dir.join("frames/f_2.npy"), b"\x93NUMPY broken").unwrap();
    let lines = dir.join("out.geojsonl");
    std::fs::write(&lines, "previous\n").unwrap();
    let err = failed(&stream(&glob, &["-o", s(&lines)]));
    // The frame is named once (its read error already begins with its path).
    assert_eq!(err.matches("f_2.npy").count(), 1, "{err}");
    assert!(
        err.contains("1 of 3 frames failed; nothing was written"),
        "{err}"
    );
    assert_eq!(std::fs::read_to_string(&lines).unwrap(), "previous\n");
    assert_eq!(names(&dir), ["frames", "out.geojsonl"]);
    let folder = dir.join("per_frame");
    std::fs::create_dir_all(&folder).unwrap();
    std::fs::write(folder.join("f_0.geojson"), "old").unwrap();
    failed(&stream(&glob, &["--out-dir", s(&folder)]));
    assert_eq!(names(&folder), ["f_0.geojson"]);
    assert_eq!(
        std::fs::read_to_string(folder.join("f_0.geojson")).unwrap(),
        "old"
    );
}

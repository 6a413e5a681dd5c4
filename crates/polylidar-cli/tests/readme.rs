//! Every command of the README's "Command line" examples, run on the shared data
//! (`../shared/fixtures`): each must succeed, and each `extract` must find something under
//! `--strict` (exit code 3 when the result is empty or nearly empty).
//!
//! The README's `depth.png`, `room.ply` and `points.csv` stand for the user's own files;
//! this test makes them: the ICL-NUIM depth frame with its intrinsics as a RealSense
//! metadata CSV, a generated room meshed with edges up to 10 cm, and 10,000 points sampled
//! inside `shapes/caholes.geojson` (whose area the polygons must recover).
#![allow(clippy::expect_used, clippy::unwrap_used, clippy::panic)]

use std::path::{Path, PathBuf};
use std::process::Command;

use synthscan::shapes::{multipolygon_from_geojson, sample_uniform};

/// The commands of the README's example block, split into words, comments removed.
fn readme_commands() -> Vec<Vec<String>> {
    let readme = include_str!("../../../README.md");
    let section = readme
        .split("## Command line")
        .nth(1)
        .and_then(|s| s.split("## ").next())
        .expect("the README has a Command line section");
    let block = section
        .split("```sh")
        .nth(2)
        .and_then(|s| s.split("```").next())
        .expect("the section's second sh block holds the examples");
    block
        .lines()
        .map(|line| line.split('#').next().unwrap_or("").trim())
        .filter(|line| line.starts_with("polylidar "))
        .map(|line| line.split_whitespace().skip(1).map(str::to_owned).collect())
        .collect()
}

fn polylidar(dir: &Path, args: &[String]) -> std::process::Output {
    Command::new(env!("CARGO_BIN_EXE_polylidar"))
        .current_dir(dir)
        .args(args)
        .output()
        .expect("the binary runs")
}

/// The README's stand-in inputs, made in `dir` from the fixtures.
fn make_inputs(dir: &Path, depth: &Path, shape: &Path) -> f64 {
    std::fs::copy(depth, dir.join("depth.png")).unwrap();
    std::fs::write(
        dir.join("depth_metadata.csv"),
        "Resolution x,640\nResolution y,480\nFx,525\nFy,525\nPPx,319.5\nPPy,239.5\nDepth Units,0.001\n",
    )
    .unwrap();
    let scene = synthscan::Scene::room(&synthscan::RoomConfig::default()).unwrap();
    let (vertices, triangles, _) = scene.to_mesh(0.1).unwrap();
    let mesh = polylidar_io::MeshData {
        vertices,
        triangles,
    };
    polylidar_io::write_ply(dir.join("room.ply"), &mesh).unwrap();
    let shape = multipolygon_from_geojson(&std::fs::read_to_string(shape).unwrap()).unwrap();
    let points = sample_uniform(&shape, 10_000, 7).unwrap();
    let mut csv = String::from("x,y\n");
    for [x, y] in points {
        csv.push_str(&format!("{x},{y}\n"));
    }
    std::fs::write(dir.join("points.csv"), csv).unwrap();
    geo::Area::unsigned_area(&shape)
}

#[test]
fn every_readme_example_finds_something_on_the_shared_data() {
    let needed = [
        "synpeb/pc_01.pcd",
        "realsense/rgbd_opc.npy",
        "rgbd/icl_living_depth_00000.png",
        "shapes/caholes.geojson",
        "lidar/autzen_trim.laz",
        "lidar/simple.las",
        "kitti/000000.bin",
    ];
    let Some(found) = needed
        .iter()
        .map(|f| test_fixtures::fixture(f))
        .collect::<Option<Vec<PathBuf>>>()
    else {
        return;
    };
    let dir = std::env::temp_dir().join(format!("polylidar-readme-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let shape_area = make_inputs(&dir, &found[2], &found[3]);
    let fixtures = test_fixtures::fixtures_dir();
    let commands = readme_commands();
    assert!(
        commands.len() >= 9,
        "the README lost examples: {commands:?}"
    );
    for command in commands {
        let mut args: Vec<String> = command
            .iter()
            .map(|a| match a.strip_prefix("../shared/fixtures/") {
                Some(rest) => fixtures.join(rest).display().to_string(),
                None => a.clone(),
            })
            .collect();
        let extract = args[0] == "extract";
        if extract {
            args.push("--strict".to_owned());
        }
        let out = polylidar(&dir, &args);
        let stderr = String::from_utf8_lossy(&out.stderr);
        assert!(
            out.status.success(),
            "`polylidar {}` failed ({}):\n{stderr}",
            command.join(" "),
            out.status
        );
        if extract && command.contains(&"points.csv".to_owned()) {
            let text = std::fs::read_to_string(dir.join("polygons.geojson")).unwrap();
            let found = multipolygon_from_geojson(&text).unwrap();
            let recovered = geo::Area::unsigned_area(&found) / shape_area;
            assert!(
                (0.9..1.1).contains(&recovered),
                "the 2D example recovers {:.1} % of the shape's area",
                100.0 * recovered
            );
        }
    }
    std::fs::remove_dir_all(&dir).ok();
}

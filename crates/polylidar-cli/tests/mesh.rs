//! `polylidar mesh` on the shared RGB-D frames: OBJ + MTL + PNG atlas and PLY that agree
//! with each other, per-plane textures, and clear errors.
#![allow(clippy::expect_used, clippy::unwrap_used, clippy::panic)]

mod common;

use std::path::PathBuf;

use common::{polylidar_in as polylidar, succeeded};

fn temp_dir(name: &str) -> test_fixtures::ScratchDir {
    common::scratch("mesh", name)
}

/// Asserts that over a third of the atlas's texels hold a colour brighter than black.
fn assert_mostly_lit(atlas: &polylidar_io::ColorImage) {
    let lit = atlas
        .rgb
        .iter()
        .filter(|c| c.iter().any(|&v| v > 30))
        .count();
    assert!(
        lit * 3 > atlas.rgb.len(),
        "{lit} of {} texels lit",
        atlas.rgb.len()
    );
}

/// The paths of a shared depth frame and of the PrimeSense camera JSON, or `None` (the
/// skip recorded for `test`) when the fixtures are missing.
fn frame_and_camera(frame: &str, test: &str) -> Option<(PathBuf, PathBuf)> {
    match (
        test_fixtures::fixture(frame),
        test_fixtures::fixture("rgbd/camera_primesense.json"),
    ) {
        (Some(depth), Some(camera)) => Some((depth, camera)),
        _ => {
            test_fixtures::record_skip(&format!("{test}: {frame} missing"));
            None
        }
    }
}

#[test]
fn textured_mesh_of_an_icl_frame() {
    let Some((depth, camera)) =
        frame_and_camera("rgbd/icl_living_depth_00000.png", "polylidar mesh")
    else {
        return;
    };
    let dir = temp_dir("icl");
    let (depth, camera) = (depth.display().to_string(), camera.display().to_string());
    let out = polylidar(
        &dir,
        &[
            "mesh",
            &depth,
            "--intrinsics",
            &camera,
            "--preset",
            "synpeb-auto",
            "--stride",
            "2",
            "--texture",
            "-o",
            "room.obj",
            "--plot",
            "room_plot.png",
            "--json",
        ],
    );
    succeeded(&out);
    let report: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    assert!(report["planes"].as_u64().unwrap() >= 3, "{report}");
    let triangles = report["triangles"].as_u64().unwrap() as usize;
    assert!(
        triangles < report["segment_triangles"].as_u64().unwrap() as usize / 3,
        "{report}"
    );
    let obj = std::fs::read_to_string(dir.join("room.obj")).unwrap();
    let count = |prefix: &str| obj.lines().filter(|l| l.starts_with(prefix)).count();
    assert_eq!(count("f "), triangles);
    assert_eq!(count("v "), count("vt "));
    assert!(obj.contains("mtllib room.mtl"));
    let mtl = std::fs::read_to_string(dir.join("room.mtl")).unwrap();
    assert!(mtl.contains("map_Kd room.png"));
    let atlas = polylidar_io::read_color_image(dir.join("room.png")).unwrap();
    assert!(atlas.width > 10 && atlas.height > 10);
    // The atlas holds the frame's colours: black only outside the polygons, between the
    // textures and past the last shelf.
    assert_mostly_lit(&atlas);
    let ply = std::fs::read(dir.join("room.ply")).unwrap();
    let header = String::from_utf8_lossy(&ply[..400.min(ply.len())]).into_owned();
    assert!(
        header.contains(&format!("element face {triangles}")),
        "{header}"
    );
    assert!(header.contains("comment TextureFile room.png"));
    let plot = polylidar_io::read_color_image(dir.join("room_plot.png")).unwrap();
    assert_eq!((plot.width, plot.height), (640, 480)); // 320 × 240 at stride 2, twice
    // Per-plane textures: one PNG per plane, one material each.
    let out = polylidar(
        &dir,
        &[
            "mesh",
            &depth,
            "--intrinsics",
            &camera,
            "--preset",
            "synpeb-auto",
            "--stride",
            "2",
            "--texture",
            "--per-plane",
            "--method",
            "point",
            "-o",
            "planes.obj",
        ],
    );
    succeeded(&out);
    let mtl = std::fs::read_to_string(dir.join("planes.mtl")).unwrap();
    let maps = mtl.lines().filter(|l| l.starts_with("map_Kd")).count();
    assert!(maps >= 3);
    for line in mtl.lines().filter_map(|l| l.strip_prefix("map_Kd ")) {
        assert!(dir.join(line).is_file(), "{line} missing");
    }
    std::fs::remove_dir_all(&dir).ok();
}

#[test]
fn a_texture_without_colours_is_a_clear_error() {
    let dir = temp_dir("demo");
    let out = polylidar(
        &dir,
        &["mesh", "--demo", "shape", "--texture", "-o", "shape.obj"],
    );
    assert_eq!(out.status.code(), Some(1));
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(stderr.contains("--texture needs colours"), "{stderr}");
    // Without a texture the 2D demo meshes fine.
    let out = polylidar(&dir, &["mesh", "--demo", "shape", "-o", "shape.obj"]);
    succeeded(&out);
    assert!(
        std::fs::read_to_string(dir.join("shape.obj"))
            .unwrap()
            .contains("usemtl untextured")
    );
    std::fs::remove_dir_all(&dir).ok();
}

/// `polylidar mesh` takes the camera of a depth PNG as `extract` does: `--intrinsics` as
/// four numbers, an Open3D camera JSON or a RealSense metadata CSV (named, or found
/// beside the PNG), and `--depth-scale`; each gives the same mesh of the same frame.
#[test]
fn every_camera_source_gives_the_same_mesh() {
    let Some((depth, camera)) = frame_and_camera(
        "rgbd/icl_living_depth_00000.png",
        "polylidar mesh camera sources",
    ) else {
        return;
    };
    let dir = temp_dir("camera");
    // The frame with a RealSense CSV beside it (PrimeSense intrinsics, millimetres).
    std::fs::copy(&depth, dir.join("frame.png")).unwrap();
    std::fs::write(
        dir.join("frame_metadata.csv"),
        "Resolution x,640\nResolution y,480\nFx,525\nFy,525\nPPx,319.5\nPPy,239.5\nDepth Units,0.001\n",
    )
    .unwrap();
    let (depth, camera) = (depth.display().to_string(), camera.display().to_string());
    let mesh = |name: &str, input: &str, camera: &[&str]| -> String {
        let obj = format!("{name}.obj");
        let mut args = vec![
            "mesh",
            input,
            "--preset",
            "synpeb-auto",
            "--stride",
            "4",
            "-o",
            &obj,
        ];
        args.extend_from_slice(camera);
        let out = polylidar(&dir, &args);
        assert!(
            out.status.success(),
            "{name}: {}",
            String::from_utf8_lossy(&out.stderr)
        );
        std::fs::read_to_string(dir.join(&obj)).unwrap()
    };
    let numbers = mesh(
        "numbers",
        &depth,
        &[
            "--intrinsics",
            "525,525,319.5,239.5",
            "--depth-scale",
            "1000",
        ],
    );
    assert!(numbers.lines().filter(|l| l.starts_with("f ")).count() > 10);
    let json = mesh("json", &depth, &["--intrinsics", &camera]);
    let beside = mesh("beside", "frame.png", &[]);
    let csv = mesh("csv", &depth, &["--intrinsics", "frame_metadata.csv"]);
    // The OBJ names its own MTL: compare everything else.
    let body = |obj: &str| -> Vec<String> {
        obj.lines()
            .filter(|l| !l.starts_with("mtllib"))
            .map(str::to_owned)
            .collect()
    };
    for (name, other) in [("json", &json), ("beside", &beside), ("csv", &csv)] {
        assert!(
            body(&numbers) == body(other),
            "{name} differs from the numbers"
        );
    }
    // Another depth scale is another cloud: depths halved, planes half as far.
    let halved = mesh(
        "halved",
        &depth,
        &[
            "--intrinsics",
            "525,525,319.5,239.5",
            "--depth-scale",
            "2000",
        ],
    );
    assert!(body(&halved) != body(&numbers));
    // Bad camera options are named.
    for (args, expected) in [
        (
            vec!["--intrinsics", "525,525,319.5"],
            "--intrinsics 525,525,319.5",
        ),
        (vec!["--intrinsics", &camera, "--depth-scale", "0"], "depth"),
    ] {
        let mut all = vec!["mesh", &depth, "-o", "bad.obj"];
        all.extend(args);
        let out = polylidar(&dir, &all);
        assert_eq!(out.status.code(), Some(1));
        let stderr = String::from_utf8_lossy(&out.stderr);
        assert!(stderr.contains(expected), "{stderr}");
    }
    std::fs::remove_dir_all(&dir).ok();
}

#[test]
fn a_decimated_frame_is_meshed_with_its_blocks_colours() {
    // The rgbd preset decimates a 640 × 480 frame by 2: the mesh, its texture and the
    // plot follow the 320 × 240 grid, the labels the input's pixels.
    let Some((depth, camera)) = frame_and_camera("rgbd/tum_depth.png", "polylidar mesh") else {
        return;
    };
    let dir = temp_dir("decimated");
    let (depth, camera) = (depth.display().to_string(), camera.display().to_string());
    let common = [
        depth.as_str(),
        "--intrinsics",
        &camera,
        "--depth-scale",
        "5000",
        "--preset",
        "rgbd",
    ];
    let mut args = vec!["mesh"];
    args.extend(common);
    args.extend(["--texture", "-o", "tum.obj", "--plot", "tum_plot.png"]);
    let out = polylidar(&dir, &args);
    succeeded(&out);
    let stdout = String::from_utf8_lossy(&out.stdout);
    assert!(stdout.contains("decimated 2 × 2"), "{stdout}");
    let atlas = polylidar_io::read_color_image(dir.join("tum.png")).unwrap();
    assert_mostly_lit(&atlas);
    let plot = polylidar_io::read_color_image(dir.join("tum_plot.png")).unwrap();
    assert_eq!((plot.width, plot.height), (640, 480)); // 320 × 240 blocks, twice

    let mut args = vec!["extract"];
    args.extend(common);
    args.extend(["-o", "tum.geojson", "--labels-out", "tum_labels.npy"]);
    let stderr = succeeded(&polylidar(&dir, &args));
    assert!(stderr.contains("decimated 2 × 2"), "{stderr}");
    let npy = std::fs::read(dir.join("tum_labels.npy")).unwrap();
    let header = String::from_utf8_lossy(&npy[..128]).into_owned();
    assert!(header.contains("(480, 640)"), "{header}");
    args.extend(["--decimate", "off"]);
    let stderr = succeeded(&polylidar(&dir, &args));
    assert!(!stderr.contains("decimated"), "{stderr}");
    std::fs::remove_dir_all(&dir).ok();
}

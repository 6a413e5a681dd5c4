//! `polylidar mesh` on the shared RGB-D frames: OBJ + MTL + PNG atlas and PLY that agree
//! with each other, per-plane textures, and clear errors.
#![allow(clippy::expect_used, clippy::unwrap_used, clippy::panic)]

use std::path::{Path, PathBuf};
use std::process::Command;

fn polylidar(dir: &Path, args: &[&str]) -> std::process::Output {
    Command::new(env!("CARGO_BIN_EXE_polylidar"))
        .current_dir(dir)
        .args(args)
        .output()
        .expect("the binary runs")
}

fn temp_dir(name: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("polylidar-mesh-{name}-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    dir
}

#[test]
fn textured_mesh_of_an_icl_frame() {
    let (Some(depth), Some(camera)) = (
        test_fixtures::fixture("rgbd/icl_living_depth_00000.png"),
        test_fixtures::fixture("rgbd/camera_primesense.json"),
    ) else {
        test_fixtures::record_skip("polylidar mesh: ICL frame missing");
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
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
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
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
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
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    assert!(
        std::fs::read_to_string(dir.join("shape.obj"))
            .unwrap()
            .contains("usemtl untextured")
    );
    std::fs::remove_dir_all(&dir).ok();
}

//! Helpers shared by the fuzz targets: the memory budget they read under, and the input
//! kind of arbitrary bytes for the end-to-end target.

use polylidar::{Config, Preset};
use polylidar_io::{CameraIntrinsics, InputKind, Limits, PointCloud};

/// The configuration a selector byte names: one of the presets, or (one value past them)
/// the default configuration.
pub fn config_of(selector: u8) -> Config {
    Preset::all()
        .get(usize::from(selector) % (Preset::all().len() + 1))
        .map_or_else(Config::default, |preset| preset.config())
}

/// The budget of the reader targets: small enough that no input can take the fuzzer past
/// its `-rss_limit_mb`, large enough for every seed.
pub fn reader_limits() -> Limits {
    Limits::default().with_max_memory(16 << 20)
}

/// The budget of the end-to-end target: about ten thousand points at most, so that one
/// run of the pipeline stays short.
pub fn pipeline_limits() -> Limits {
    Limits::default().with_max_memory(4 << 20)
}

/// Reads `data` as the format `selector` names (as `read_input` would a file of that
/// extension), or `None` when the reader refuses it.
pub fn input_of(selector: u8, data: &[u8], limits: &Limits) -> Option<InputKind> {
    let mesh_or_cloud = |mesh: polylidar_io::MeshData| {
        if mesh.triangles.is_empty() {
            InputKind::Cloud(PointCloud::unorganized(mesh.vertices))
        } else {
            InputKind::Mesh(mesh)
        }
    };
    Some(match selector % 8 {
        0 => {
            let mut cloud = polylidar_io::parse_pcd_with(data, limits).ok()?;
            if !cloud.is_organized() {
                cloud.points.retain(|p| p.iter().all(|v| v.is_finite()));
                cloud.cols = cloud.points.len();
            }
            InputKind::Cloud(cloud)
        }
        1 => mesh_or_cloud(polylidar_io::parse_ply_with(data, limits).ok()?.0),
        2 => mesh_or_cloud(polylidar_io::parse_obj_with(data, limits).ok()?.0),
        3 => {
            let array = polylidar_io::parse_npy_with(data, limits).ok()?;
            if matches!(array.shape.as_slice(), &[_, 2]) {
                InputKind::Points2d(array.into_points_2d().ok()?)
            } else {
                InputKind::Cloud(array.into_point_cloud().ok()?)
            }
        }
        4 => {
            let table = polylidar_io::parse_csv_points_with(data, limits).ok()?;
            match (table.to_points_2d(), table.to_points_3d()) {
                (Some(p), _) => InputKind::Points2d(p),
                (_, Some(p)) => InputKind::Cloud(PointCloud::unorganized(p)),
                _ => return None,
            }
        }
        5 => InputKind::Cloud(PointCloud::unorganized(
            polylidar_io::parse_las_with(data, limits).ok()?.points,
        )),
        6 => InputKind::Scan(polylidar_io::parse_kitti_bin_with(data, limits).ok()?),
        _ => {
            let image = polylidar_io::parse_depth_png_with(data, limits).ok()?;
            let intrinsics = CameraIntrinsics {
                width: image.width,
                height: image.height,
                fx: 500.0,
                fy: 500.0,
                ppx: image.width as f64 / 2.0,
                ppy: image.height as f64 / 2.0,
                depth_scale: None,
            };
            InputKind::Depth { image, intrinsics }
        }
    })
}

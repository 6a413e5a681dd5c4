//! Camera intrinsics: RealSense metadata CSV and Open3D camera JSON never panic; sizes
//! and focal lengths that parse are finite.
#![no_main]

use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| {
    let text = String::from_utf8_lossy(data);
    if let Ok(k) = polylidar_io::parse_realsense_intrinsics(&text) {
        assert!(k.fx.is_finite() && k.fy.is_finite() && k.ppx.is_finite() && k.ppy.is_finite());
    }
    let _ = polylidar_io::parse_open3d_camera(&text);
});

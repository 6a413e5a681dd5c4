//! KITTI Velodyne `.bin`: never a panic; one reflectance per point, all finite.
#![no_main]

use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| {
    let limits = polylidar_fuzz::reader_limits();
    if let Ok(scan) = polylidar_io::parse_kitti_bin_with(data, &limits) {
        assert_eq!(scan.points.len(), scan.reflectance.len());
        assert!(scan.points.iter().flatten().all(|v| v.is_finite()));
    }
});

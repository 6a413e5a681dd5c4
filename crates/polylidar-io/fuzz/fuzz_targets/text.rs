//! CSV point tables and RealSense metadata: never panic.
#![no_main]

use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| {
    if let Ok(table) = polylidar_io::parse_csv_points(data) {
        assert!(table.dims == 2 || table.dims == 3);
        assert_eq!(table.data.len() % table.dims, 0);
    }
    let _ = polylidar_io::parse_realsense_intrinsics(&String::from_utf8_lossy(data));
});

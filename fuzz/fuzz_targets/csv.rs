//! CSV point tables: never a panic; 2 or 3 coordinates per point.
#![no_main]

use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| {
    let limits = polylidar_fuzz::reader_limits();
    if let Ok(table) = polylidar_io::parse_csv_points_with(data, &limits) {
        assert!(table.dims == 2 || table.dims == 3);
        assert_eq!(table.data.len() % table.dims, 0);
    }
});

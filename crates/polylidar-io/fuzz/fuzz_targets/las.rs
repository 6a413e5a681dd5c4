//! LAS/LAZ decoding through the size guard: never panics, never aborts on allocation.
#![no_main]

use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| {
    if let Ok(las) = polylidar_io::parse_las(data) {
        assert_eq!(las.points.len(), las.classification.len());
    }
});

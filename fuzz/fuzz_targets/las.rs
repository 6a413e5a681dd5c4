//! LAS/LAZ through the header checks and the budget: never a panic (the LAZ decoder's
//! own are caught silently), never an abort on allocation.
#![no_main]

use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| {
    let limits = polylidar_fuzz::reader_limits();
    if let Ok(las) = polylidar_io::parse_las_with(data, &limits) {
        assert_eq!(las.points.len(), las.classification.len());
    }
});

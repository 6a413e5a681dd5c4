//! NPY: never a panic; the element count matches the shape.
#![no_main]

use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| {
    let limits = polylidar_fuzz::reader_limits();
    if let Ok(array) = polylidar_io::parse_npy_with(data, &limits) {
        assert_eq!(array.data.len(), array.shape.iter().product::<usize>());
        let _ = array.clone().into_points_2d();
        let _ = array.into_point_cloud();
    }
});

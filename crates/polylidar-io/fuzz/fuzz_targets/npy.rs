//! NPY parsing: never panics; element count matches the shape.
#![no_main]

use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| {
    if let Ok(array) = polylidar_io::parse_npy(data) {
        assert_eq!(array.data.len(), array.shape.iter().product::<usize>());
        let _ = array.clone().into_points_2d();
        let _ = array.into_point_cloud();
    }
});

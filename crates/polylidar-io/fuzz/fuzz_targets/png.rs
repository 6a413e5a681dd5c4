//! Depth and colorized depth PNG decoding: never panic; sizes are consistent.
#![no_main]

use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| {
    if let Ok(img) = polylidar_io::parse_depth_png(data) {
        assert_eq!(img.data.len(), img.width * img.height);
    }
    if let Ok(img) = polylidar_io::parse_colorized_depth_png(data) {
        assert_eq!(img.data.len(), img.width * img.height);
    }
});

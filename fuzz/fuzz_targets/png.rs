//! Depth, colorized depth and colour pictures (PNG, JPEG): never a panic, never past the
//! budget; sizes consistent.
#![no_main]

use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| {
    let limits = polylidar_fuzz::reader_limits();
    if let Ok(img) = polylidar_io::parse_depth_png_with(data, &limits) {
        assert_eq!(img.data.len(), img.width * img.height);
    }
    if let Ok(img) = polylidar_io::parse_colorized_depth_png_with(data, &limits) {
        assert_eq!(img.data.len(), img.width * img.height);
    }
    if let Ok(img) = polylidar_io::parse_color_image_with(data, &limits) {
        assert_eq!(img.rgb.len(), img.width * img.height);
    }
});

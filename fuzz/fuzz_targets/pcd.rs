//! PCD headers and data (ascii, binary, LZF): never a panic, never past the budget; a
//! cloud that parses re-encodes and parses back to the same shape.
#![no_main]

use libfuzzer_sys::fuzz_target;
use polylidar_io::{PcdEncoding, PcdWriteOptions, encode_pcd, parse_pcd_with};

fuzz_target!(|data: &[u8]| {
    let limits = polylidar_fuzz::reader_limits();
    let _ = polylidar_io::parse_pcd_fields_with(data, &limits);
    let _ = polylidar_io::parse_pcd_colors(data);
    if let Ok(cloud) = parse_pcd_with(data, &limits) {
        assert_eq!(cloud.points.len(), cloud.rows * cloud.cols);
        if cloud.points.len() < 10_000 {
            let bytes = encode_pcd(&cloud, &PcdWriteOptions::new(PcdEncoding::BinaryCompressed))
                .expect("a parsed cloud encodes");
            let back = parse_pcd_with(&bytes, &limits).expect("an encoded cloud parses");
            assert_eq!((back.rows, back.cols), (cloud.rows, cloud.cols));
        }
    }
});

//! PCD header and data parsing: never panics; a cloud that parses re-encodes and parses
//! back to the same shape.
#![no_main]

use libfuzzer_sys::fuzz_target;
use polylidar_io::{PcdEncoding, PcdWriteOptions, encode_pcd, parse_pcd, parse_pcd_fields};

fuzz_target!(|data: &[u8]| {
    let _ = parse_pcd_fields(data);
    if let Ok(cloud) = parse_pcd(data) {
        assert_eq!(cloud.points.len(), cloud.rows * cloud.cols);
        if cloud.points.len() < 10_000 {
            let bytes = encode_pcd(&cloud, &PcdWriteOptions::new(PcdEncoding::BinaryCompressed))
                .expect("a parsed cloud encodes");
            let back = parse_pcd(&bytes).expect("an encoded cloud parses");
            assert_eq!((back.rows, back.cols), (cloud.rows, cloud.cols));
        }
    }
});

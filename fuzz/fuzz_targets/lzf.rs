//! LZF: arbitrary streams never panic the decoder; compress/decompress round-trips.
#![no_main]

use libfuzzer_sys::fuzz_target;
use polylidar_io::lzf;

fuzz_target!(|data: &[u8]| {
    let _ = lzf::decompress(data, data.len().saturating_mul(4));
    let packed = lzf::compress(data);
    assert_eq!(
        lzf::decompress(&packed, data.len()).expect("own stream decodes"),
        data
    );
});

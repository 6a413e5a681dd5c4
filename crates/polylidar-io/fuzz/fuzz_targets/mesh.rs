//! PLY and OBJ parsing: never panics; every triangle index is in range.
#![no_main]

use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| {
    for mesh in [polylidar_io::parse_ply(data), polylidar_io::parse_obj(data)]
        .into_iter()
        .flatten()
    {
        let n = mesh.vertices.len();
        assert!(mesh.triangles.iter().flatten().all(|&i| (i as usize) < n));
    }
});

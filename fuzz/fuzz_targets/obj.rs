//! OBJ: never a panic; every triangle index in range.
#![no_main]

use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| {
    let limits = polylidar_fuzz::reader_limits();
    if let Ok((mesh, stats)) = polylidar_io::parse_obj_with(data, &limits) {
        let n = mesh.vertices.len();
        assert!(mesh.triangles.iter().flatten().all(|&i| (i as usize) < n));
        assert!(stats.faces_skipped <= stats.faces);
    }
});

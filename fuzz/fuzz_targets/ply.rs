//! PLY (ascii, binary both byte orders): never a panic; every triangle index in range;
//! colours, when read, one per vertex.
#![no_main]

use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| {
    let limits = polylidar_fuzz::reader_limits();
    if let Ok((mesh, stats)) = polylidar_io::parse_ply_with(data, &limits) {
        let n = mesh.vertices.len();
        assert!(mesh.triangles.iter().flatten().all(|&i| (i as usize) < n));
        assert!(stats.faces_skipped <= stats.faces);
        if let Ok(Some(colors)) = polylidar_io::parse_ply_colors(data) {
            assert_eq!(colors.len(), n);
        }
    }
});

//! The 2D pipeline on arbitrary point sets (integer grids with duplicates and collinear
//! runs): never a panic, and every polygon it returns is OGC-valid.
#![no_main]

use geo::Validation;
use libfuzzer_sys::fuzz_target;
use polylidar::{Config, Polylidar};

fuzz_target!(|data: &[u8]| {
    let [alpha, rest @ ..] = data else {
        return;
    };
    let points: Vec<[f64; 2]> = rest
        .chunks_exact(2)
        .map(|c| [f64::from(c[0] % 24), f64::from(c[1] % 24)])
        .collect();
    let config = Config::new()
        .with_alpha(0.5 + f64::from(*alpha % 16) * 0.25)
        .with_min_triangles(1)
        .with_threads(1);
    let Ok(polylidar) = Polylidar::new(config) else {
        return;
    };
    if let Ok(extraction) = polylidar.extract_2d(&points) {
        for polygon in &polylidar::output::to_multipolygon(&extraction.polygons) {
            assert!(polygon.is_valid(), "{:?}", polygon.validation_errors());
        }
    }
});

//! End to end: bytes read as one of the input formats (first byte), a preset (second
//! byte), the pipeline run on what was read: a result or an error, never a panic.
//! Run with `-rss_limit_mb` (scripts/fuzz.sh): the read budget keeps every run small.
#![no_main]

use libfuzzer_sys::fuzz_target;
use polylidar::Polylidar;
use polylidar::io::Input;

fuzz_target!(|data: &[u8]| {
    let [format, preset, rest @ ..] = data else {
        return;
    };
    let limits = polylidar_fuzz::pipeline_limits();
    let Some(kind) = polylidar_fuzz::input_of(*format, rest, &limits) else {
        return;
    };
    let Ok(input) = Input::from_io(kind) else {
        return;
    };
    let config = polylidar_fuzz::config_of(*preset).with_threads(1);
    let Ok(polylidar) = Polylidar::new(config) else {
        return;
    };
    if let Ok(extraction) = polylidar.extract(&input) {
        for polygon in &extraction.polygons {
            assert!(polygon.shell.len() >= 3 || polygon.shell.is_empty());
        }
    }
});

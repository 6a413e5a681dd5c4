//! The LAZ decoder of the `las` crate panics on some corrupt data; the reader turns that
//! into an error and nothing reaches the panic hook (so no panic text or backtrace reaches
//! stderr). Its own test binary: it installs a panic hook that counts every call.

// Test helpers fail loudly by design.
#![allow(clippy::unwrap_used, clippy::expect_used)]

use std::io::Cursor;
use std::sync::atomic::{AtomicUsize, Ordering};

static HOOK_CALLS: AtomicUsize = AtomicUsize::new(0);

fn small_laz() -> Vec<u8> {
    let mut builder = las::Builder::from((1, 2));
    builder.point_format = las::point::Format::new(3).unwrap();
    builder.point_format.is_compressed = true;
    let header = builder.into_header().unwrap();
    let mut writer = las::Writer::new(Cursor::new(Vec::new()), header).unwrap();
    for i in 0..200 {
        let mut p = las::Point {
            x: f64::from(i % 17),
            y: f64::from(i * 3 % 29),
            z: 100.0 + f64::from(i % 7),
            intensity: (i * 37 % 1000) as u16,
            ..Default::default()
        };
        p.gps_time = Some(f64::from(i) * 0.25);
        p.color = Some(las::Color::new(i as u16, 0, 7));
        writer.write_point(p).unwrap();
    }
    writer.close().unwrap();
    writer.into_inner().unwrap().into_inner()
}

#[test]
fn corrupt_laz_is_an_error_without_panic_output() {
    std::panic::set_hook(Box::new(|_| {
        HOOK_CALLS.fetch_add(1, Ordering::SeqCst);
    }));
    let laz = small_laz();
    let start = u32::from_le_bytes([laz[96], laz[97], laz[98], laz[99]]) as usize;
    let mut decoder_failures = 0;
    // About a hundred bytes of the compressed points flipped in turn, and as many cuts.
    let step = ((laz.len() - start) / 100).max(1);
    for at in (start..laz.len()).step_by(step) {
        for variant in [0, 1] {
            let mut bytes = laz.clone();
            if variant == 0 {
                bytes[at] ^= 0xA5;
            } else {
                bytes.truncate(at);
            }
            if let Err(e) = polylidar_io::parse_las(&bytes) {
                let text = e.to_string();
                assert!(!text.contains("failed to fill whole buffer"), "{text}");
                if text.contains("cannot be decoded") {
                    decoder_failures += 1;
                }
            }
        }
    }
    let _ = std::panic::take_hook();
    assert_eq!(HOOK_CALLS.load(Ordering::SeqCst), 0);
    // Two of these inputs made laz 0.13 panic when this test was written, on a debug
    // assertion of its decoder (`sym < …`). Builds without debug assertions (`cargo test
    // --release`) leave it out, and the same inputs end in the reader's other errors.
    if cfg!(debug_assertions) {
        assert!(
            decoder_failures > 0,
            "no input reached the decoder's panics"
        );
    }
}

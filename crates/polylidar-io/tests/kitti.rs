//! KITTI `.bin` frames: properties of the reader against a direct decoding of the bytes,
//! and the two real HDL-64E frames of `../shared/fixtures/kitti`.

// Test helpers fail loudly by design.
#![allow(clippy::unwrap_used, clippy::panic)]

use polylidar_io::{
    ErrorKind, InputKind, KittiScan, encode_kitti_bin, parse_kitti_bin, read_input,
};
use proptest::prelude::*;

/// What a KITTI file of `bytes` holds, decoded independently of the reader: `None` when the
/// reader must refuse it.
fn oracle(bytes: &[u8]) -> Option<Vec<[f32; 4]>> {
    if bytes.is_empty() || !bytes.len().is_multiple_of(16) {
        return None;
    }
    let words: Vec<f32> = bytes
        .chunks(4)
        .map(|w| {
            f32::from_bits(
                u32::from(w[0])
                    | u32::from(w[1]) << 8
                    | u32::from(w[2]) << 16
                    | u32::from(w[3]) << 24,
            )
        })
        .collect();
    if words.iter().any(|w| !w.is_finite()) {
        return None;
    }
    Some(words.chunks(4).map(|c| [c[0], c[1], c[2], c[3]]).collect())
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(512))]

    #[test]
    fn reader_agrees_with_direct_decoding(bytes in proptest::collection::vec(any::<u8>(), 0..200)) {
        let read = parse_kitti_bin(&bytes);
        match oracle(&bytes) {
            None => prop_assert!(read.is_err()),
            Some(records) => {
                let scan = read.unwrap();
                prop_assert_eq!(scan.len(), records.len());
                for (k, r) in records.iter().enumerate() {
                    prop_assert_eq!(scan.points[k], [f64::from(r[0]), f64::from(r[1]), f64::from(r[2])]);
                    prop_assert_eq!(scan.reflectance[k].to_bits(), r[3].to_bits());
                }
            }
        }
    }

    #[test]
    fn finite_records_round_trip(records in proptest::collection::vec(
        (-200.0f32..200.0, -200.0f32..200.0, -30.0f32..30.0, 0.0f32..=1.0), 1..64)
    ) {
        let scan = KittiScan {
            points: records.iter().map(|r| [f64::from(r.0), f64::from(r.1), f64::from(r.2)]).collect(),
            reflectance: records.iter().map(|r| r.3).collect(),
        };
        let bytes = encode_kitti_bin(&scan).unwrap();
        prop_assert_eq!(bytes.len(), 16 * records.len());
        prop_assert_eq!(parse_kitti_bin(&bytes).unwrap(), scan);
    }

    #[test]
    fn one_bad_value_is_named(records in 1usize..20, at in any::<usize>(), bits in prop_oneof![Just(f32::NAN), Just(f32::INFINITY), Just(f32::NEG_INFINITY)]) {
        let mut words = vec![1.5f32; 4 * records];
        let at = at % words.len();
        words[at] = bits;
        let bytes: Vec<u8> = words.iter().flat_map(|w| w.to_le_bytes()).collect();
        let error = parse_kitti_bin(&bytes).unwrap_err();
        let ErrorKind::NonFinite { record, field, .. } = error.kind else {
            panic!("expected NonFinite, got {error}");
        };
        prop_assert_eq!(record, at / 4);
        prop_assert_eq!(field, ["x", "y", "z", "reflectance"][at % 4]);
    }
}

#[test]
fn real_frames_read_in_firing_order() {
    for name in ["kitti/000000.bin", "kitti/000001.bin"] {
        let Some(path) = test_fixtures::fixture(name) else {
            return;
        };
        let InputKind::Scan(scan) = read_input(&path).unwrap() else {
            panic!("{name}: a .bin must read as a scan");
        };
        let bytes = std::fs::metadata(&path).unwrap().len() as usize;
        assert_eq!(scan.len() * 16, bytes, "{name}");
        assert!(
            (100_000..150_000).contains(&scan.len()),
            "{name}: {}",
            scan.len()
        );
        // Reflectance is kept as stored: non-negative, nearly all within 0–1.
        assert!(scan.reflectance.iter().all(|&r| r >= 0.0), "{name}");
        let within = scan.reflectance.iter().filter(|&&r| r <= 1.0).count();
        assert!(within * 100 >= scan.len() * 99, "{name}");
        // Firing order: the azimuth sweeps round once per beam, so it passes straight ahead
        // (from −y to +y, at +x) about once per beam of the HDL-64E.
        let turns = scan
            .points
            .windows(2)
            .filter(|w| w[0][1] < 0.0 && w[1][1] >= 0.0 && w[0][0] > 0.0 && w[1][0] > 0.0)
            .count();
        assert!(
            (60..=70).contains(&turns),
            "{name}: {turns} forward crossings"
        );
    }
}

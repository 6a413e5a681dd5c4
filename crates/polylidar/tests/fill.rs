//! Missing returns filled before meshing (`Config::fill_missing`, on in `rgbd-auto`).
#![allow(clippy::unwrap_used, clippy::expect_used)]

use polylidar::{Config, FillConfig, OrganizedPointCloud, Polylidar};

/// A 60 × 80 depth-camera view of a wall 2 m away, tilted 30° about the vertical, with a
/// third of its pixels missing at random (as at grazing incidence).
fn riddled_wall() -> (OrganizedPointCloud, Vec<bool>) {
    let (rows, cols, f) = (60usize, 80usize, 100.0);
    let tilt = 30f64.to_radians().tan();
    let mut state = 0x9e37_79b9_7f4a_7c15u64;
    let mut missing = Vec::with_capacity(rows * cols);
    let points = (0..rows * cols)
        .map(|i| {
            state = state
                .wrapping_mul(6_364_136_223_846_793_005)
                .wrapping_add(1);
            let drop = (state >> 33).is_multiple_of(3);
            missing.push(drop);
            if drop {
                return [f64::NAN; 3];
            }
            let (u, v) = ((i % cols) as f64 - 40.0, (i / cols) as f64 - 30.0);
            // The ray (u/f, v/f, 1) meets the plane z = 2 + tilt · x.
            let z = 2.0 / (1.0 - tilt * u / f);
            [u / f * z, v / f * z, z]
        })
        .collect();
    (
        OrganizedPointCloud::new(rows, cols, points).unwrap(),
        missing,
    )
}

fn config(fill: bool) -> Config {
    Config::new()
        .with_lmax(0.1)
        .with_min_triangles(500)
        .with_z_thresh(0.05)
        .with_threads(2)
        .with_fill_missing(fill.then(FillConfig::default))
}

#[test]
fn a_wall_riddled_with_missing_returns_is_one_plane_once_filled() {
    let (cloud, missing) = riddled_wall();
    let valid = missing.iter().filter(|&&m| !m).count();
    let labelled = |fill: bool| {
        let extraction = Polylidar::new(config(fill))
            .unwrap()
            .extract_organized(&cloud)
            .unwrap();
        let labels = extraction.plane_labels();
        (extraction, labels)
    };

    let (plain, labels) = labelled(false);
    let found = labels.iter().filter(|&&l| l >= 0).count();
    assert!(
        found < valid / 2,
        "{found} of {valid} labelled without filling"
    );
    assert_eq!(plain.diagnostics.counts.filled, 0);
    assert!(plain.filled.is_empty());

    let (filled, labels) = labelled(true);
    assert_eq!(filled.polygons.len(), 1);
    let counts = &filled.diagnostics.counts;
    assert!(counts.filled > 0);
    assert_eq!(counts.points, valid, "the count is of measured points");
    assert_eq!(filled.filled.iter().filter(|&&f| f).count(), counts.filled);
    for (i, (&label, &was_filled)) in labels.iter().zip(&filled.filled).enumerate() {
        assert!(!was_filled || missing[i], "pixel {i} was measured");
        if was_filled {
            assert_eq!(label, -1, "a filled pixel has no label");
        }
    }
    let found = labels.iter().filter(|&&l| l == 0).count();
    assert!(found * 10 >= valid * 9, "{found} of {valid} on the wall");
    assert_eq!(
        filled.point_labels().iter().filter(|&&l| l >= 0).count(),
        found
    );
}

#[test]
fn fill_settings_are_checked() {
    for (min_neighbours, max_spread) in [(0, 0.03), (9, 0.03), (4, -0.1), (4, f64::NAN)] {
        let config = config(false).with_fill_missing(Some(
            FillConfig::default()
                .with_min_neighbours(min_neighbours)
                .with_max_spread(max_spread),
        ));
        let error = Polylidar::new(config).expect_err("invalid fill");
        assert!(error.to_string().contains("fill_missing"), "{error}");
    }
    let preset = Config::preset("rgbd-auto").unwrap();
    assert_eq!(preset.fill_missing, Some(FillConfig::default()));
    assert_eq!(Config::preset("synpeb-auto").unwrap().fill_missing, None);
}

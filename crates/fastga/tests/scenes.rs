//! Synthetic scenes with known planes: the dominant normals are recovered within 2°.

mod common;

use common::{angle_deg, jitter, normalize, random_unit, rng, rotate};
use fastga::{FastGa, FastGaConfig, GaussianAccumulator, Parallelism, cluster_peaks};
use rand::seq::SliceRandom;

/// Normals of planes `(normal, count)` tilted by Gaussian noise of `sigma_deg`, plus
/// `clutter` uniformly random normals, shuffled (seeded).
fn scene(planes: &[([f64; 3], usize)], sigma_deg: f64, clutter: usize, seed: u64) -> Vec<[f64; 3]> {
    let mut rng = rng(seed);
    let mut out = Vec::new();
    for &(n, count) in planes {
        for _ in 0..count {
            out.push(jitter(&mut rng, normalize(n), sigma_deg));
        }
    }
    for _ in 0..clutter {
        out.push(random_unit(&mut rng));
    }
    out.shuffle(&mut rng);
    out
}

fn assert_recovered(found: &[fastga::DominantNormal], truth: &[[f64; 3]], what: &str) {
    assert_eq!(
        found.len(),
        truth.len(),
        "{what}: found {found:?}, expected {truth:?}"
    );
    for t in truth {
        let best = found
            .iter()
            .map(|d| angle_deg(d.normal, *t))
            .fold(f64::INFINITY, f64::min);
        assert!(best < 2.0, "{what}: {t:?} recovered only within {best:.2}°");
    }
}

/// A rotated box corner: three orthogonal planes of different sizes, 1.5° noise, 20 % clutter.
#[test]
fn three_orthogonal_planes_with_noise_and_clutter() {
    let axis = normalize([0.3, -0.5, 0.8]);
    let frame = [[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]].map(|e| rotate(e, axis, 23.0));
    let planes = [(frame[2], 30_000), (frame[0], 20_000), (frame[1], 12_000)];
    let normals = scene(&planes, 1.5, 15_000, 1);
    for level in [4, 5] {
        for sample_fraction in [1.0, 0.12] {
            let config = FastGaConfig::default()
                .with_level(level)
                .with_sample_fraction(sample_fraction);
            let found = FastGa::new(config).unwrap().detect(&normals).unwrap();
            assert_recovered(
                &found.normals,
                &frame,
                &format!("level {level}, sample {sample_fraction}"),
            );
            // The biggest plane is the strongest.
            assert!(angle_deg(found.normals[0].normal, frame[2]) < 2.0);
        }
    }
}

#[test]
fn two_planes_ten_degrees_apart() {
    let a = normalize([0.2, 0.1, 1.0]);
    let b = rotate(a, normalize([1.0, -2.0, 0.3]), 10.0);
    let normals = scene(&[(a, 20_000), (b, 15_000)], 1.0, 3_000, 2);
    for level in [4, 5] {
        let config = FastGaConfig::default().with_level(level);
        let found = FastGa::new(config).unwrap().detect(&normals).unwrap();
        assert_recovered(&found.normals, &[a, b], &format!("level {level}"));
    }
}

/// Floor and walls exactly on the axes: the floor normal is the icosahedron's north pole
/// vertex, which the charts hold only in their borders.
#[test]
fn axis_aligned_room_including_the_pole() {
    let truth = [
        [0.0, 0.0, 1.0],
        [1.0, 0.0, 0.0],
        [0.0, -1.0, 0.0],
        [0.0, 0.0, -1.0],
    ];
    let planes: Vec<([f64; 3], usize)> = truth.iter().map(|&n| (n, 5_000)).collect();
    for sigma in [0.0, 2.0] {
        let normals = scene(&planes, sigma, 2_000, 3);
        for level in 3..=5 {
            let config = FastGaConfig::default().with_level(level);
            let found = FastGa::new(config).unwrap().detect(&normals).unwrap();
            assert_recovered(
                &found.normals,
                &truth,
                &format!("sigma {sigma} level {level}"),
            );
        }
    }
}

#[test]
fn detection_is_identical_sequential_and_parallel() {
    let normals = scene(
        &[([1.0, 2.0, 3.0], 8_000), ([-3.0, 0.0, 1.0], 6_000)],
        2.0,
        4_000,
        4,
    );
    let run = |parallelism| {
        let config = FastGaConfig::default().with_parallelism(parallelism);
        FastGa::new(config).unwrap().detect(&normals).unwrap()
    };
    assert_eq!(run(Parallelism::Sequential), run(Parallelism::Rayon));
}

#[test]
fn peaks_are_local_maxima_of_the_vertex_values() {
    let normals = scene(
        &[([0.0, 1.0, 1.0], 10_000), ([1.0, 0.0, 0.0], 5_000)],
        3.0,
        5_000,
        6,
    );
    let mut ga = GaussianAccumulator::new(4).unwrap();
    ga.integrate(&normals, 1.0, Parallelism::Rayon).unwrap();
    let values = ga.vertex_values();
    let max = values.iter().copied().fold(0.0, f64::max);
    let peaks = ga.find_peaks(15.0);
    assert!(peaks.len() >= 2);
    for p in &peaks {
        assert!(p.value >= 15.0);
        assert!((p.value - 255.0 * values[p.vertex as usize] / max).abs() < 1e-9);
        for u in ga.icosahedron().vertex_neighbors(p.vertex) {
            assert!(values[u as usize] <= values[p.vertex as usize]);
        }
    }
    let clustered = cluster_peaks(&peaks, 0.1, 0.15);
    assert!(clustered.windows(2).all(|w| w[0].weight >= w[1].weight));
}

/// The PNG file is written atomically: it replaces an older file whole, and a write that
/// fails leaves what was there and no temporary file.
#[cfg(feature = "png")]
#[test]
fn image_is_written_as_png() {
    let normals = scene(&[([0.0, 0.0, 1.0], 1_000)], 5.0, 1_000, 7);
    let mut ga = GaussianAccumulator::new(4).unwrap();
    ga.integrate(&normals, 1.0, Parallelism::Sequential)
        .unwrap();
    let image = ga.unwrapped_image();
    assert_eq!((image.width(), image.height()), (90, 34));
    let dir = std::env::temp_dir().join(format!("fastga-png-test-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let entries = || {
        let mut names: Vec<String> = std::fs::read_dir(&dir)
            .unwrap()
            .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
            .collect();
        names.sort();
        names
    };

    let path = dir.join("image.png");
    std::fs::write(&path, b"an older file").unwrap();
    image.write_png(&path).unwrap();
    let bytes = std::fs::read(&path).unwrap();
    assert_eq!(&bytes[..8], b"\x89PNG\r\n\x1a\n");
    let mut encoded = Vec::new();
    image.write_png_to(&mut encoded).unwrap();
    assert_eq!(bytes, encoded);

    // A directory cannot be replaced by the file: the rename fails after the temporary file
    // was written, and the temporary file is removed.
    let occupied = dir.join("occupied.png");
    std::fs::create_dir(&occupied).unwrap();
    assert!(matches!(
        image.write_png(&occupied),
        Err(fastga::FastGaError::Io { .. })
    ));
    assert!(occupied.is_dir());
    assert_eq!(entries(), ["image.png", "occupied.png"]);

    let missing = dir.join("no-such-dir").join("x.png");
    assert!(matches!(
        image.write_png(&missing),
        Err(fastga::FastGaError::Io { .. })
    ));
    assert_eq!(entries(), ["image.png", "occupied.png"]);
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn invalid_configurations_are_rejected() {
    let base = FastGaConfig::default();
    for config in [
        base.with_level(8),
        base.with_sample_fraction(0.0),
        base.with_value_threshold(256.0),
        base.with_value_threshold(f64::NAN),
        base.with_cluster_distance(-0.1),
        base.with_min_cluster_weight(f64::INFINITY),
        base.with_unit_tolerance(-1.0),
    ] {
        assert!(FastGa::new(config).is_err(), "{config:?}");
    }
    assert!((base.with_cluster_angle_deg(60.0).cluster_distance - 1.0).abs() < 1e-12);
    for preset in [
        FastGaConfig::rgbd(),
        FastGaConfig::synpeb(),
        FastGaConfig::synpeb_benchmark(),
        FastGaConfig::mesh(),
    ] {
        preset.validate().unwrap();
    }
}

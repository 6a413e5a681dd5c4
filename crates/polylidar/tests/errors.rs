//! Bad input through the facade gives errors naming the problem, never a panic.

use polylidar::{Config, MeshError, Polylidar, PolylidarError};

fn run_2d(points: &[[f64; 2]]) -> Result<polylidar::Extraction, PolylidarError> {
    Polylidar::new(Config::new().with_alpha(1.0))?.extract_2d(points)
}

#[test]
fn degenerate_point_sets() {
    assert!(matches!(
        run_2d(&[]).unwrap_err(),
        PolylidarError::Mesh(MeshError::TooFewPoints { found: 0 })
    ));
    assert!(matches!(
        run_2d(&[[0.0, 0.0], [1.0, 0.0]]),
        Err(PolylidarError::Mesh(MeshError::TooFewPoints { .. }))
    ));
    assert!(matches!(
        run_2d(&[[0.0, 0.0], [1.0, 0.0], [f64::INFINITY, 1.0]]),
        Err(PolylidarError::Mesh(MeshError::NonFinitePoint { index: 2 }))
    ));
    assert!(matches!(
        run_2d(&[[0.0, 0.0], [1.0, 1.0], [2.0, 2.0], [5.0, 5.0]]),
        Err(PolylidarError::Mesh(MeshError::Collinear { .. }))
    ));
    assert!(matches!(
        run_2d(&[[3.0, 3.0]; 10]),
        Err(PolylidarError::Mesh(MeshError::Collinear { .. }))
    ));
    let nan_cloud = [[0.0, 0.0, 0.0], [1.0, 0.0, f64::NAN], [0.0, 1.0, 0.0]];
    assert!(matches!(
        Polylidar::new(Config::new())
            .unwrap()
            .extract_25d(&nan_cloud),
        Err(PolylidarError::Mesh(MeshError::NonFinitePoint { index: 1 }))
    ));
}

#[test]
fn nothing_kept_is_explained_by_the_counts() {
    let points: Vec<[f64; 2]> = (0..100)
        .map(|i| [(i % 10) as f64, (i / 10) as f64])
        .collect();
    let extraction = Polylidar::new(Config::new().with_lmax(0.5))
        .unwrap()
        .extract_2d(&points)
        .unwrap();
    let counts = extraction.diagnostics.counts;
    assert!(extraction.polygons.is_empty());
    assert_eq!(counts.dropped_lmax, counts.triangles);
    assert_eq!(counts.triangles_kept, 0);
}

#[test]
fn bad_config_values_are_named() {
    for (config, field) in [
        (Config::new().with_alpha(-1.0), "alpha"),
        (Config::new().with_lmax(f64::NAN), "lmax"),
        (Config::new().with_norm_thresh(1.5), "norm_thresh"),
        (Config::new().with_up([0.0; 3]), "up"),
    ] {
        match Polylidar::new(config) {
            Err(PolylidarError::Config { field: f, .. }) => assert_eq!(f, field),
            other => panic!("expected a config error for {field}, got {other:?}"),
        }
    }
}

#[test]
fn results_do_not_depend_on_the_thread_count() {
    let shape = synthscan::shapes::demo_shape();
    let points = synthscan::shapes::sample_uniform(&shape, 5000, 3).unwrap();
    let alpha = synthscan::shapes::paper_alpha(&shape, 5000);
    let run = |threads| {
        let extraction = Polylidar::new(Config::new().with_alpha(alpha).with_threads(threads))
            .unwrap()
            .extract_2d(&points)
            .unwrap();
        (extraction.polygons, extraction.diagnostics.counts)
    };
    let one = run(1);
    assert_eq!(one, run(2));
    assert_eq!(one, run(3));
}

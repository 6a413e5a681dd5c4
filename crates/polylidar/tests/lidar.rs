//! The 2.5D path on real airborne LiDAR: the Autzen sample (`../shared/fixtures/lidar/`,
//! US survey feet, z 406–521). Seen from above it holds a large flat paved area, a river
//! with few returns, a footbridge, and trees up to ~90 ft tall.
//!
//! The 2.5D pipeline keeps near-horizontal triangles only, so the flat surfaces must come
//! out as valid polygons whose interiors exclude the tree canopies: the test checks that
//! almost no point standing more than 15 ft above the flat area lies inside a polygon.

use geo::{Contains, Coord, LineString, Point, Polygon, Validation};
use polylidar::{Config, Polylidar};

#[test]
fn autzen_flat_surfaces_exclude_trees() {
    let Some(path) = test_fixtures::fixture("lidar/autzen_trim.laz") else {
        return;
    };
    let cloud = polylidar_io::read_las(&path).unwrap();
    assert_eq!(cloud.points.len(), 110_000);
    let config = Config::new()
        .with_lmax(8.0)
        .with_norm_thresh(0.95)
        .with_min_triangles(200)
        .with_min_hole_vertices(6);
    let extraction = Polylidar::new(config)
        .unwrap()
        .extract_25d(&cloud.points)
        .unwrap();
    let counts = extraction.diagnostics.counts;
    assert!(
        counts.dropped_normal > 10_000,
        "steep triangles (trees, banks) are dropped: {counts:?}"
    );
    assert!(counts.polygons >= 1);

    let ring = |points: &[[f64; 3]]| -> LineString<f64> {
        points.iter().map(|p| Coord { x: p[0], y: p[1] }).collect()
    };
    let polygons: Vec<Polygon<f64>> = extraction
        .polygons
        .iter()
        .map(|p| {
            Polygon::new(
                ring(&p.shell_points),
                p.hole_points.iter().map(|h| ring(h)).collect(),
            )
        })
        .collect();
    for p in &polygons {
        assert!(p.is_valid(), "{:?}", p.validation_errors());
    }
    // The largest flat surface is the paved area, about 425 ft high, holed by tree canopies.
    let largest = extraction
        .polygons
        .iter()
        .max_by_key(|p| p.triangles.len())
        .unwrap();
    assert!(largest.triangles.len() > 50_000);
    assert!(
        largest.holes.len() > 20,
        "tree canopies are holes: {}",
        largest.holes.len()
    );

    // Points 15 ft above the flat area are canopy (or bridge railings): they must stay out.
    let tall: Vec<Point<f64>> = cloud
        .points
        .iter()
        .filter(|p| p[2] > 445.0)
        .map(|p| Point::new(p[0], p[1]))
        .collect();
    let inside = tall
        .iter()
        .filter(|q| polygons.iter().any(|p| p.contains(*q)))
        .count();
    eprintln!(
        "{inside} of {} tall points inside flat polygons; {counts:?}",
        tall.len()
    );
    assert!(tall.len() > 5_000);
    assert!(
        (inside as f64) < 0.02 * tall.len() as f64,
        "{inside} of {} tall points inside flat polygons",
        tall.len()
    );
}

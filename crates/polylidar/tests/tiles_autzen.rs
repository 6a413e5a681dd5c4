//! Tiled extraction on real airborne LiDAR: the Autzen sample (`../shared/fixtures/lidar/`,
//! US survey feet) cut into 2 × 2 tiles whose seams cross at the middle of the cloud,
//! against one run on the whole cloud. The merged polygons must cover the same ground as
//! the single run's (symmetric difference of the unions over their area), each large
//! polygon must come out whole, and every merged polygon must be valid.

use geo::{Area, BooleanOps, Coord, LineString, MultiPolygon, Polygon, Validation};
use polylidar::tiles::{MergeTolerance, TileGrid, extract_tiled};
use polylidar::{Config, Polylidar};

#[test]
fn autzen_in_four_tiles_equals_the_single_run() {
    let Some(path) = test_fixtures::fixture("lidar/autzen_trim.laz") else {
        return;
    };
    let cloud = polylidar_io::read_las(&path).unwrap();
    let config = Config::new()
        .with_lmax(8.0)
        .with_norm_thresh(0.95)
        .with_min_triangles(200)
        .with_min_hole_vertices(6);
    let polylidar = Polylidar::new(config).unwrap();
    let single = polylidar.extract_25d(&cloud.points).unwrap();
    let ring = |points: &[[f64; 3]]| -> LineString<f64> {
        points.iter().map(|p| Coord { x: p[0], y: p[1] }).collect()
    };
    let single: Vec<Polygon<f64>> = single
        .polygons
        .iter()
        .map(|p| {
            Polygon::new(
                ring(&p.shell_points),
                p.hole_points.iter().map(|h| ring(h)).collect(),
            )
        })
        .collect();

    let (mut lo, mut hi) = ([f64::INFINITY; 2], [f64::NEG_INFINITY; 2]);
    for p in &cloud.points {
        for k in 0..2 {
            lo[k] = lo[k].min(p[k]);
            hi[k] = hi[k].max(p[k]);
        }
    }
    let centre = [0.5 * (lo[0] + hi[0]), 0.5 * (lo[1] + hi[1])];
    let size = 600.0;
    // A margin of 5 lmax: the triangles along the seams are the whole cloud's.
    let grid = TileGrid::new([centre[0] - size, centre[1] - size], size, 40.0, 2, 2).unwrap();
    let tolerance = MergeTolerance::for_config(polylidar.config());
    let merged = extract_tiled(&polylidar, &grid, &cloud.points, &tolerance).unwrap();

    for p in &merged.polygons {
        assert!(
            p.footprint.is_valid(),
            "{:?}",
            p.footprint.validation_errors()
        );
    }
    let single_union = MultiPolygon::new(single.clone());
    let merged_union = MultiPolygon::new(
        merged
            .polygons
            .iter()
            .map(|p| p.footprint.clone())
            .collect(),
    );
    let difference = single_union.xor(&merged_union).unsigned_area() / single_union.unsigned_area();
    let crossing = merged.polygons.iter().filter(|p| p.tiles.len() > 1).count();
    eprintln!(
        "autzen 2 × 2 tiles: {} polygons single, {} merged ({crossing} across seams), \
         area {:.0} vs {:.0} ft², symmetric difference / area = {difference:.2e}",
        single.len(),
        merged.polygons.len(),
        single_union.unsigned_area(),
        merged.area(),
    );
    assert!(difference < 1e-6, "{difference}");
    let holes = |polygons: &mut dyn Iterator<Item = &Polygon<f64>>| -> usize {
        polygons.map(|p| p.interiors().len()).sum()
    };
    assert_eq!(
        holes(&mut single.iter()),
        holes(&mut merged.polygons.iter().map(|p| &p.footprint)),
        "holes (tree canopies) kept"
    );
    assert!(crossing >= 1, "the paved area spans the seams");
    // Every single-run polygon of 1 % of the total area or more is one merged polygon.
    let total = single_union.unsigned_area();
    for (i, s) in single.iter().enumerate() {
        if s.unsigned_area() < 0.01 * total {
            continue;
        }
        let parts: Vec<f64> = merged
            .polygons
            .iter()
            .map(|m| m.footprint.intersection(s).unsigned_area() / s.unsigned_area())
            .filter(|&share| share > 1e-3)
            .collect();
        assert_eq!(
            parts.len(),
            1,
            "single-run polygon {i} in pieces: {parts:?}"
        );
        assert!(parts[0] > 0.999, "polygon {i}: {}", parts[0]);
    }
}

//! Tiled extraction against one run on the whole cloud (the oracle), on synthetic scenes.

use geo::{Area, BooleanOps, Contains, LineString, MultiPolygon, Point, Polygon, Validation};

use super::*;

/// A hash of `i` in `[0, 1)` (splitmix64): repeatable jitter without a generator.
fn unit_hash(i: u64) -> f64 {
    let mut z = i.wrapping_add(0x9E37_79B9_7F4A_7C15);
    z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
    z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
    ((z ^ (z >> 31)) >> 11) as f64 / (1u64 << 53) as f64
}

/// A block seen from above: ground at 0 and flat roofs (`[x0, y0, x1, y1, height]`), one
/// with a courtyard (`[x0, y0, x1, y1]`, down to the ground), sampled on a jittered grid of
/// spacing `step`.
fn scene(extent: f64, step: f64, roofs: &[[f64; 5]], courtyard: Option<[f64; 4]>) -> Vec<[f64; 3]> {
    let n = (extent / step) as u64;
    let mut points = Vec::new();
    for j in 0..n {
        for i in 0..n {
            let k = j * n + i;
            let x = (i as f64 + 0.3 * unit_hash(2 * k)) * step;
            let y = (j as f64 + 0.3 * unit_hash(2 * k + 1)) * step;
            let inside = |r: &[f64]| (r[0]..r[2]).contains(&x) && (r[1]..r[3]).contains(&y);
            let z = roofs
                .iter()
                .find(|r| inside(&r[..]))
                .filter(|_| !courtyard.is_some_and(|c| inside(&c[..])))
                .map_or(0.0, |r| r[4]);
            points.push([x, y, z + 0.01 * unit_hash(k + 1_000_003)]);
        }
    }
    points
}

fn config() -> Config {
    Config::new()
        .with_lmax(1.6)
        .with_norm_thresh(0.94)
        .with_min_triangles(50)
        .with_min_hole_vertices(6)
}

fn footprints(extraction: &crate::Extraction) -> Vec<Polygon<f64>> {
    crate::output::to_multipolygon(&extraction.polygons).0
}

/// Area of the symmetric difference of `a` and `b` over the area of `a`.
fn relative_difference(a: &Polygon<f64>, b: &Polygon<f64>) -> f64 {
    a.xor(b).unsigned_area() / a.unsigned_area()
}

/// Each polygon of the single run is matched by exactly one merged polygon, within a
/// relative area difference of `tolerance`, and no merged polygon is left over.
fn assert_matches(single: &[Polygon<f64>], merged: &TileSet, tolerance: f64) {
    assert_eq!(
        single.len(),
        merged.polygons.len(),
        "single run: {} polygons, tiled: {}",
        single.len(),
        merged.polygons.len()
    );
    for (i, s) in single.iter().enumerate() {
        let overlapping: Vec<&TilePolygon> = merged
            .polygons
            .iter()
            .filter(|m| m.footprint.intersection(s).unsigned_area() > 0.5 * s.unsigned_area())
            .collect();
        assert_eq!(overlapping.len(), 1, "polygon {i} of the single run");
        let d = relative_difference(s, &overlapping[0].footprint);
        assert!(d < tolerance, "polygon {i}: relative difference {d}");
        assert_eq!(
            s.interiors().len(),
            overlapping[0].footprint.interiors().len()
        );
    }
    for m in &merged.polygons {
        assert!(
            m.footprint.is_valid(),
            "{:?}",
            m.footprint.validation_errors()
        );
    }
}

#[test]
fn roof_on_four_tiles_is_one_polygon_with_its_courtyard() {
    // Tiles of 30 from the origin: the first roof covers the corner (30, 30) of four
    // tiles, its courtyard sits on the seam x = 30; the second roof is inside one tile.
    let roofs = [[18.0, 20.0, 44.0, 41.0, 9.0], [64.0, 5.0, 80.0, 20.0, 6.0]];
    let points = scene(90.0, 0.5, &roofs, Some([26.0, 27.0, 34.0, 33.0]));
    let polylidar = Polylidar::new(config()).unwrap();
    let single = footprints(&polylidar.extract_25d(&points).unwrap());
    let grid = TileGrid::new([0.0, 0.0], 30.0, 5.0, 3, 3).unwrap();
    let tolerance = MergeTolerance::for_config(polylidar.config());
    let merged = extract_tiled(&polylidar, &grid, &points, &tolerance).unwrap();
    assert_matches(&single, &merged, 1e-3);

    let centre = Point::new(20.0, 35.0);
    let roof: Vec<&TilePolygon> = merged
        .polygons
        .iter()
        .filter(|p| p.footprint.contains(&centre))
        .collect();
    assert_eq!(roof.len(), 1);
    let roof = roof[0];
    assert_eq!(roof.tiles.len(), 4, "{:?}", roof.tiles);
    assert_eq!(roof.footprint.interiors().len(), 1, "the courtyard");
    assert!((roof.z_at(31.0, 31.0) - 9.0).abs() < 0.05);
    let expected = 26.0 * 21.0 - 8.0 * 6.0;
    assert!(
        (roof.area - expected).abs() / expected < 0.1,
        "{} vs {expected}",
        roof.area
    );
}

#[test]
fn gabled_roof_on_four_tiles_is_two_polygons_on_the_3d_path() {
    // A roof pitched 18° over [18, 44] × [19, 41], its ridge along x on the seam y = 30:
    // the southern face's pieces end on the seam where the northern face's begin, and
    // their normals part by 36°, within the 2.5D path's tolerance (twice the 20° cone)
    // but not within the 3D path's. The `aerial` preset runs the unorganized 3D path.
    let (pitch, ridge, half, eave) = (18f64.to_radians(), 30.0, 11.0, 6.0);
    let slope = pitch.tan();
    let points: Vec<[f64; 3]> = scene(72.0, 0.6, &[], None)
        .into_iter()
        .map(
            |[x, y, z]| match (18.0..44.0).contains(&x) && (19.0..41.0).contains(&y) {
                true => [x, y, z + eave + slope * (half - (y - ridge).abs())],
                false => [x, y, z],
            },
        )
        .collect();
    let polylidar = Polylidar::new(Config::preset("aerial").unwrap()).unwrap();
    let tolerance = MergeTolerance::for_config(polylidar.config());
    let whole = TileGrid::new([0.0, 0.0], 72.0, 0.0, 1, 1).unwrap();
    let single = extract_tile(&polylidar, &whole, TileId { col: 0, row: 0 }, &points).unwrap();
    let grid = TileGrid::new([0.0, 0.0], 30.0, 6.0, 3, 3).unwrap();
    let merged = extract_tiled(&polylidar, &grid, &points, &tolerance).unwrap();
    let faces = |set: &TileSet| -> Vec<TilePolygon> {
        set.polygons
            .iter()
            .filter(|p| (p.normal[2] - pitch.cos()).abs() < 0.01)
            .cloned()
            .collect()
    };
    let (faces, single) = (faces(&merged), faces(&single));
    assert_eq!(faces.len(), 2, "two roof faces");
    assert_eq!(single.len(), 2, "two roof faces in one run");
    for face in &faces {
        assert!(face.footprint.is_valid());
        assert!(face.tiles.len() >= 2, "{:?}", face.tiles);
        // The band along the ridge, where the neighbourhoods of the normals straddle both
        // faces, goes to neither: the faces come out a little short of their 11 m.
        let expected = 26.0 * half;
        assert!(
            (face.area - expected).abs() / expected < 0.15,
            "{} vs {expected}",
            face.area
        );
        assert!((face.z_at(31.0, ridge) - (eave + slope * half)).abs() < 0.1);
        let same = single
            .iter()
            .filter(|s| s.footprint.intersection(&face.footprint).unsigned_area() > 0.5 * s.area)
            .count();
        assert_eq!(same, 1, "one face of the single run under it");
    }
    assert!(
        faces[0].normal[1] * faces[1].normal[1] < 0.0,
        "facing apart"
    );
}

#[test]
fn merging_in_a_tree_equals_merging_at_once() {
    let roofs = [
        [10.0, 10.0, 50.0, 22.0, 5.0],
        [35.0, 30.0, 55.0, 58.0, 12.0],
    ];
    let points = scene(64.0, 0.5, &roofs, None);
    let polylidar = Polylidar::new(config()).unwrap();
    let grid = TileGrid::new([0.0, 0.0], 16.0, 4.0, 4, 4).unwrap();
    let tolerance = MergeTolerance::for_config(polylidar.config());
    let windows = grid.split(&points);
    let sets: Vec<TileSet> = grid
        .tiles()
        .zip(&windows)
        .map(|(t, w)| extract_tile(&polylidar, &grid, t, w).unwrap())
        .collect();
    let at_once = merge(sets.clone(), &tolerance).unwrap();
    // Pairs, then pairs of pairs, through bytes as between processes.
    let mut level = sets;
    while level.len() > 1 {
        level = level
            .chunks(3)
            .map(|c| {
                let decoded = c
                    .iter()
                    .map(|s| TileSet::from_bytes(&s.to_bytes()).unwrap())
                    .collect();
                merge(decoded, &tolerance).unwrap()
            })
            .collect();
    }
    let tree = level.pop().unwrap();
    assert_eq!(tree.cover, at_once.cover);
    assert_eq!(tree.polygons.len(), at_once.polygons.len());
    for (a, b) in tree.polygons.iter().zip(&at_once.polygons) {
        assert_eq!(a.tiles, b.tiles);
        let d = relative_difference(&a.footprint, &b.footprint);
        assert!(d < 1e-7, "{d}");
    }
    let single = footprints(&polylidar.extract_25d(&points).unwrap());
    assert_matches(&single, &at_once, 1e-3);
}

#[test]
fn overlap_is_counted_once() {
    // A flat field: its area is the area of the single run, not more (the windows overlap
    // by 2 × 6 on every seam).
    let points = scene(60.0, 0.5, &[], None);
    let polylidar = Polylidar::new(config()).unwrap();
    let single = footprints(&polylidar.extract_25d(&points).unwrap());
    let grid = TileGrid::new([0.0, 0.0], 20.0, 6.0, 3, 3).unwrap();
    let merged = extract_tiled(
        &polylidar,
        &grid,
        &points,
        &MergeTolerance::for_config(polylidar.config()),
    )
    .unwrap();
    assert_eq!(merged.polygons.len(), 1);
    assert_eq!(merged.polygons[0].tiles.len(), 9);
    let union = MultiPolygon::new(single);
    let d = (union.unsigned_area() - merged.area()).abs() / union.unsigned_area();
    assert!(d < 1e-9, "{d}");
}

#[test]
fn merge_refuses_a_tile_twice_and_mixed_grids() {
    let grid = TileGrid::new([0.0, 0.0], 10.0, 1.0, 2, 2).unwrap();
    let tile = TileId { col: 0, row: 1 };
    let set = TileSet {
        grid,
        cover: vec![tile],
        polygons: Vec::new(),
    };
    let tolerance = MergeTolerance::for_config(&config());
    assert!(matches!(
        merge(vec![set.clone(), set.clone()], &tolerance),
        Err(TileError::Merge(_))
    ));
    let other = TileSet {
        grid: TileGrid { size: 11.0, ..grid },
        cover: vec![TileId { col: 1, row: 1 }],
        polygons: Vec::new(),
    };
    assert!(matches!(
        merge(vec![set, other], &tolerance),
        Err(TileError::Merge(_))
    ));
    assert!(matches!(
        merge(Vec::new(), &tolerance),
        Err(TileError::Merge(_))
    ));
}

#[test]
fn grid_checks_and_windows() {
    assert!(TileGrid::new([0.0, 0.0], 0.0, 1.0, 1, 1).is_err());
    assert!(TileGrid::new([0.0, 0.0], 1.0, -1.0, 1, 1).is_err());
    assert!(TileGrid::new([f64::NAN, 0.0], 1.0, 1.0, 1, 1).is_err());
    assert!(TileGrid::new([0.0, 0.0], 1.0, 1.0, 0, 1).is_err());
    assert!(TileGrid::covering_points(&[[f64::NAN; 3]], 1.0, 0.0).is_err());
    let grid = TileGrid::new([0.0, 0.0], 10.0, 2.0, 3, 3).unwrap();
    let mut at: Vec<TileId> = grid.windows_of(10.5, 21.0).collect();
    at.sort_unstable();
    let t = |col, row| TileId { col, row };
    let mut expected = vec![t(0, 2), t(1, 2), t(0, 1), t(1, 1)];
    expected.sort_unstable();
    assert_eq!(at, expected);
    assert_eq!(grid.windows_of(15.0, 15.0).count(), 1);
    assert_eq!(grid.windows_of(-3.0, 15.0).count(), 0);
    assert!(grid.index(t(3, 0)).is_err());
    let polylidar = Polylidar::new(config()).unwrap();
    let empty = extract_tile(&polylidar, &grid, t(0, 0), &[[1.0, 1.0, 0.0]]).unwrap();
    assert!(empty.polygons.is_empty());
    let tilted = Polylidar::new(config().with_up([0.0, 1.0, 1.0])).unwrap();
    assert!(matches!(
        extract_tile(&tilted, &grid, t(0, 0), &[]),
        Err(TileError::Grid(_))
    ));
}

#[test]
fn bytes_round_trip_and_reject_garbage() {
    let points = scene(30.0, 0.5, &[[5.0, 5.0, 20.0, 20.0, 4.0]], None);
    let polylidar = Polylidar::new(config()).unwrap();
    let grid = TileGrid::new([0.0, 0.0], 15.0, 3.0, 2, 2).unwrap();
    let set = extract_tile(&polylidar, &grid, TileId { col: 0, row: 0 }, &points).unwrap();
    assert!(!set.polygons.is_empty());
    let bytes = set.to_bytes();
    assert_eq!(TileSet::from_bytes(&bytes).unwrap(), set);
    for cut in [0, 7, 20, bytes.len() - 1] {
        assert!(TileSet::from_bytes(&bytes[..cut]).is_err());
    }
    let mut long = bytes.clone();
    long.push(0);
    assert!(TileSet::from_bytes(&long).is_err());
    let geojson: serde_json::Value = serde_json::from_str(&set.to_geojson(true)).unwrap();
    assert_eq!(
        geojson["features"].as_array().unwrap().len(),
        set.polygons.len()
    );
}

/// A flat piece of `tile` with exterior `[x0, x1] × [0, 10]` and `holes`.
fn flat_piece(tile: TileId, x0: f64, x1: f64, holes: Vec<LineString<f64>>) -> TilePolygon {
    let exterior = LineString::from(vec![
        (x0, 0.0),
        (x1, 0.0),
        (x1, 10.0),
        (x0, 10.0),
        (x0, 0.0),
    ]);
    let footprint = Polygon::new(exterior, holes);
    TilePolygon {
        area: footprint.unsigned_area(),
        footprint,
        normal: [0.0, 0.0, 1.0],
        offset: 0.0,
        tiles: vec![tile],
    }
}

#[test]
fn holes_away_from_the_seams_come_through_a_merge_unchanged() {
    let square = |x: f64, y: f64, s: f64| {
        LineString::from(vec![(x, y), (x + s, y), (x + s, y + s), (x, y + s), (x, y)])
    };
    // Left: a hole far from everything (set apart), one touching the exterior at a point
    // (it goes through the union) and one touching that one (so it does too). Right: a hole
    // on nothing but its own tile, and one whose box reaches the seam x = 10.
    let touching = LineString::from(vec![(5.0, 0.0), (6.0, 1.0), (4.0, 1.0), (5.0, 0.0)]);
    let chained = LineString::from(vec![(6.0, 1.0), (7.0, 2.0), (6.0, 2.0), (6.0, 1.0)]);
    let left_holes = vec![square(2.0, 5.0, 2.0), touching, chained];
    let right_holes = vec![square(15.0, 5.0, 2.0), square(10.5, 2.0, 1.0)];
    let grid = TileGrid::new([0.0, 0.0], 10.0, 1.0, 2, 1).unwrap();
    let (left, right) = (TileId { col: 0, row: 0 }, TileId { col: 1, row: 0 });
    let sets = vec![
        TileSet {
            grid,
            cover: vec![left],
            polygons: vec![flat_piece(left, 0.0, 10.0, left_holes)],
        },
        TileSet {
            grid,
            cover: vec![right],
            polygons: vec![flat_piece(right, 10.0, 20.0, right_holes)],
        },
    ];
    let expected = sets
        .iter()
        .flat_map(|s| s.polygons.iter())
        .map(|p| p.area)
        .sum::<f64>();
    let merged = merge(sets, &MergeTolerance::for_config(&config())).unwrap();
    assert_eq!(merged.polygons.len(), 1);
    let p = &merged.polygons[0];
    assert!(
        p.footprint.is_valid(),
        "{:?}",
        p.footprint.validation_errors()
    );
    assert_eq!(p.footprint.interiors().len(), 5);
    assert!((p.area - expected).abs() < 1e-9, "{} vs {expected}", p.area);
    assert!((p.footprint.unsigned_area() - expected).abs() < 1e-9);
    for hole in [square(2.0, 5.0, 2.0), square(15.0, 5.0, 2.0)] {
        assert!(
            p.footprint.interiors().contains(&hole),
            "{hole:?} unchanged"
        );
    }
}

//! 2D shapes with a known answer, for the 2D path (Polylidar, the 2D paper): uniform point
//! samples inside (multi)polygons, the paper's α and L² shape error, its convexity
//! measure, GeoJSON shape loading, and the built-in demo shape.

pub use geo::MultiPolygon;
use geo::{Area, BooleanOps, Coord, LineString, Polygon, TriangulateEarcut};
use rand::rngs::Xoshiro256PlusPlus;
use rand::{RngExt, SeedableRng};

/// Why a shape could not be used.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
#[non_exhaustive]
pub enum ShapeError {
    /// The text is not GeoJSON.
    #[error("not valid GeoJSON: {0}")]
    GeoJson(String),
    /// The GeoJSON holds no polygon.
    #[error("the GeoJSON holds no Polygon or MultiPolygon geometry")]
    NoPolygon,
    /// The shape has no area to sample from.
    #[error("the shape has zero area")]
    ZeroArea,
}

/// Reads every Polygon and MultiPolygon in a GeoJSON text (a geometry, a feature or a
/// feature collection) into one multipolygon.
///
/// # Errors
/// [`ShapeError::GeoJson`] for malformed text, [`ShapeError::NoPolygon`] if there is no
/// polygon in it.
pub fn multipolygon_from_geojson(text: &str) -> Result<MultiPolygon<f64>, ShapeError> {
    let geojson: geojson::GeoJson = text
        .parse()
        .map_err(|e: geojson::Error| ShapeError::GeoJson(e.to_string()))?;
    let collection = geo::GeometryCollection::<f64>::try_from(&geojson)
        .map_err(|e| ShapeError::GeoJson(e.to_string()))?;
    let mut polygons = Vec::new();
    for geometry in collection {
        match geometry {
            geo::Geometry::Polygon(p) => polygons.push(p),
            geo::Geometry::MultiPolygon(mp) => polygons.extend(mp),
            _ => {}
        }
    }
    if polygons.is_empty() {
        return Err(ShapeError::NoPolygon);
    }
    Ok(MultiPolygon::new(polygons))
}

/// `n` points drawn uniformly inside `shape` (holes excluded), reproducibly from `seed`.
///
/// The shape is cut into triangles (earcut); each sample picks a triangle with probability
/// proportional to its area, then a uniform point in it.
///
/// # Errors
/// [`ShapeError::ZeroArea`] for a shape without area.
pub fn sample_uniform(
    shape: &MultiPolygon<f64>,
    n: usize,
    seed: u64,
) -> Result<Vec<[f64; 2]>, ShapeError> {
    let mut triangles = Vec::new();
    let mut cumulative = Vec::new();
    let mut total = 0.0;
    for polygon in shape {
        for t in polygon.earcut_triangles_iter() {
            let area = t.unsigned_area();
            if area > 0.0 {
                total += area;
                triangles.push([t.v1(), t.v2(), t.v3()]);
                cumulative.push(total);
            }
        }
    }
    if total.is_nan() || total <= 0.0 {
        return Err(ShapeError::ZeroArea);
    }
    let mut rng = Xoshiro256PlusPlus::seed_from_u64(seed);
    Ok((0..n)
        .map(|_| {
            let pick = rng.random::<f64>() * total;
            let k = cumulative
                .partition_point(|&c| c < pick)
                .min(triangles.len() - 1);
            let [a, b, c] = triangles[k];
            let (mut u, mut v): (f64, f64) = (rng.random(), rng.random());
            if u + v > 1.0 {
                (u, v) = (1.0 - u, 1.0 - v);
            }
            [
                a.x + u * (b.x - a.x) + v * (c.x - a.x),
                a.y + u * (b.y - a.y) + v * (c.y - a.y),
            ]
        })
        .collect())
}

/// The α of the 2D paper's benchmarks for `n` points sampled in `shape`: `2·√(area / n)`,
/// twice the mean point spacing.
pub fn paper_alpha(shape: &MultiPolygon<f64>, n: usize) -> f64 {
    2.0 * (shape.unsigned_area() / n as f64).sqrt()
}

/// The L² shape error of the 2D paper: area of the symmetric difference between `truth`
/// and `found`, divided by the area of `truth`.
pub fn l2_error(truth: &MultiPolygon<f64>, found: &MultiPolygon<f64>) -> f64 {
    let missed = truth.difference(found).unsigned_area();
    let extra = found.difference(truth).unsigned_area();
    (missed + extra) / truth.unsigned_area()
}

/// Area of a shape divided by the area of its convex hull (the 2D paper's convexity CV).
pub fn convexity(shape: &MultiPolygon<f64>) -> f64 {
    use geo::ConvexHull;
    shape.unsigned_area() / shape.convex_hull().unsigned_area()
}

/// The built-in demo shape: a 100 × 60 flower-like outline with two round holes and a
/// square one.
pub fn demo_shape() -> MultiPolygon<f64> {
    let (cx, cy) = (50.0, 30.0);
    let shell: LineString<f64> = (0..240)
        .map(|i| {
            let t = f64::from(i) / 240.0 * std::f64::consts::TAU;
            let r = 1.0 + 0.18 * (5.0 * t).sin();
            Coord {
                x: cx + 46.0 * r * t.cos(),
                y: cy + 27.0 * r * t.sin(),
            }
        })
        .collect();
    let circle = |x: f64, y: f64, r: f64| -> LineString<f64> {
        (0..48)
            .rev()
            .map(|i| {
                let t = f64::from(i) / 48.0 * std::f64::consts::TAU;
                Coord {
                    x: x + r * t.cos(),
                    y: y + r * t.sin(),
                }
            })
            .collect()
    };
    let square = LineString::from(vec![(62.0, 22.0), (62.0, 34.0), (74.0, 34.0), (74.0, 22.0)]);
    MultiPolygon::new(vec![Polygon::new(
        shell,
        vec![circle(28.0, 30.0, 7.0), circle(48.0, 40.0, 5.0), square],
    )])
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn samples_are_inside_and_reproducible() {
        use geo::Contains;
        let shape = demo_shape();
        let a = sample_uniform(&shape, 2000, 7).unwrap();
        assert_eq!(a, sample_uniform(&shape, 2000, 7).unwrap());
        assert!(
            a.iter()
                .all(|p| shape.contains(&geo::Point::new(p[0], p[1])))
        );
        // Uniformity: the share of samples in a hole-free box matches its area share.
        let in_box = a
            .iter()
            .filter(|p| (75.0..85.0).contains(&p[0]) && (25.0..35.0).contains(&p[1]))
            .count();
        let expected = 2000.0 * 100.0 / shape.unsigned_area();
        assert!(
            (in_box as f64 - expected).abs() < 4.0 * expected.sqrt(),
            "{in_box} vs {expected}"
        );
    }

    #[test]
    fn l2_error_of_a_shape_with_itself_is_zero() {
        let shape = demo_shape();
        // Boolean operations snap to a fixed grid, hence the tolerance.
        assert!(l2_error(&shape, &shape) < 1e-9);
        assert!((l2_error(&shape, &MultiPolygon::new(vec![])) - 1.0).abs() < 1e-9);
    }

    #[test]
    fn geojson_errors() {
        assert!(matches!(
            multipolygon_from_geojson("{"),
            Err(ShapeError::GeoJson(_))
        ));
        let point = r#"{"type": "Point", "coordinates": [1.0, 2.0]}"#;
        assert_eq!(multipolygon_from_geojson(point), Err(ShapeError::NoPolygon));
    }
}

//! GeoJSON output: one Feature per polygon.

use polylidar::Extraction;
use serde_json::{Value, json};

/// A GeoJSON FeatureCollection of the extraction's polygons. Rings are closed, shells
/// counter-clockwise and holes clockwise (RFC 7946); 3D input keeps its z.
pub fn feature_collection(extraction: &Extraction, with_z: bool) -> String {
    let ring = |points: &[[f64; 3]]| -> Value {
        let coord = |p: &[f64; 3]| {
            if with_z {
                json!([p[0], p[1], p[2]])
            } else {
                json!([p[0], p[1]])
            }
        };
        Value::Array(points.iter().chain(points.first()).map(coord).collect())
    };
    let features: Vec<Value> = extraction
        .polygons
        .iter()
        .enumerate()
        .map(|(i, polygon)| {
            let rings: Vec<Value> = std::iter::once(ring(&polygon.shell_points))
                .chain(polygon.hole_points.iter().map(|h| ring(h)))
                .collect();
            json!({
                "type": "Feature",
                "properties": {
                    "index": i,
                    "triangles": polygon.triangles.len(),
                    "shell_vertices": polygon.shell.len(),
                    "holes": polygon.holes.len(),
                },
                "geometry": { "type": "Polygon", "coordinates": rings },
            })
        })
        .collect();
    json!({ "type": "FeatureCollection", "features": features }).to_string()
}

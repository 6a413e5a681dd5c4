//! GeoJSON output: one Feature per polygon, with its plane and sizes as properties.

use polylidar::Extraction;
use serde_json::{Value, json};

/// A GeoJSON FeatureCollection of the extraction's polygons — the post-processed ones when
/// `processed`, else the extracted ones. Rings are closed; shells are counter-clockwise
/// and holes clockwise about the plane normal (RFC 7946 for 2D); 3D input keeps its z.
///
/// Properties: `index`, `normal`, `offset` (`normal · p + offset = 0`), `area` (shell minus
/// holes, in the plane), `triangles` and `points` (of the plane segment), `holes`; for
/// post-processed polygons also `source` (index of the extracted polygon).
pub fn feature_collection(extraction: &Extraction, with_z: bool, processed: bool) -> String {
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
    let feature = |properties: Value, shell: &[[f64; 3]], holes: &[Vec<[f64; 3]>]| {
        let rings: Vec<Value> = std::iter::once(ring(shell))
            .chain(holes.iter().map(|h| ring(h)))
            .collect();
        json!({
            "type": "Feature",
            "properties": properties,
            "geometry": { "type": "Polygon", "coordinates": rings },
        })
    };
    let points = vertex_counts(extraction);
    let features: Vec<Value> = if processed {
        extraction
            .postprocessed
            .iter()
            .enumerate()
            .map(|(i, p)| {
                let source = &extraction.polygons[p.source];
                let properties = json!({
                    "index": i,
                    "source": p.source,
                    "normal": source.plane.normal,
                    "offset": source.plane.offset,
                    "area": area(source.plane.normal, &p.shell, &p.holes),
                    "triangles": source.triangles.len(),
                    "points": points[p.source],
                    "holes": p.holes.len(),
                });
                feature(properties, &p.shell, &p.holes)
            })
            .collect()
    } else {
        extraction
            .polygons
            .iter()
            .enumerate()
            .map(|(i, p)| {
                let properties = json!({
                    "index": i,
                    "normal": p.plane.normal,
                    "offset": p.plane.offset,
                    "area": area(p.plane.normal, &p.shell_points, &p.hole_points),
                    "triangles": p.triangles.len(),
                    "points": points[i],
                    "holes": p.holes.len(),
                });
                feature(properties, &p.shell_points, &p.hole_points)
            })
            .collect()
    };
    json!({ "type": "FeatureCollection", "features": features }).to_string()
}

/// The number of distinct vertices of each polygon's triangles.
fn vertex_counts(extraction: &Extraction) -> Vec<usize> {
    let mut marks = vec![usize::MAX; extraction.mesh.num_vertices()];
    let triangles = extraction.mesh.triangles();
    extraction
        .polygons
        .iter()
        .enumerate()
        .map(|(index, polygon)| {
            let mut count = 0;
            for &t in &polygon.triangles {
                for v in triangles[t as usize] {
                    if marks[v as usize] != index {
                        marks[v as usize] = index;
                        count += 1;
                    }
                }
            }
            count
        })
        .collect()
}

/// Area of a planar ring about `normal` (Newell's vector area).
fn ring_area(normal: [f64; 3], ring: &[[f64; 3]]) -> f64 {
    let mut sum = [0.0; 3];
    for (i, a) in ring.iter().enumerate() {
        let b = ring[(i + 1) % ring.len()];
        sum[0] += a[1] * b[2] - a[2] * b[1];
        sum[1] += a[2] * b[0] - a[0] * b[2];
        sum[2] += a[0] * b[1] - a[1] * b[0];
    }
    0.5 * (normal[0] * sum[0] + normal[1] * sum[1] + normal[2] * sum[2]).abs()
}

/// Shell area minus hole areas.
fn area(normal: [f64; 3], shell: &[[f64; 3]], holes: &[Vec<[f64; 3]>]) -> f64 {
    ring_area(normal, shell) - holes.iter().map(|h| ring_area(normal, h)).sum::<f64>()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn area_of_a_tilted_square_with_a_hole() {
        // A 2 × 2 square in the plane x = z, with a 1 × 1 hole: area 4·√2 − √2.
        let s = std::f64::consts::FRAC_1_SQRT_2;
        let lift = |p: [f64; 2]| [p[0], p[1], p[0]];
        let shell: Vec<_> = [[0.0, 0.0], [2.0, 0.0], [2.0, 2.0], [0.0, 2.0]]
            .map(lift)
            .to_vec();
        let hole: Vec<_> = [[0.5, 0.5], [0.5, 1.5], [1.5, 1.5], [1.5, 0.5]]
            .map(lift)
            .to_vec();
        let got = area([-s, 0.0, s], &shell, &[hole]);
        assert!((got - 3.0 * 2f64.sqrt()).abs() < 1e-12, "{got}");
    }
}

//! Results as files and numbers: the GeoJSON writer shared by the command line and the
//! Python package, and polygon areas measured in the polygon's own plane.

use serde_json::{Value, json};

use crate::Extraction;

/// Which polygons of an [`Extraction`] to write.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum PolygonSet {
    /// [`Extraction::polygons`], as extracted.
    Extracted,
    /// [`Extraction::postprocessed`] (empty unless the config has a `postprocess`
    /// section).
    Postprocessed,
}

/// A GeoJSON FeatureCollection (RFC 7946) of the extraction's polygons, one Feature per
/// polygon. Rings are closed; shells are counter-clockwise and holes clockwise about the
/// plane normal; with `with_z` the coordinates keep their z (3D input), else they are
/// `[x, y]` (2D input).
///
/// Properties: `index`, `normal`, `offset` (`normal · p + offset = 0`), `area` (shell
/// minus holes, in the plane; [`polygon_area`]), `triangles` and `points` (of the plane
/// segment), `holes`; post-processed polygons also have `source` (index of the extracted
/// polygon they came from).
///
/// ```
/// use polylidar::{Config, Polylidar, output::{PolygonSet, feature_collection}};
/// let points: Vec<[f64; 2]> = (0..100).map(|i| [(i % 10) as f64, (i / 10) as f64]).collect();
/// let extraction = Polylidar::new(Config::new().with_lmax(1.5))?.extract_2d(&points)?;
/// let text = feature_collection(&extraction, false, PolygonSet::Extracted);
/// let value: serde_json::Value = serde_json::from_str(&text).unwrap();
/// let feature = &value["features"][0];
/// assert_eq!(feature["properties"]["area"], 81.0);
/// assert_eq!(feature["geometry"]["coordinates"][0].as_array().unwrap().len(), 37);
/// # Ok::<(), polylidar::PolylidarError>(())
/// ```
pub fn feature_collection(extraction: &Extraction, with_z: bool, set: PolygonSet) -> String {
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
    let features: Vec<Value> = match set {
        PolygonSet::Postprocessed => extraction
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
                    "area": polygon_area(source.plane.normal, &p.shell, &p.holes),
                    "triangles": source.triangles.len(),
                    "points": points[p.source],
                    "holes": p.holes.len(),
                });
                feature(properties, &p.shell, &p.holes)
            })
            .collect(),
        PolygonSet::Extracted => extraction
            .polygons
            .iter()
            .enumerate()
            .map(|(i, p)| {
                let properties = json!({
                    "index": i,
                    "normal": p.plane.normal,
                    "offset": p.plane.offset,
                    "area": polygon_area(p.plane.normal, &p.shell_points, &p.hole_points),
                    "triangles": p.triangles.len(),
                    "points": points[i],
                    "holes": p.holes.len(),
                });
                feature(properties, &p.shell_points, &p.hole_points)
            })
            .collect(),
    };
    json!({ "type": "FeatureCollection", "features": features }).to_string()
}

/// The number of distinct mesh vertices of each polygon's triangles (the points of its
/// plane segment), in the order of [`Extraction::polygons`].
///
/// ```
/// use polylidar::{Config, Polylidar, output::vertex_counts};
/// let points: Vec<[f64; 2]> = (0..100).map(|i| [(i % 10) as f64, (i / 10) as f64]).collect();
/// let extraction = Polylidar::new(Config::new().with_lmax(1.5))?.extract_2d(&points)?;
/// assert_eq!(vertex_counts(&extraction), vec![100]);
/// # Ok::<(), polylidar::PolylidarError>(())
/// ```
pub fn vertex_counts(extraction: &Extraction) -> Vec<usize> {
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

/// The area of a planar ring (open: the last point is not the first) about `normal`
/// (Newell's vector area projected on the unit normal). `0` for fewer than 3 points.
///
/// ```
/// use polylidar::output::ring_area;
/// let square = [[0.0, 0.0, 1.0], [2.0, 0.0, 1.0], [2.0, 2.0, 1.0], [0.0, 2.0, 1.0]];
/// assert_eq!(ring_area([0.0, 0.0, 1.0], &square), 4.0);
/// ```
pub fn ring_area(normal: [f64; 3], ring: &[[f64; 3]]) -> f64 {
    let mut sum = [0.0; 3];
    for (i, a) in ring.iter().enumerate() {
        let b = ring[(i + 1) % ring.len()];
        sum[0] += a[1] * b[2] - a[2] * b[1];
        sum[1] += a[2] * b[0] - a[0] * b[2];
        sum[2] += a[0] * b[1] - a[1] * b[0];
    }
    0.5 * (normal[0] * sum[0] + normal[1] * sum[1] + normal[2] * sum[2]).abs()
}

/// The area of a polygon in its plane: the shell's [`ring_area`] minus its holes'.
///
/// ```
/// use polylidar::output::polygon_area;
/// let shell = [[0.0, 0.0, 0.0], [4.0, 0.0, 0.0], [4.0, 4.0, 0.0], [0.0, 4.0, 0.0]];
/// let hole = vec![[1.0, 1.0, 0.0], [1.0, 2.0, 0.0], [2.0, 2.0, 0.0], [2.0, 1.0, 0.0]];
/// assert_eq!(polygon_area([0.0, 0.0, 1.0], &shell, &[hole]), 15.0);
/// ```
pub fn polygon_area(normal: [f64; 3], shell: &[[f64; 3]], holes: &[Vec<[f64; 3]>]) -> f64 {
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
        let got = polygon_area([-s, 0.0, s], &shell, &[hole]);
        assert!((got - 3.0 * 2f64.sqrt()).abs() < 1e-12, "{got}");
    }

    #[test]
    fn degenerate_rings_have_no_area() {
        assert_eq!(ring_area([0.0, 0.0, 1.0], &[]), 0.0);
        assert_eq!(ring_area([0.0, 0.0, 1.0], &[[1.0, 2.0, 3.0]]), 0.0);
    }
}

//! Results as files and numbers: the GeoJSON writer shared by the command line and the
//! Python package, and polygon areas measured in the polygon's own plane.

pub use geo::MultiPolygon;
use geo::{Coord, LineString, Polygon};
use serde::{Serialize, Serializer};

use crate::{ExtractedPolygon, Extraction};

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
    feature_collection_with(extraction, with_z, set, Annotations::default())
}

/// Optional members of [`feature_collection_with`]'s GeoJSON.
#[derive(Debug, Clone, Copy, Default)]
pub struct Annotations<'a> {
    /// A `frame` member of the FeatureCollection (a stream's frame name), after `type`.
    pub frame: Option<&'a str>,
    /// A `color` property (`[r, g, b]`) per polygon of [`Extraction::polygons`], in its
    /// order; a post-processed polygon takes its source's, `None` writes none.
    pub colors: Option<&'a [Option<[u8; 3]>]>,
}

/// [`feature_collection`] with the members of `annotations`.
///
/// ```
/// use polylidar::{Config, Polylidar, output::{Annotations, PolygonSet, feature_collection_with}};
/// let points: Vec<[f64; 2]> = (0..100).map(|i| [(i % 10) as f64, (i / 10) as f64]).collect();
/// let extraction = Polylidar::new(Config::new().with_lmax(1.5))?.extract_2d(&points)?;
/// let annotations = Annotations { frame: Some("f_000"), colors: Some(&[Some([200, 10, 10])]) };
/// let text = feature_collection_with(&extraction, false, PolygonSet::Extracted, annotations);
/// assert!(text.starts_with(r#"{"type":"FeatureCollection","frame":"f_000","features":"#));
/// assert!(text.contains(r#""holes":0,"color":[200,10,10]}"#));
/// # Ok::<(), polylidar::PolylidarError>(())
/// ```
pub fn feature_collection_with(
    extraction: &Extraction,
    with_z: bool,
    set: PolygonSet,
    annotations: Annotations<'_>,
) -> String {
    let color = |polygon: usize| {
        annotations
            .colors
            .and_then(|colors| colors.get(polygon).copied().flatten())
    };
    let points = vertex_counts(extraction);
    let features: Vec<Feature<'_>> = match set {
        PolygonSet::Postprocessed => extraction
            .postprocessed
            .iter()
            .enumerate()
            .map(|(i, p)| {
                let source = &extraction.polygons[p.source];
                Feature::new(
                    Properties {
                        index: i,
                        source: Some(p.source),
                        normal: source.plane.normal,
                        offset: source.plane.offset,
                        area: polygon_area(source.plane.normal, &p.shell, &p.holes),
                        triangles: source.triangles.len(),
                        points: points[p.source],
                        holes: p.holes.len(),
                        color: color(p.source),
                    },
                    Rings {
                        shell: &p.shell,
                        holes: &p.holes,
                        with_z,
                    },
                )
            })
            .collect(),
        PolygonSet::Extracted => extraction
            .polygons
            .iter()
            .enumerate()
            .map(|(i, p)| {
                Feature::new(
                    Properties {
                        index: i,
                        source: None,
                        normal: p.plane.normal,
                        offset: p.plane.offset,
                        area: polygon_area(p.plane.normal, &p.shell_points, &p.hole_points),
                        triangles: p.triangles.len(),
                        points: points[i],
                        holes: p.holes.len(),
                        color: color(i),
                    },
                    Rings {
                        shell: &p.shell_points,
                        holes: &p.hole_points,
                        with_z,
                    },
                )
            })
            .collect(),
    };
    let collection = Collection {
        kind: "FeatureCollection",
        frame: annotations.frame,
        features,
    };
    // Serializing plain structs and slices into a String cannot fail: every map key is a
    // string and every number is written (a non-finite one as `null`).
    serde_json::to_string(&collection).unwrap_or_default()
}

/// The FeatureCollection as written: typed and borrowed, so that the coordinates go
/// straight from the polygons into the text (a `serde_json::Value` tree would allocate a
/// node per number).
#[derive(Serialize)]
struct Collection<'a> {
    #[serde(rename = "type")]
    kind: &'static str,
    #[serde(skip_serializing_if = "Option::is_none")]
    frame: Option<&'a str>,
    features: Vec<Feature<'a>>,
}

#[derive(Serialize)]
struct Feature<'a> {
    #[serde(rename = "type")]
    kind: &'static str,
    properties: Properties,
    geometry: Geometry<'a>,
}

impl<'a> Feature<'a> {
    fn new(properties: Properties, coordinates: Rings<'a>) -> Self {
        Self {
            kind: "Feature",
            properties,
            geometry: Geometry {
                kind: "Polygon",
                coordinates,
            },
        }
    }
}

#[derive(Serialize)]
struct Properties {
    index: usize,
    #[serde(skip_serializing_if = "Option::is_none")]
    source: Option<usize>,
    normal: [f64; 3],
    offset: f64,
    area: f64,
    triangles: usize,
    points: usize,
    holes: usize,
    #[serde(skip_serializing_if = "Option::is_none")]
    color: Option<[u8; 3]>,
}

#[derive(Serialize)]
struct Geometry<'a> {
    #[serde(rename = "type")]
    kind: &'static str,
    coordinates: Rings<'a>,
}

/// A polygon's rings as GeoJSON coordinates: the shell, then the holes, each closed by
/// repeating its first point.
struct Rings<'a> {
    shell: &'a [[f64; 3]],
    holes: &'a [Vec<[f64; 3]>],
    with_z: bool,
}

/// One open ring, written closed.
struct Ring<'a> {
    points: &'a [[f64; 3]],
    with_z: bool,
}

impl Serialize for Rings<'_> {
    fn serialize<S: Serializer>(&self, serializer: S) -> Result<S::Ok, S::Error> {
        let ring = |points| Ring {
            points,
            with_z: self.with_z,
        };
        serializer.collect_seq(
            std::iter::once(self.shell)
                .chain(self.holes.iter().map(Vec::as_slice))
                .map(ring),
        )
    }
}

impl Serialize for Ring<'_> {
    fn serialize<S: Serializer>(&self, serializer: S) -> Result<S::Ok, S::Error> {
        let closed = self.points.iter().chain(self.points.first());
        if self.with_z {
            serializer.collect_seq(closed)
        } else {
            serializer.collect_seq(closed.map(|p| [p[0], p[1]]))
        }
    }
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

/// The extracted polygons as a geo multipolygon in the xy plane.
pub fn to_multipolygon(polygons: &[ExtractedPolygon]) -> MultiPolygon<f64> {
    let ring = |points: &[[f64; 3]]| -> LineString<f64> {
        points.iter().map(|p| Coord { x: p[0], y: p[1] }).collect()
    };
    polygons
        .iter()
        .map(|p| {
            Polygon::new(
                ring(&p.shell_points),
                p.hole_points.iter().map(|h| ring(h)).collect(),
            )
        })
        .collect()
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

    /// The typed writer against a `serde_json::Value` tree built member by member.
    #[test]
    fn geojson_matches_a_value_tree() {
        use crate::{Config, Polylidar};
        use serde_json::{Value, json};
        // A 12 × 12 grid with a 4 × 4 hole in it: one polygon with one hole.
        let points: Vec<[f64; 2]> = (0..144)
            .map(|i| [f64::from(i % 12) * 0.5, f64::from(i / 12) * 0.25])
            .filter(|p| !(1.6..3.4).contains(&p[0]) || !(0.8..1.7).contains(&p[1]))
            .collect();
        let extraction = Polylidar::new(Config::new().with_lmax(0.6))
            .unwrap()
            .extract_2d(&points)
            .unwrap();
        assert_eq!(extraction.polygons[0].hole_points.len(), 1);
        let colors = [Some([1, 2, 3])];
        let annotations = Annotations {
            frame: Some("frame 7"),
            colors: Some(&colors),
        };
        for with_z in [false, true] {
            let ring = |ring: &[[f64; 3]]| -> Value {
                let closed = ring.iter().chain(ring.first());
                let coords: Vec<Value> = closed
                    .map(|p| match with_z {
                        true => json!(p),
                        false => json!([p[0], p[1]]),
                    })
                    .collect();
                Value::Array(coords)
            };
            let counts = vertex_counts(&extraction);
            let features: Vec<Value> = extraction
                .polygons
                .iter()
                .enumerate()
                .map(|(i, p)| {
                    let mut rings = vec![ring(&p.shell_points)];
                    rings.extend(p.hole_points.iter().map(|h| ring(h)));
                    json!({
                        "type": "Feature",
                        "properties": {
                            "index": i,
                            "normal": p.plane.normal,
                            "offset": p.plane.offset,
                            "area": polygon_area(p.plane.normal, &p.shell_points, &p.hole_points),
                            "triangles": p.triangles.len(),
                            "points": counts[i],
                            "holes": p.holes.len(),
                            "color": [1, 2, 3],
                        },
                        "geometry": { "type": "Polygon", "coordinates": rings },
                    })
                })
                .collect();
            let expected =
                json!({ "type": "FeatureCollection", "frame": "frame 7", "features": features });
            let text =
                feature_collection_with(&extraction, with_z, PolygonSet::Extracted, annotations);
            assert_eq!(text, expected.to_string(), "with_z {with_z}");
        }
    }

    #[test]
    fn degenerate_rings_have_no_area() {
        assert_eq!(ring_area([0.0, 0.0, 1.0], &[]), 0.0);
        assert_eq!(ring_area([0.0, 0.0, 1.0], &[[1.0, 2.0, 3.0]]), 0.0);
    }
}

//! Tile sets as bytes (to pass between processes: the Dask front's tasks), polygons as WKB
//! (GeoPandas, Shapely, GDAL) and tile sets as GeoJSON.
//!
//! The byte form keeps every coordinate bit for bit, so that pieces merged in another
//! process still meet exactly along their seams.

use geo::{Coord, LineString, Polygon};
use serde_json::{Value, json};

use super::{TileError, TileGrid, TileId, TilePolygon, TileSet};

/// The first bytes of an encoded [`TileSet`] (with its format version).
const MAGIC: &[u8; 8] = b"PLTILES1";

impl TileSet {
    /// The tile set as bytes, for [`Self::from_bytes`] (little-endian, coordinates exact).
    ///
    /// ```
    /// use polylidar::tiles::{TileGrid, TileId, TileSet};
    /// let grid = TileGrid::new([0.0, 0.0], 10.0, 1.0, 2, 2)?;
    /// let set = TileSet { grid, cover: vec![TileId { col: 1, row: 0 }], polygons: vec![] };
    /// assert_eq!(TileSet::from_bytes(&set.to_bytes())?, set);
    /// # Ok::<(), polylidar::tiles::TileError>(())
    /// ```
    pub fn to_bytes(&self) -> Vec<u8> {
        let mut out = Vec::new();
        out.extend_from_slice(MAGIC);
        let g = &self.grid;
        for v in [g.origin[0], g.origin[1], g.size, g.margin] {
            out.extend_from_slice(&v.to_le_bytes());
        }
        for v in [g.cols, g.rows] {
            out.extend_from_slice(&v.to_le_bytes());
        }
        put_tiles(&mut out, &self.cover);
        put_len(&mut out, self.polygons.len());
        for p in &self.polygons {
            for v in p.normal.iter().chain([&p.offset, &p.area]) {
                out.extend_from_slice(&v.to_le_bytes());
            }
            put_tiles(&mut out, &p.tiles);
            let rings: Vec<&LineString<f64>> = std::iter::once(p.footprint.exterior())
                .chain(p.footprint.interiors())
                .collect();
            put_len(&mut out, rings.len());
            for ring in rings {
                put_len(&mut out, ring.0.len());
                for c in ring.coords() {
                    out.extend_from_slice(&c.x.to_le_bytes());
                    out.extend_from_slice(&c.y.to_le_bytes());
                }
            }
        }
        out
    }

    /// The tile set [`Self::to_bytes`] encoded.
    ///
    /// # Errors
    /// [`TileError::Decode`] for bytes that are not one (wrong magic, truncated, counts
    /// beyond the data, an invalid grid).
    pub fn from_bytes(bytes: &[u8]) -> Result<Self, TileError> {
        let mut r = Reader { bytes, at: 0 };
        if r.take(MAGIC.len())? != MAGIC {
            return Err(TileError::Decode("it does not start with PLTILES1".into()));
        }
        let (x0, y0, size, margin) = (r.f64()?, r.f64()?, r.f64()?, r.f64()?);
        let (cols, rows) = (r.u32()?, r.u32()?);
        let grid = TileGrid::new([x0, y0], size, margin, cols, rows)
            .map_err(|e| TileError::Decode(e.to_string()))?;
        let cover = r.tiles()?;
        let n = r.len(8 * 5)?;
        let mut polygons = Vec::with_capacity(n);
        for _ in 0..n {
            let normal = [r.f64()?, r.f64()?, r.f64()?];
            let (offset, area) = (r.f64()?, r.f64()?);
            let tiles = r.tiles()?;
            let n_rings = r.len(4)?;
            let mut rings = Vec::with_capacity(n_rings);
            for _ in 0..n_rings {
                let n_coords = r.len(16)?;
                let mut coords = Vec::with_capacity(n_coords);
                for _ in 0..n_coords {
                    coords.push(Coord {
                        x: r.f64()?,
                        y: r.f64()?,
                    });
                }
                rings.push(LineString::new(coords));
            }
            let mut rings = rings.into_iter();
            let exterior = rings
                .next()
                .ok_or_else(|| TileError::Decode("a polygon without a shell".into()))?;
            polygons.push(TilePolygon {
                footprint: Polygon::new(exterior, rings.collect()),
                normal,
                offset,
                area,
                tiles,
            });
        }
        if r.at != bytes.len() {
            return Err(TileError::Decode(format!(
                "{} bytes after the end",
                bytes.len() - r.at
            )));
        }
        Ok(Self {
            grid,
            cover,
            polygons,
        })
    }

    /// The polygons as a GeoJSON FeatureCollection (RFC 7946 layout; coordinates in the
    /// cloud's own units and system): closed rings, with `z` on the plane when `with_z`.
    /// Properties: `index`, `normal`, `offset` (`normal · p + offset = 0`), `area` (of
    /// the footprint), `tiles` (`[col, row]` pairs).
    ///
    /// ```
    /// use polylidar::tiles::{TileGrid, TileSet};
    /// let grid = TileGrid::new([0.0, 0.0], 10.0, 1.0, 1, 1)?;
    /// let text = TileSet { grid, cover: vec![], polygons: vec![] }.to_geojson(true);
    /// assert!(text.contains("FeatureCollection"));
    /// # Ok::<(), polylidar::tiles::TileError>(())
    /// ```
    pub fn to_geojson(&self, with_z: bool) -> String {
        let features: Vec<Value> = self
            .polygons
            .iter()
            .enumerate()
            .map(|(index, p)| {
                let (shell, holes) = p.rings_3d();
                let ring = |r: &[[f64; 3]]| -> Value {
                    r.iter()
                        .map(|c| {
                            if with_z {
                                json!(c)
                            } else {
                                json!([c[0], c[1]])
                            }
                        })
                        .collect()
                };
                let rings: Vec<Value> = std::iter::once(ring(&shell))
                    .chain(holes.iter().map(|h| ring(h)))
                    .collect();
                let tiles: Vec<[u32; 2]> = p.tiles.iter().map(|t| [t.col, t.row]).collect();
                json!({
                    "type": "Feature",
                    "geometry": {"type": "Polygon", "coordinates": rings},
                    "properties": {
                        "index": index,
                        "normal": p.normal,
                        "offset": p.offset,
                        "area": p.area,
                        "tiles": tiles,
                    },
                })
            })
            .collect();
        json!({"type": "FeatureCollection", "features": features}).to_string()
    }
}

impl TilePolygon {
    /// The footprint as ISO WKB (little-endian): a `Polygon` in xy, or with `with_z` a
    /// `Polygon Z` (type 1003) with the rings lifted onto the plane. GeoPandas reads it
    /// with `geopandas.GeoSeries.from_wkb`.
    ///
    /// ```
    /// use geo::{Polygon, LineString};
    /// use polylidar::tiles::TilePolygon;
    /// let square = LineString::from(vec![(0.0, 0.0), (1.0, 0.0), (1.0, 1.0), (0.0, 1.0), (0.0, 0.0)]);
    /// let p = TilePolygon {
    ///     footprint: Polygon::new(square, vec![]),
    ///     normal: [0.0, 0.0, 1.0], offset: -2.0, area: 1.0, tiles: vec![],
    /// };
    /// let wkb = p.to_wkb(false);
    /// assert_eq!(wkb.len(), 1 + 4 + 4 + 4 + 5 * 16);
    /// assert_eq!(p.to_wkb(true).len(), 1 + 4 + 4 + 4 + 5 * 24);
    /// ```
    pub fn to_wkb(&self, with_z: bool) -> Vec<u8> {
        let (shell, holes) = self.rings_3d();
        let mut out = vec![1u8];
        out.extend_from_slice(&(if with_z { 1003u32 } else { 3u32 }).to_le_bytes());
        put_u32(&mut out, 1 + holes.len());
        for ring in std::iter::once(&shell).chain(&holes) {
            put_u32(&mut out, ring.len());
            for c in ring {
                let n = if with_z { 3 } else { 2 };
                for v in &c[..n] {
                    out.extend_from_slice(&v.to_le_bytes());
                }
            }
        }
        out
    }
}

/// Writes a count as a little-endian `u32` (counts of rings and coordinates of one
/// polygon, and tiles of a grid, are below 2³²: a grid has at most 2⁴⁰ tiles, a polygon
/// is built from the `u32`-indexed points of one window).
fn put_u32(out: &mut Vec<u8>, n: usize) {
    out.extend_from_slice(&u32::try_from(n).unwrap_or(u32::MAX).to_le_bytes());
}

fn put_len(out: &mut Vec<u8>, n: usize) {
    out.extend_from_slice(&(n as u64).to_le_bytes());
}

fn put_tiles(out: &mut Vec<u8>, tiles: &[TileId]) {
    put_len(out, tiles.len());
    for t in tiles {
        out.extend_from_slice(&t.col.to_le_bytes());
        out.extend_from_slice(&t.row.to_le_bytes());
    }
}

struct Reader<'a> {
    bytes: &'a [u8],
    at: usize,
}

impl Reader<'_> {
    fn take(&mut self, n: usize) -> Result<&[u8], TileError> {
        let end = self
            .at
            .checked_add(n)
            .filter(|&e| e <= self.bytes.len())
            .ok_or_else(|| TileError::Decode(format!("truncated at byte {}", self.at)))?;
        let slice = &self.bytes[self.at..end];
        self.at = end;
        Ok(slice)
    }

    fn f64(&mut self) -> Result<f64, TileError> {
        let b = self.take(8)?;
        Ok(f64::from_le_bytes(b.try_into().unwrap_or([0; 8])))
    }

    fn u32(&mut self) -> Result<u32, TileError> {
        let b = self.take(4)?;
        Ok(u32::from_le_bytes(b.try_into().unwrap_or([0; 4])))
    }

    /// A count of items of at least `item_bytes` each: no more than the bytes left hold.
    fn len(&mut self, item_bytes: usize) -> Result<usize, TileError> {
        let b = self.take(8)?;
        let n = u64::from_le_bytes(b.try_into().unwrap_or([0; 8]));
        let left = (self.bytes.len() - self.at) as u64;
        if n.saturating_mul(item_bytes as u64) > left {
            return Err(TileError::Decode(format!(
                "a count of {n} at byte {} is beyond the data",
                self.at - 8
            )));
        }
        Ok(n as usize)
    }

    fn tiles(&mut self) -> Result<Vec<TileId>, TileError> {
        let n = self.len(8)?;
        (0..n)
            .map(|_| {
                Ok(TileId {
                    col: self.u32()?,
                    row: self.u32()?,
                })
            })
            .collect()
    }
}

//! Clouds too large for one run, in square tiles with seams handled.
//!
//! An unorganized cloud seen from above (airborne LiDAR, a robot fleet's map) is split into
//! square tiles on a regular grid in xy ([`TileGrid`]). Each tile is extracted on its
//! *window* — its *core* square grown by an overlap margin — with the 2.5D pipeline
//! ([`Polylidar::extract_25d`]), or with the unorganized 3D path when the configuration
//! asks for it (the `aerial` preset: pitched roofs too), so that the triangles near the
//! core's edges are those a run on the whole cloud would build. Each polygon is then clipped to the tile's core
//! ([`extract_tile`]): the overlap produces no duplicates, and the pieces of one surface
//! cut by a seam meet exactly along the seam line.
//!
//! [`merge`] joins the tiles' results: two pieces from different inputs are one polygon
//! when they share a stretch of a seam line of positive length and their planes agree
//! within a [`MergeTolerance`] (normal angle, and height difference at the seam). Their
//! footprints are united with `geo`'s boolean operations, so holes (a courtyard on a seam)
//! are kept and the results are valid polygons. Merging is associative: tiles can be
//! merged in any tree (the Dask front merges in a tree of tasks) with the same result.
//!
//! The merged polygons are the extraction's raw polygons (before post-processing) in xy, each with the plane of its triangles; [`TilePolygon::rings_3d`] lifts them onto it.
//! A region smaller than `min_triangles` within one window is dropped even when it
//! continues in the next tile; with a margin of a few `lmax` this only touches regions
//! close to the size limit.
//!
//! ```
//! use polylidar::tiles::{MergeTolerance, TileGrid, extract_tiled};
//! use polylidar::{Config, Polylidar};
//!
//! // A flat 30 × 30 roof on a grid of spacing 0.5, cut by the seams of 2 × 2 tiles.
//! let points: Vec<[f64; 3]> = (0..61 * 61)
//!     .map(|i| [0.5 * (i % 61) as f64, 0.5 * (i / 61) as f64, 10.0])
//!     .collect();
//! let polylidar = Polylidar::new(Config::new().with_lmax(1.0).with_min_triangles(10))?;
//! let grid = TileGrid::new([0.0, 0.0], 16.0, 2.0, 2, 2)?;
//! let tolerance = MergeTolerance::for_config(polylidar.config());
//! let merged = extract_tiled(&polylidar, &grid, &points, &tolerance)?;
//! assert_eq!(merged.polygons.len(), 1);
//! assert!((merged.polygons[0].area - 900.0).abs() < 1e-6);
//! assert_eq!(merged.polygons[0].tiles.len(), 4);
//! # Ok::<(), polylidar::tiles::TileError>(())
//! ```

use std::collections::HashMap;
use std::fmt;

use geo::{Area, BooleanOps, Centroid, Coord, LineString, MultiPolygon, Polygon, Rect};
use rstar::primitives::{GeomWithData, Rectangle};
use rstar::{AABB, RTree};

use crate::{Config, Polylidar, PolylidarError};

mod codec;

/// On the unorganized 3D path, planes steeper than this (walls, façades: slivers seen
/// from above) are left out of a tile's polygons, degrees from horizontal.
pub const MAX_SLOPE_DEG: f64 = 70.0;

/// At most this many tiles along one axis of a [`TileGrid`].
pub const MAX_TILES_PER_AXIS: u32 = 1 << 20;

/// Errors of tiling, tile extraction and merging.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum TileError {
    /// A grid parameter is out of range, or a tile is not on the grid.
    #[error("invalid tile grid: {0}")]
    Grid(String),
    /// The pipeline failed on a tile.
    #[error("tile {tile}: {source}")]
    Extract {
        /// The tile.
        tile: TileId,
        /// The pipeline's error.
        #[source]
        source: PolylidarError,
    },
    /// The inputs of a merge do not fit together (other grids, a tile in two inputs).
    #[error("cannot merge: {0}")]
    Merge(String),
    /// Bytes that are not an encoded [`TileSet`].
    #[error("not an encoded tile set: {0}")]
    Decode(String),
    /// Reading an input file failed.
    #[error(transparent)]
    Polylidar(#[from] PolylidarError),
}

/// A tile of a [`TileGrid`]: column (along x) and row (along y), from the grid's origin.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub struct TileId {
    /// Column, along x.
    pub col: u32,
    /// Row, along y.
    pub row: u32,
}

impl fmt::Display for TileId {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "({}, {})", self.col, self.row)
    }
}

/// Square tiles in xy: tile `(col, row)` has the core `[x0 + col·size, x0 + (col+1)·size)
/// × [y0 + row·size, y0 + (row+1)·size)` and the window of that core grown by `margin` on
/// every side. Lengths are in the units of the cloud.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct TileGrid {
    /// The lower-left corner `[x0, y0]` of tile `(0, 0)`.
    pub origin: [f64; 2],
    /// The side of a tile's core square.
    pub size: f64,
    /// The overlap margin around each core: a few `lmax` (the longest kept triangle edge)
    /// is enough for the triangles along the core's edges to be the whole cloud's.
    pub margin: f64,
    /// Tiles along x.
    pub cols: u32,
    /// Tiles along y.
    pub rows: u32,
}

impl TileGrid {
    /// A grid of `cols × rows` tiles of side `size` from `origin`, windows grown by
    /// `margin`.
    ///
    /// # Errors
    /// [`TileError::Grid`] for a non-finite origin, a size that is not positive and
    /// finite, a negative or non-finite margin, or no tiles (or more than
    /// [`MAX_TILES_PER_AXIS`] along an axis).
    pub fn new(
        origin: [f64; 2],
        size: f64,
        margin: f64,
        cols: u32,
        rows: u32,
    ) -> Result<Self, TileError> {
        if !origin.iter().all(|c| c.is_finite()) {
            return Err(TileError::Grid(format!("origin {origin:?} is not finite")));
        }
        if !(size.is_finite() && size > 0.0) {
            return Err(TileError::Grid(format!("size {size} is not positive")));
        }
        if !(margin.is_finite() && margin >= 0.0) {
            return Err(TileError::Grid(format!("margin {margin} is negative")));
        }
        if cols == 0 || rows == 0 || cols > MAX_TILES_PER_AXIS || rows > MAX_TILES_PER_AXIS {
            return Err(TileError::Grid(format!(
                "{cols} × {rows} tiles (1 to {MAX_TILES_PER_AXIS} a side)"
            )));
        }
        Ok(Self {
            origin,
            size,
            margin,
            cols,
            rows,
        })
    }

    /// The grid of tiles of side `size` from `min` that covers the box `min`–`max`: every
    /// point of the box is in one tile's core.
    ///
    /// ```
    /// use polylidar::tiles::TileGrid;
    /// let grid = TileGrid::covering([0.0, 0.0], [100.0, 40.0], 50.0, 5.0)?;
    /// assert_eq!((grid.cols, grid.rows), (3, 1));
    /// # Ok::<(), polylidar::tiles::TileError>(())
    /// ```
    ///
    /// # Errors
    /// As [`Self::new`]; also when `max` is below `min` or the box needs more than
    /// [`MAX_TILES_PER_AXIS`] tiles a side.
    pub fn covering(
        min: [f64; 2],
        max: [f64; 2],
        size: f64,
        margin: f64,
    ) -> Result<Self, TileError> {
        let count = |k: usize| -> Result<u32, TileError> {
            let n = ((max[k] - min[k]) / size).floor() + 1.0;
            if !(n.is_finite() && n >= 1.0 && n <= f64::from(MAX_TILES_PER_AXIS)) {
                return Err(TileError::Grid(format!(
                    "the box {min:?}–{max:?} in tiles of {size}"
                )));
            }
            Ok(n as u32)
        };
        if !(size.is_finite() && size > 0.0) {
            return Err(TileError::Grid(format!("size {size} is not positive")));
        }
        Self::new(min, size, margin, count(0)?, count(1)?)
    }

    /// The grid of [`Self::covering`] for the finite points of `points`.
    ///
    /// # Errors
    /// [`TileError::Grid`] when no point is finite, else as [`Self::covering`].
    pub fn covering_points(points: &[[f64; 3]], size: f64, margin: f64) -> Result<Self, TileError> {
        let (mut lo, mut hi) = ([f64::INFINITY; 2], [f64::NEG_INFINITY; 2]);
        for p in points.iter().filter(|p| p.iter().all(|c| c.is_finite())) {
            for k in 0..2 {
                lo[k] = lo[k].min(p[k]);
                hi[k] = hi[k].max(p[k]);
            }
        }
        if lo[0] > hi[0] {
            return Err(TileError::Grid("no finite point to tile".into()));
        }
        Self::covering(lo, hi, size, margin)
    }

    /// The number of tiles.
    pub fn len(&self) -> usize {
        self.cols as usize * self.rows as usize
    }

    /// Always `false`: a grid has at least one tile.
    pub fn is_empty(&self) -> bool {
        false
    }

    /// Every tile, row by row.
    pub fn tiles(&self) -> impl Iterator<Item = TileId> + '_ {
        (0..self.rows).flat_map(move |row| (0..self.cols).map(move |col| TileId { col, row }))
    }

    /// The position of `tile` in [`Self::tiles`].
    ///
    /// # Errors
    /// [`TileError::Grid`] for a tile off the grid.
    pub fn index(&self, tile: TileId) -> Result<usize, TileError> {
        if tile.col >= self.cols || tile.row >= self.rows {
            return Err(TileError::Grid(format!(
                "tile {tile} is off the {} × {} grid",
                self.cols, self.rows
            )));
        }
        Ok(tile.row as usize * self.cols as usize + tile.col as usize)
    }

    /// The x of vertical grid line `k` (`k = 0` through the origin).
    fn x_line(&self, k: i64) -> f64 {
        self.origin[0] + k as f64 * self.size
    }

    /// The y of horizontal grid line `k`.
    fn y_line(&self, k: i64) -> f64 {
        self.origin[1] + k as f64 * self.size
    }

    /// The core square of `tile`.
    pub fn core(&self, tile: TileId) -> Rect<f64> {
        let (c, r) = (i64::from(tile.col), i64::from(tile.row));
        Rect::new(
            Coord {
                x: self.x_line(c),
                y: self.y_line(r),
            },
            Coord {
                x: self.x_line(c + 1),
                y: self.y_line(r + 1),
            },
        )
    }

    /// The window of `tile`: its core grown by the margin on every side.
    pub fn window(&self, tile: TileId) -> Rect<f64> {
        let core = self.core(tile);
        let m = self.margin;
        Rect::new(
            Coord {
                x: core.min().x - m,
                y: core.min().y - m,
            },
            Coord {
                x: core.max().x + m,
                y: core.max().y + m,
            },
        )
    }

    /// The tiles whose (closed) window holds the point `[x, y]`: one to four when the
    /// margin is below half the size.
    pub fn windows_of(&self, x: f64, y: f64) -> impl Iterator<Item = TileId> + '_ {
        let span = |v: f64, o: f64, n: u32| {
            let lo = ((v - self.margin - o) / self.size).floor().max(0.0);
            let hi = ((v + self.margin - o) / self.size)
                .floor()
                .min(f64::from(n) - 1.0);
            if lo.is_finite() && hi.is_finite() && lo <= hi {
                lo as u32..hi as u32 + 1
            } else {
                0..0
            }
        };
        let cols = span(x, self.origin[0], self.cols);
        let rows = span(y, self.origin[1], self.rows);
        rows.flat_map(move |row| cols.clone().map(move |col| TileId { col, row }))
            .filter(move |&t| {
                let w = self.window(t);
                (w.min().x..=w.max().x).contains(&x) && (w.min().y..=w.max().y).contains(&y)
            })
    }

    /// The points of each tile's window, in the order of [`Self::tiles`]; a point in the
    /// overlap of several windows is in each, a point with a non-finite coordinate in none.
    pub fn split(&self, points: &[[f64; 3]]) -> Vec<Vec<[f64; 3]>> {
        let mut tiles = vec![Vec::new(); self.len()];
        for p in points.iter().filter(|p| p.iter().all(|c| c.is_finite())) {
            for t in self.windows_of(p[0], p[1]) {
                tiles[t.row as usize * self.cols as usize + t.col as usize].push(*p);
            }
        }
        tiles
    }

    /// `c` with every coordinate within `eps` of a grid line moved onto the line. A boolean
    /// operation rounds to its own integer grid (about a billionth of its extent), so
    /// after one the coordinates of a seam are snapped back onto it with `eps` a hundred
    /// times that: the pieces of one surface on both sides of a seam then share the seam's
    /// coordinates exactly.
    fn snap(&self, c: Coord<f64>, eps: f64) -> Coord<f64> {
        let onto = |v: f64, o: f64, line: &dyn Fn(i64) -> f64| {
            let k = ((v - o) / self.size).round();
            if !k.is_finite() {
                return v;
            }
            let l = line(k as i64);
            if (v - l).abs() <= eps { l } else { v }
        };
        Coord {
            x: onto(c.x, self.origin[0], &|k| self.x_line(k)),
            y: onto(c.y, self.origin[1], &|k| self.y_line(k)),
        }
    }

    /// The holes of a piece with exterior `exterior` that a union with the pieces across
    /// its seams may change (first), and those it cannot (second): a hole is set apart when
    /// its bounding box, grown by a margin well above the unions' rounding, reaches no grid
    /// line, no exterior edge's box and no box of a hole that goes through the union (the
    /// union rounds the rings it handles, which must not move onto a ring left out of it).
    fn holes_near_seams(
        &self,
        exterior: &LineString<f64>,
        holes: Vec<LineString<f64>>,
    ) -> (Vec<LineString<f64>>, Vec<LineString<f64>>) {
        let margin = 1e-6 * self.size;
        let grown = |r: Rect<f64>| {
            Rect::new(
                Coord {
                    x: r.min().x - margin,
                    y: r.min().y - margin,
                },
                Coord {
                    x: r.max().x + margin,
                    y: r.max().y + margin,
                },
            )
        };
        let boxes: Vec<Option<Rect<f64>>> = holes
            .iter()
            .map(|h| geo::BoundingRect::bounding_rect(h).map(grown))
            .collect();
        let envelope =
            |r: &Rect<f64>| AABB::from_corners([r.min().x, r.min().y], [r.max().x, r.max().y]);
        let tree = RTree::bulk_load(
            boxes
                .iter()
                .enumerate()
                .filter_map(|(i, b)| {
                    b.map(|b| GeomWithData::new(Rectangle::from_aabb(envelope(&b)), i))
                })
                .collect(),
        );
        // Near: a hole without a box or reaching a grid line, a hole whose box overlaps an
        // exterior edge's box, and then every hole whose box overlaps a near hole's box
        // (the union rounds those too): a flood through the boxes' R-tree.
        let mut near: Vec<bool> = boxes
            .iter()
            .map(|b| b.is_none_or(|b| self.reaches_a_line(&b)))
            .collect();
        let mut flood: Vec<usize> = (0..holes.len()).filter(|&i| near[i]).collect();
        let touch = |r: &Rect<f64>, near: &mut [bool], flood: &mut Vec<usize>| {
            for hit in tree.locate_in_envelope_intersecting(&envelope(r)) {
                if !near[hit.data] {
                    near[hit.data] = true;
                    flood.push(hit.data);
                }
            }
        };
        for edge in exterior.lines() {
            touch(&Rect::new(edge.start, edge.end), &mut near, &mut flood);
        }
        while let Some(i) = flood.pop() {
            if let Some(b) = boxes[i] {
                touch(&b, &mut near, &mut flood);
            }
        }
        let (mut inside, mut apart) = (Vec::new(), Vec::new());
        for (hole, near) in holes.into_iter().zip(near) {
            if near {
                inside.push(hole)
            } else {
                apart.push(hole)
            }
        }
        (inside, apart)
    }

    /// Whether `r` reaches a grid line.
    fn reaches_a_line(&self, r: &Rect<f64>) -> bool {
        let crosses = |lo: f64, hi: f64, origin: f64| {
            ((lo - origin) / self.size).ceil() <= ((hi - origin) / self.size).floor()
        };
        crosses(r.min().x, r.max().x, self.origin[0])
            || crosses(r.min().y, r.max().y, self.origin[1])
    }

    /// The parts of the result of a boolean operation, snapped onto the grid lines (see
    /// [`Self::snap`]) with a distance of 10⁻⁷ of the result's extent.
    fn snap_parts(&self, parts: MultiPolygon<f64>) -> Vec<Polygon<f64>> {
        let eps = geo::BoundingRect::bounding_rect(&parts)
            .map_or(0.0, |r| 1e-7 * (r.width() + r.height()));
        parts
            .into_iter()
            .map(|p| self.snap_polygon(p, eps))
            .collect()
    }

    fn snap_polygon(&self, polygon: Polygon<f64>, eps: f64) -> Polygon<f64> {
        let ring = |r: &LineString<f64>| -> LineString<f64> {
            let mut coords: Vec<Coord<f64>> = Vec::with_capacity(r.0.len());
            for c in r.coords().map(|&c| self.snap(c, eps)) {
                if coords.last() != Some(&c) {
                    coords.push(c);
                }
            }
            LineString::new(coords)
        };
        let (exterior, interiors) = polygon.into_inner();
        Polygon::new(ring(&exterior), interiors.iter().map(ring).collect())
    }
}

/// A polygon of a tiled extraction: its footprint in xy and the plane it lies on.
#[derive(Debug, Clone, PartialEq)]
pub struct TilePolygon {
    /// The footprint in xy (a valid polygon; holes kept).
    pub footprint: Polygon<f64>,
    /// The unit normal of the plane (`normal[2] > 0`): the area-weighted mean normal of
    /// its triangles, over the pieces merged into it.
    pub normal: [f64; 3],
    /// The offset `d` of the plane `normal · p + d = 0`.
    pub offset: f64,
    /// The footprint's area.
    pub area: f64,
    /// The tiles it has pieces in, sorted.
    pub tiles: Vec<TileId>,
}

impl TilePolygon {
    /// The height of the plane above `(x, y)`.
    pub fn z_at(&self, x: f64, y: f64) -> f64 {
        -(self.normal[0] * x + self.normal[1] * y + self.offset) / self.normal[2]
    }

    /// The footprint's rings lifted onto the plane: the shell, then the holes (closed
    /// rings, as the footprint's).
    pub fn rings_3d(&self) -> (Vec<[f64; 3]>, Vec<Vec<[f64; 3]>>) {
        let lift = |r: &LineString<f64>| -> Vec<[f64; 3]> {
            r.coords()
                .map(|c| [c.x, c.y, self.z_at(c.x, c.y)])
                .collect()
        };
        (
            lift(self.footprint.exterior()),
            self.footprint.interiors().iter().map(lift).collect(),
        )
    }

    /// The point of the plane above the footprint's centroid.
    fn anchor(&self) -> [f64; 3] {
        let c = self
            .footprint
            .centroid()
            .map_or(Coord { x: 0.0, y: 0.0 }, |p| p.0);
        [c.x, c.y, self.z_at(c.x, c.y)]
    }
}

/// The polygons of some tiles of a grid: one tile's extraction ([`extract_tile`]) or the
/// merge of several ([`merge`]).
#[derive(Debug, Clone, PartialEq)]
pub struct TileSet {
    /// The grid the tiles are on.
    pub grid: TileGrid,
    /// The tiles covered, sorted: their results are in `polygons`.
    pub cover: Vec<TileId>,
    /// The polygons, clipped to the covered cores and merged across their seams.
    pub polygons: Vec<TilePolygon>,
}

impl TileSet {
    /// The total footprint area of the polygons.
    pub fn area(&self) -> f64 {
        self.polygons.iter().map(|p| p.area).sum()
    }
}

/// When two pieces that meet along a seam are one polygon.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct MergeTolerance {
    /// The largest angle between their normals, in degrees.
    pub max_angle_deg: f64,
    /// The largest difference of their planes' heights at the middle of the stretch of
    /// seam they share (length unit).
    pub max_offset: f64,
    /// The shortest stretch of seam they must share (length unit; `0`: any positive
    /// length).
    pub min_shared: f64,
}

impl MergeTolerance {
    /// The tolerances that fit the regions of `config`. On the 2.5D path every triangle of
    /// a region is within `acos(norm_thresh)` of `up`, so two pieces of one region differ
    /// by at most twice that, and their planes may part by a few triangle lengths at a
    /// seam (4 · the largest of `lmax`, 2 α and `z_thresh`; no height test when all are
    /// `0`). On the unorganized 3D path ([`Config::unorganized`]) a region is one plane,
    /// so pieces must agree as closely as the segments that refinement merges:
    /// `acos(norm_thresh)`, and 4 · `z_thresh` (or `lmax` when it is `0`) — two faces of
    /// a pitched roof that touch a seam side by side are not one polygon.
    pub fn for_config(config: &Config) -> Self {
        let cone = config.norm_thresh.clamp(-1.0, 1.0).acos().to_degrees();
        let (angle, length) = match config.unorganized {
            Some(_) if config.z_thresh > 0.0 => (cone, config.z_thresh),
            Some(_) => (cone, config.lmax),
            None => (
                2.0 * cone,
                config.lmax.max(2.0 * config.alpha).max(config.z_thresh),
            ),
        };
        Self {
            max_angle_deg: angle.max(1.0),
            max_offset: if length > 0.0 {
                4.0 * length
            } else {
                f64::INFINITY
            },
            min_shared: 0.0,
        }
    }

    fn agree(&self, a: &TilePolygon, b: &TilePolygon, at: Coord<f64>) -> bool {
        let cos = a.normal[0] * b.normal[0] + a.normal[1] * b.normal[1] + a.normal[2] * b.normal[2];
        let angle = cos.clamp(-1.0, 1.0).acos().to_degrees();
        angle <= self.max_angle_deg
            && (a.z_at(at.x, at.y) - b.z_at(at.x, at.y)).abs() <= self.max_offset
    }
}

/// Extracts the polygons of one tile: the 2.5D pipeline on the points of `points` in the
/// tile's window (others are ignored, so the whole cloud may be passed) — or the
/// unorganized 3D path ([`Polylidar::extract_unorganized`]) when the configuration has an
/// [`unorganized`](Config::unorganized) section, for pitched roofs, keeping the planes
/// within [`MAX_SLOPE_DEG`] of horizontal — each polygon's footprint clipped to the tile's
/// core. A window with fewer than 3 points, or points that cannot be
/// triangulated (all on one line), has no polygons. The pipeline's post-processing is not
/// applied: it belongs after the merge.
///
/// # Errors
/// [`TileError::Grid`] for a tile off the grid or a `up` that is not `+z` (tiles are
/// squares in xy); [`TileError::Extract`] when the pipeline fails otherwise.
pub fn extract_tile(
    polylidar: &Polylidar,
    grid: &TileGrid,
    tile: TileId,
    points: &[[f64; 3]],
) -> Result<TileSet, TileError> {
    grid.index(tile)?;
    let up = polylidar.config().up;
    if !(up[0] == 0.0 && up[1] == 0.0 && up[2] > 0.0) {
        return Err(TileError::Grid(format!(
            "tiles are squares in xy, so up must be +z, not {up:?}"
        )));
    }
    let window = grid.window(tile);
    let inside: Vec<[f64; 3]> = points
        .iter()
        .filter(|p| {
            p[2].is_finite()
                && (window.min().x..=window.max().x).contains(&p[0])
                && (window.min().y..=window.max().y).contains(&p[1])
        })
        .copied()
        .collect();
    let mut set = TileSet {
        grid: *grid,
        cover: vec![tile],
        polygons: Vec::new(),
    };
    if inside.len() < 3 {
        return Ok(set);
    }
    let three_d = polylidar.config().unorganized.is_some();
    let extracted = match three_d {
        true => polylidar.extract_unorganized(&inside, None),
        false => polylidar.extract_25d(&inside),
    };
    let extraction = match extracted {
        Ok(extraction) => extraction,
        Err(PolylidarError::Mesh(_)) => return Ok(set),
        Err(source) => return Err(TileError::Extract { tile, source }),
    };
    let core = grid.core(tile);
    let min_up = MAX_SLOPE_DEG.to_radians().cos();
    for polygon in &extraction.polygons {
        let (mut normal, mut offset) = (polygon.plane.normal, polygon.plane.offset);
        if normal[2] < 0.0 {
            normal = normal.map(|c| -c);
            offset = -offset;
        }
        if normal[2] <= 0.0 || (three_d && normal[2] < min_up) {
            continue;
        }
        // A 2.5D polygon is valid in xy as it is; a 3D one in its plane, so its vertices
        // go onto the plane first (xy is then an affine image of the plane's frame).
        let ring = |points: &[[f64; 3]]| -> LineString<f64> {
            points
                .iter()
                .map(|p| {
                    let s = match three_d {
                        true => normal[0] * p[0] + normal[1] * p[1] + normal[2] * p[2] + offset,
                        false => 0.0,
                    };
                    Coord {
                        x: p[0] - s * normal[0],
                        y: p[1] - s * normal[1],
                    }
                })
                .collect()
        };
        let footprint = Polygon::new(
            ring(&polygon.shell_points),
            polygon.hole_points.iter().map(|h| ring(h)).collect(),
        );
        // Clipped to the core as far as the polygon reaches: the operation's integer grid
        // then follows the polygon's extent, not the tile's.
        let Some(bb) = geo::BoundingRect::bounding_rect(&footprint) else {
            continue;
        };
        let pad = 0.01 * (bb.width() + bb.height());
        let (lo, hi) = (
            [
                core.min().x.max(bb.min().x - pad),
                core.min().y.max(bb.min().y - pad),
            ],
            [
                core.max().x.min(bb.max().x + pad),
                core.max().y.min(bb.max().y + pad),
            ],
        );
        if !(lo[0] < hi[0] && lo[1] < hi[1]) {
            continue;
        }
        let clip = Rect::new(Coord { x: lo[0], y: lo[1] }, Coord { x: hi[0], y: hi[1] });
        for part in grid.snap_parts(footprint.intersection(&clip.to_polygon())) {
            let area = part.unsigned_area();
            if area > 0.0 {
                set.polygons.push(TilePolygon {
                    footprint: part,
                    normal,
                    offset,
                    area,
                    tiles: vec![tile],
                });
            }
        }
    }
    Ok(set)
}

/// Which axis a grid line is orthogonal to.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
enum Line {
    /// `x = x0 + k · size`.
    X(i64),
    /// `y = y0 + k · size`.
    Y(i64),
}

/// The stretches of grid lines the rings of `polygon` run along: `(line, lo, hi)`.
fn seam_stretches(grid: &TileGrid, polygon: &Polygon<f64>) -> Vec<(Line, f64, f64)> {
    let mut out = Vec::new();
    let on = |v: f64, o: f64, line: &dyn Fn(i64) -> f64| -> Option<i64> {
        let k = ((v - o) / grid.size).round();
        (k.is_finite() && line(k as i64) == v).then_some(k as i64)
    };
    for ring in std::iter::once(polygon.exterior()).chain(polygon.interiors()) {
        for edge in ring.lines() {
            let (a, b) = (edge.start, edge.end);
            let vertical = a.x == b.x && a.y != b.y;
            let horizontal = a.y == b.y && a.x != b.x;
            if let Some(k) = on(a.x, grid.origin[0], &|k| grid.x_line(k)).filter(|_| vertical) {
                out.push((Line::X(k), a.y.min(b.y), a.y.max(b.y)));
            } else if let Some(k) =
                on(a.y, grid.origin[1], &|k| grid.y_line(k)).filter(|_| horizontal)
            {
                out.push((Line::Y(k), a.x.min(b.x), a.x.max(b.x)));
            }
        }
    }
    out
}

/// Merges the results of tiles: pieces from different inputs that share a stretch of a
/// seam and lie on one plane (within `tolerance`) become one polygon, the union of their
/// footprints. Any grouping of the same tiles, merged in any order, gives the same
/// polygons; they are sorted by the lower-left corner of their bounding box.
///
/// # Errors
/// [`TileError::Merge`] for no input, inputs on different grids, or a tile covered by two
/// inputs (it would count twice).
pub fn merge(sets: Vec<TileSet>, tolerance: &MergeTolerance) -> Result<TileSet, TileError> {
    let grid = match sets.first() {
        Some(set) => set.grid,
        None => return Err(TileError::Merge("no tile set to merge".into())),
    };
    if let Some(other) = sets.iter().find(|s| s.grid != grid) {
        return Err(TileError::Merge(format!(
            "the tile sets are on different grids: {grid:?} and {:?}",
            other.grid
        )));
    }
    let mut cover: Vec<TileId> = sets.iter().flat_map(|s| s.cover.iter().copied()).collect();
    cover.sort_unstable();
    if let Some(w) = cover.windows(2).find(|w| w[0] == w[1]) {
        return Err(TileError::Merge(format!(
            "tile {} is in two of the merged tile sets",
            w[0]
        )));
    }
    let mut pieces: Vec<(usize, TilePolygon)> = Vec::new();
    for (s, set) in sets.into_iter().enumerate() {
        pieces.extend(set.polygons.into_iter().map(|p| (s, p)));
    }

    let mut lines: HashMap<Line, Vec<(f64, f64, usize)>> = HashMap::new();
    for (i, (_, piece)) in pieces.iter().enumerate() {
        for (line, lo, hi) in seam_stretches(&grid, &piece.footprint) {
            lines.entry(line).or_default().push((lo, hi, i));
        }
    }
    let mut groups = UnionFind::new(pieces.len());
    let mut keys: Vec<&Line> = lines.keys().collect();
    keys.sort_unstable_by_key(|l| match l {
        Line::X(k) => (0, *k),
        Line::Y(k) => (1, *k),
    });
    for line in keys {
        let mut stretches = lines[line].clone();
        stretches.sort_by(|a, b| a.0.total_cmp(&b.0).then(a.2.cmp(&b.2)));
        for (i, &(lo, hi, a)) in stretches.iter().enumerate() {
            for &(lo2, hi2, b) in stretches[i + 1..].iter().take_while(|s| s.0 < hi) {
                let shared = hi.min(hi2) - lo.max(lo2);
                if pieces[a].0 == pieces[b].0 || shared <= tolerance.min_shared || shared <= 0.0 {
                    continue;
                }
                let mid = 0.5 * (lo.max(lo2) + hi.min(hi2));
                let at = match line {
                    Line::X(k) => Coord {
                        x: grid.x_line(*k),
                        y: mid,
                    },
                    Line::Y(k) => Coord {
                        x: mid,
                        y: grid.y_line(*k),
                    },
                };
                if tolerance.agree(&pieces[a].1, &pieces[b].1, at) {
                    groups.join(a, b);
                }
            }
        }
    }

    let mut members: HashMap<usize, Vec<usize>> = HashMap::new();
    for i in 0..pieces.len() {
        members.entry(groups.root(i)).or_default().push(i);
    }
    let mut polygons = Vec::new();
    for (_, group) in members {
        if let [single] = group[..] {
            polygons.push(pieces[single].1.clone());
            continue;
        }
        polygons.extend(unite(&grid, group.iter().map(|&i| &pieces[i].1)));
    }
    polygons.sort_by(|a, b| {
        let key = |p: &TilePolygon| {
            let r = geo::BoundingRect::bounding_rect(&p.footprint);
            r.map_or((0.0, 0.0), |r| (r.min().x, r.min().y))
        };
        let (ka, kb) = (key(a), key(b));
        ka.0.total_cmp(&kb.0)
            .then(ka.1.total_cmp(&kb.1))
            .then(a.area.total_cmp(&b.area))
    });
    Ok(TileSet {
        grid,
        cover,
        polygons,
    })
}

/// The union of pieces of one plane: one polygon per connected part of their footprints,
/// each on the area-weighted mean plane of the pieces.
fn unite<'a>(grid: &TileGrid, pieces: impl Iterator<Item = &'a TilePolygon>) -> Vec<TilePolygon> {
    let pieces: Vec<&TilePolygon> = pieces.collect();
    let (mut normal, mut anchor, mut weight) = ([0.0; 3], [0.0; 3], 0.0);
    let mut tiles = Vec::new();
    for p in &pieces {
        let a = p.anchor();
        for k in 0..3 {
            normal[k] += p.area * p.normal[k];
            anchor[k] += p.area * a[k];
        }
        weight += p.area;
        tiles.extend_from_slice(&p.tiles);
    }
    tiles.sort_unstable();
    tiles.dedup();
    let len = (normal[0] * normal[0] + normal[1] * normal[1] + normal[2] * normal[2]).sqrt();
    let normal = if len > 0.0 {
        normal.map(|c| c / len)
    } else {
        pieces[0].normal
    };
    let anchor = if weight > 0.0 {
        anchor.map(|c| c / weight)
    } else {
        pieces[0].anchor()
    };
    let offset = -(normal[0] * anchor[0] + normal[1] * anchor[1] + normal[2] * anchor[2]);
    // The pieces meet along seams only (each is clipped to its tile's core), so a hole that
    // reaches no grid line comes through the union unchanged: it is set aside and put back
    // into the part that holds it, and the unions handle the outlines near the seams only
    // (a city's ground has hundreds of holes, most of them far from any seam).
    let mut set_aside: Vec<LineString<f64>> = Vec::new();
    let mut footprints = pieces.iter().map(|p| {
        let (exterior, interiors) = p.footprint.clone().into_inner();
        let (near, far) = grid.holes_near_seams(&exterior, interiors);
        set_aside.extend(far);
        Polygon::new(exterior, near)
    });
    // Pairwise unions: `geo::unary_union` (one fill rule for all rings, taken from the
    // first ring's winding) lost holes of the Autzen paved area where these keep them.
    // Each union rounds to its own integer grid: snapping after each keeps the seams of
    // the pieces still to come exact.
    let first = footprints.next().map_or_else(Vec::new, |f| vec![f]);
    let union = footprints.fold(MultiPolygon::new(first), |acc, f| {
        MultiPolygon::new(grid.snap_parts(acc.union(&f)))
    });
    put_back(union.0, set_aside)
        .into_iter()
        .filter_map(|part| {
            let area = part.unsigned_area();
            (area > 0.0).then(|| TilePolygon {
                footprint: part,
                normal,
                offset,
                area,
                tiles: tiles.clone(),
            })
        })
        .collect()
}

/// `parts` (disjoint polygons) with each of `holes` added to the part that holds it: the
/// smallest part whose exterior has a vertex of the hole strictly inside (a part inside
/// another's courtyard lies in that part's hole, so the smallest is the right one).
fn put_back(mut parts: Vec<Polygon<f64>>, holes: Vec<LineString<f64>>) -> Vec<Polygon<f64>> {
    use geo::coordinate_position::{CoordPos, coord_pos_relative_to_ring};
    if holes.is_empty() {
        return parts;
    }
    let areas: Vec<f64> = parts
        .iter()
        .map(|p| p.exterior().signed_area().abs())
        .collect();
    let mut extra: Vec<Vec<LineString<f64>>> = vec![Vec::new(); parts.len()];
    for hole in holes {
        let holder = hole.coords().find_map(|&c| {
            (0..parts.len())
                .filter(|&i| coord_pos_relative_to_ring(c, parts[i].exterior()) == CoordPos::Inside)
                .min_by(|&a, &b| areas[a].total_cmp(&areas[b]))
        });
        if let Some(i) = holder {
            extra[i].push(hole);
        }
    }
    for (part, holes) in parts.iter_mut().zip(extra) {
        for hole in holes {
            part.interiors_push(hole);
        }
    }
    parts
}

/// Disjoint sets of piece indices (path halving, union by index).
struct UnionFind(Vec<usize>);

impl UnionFind {
    fn new(n: usize) -> Self {
        Self((0..n).collect())
    }

    fn root(&mut self, mut i: usize) -> usize {
        while self.0[i] != i {
            self.0[i] = self.0[self.0[i]];
            i = self.0[i];
        }
        i
    }

    fn join(&mut self, a: usize, b: usize) {
        let (ra, rb) = (self.root(a), self.root(b));
        let (lo, hi) = (ra.min(rb), ra.max(rb));
        self.0[hi] = lo;
    }
}

/// Every tile of `grid` extracted from `points` ([`extract_tile`], one after the other,
/// each using the pipeline's threads) and merged ([`merge`]): what the Dask front does on
/// a cluster, in one process.
///
/// # Errors
/// As [`extract_tile`] and [`merge`].
pub fn extract_tiled(
    polylidar: &Polylidar,
    grid: &TileGrid,
    points: &[[f64; 3]],
    tolerance: &MergeTolerance,
) -> Result<TileSet, TileError> {
    let windows = grid.split(points);
    let sets = grid
        .tiles()
        .zip(&windows)
        .map(|(tile, points)| extract_tile(polylidar, grid, tile, points))
        .collect::<Result<Vec<_>, _>>()?;
    merge(sets, tolerance)
}

/// The points of LAS / LAZ files that fall in `tile`'s window: what one tile task reads
/// when the cloud is a set of files.
///
/// # Errors
/// [`TileError::Grid`] for a tile off the grid, [`TileError::Polylidar`] when a file
/// cannot be read.
#[cfg(feature = "io")]
pub fn read_window(
    paths: &[impl AsRef<std::path::Path>],
    grid: &TileGrid,
    tile: TileId,
) -> Result<Vec<[f64; 3]>, TileError> {
    grid.index(tile)?;
    let w = grid.window(tile);
    let mut points = Vec::new();
    for path in paths {
        let cloud = polylidar_io::read_las(path).map_err(PolylidarError::from)?;
        points.extend(cloud.points.into_iter().filter(|p| {
            p.iter().all(|c| c.is_finite())
                && (w.min().x..=w.max().x).contains(&p[0])
                && (w.min().y..=w.max().y).contains(&p[1])
        }));
    }
    Ok(points)
}

#[cfg(test)]
mod tests;

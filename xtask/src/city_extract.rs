//! `cargo xtask city --extract`: the synthetic city extracted in tiles in one process, as
//! the Dask front runs it on a cluster (each tile generated, extracted and encoded as
//! bytes on a pool of `workers` threads; merges of 4 in a tree), with the
//! cost of each part, so that the time of a cluster of any size can be modelled, and
//! optionally the merged polygons scored against the city's roof faces.

use std::collections::HashMap;
use std::time::Instant;

use geo::{Area, BooleanOps, BoundingRect, Contains, Coord, MultiPolygon};
use polylidar::tiles::{self, MergeTolerance, TileGrid, TileSet};
use polylidar::{Config, Polylidar};
use rayon::prelude::*;
use rstar::RTree;
use rstar::primitives::{GeomWithData, Rectangle};
use seg_metrics::{EvaluateOptions, evaluate};
use synthscan::City;

use crate::error::{Result, msg};

/// A roof return belongs to a polygon whose footprint holds it when it lies within this
/// height of the polygon's plane, metres (the city's roofs stand metres above the ground
/// and its height noise is 3 cm).
const SCORE_DZ: f64 = 1.0;

/// A roof face counts as split at a seam when its returns lie in several tile cores and
/// at least two polygons hold this share of them each.
const SPLIT_SHARE: f64 = 0.1;

/// What `cargo xtask city --extract` runs.
pub struct Options<'a> {
    /// Tile side, metres.
    pub size: f64,
    /// Overlap margin, metres.
    pub margin: f64,
    /// Tiles extracted at once.
    pub workers: usize,
    /// The preset's name.
    pub preset: &'a str,
    /// Also one run on the whole city.
    pub single: bool,
    /// Score the merged polygons against the roof faces.
    pub score: bool,
}

/// Runs the tiled extraction and prints the costs (and the comparison with one run).
pub fn run(city: &City, options: &Options<'_>) -> Result<()> {
    let Options {
        size,
        margin,
        workers,
        single,
        ..
    } = *options;
    let config = Config::preset(options.preset)
        .ok_or_else(|| msg(format!("no preset {:?}", options.preset)))?
        .with_threads(0);
    let tolerance = MergeTolerance::for_config(&config);
    let polylidar = Polylidar::new(config.clone())?;
    let n = (city.side() / size).ceil() as u32;
    let grid = TileGrid::new([0.0, 0.0], size, margin, n, n)?;
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(workers.max(1))
        .build()?;
    let started = Instant::now();
    let results = pool.install(|| {
        grid.tiles()
            .collect::<Vec<_>>()
            .into_par_iter()
            .map(|tile| -> Result<(Vec<u8>, usize, f64, f64)> {
                let t0 = Instant::now();
                let w = grid.window(tile);
                let points = city
                    .tile([w.min().x, w.min().y], size + 2.0 * margin)
                    .points;
                let t1 = Instant::now();
                let set = tiles::extract_tile(&polylidar, &grid, tile, &points)?;
                let bytes = set.to_bytes();
                Ok((
                    bytes,
                    points.len(),
                    (t1 - t0).as_secs_f64(),
                    t1.elapsed().as_secs_f64(),
                ))
            })
            .collect::<Result<Vec<_>>>()
    })?;
    let tiled_wall = started.elapsed().as_secs_f64();
    let window_points: usize = results.iter().map(|r| r.1).sum();
    let generate: f64 = results.iter().map(|r| r.2).sum();
    let extract: f64 = results.iter().map(|r| r.3).sum();
    let mut level: Vec<Vec<u8>> = results.into_iter().map(|r| r.0).collect();
    let merge_started = Instant::now();
    let mut merges = 0usize;
    while level.len() > 1 {
        level = pool.install(|| {
            level
                .par_chunks(4)
                .map(|chunk| -> Result<Vec<u8>> {
                    let sets = chunk
                        .iter()
                        .map(|b| TileSet::from_bytes(b))
                        .collect::<std::result::Result<Vec<_>, _>>()?;
                    Ok(tiles::merge(sets, &tolerance)?.to_bytes())
                })
                .collect::<Result<Vec<_>>>()
        })?;
        merges += level.len();
    }
    let merge = merge_started.elapsed().as_secs_f64();
    let merged = TileSet::from_bytes(&level[0])?;
    let peak = peak_memory_mb();
    println!(
        "city {:.0} m, {} tiles of {size} m (margin {margin} m), {} workers: {window_points} \
         window returns; generate {generate:.1} s + extract {extract:.1} s summed over tiles, \
         tiled wall {tiled_wall:.1} s; {merges} merges in {merge:.2} s wall; {} polygons; \
         extract throughput {:.0} returns/s per worker; peak memory {peak} MB",
        city.side(),
        grid.len(),
        workers,
        merged.polygons.len(),
        window_points as f64 / extract
    );
    let report = |what: &str, set: &TileSet| -> Result<()> {
        if options.score {
            let t = Instant::now();
            let score = score(city, &grid, set, &pool)?;
            println!(
                "{what}: {} roof faces scored, {} found (f {:.1} %, k {:.1} %), {} \
                 over-segmented, {} missed; {} split across tile cores; scored in {:.1} s",
                score.truth_planes,
                score.correct,
                score.f,
                score.k,
                score.over_segmented,
                score.missed,
                score.seam_splits,
                t.elapsed().as_secs_f64()
            );
        }
        Ok(())
    };
    report("tiled", &merged)?;
    if single {
        // The whole city as one tile without margin: the same path, no seams.
        let points = city.tile([0.0, 0.0], city.side()).points;
        let whole = Polylidar::new(config.with_threads(workers))?;
        let one = TileGrid::new([0.0, 0.0], city.side(), 0.0, 1, 1)?;
        let t = Instant::now();
        let set = tiles::extract_tile(
            &whole,
            &one,
            one.tiles().next().ok_or_else(|| msg("empty grid"))?,
            &points,
        )?;
        let single_s = t.elapsed().as_secs_f64();
        let footprints = |s: &TileSet| {
            MultiPolygon::new(s.polygons.iter().map(|p| p.footprint.clone()).collect())
        };
        let (a, b) = (footprints(&set), footprints(&merged));
        let difference = a.xor(&b).unsigned_area() / a.unsigned_area();
        println!(
            "single run: {} returns, {} polygons in {single_s:.1} s on {workers} threads \
             ({:.0} returns/s per thread); symmetric difference / area {difference:.1e}",
            points.len(),
            set.polygons.len(),
            points.len() as f64 / single_s / workers as f64
        );
        report("single run", &set)?;
    }
    Ok(())
}

/// The roof faces' scores of [`score`].
struct Score {
    truth_planes: usize,
    correct: usize,
    over_segmented: usize,
    missed: usize,
    f: f64,
    k: f64,
    seam_splits: usize,
}

/// Scores `merged` against the roof faces of `city`: every roof return (regenerated tile by
/// tile, ground and trees left out) takes the polygon whose footprint holds it and whose
/// plane is nearest within [`SCORE_DZ`]; then Table 10's f and k (overlap 80 %) with the
/// roof faces as the planes, and the faces split at a seam.
fn score(
    city: &City,
    grid: &TileGrid,
    merged: &TileSet,
    pool: &rayon::ThreadPool,
) -> Result<Score> {
    let boxes = RTree::bulk_load(
        merged
            .polygons
            .iter()
            .enumerate()
            .filter_map(|(i, p)| {
                let b = p.footprint.bounding_rect()?;
                let rect = Rectangle::from_corners([b.min().x, b.min().y], [b.max().x, b.max().y]);
                Some(GeomWithData::new(rect, i as i32))
            })
            .collect(),
    );
    let label = |p: &[f64; 3]| -> i32 {
        let mut best = (-1, SCORE_DZ);
        for hit in boxes.locate_all_at_point(&[p[0], p[1]]) {
            let polygon = &merged.polygons[hit.data as usize];
            let dz = (p[2] - polygon.z_at(p[0], p[1])).abs();
            if dz <= best.1 && polygon.footprint.contains(&Coord { x: p[0], y: p[1] }) {
                best = (hit.data, dz);
            }
        }
        best.0
    };
    // (points, truth, predicted, tile index) of the roof returns, tile by tile.
    let tiles: Vec<_> = grid.tiles().collect();
    let per_tile = pool.install(|| {
        tiles
            .par_iter()
            .enumerate()
            .map(|(t, &tile)| {
                let core = grid.core(tile);
                let returns = city.tile([core.min().x, core.min().y], grid.size);
                let mut out = (Vec::new(), Vec::new(), Vec::new(), t);
                for (p, &l) in returns.points.iter().zip(&returns.labels) {
                    if l >= 1 {
                        out.0.push(*p);
                        out.1.push(i32::try_from(l).unwrap_or(i32::MAX));
                        out.2.push(label(p));
                    }
                }
                out
            })
            .collect::<Vec<_>>()
    });
    let (mut points, mut truth, mut predicted) = (Vec::new(), Vec::new(), Vec::new());
    let mut pieces: HashMap<i32, HashMap<i32, usize>> = HashMap::new();
    let mut cores: HashMap<i32, Vec<usize>> = HashMap::new();
    for (p, t, q, tile) in per_tile {
        for (&l, &k) in t.iter().zip(&q) {
            *pieces.entry(l).or_default().entry(k).or_default() += 1;
            let seen = cores.entry(l).or_default();
            if seen.last() != Some(&tile) {
                seen.push(tile);
            }
        }
        points.extend(p);
        truth.extend(t);
        predicted.extend(q);
    }
    let evaluation = evaluate(&points, &truth, &predicted, &EvaluateOptions::default())?;
    let seam_splits = pieces
        .iter()
        .filter(|(face, by)| {
            let n: usize = by.values().sum();
            let big = by
                .iter()
                .filter(|&(&k, &c)| k >= 0 && c as f64 >= SPLIT_SHARE * n as f64)
                .count();
            big >= 2 && cores.get(face).is_some_and(|c| c.len() >= 2)
        })
        .count();
    Ok(Score {
        truth_planes: evaluation.truth_planes,
        correct: evaluation.correct,
        over_segmented: evaluation.over_segmented,
        missed: evaluation.missed,
        f: evaluation.f,
        k: evaluation.k,
        seam_splits,
    })
}

/// The peak resident memory of this process (VmHWM), MB; 0 where unknown.
fn peak_memory_mb() -> u64 {
    std::fs::read_to_string("/proc/self/status")
        .ok()
        .and_then(|s| {
            s.lines()
                .find(|l| l.starts_with("VmHWM:"))
                .and_then(|l| l.split_whitespace().nth(1)?.parse::<u64>().ok())
        })
        .map_or(0, |kb| kb / 1024)
}

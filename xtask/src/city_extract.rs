//! `cargo xtask city --extract`: the synthetic city extracted in tiles in one process, as
//! the Dask front runs it on a cluster (each tile generated, extracted and encoded as
//! bytes on a pool of `workers` threads; merges of 4 in a tree), with the
//! cost of each part, so that the time of a cluster of any size can be modelled.

use std::time::Instant;

use geo::{Area, BooleanOps, Coord, LineString, MultiPolygon, Polygon};
use polylidar::tiles::{self, MergeTolerance, TileGrid, TileSet};
use polylidar::{Config, Polylidar};
use rayon::prelude::*;
use synthscan::City;

use crate::error::{Result, msg};

/// Runs the tiled extraction and prints the costs (and the comparison with one run).
pub fn run(city: &City, size: f64, margin: f64, workers: usize, single: bool) -> Result<()> {
    let config = Config::preset("rooftop")
        .ok_or_else(|| msg("no rooftop preset"))?
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
    if single {
        let points = city.tile([0.0, 0.0], city.side()).points;
        let whole = Polylidar::new(config.with_threads(workers))?;
        let t = Instant::now();
        let extraction = whole.extract_25d(&points)?;
        let single_s = t.elapsed().as_secs_f64();
        let ring = |p: &[[f64; 3]]| -> LineString<f64> {
            p.iter().map(|q| Coord { x: q[0], y: q[1] }).collect()
        };
        let a = MultiPolygon::new(
            extraction
                .polygons
                .iter()
                .map(|p| {
                    Polygon::new(
                        ring(&p.shell_points),
                        p.hole_points.iter().map(|h| ring(h)).collect(),
                    )
                })
                .collect(),
        );
        let b = MultiPolygon::new(
            merged
                .polygons
                .iter()
                .map(|p| p.footprint.clone())
                .collect(),
        );
        let difference = a.xor(&b).unsigned_area() / a.unsigned_area();
        println!(
            "single run: {} returns, {} polygons in {single_s:.1} s on {workers} threads \
             ({:.0} returns/s per thread); symmetric difference / area {difference:.1e}",
            points.len(),
            extraction.polygons.len(),
            points.len() as f64 / single_s / workers as f64
        );
    }
    Ok(())
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

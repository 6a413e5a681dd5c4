//! `cargo xtask city`: writes the synthetic city of `synthscan::City` as LAS/LAZ tiles
//! with ground-truth labels, tile by tile (a billion points never sit in memory at once).
//!
//! Each tile `city_CCCC_RRRR.laz` (column, row of `--tile` metres from the origin) holds the
//! returns with their ASPRS class (2 ground, 5 trees, 6 roofs); `city_CCCC_RRRR.labels.npy`
//! beside it holds the ground-truth label of each return (int32: 0 ground, −1 trees,
//! `1 + 4 · building + face` roofs); `city.json` describes the city, the files and the
//! roof planes' count.

use std::path::{Path, PathBuf};
use std::time::Instant;

use rayon::prelude::*;
use synthscan::{City, CityConfig};

use crate::error::{Result, msg};

/// Options of `cargo xtask city`.
#[derive(Debug, clap::Args)]
pub struct CityArgs {
    /// About how many returns the city has (its size: the side is sqrt(points / density)).
    #[arg(long, default_value_t = 1_000_000)]
    points: u64,
    /// Output folder (created; not needed with --extract).
    #[arg(long, default_value = "city")]
    out: PathBuf,
    /// Side of one output tile, metres.
    #[arg(long, default_value_t = 250.0)]
    tile: f64,
    /// Returns per square metre.
    #[arg(long, default_value_t = 8.0)]
    density: f64,
    /// Seed of everything random.
    #[arg(long, default_value_t = 1)]
    seed: u64,
    /// Write uncompressed .las instead of .laz.
    #[arg(long)]
    las: bool,
    /// Instead of writing files: extract the city in tiles of --tile metres (--preset, on a
    /// pool of --workers threads, merges of 4) and report the per-tile and merge costs,
    /// throughput and peak memory.
    #[arg(long)]
    extract: bool,
    /// The preset of --extract: rooftop (2.5D: flat roofs and the ground) or aerial (the
    /// unorganized 3D path: pitched roofs too).
    #[arg(long, default_value = "rooftop")]
    preset: String,
    /// With --extract: score the merged polygons against the roof faces of the ground
    /// truth (f and k of Table 10, roofs split at a seam).
    #[arg(long)]
    score: bool,
    /// Tiles extracted at once with --extract (the workers of a cluster).
    #[arg(long, default_value_t = 2)]
    workers: usize,
    /// With --extract: also one run on the whole city (in memory) to compare with.
    #[arg(long)]
    single: bool,
    /// Overlap margin of the tiles with --extract, metres.
    #[arg(long, default_value_t = 4.0)]
    margin: f64,
}

/// Generates and writes the city.
pub fn city(args: &CityArgs) -> Result<()> {
    let started = Instant::now();
    let city = City::new(
        CityConfig::default()
            .with_points(args.points)
            .with_density(args.density)
            .with_seed(args.seed),
    )?;
    if !(args.tile.is_finite() && args.tile > 0.0) {
        return Err(msg(format!("--tile {} must be positive", args.tile)));
    }
    if args.extract {
        return crate::city_extract::run(
            &city,
            &crate::city_extract::Options {
                size: args.tile,
                margin: args.margin,
                workers: args.workers,
                preset: &args.preset,
                single: args.single,
                score: args.score,
            },
        );
    }
    std::fs::create_dir_all(&args.out)?;
    let n = (city.side() / args.tile).ceil() as u32;
    let tiles: Vec<(u32, u32)> = (0..n).flat_map(|r| (0..n).map(move |c| (c, r))).collect();
    let ext = if args.las { "las" } else { "laz" };
    let written = tiles
        .par_iter()
        .map(|&(c, r)| write_tile(&city, &args.out, args.tile, (c, r), ext))
        .collect::<Result<Vec<(String, usize)>>>()?;
    let total: usize = written.iter().map(|w| w.1).sum();
    let planes = city.roof_planes();
    let manifest = format!(
        "{{\n  \"points\": {total},\n  \"side\": {},\n  \"tile\": {},\n  \"density\": {},\n  \
         \"seed\": {},\n  \"buildings\": {},\n  \"roof_planes\": {},\n  \"files\": [{}]\n}}\n",
        city.side(),
        args.tile,
        args.density,
        args.seed,
        city.buildings().count(),
        planes.len(),
        written
            .iter()
            .map(|w| format!("\"{}\"", w.0))
            .collect::<Vec<_>>()
            .join(", ")
    );
    crate::report::write(&args.out.join("city.json"), &manifest)?;
    eprintln!(
        "city: {total} returns, {:.0} m a side, {} tiles of {} m, {} roof planes → {} in {:.1} s",
        city.side(),
        tiles.len(),
        args.tile,
        planes.len(),
        args.out.display(),
        started.elapsed().as_secs_f64()
    );
    Ok(())
}

/// Writes one tile and its labels; its file name and point count.
fn write_tile(
    city: &City,
    out: &Path,
    size: f64,
    (c, r): (u32, u32),
    ext: &str,
) -> Result<(String, usize)> {
    let tile = city.tile([f64::from(c) * size, f64::from(r) * size], size);
    let name = format!("city_{c:04}_{r:04}");
    let file = format!("{name}.{ext}");
    polylidar_io::write_las(
        out.join(&file),
        &tile.points,
        &tile.classification,
        &[],
        &polylidar_io::LasWriteOptions::default(),
    )?;
    let labels = tile
        .labels
        .iter()
        .map(|&l| i32::try_from(l).map_err(|_| msg(format!("label {l} beyond int32"))))
        .collect::<Result<Vec<i32>>>()?;
    polylidar_io::write_npy_i32(
        out.join(format!("{name}.labels.npy")),
        &[labels.len()],
        &labels,
    )?;
    Ok((file, tile.points.len()))
}

//! Command-line arguments.

use std::path::PathBuf;

use clap::{Args, Parser, Subcommand};

/// Planes and polygons with holes from 2D point sets and point clouds.
#[derive(Debug, Parser)]
#[command(name = "polylidar", version, about)]
pub struct Cli {
    /// What to do.
    #[command(subcommand)]
    pub command: Command,
}

/// Subcommands.
#[derive(Debug, Subcommand)]
pub enum Command {
    /// Extract polygons from a point file (or the built-in demo) and write them out.
    Extract(ExtractArgs),
}

/// Arguments of `polylidar extract`.
#[derive(Debug, Args)]
pub struct ExtractArgs {
    /// Input file: .csv/.txt/.xyz (N×2 or N×3), .npy (N×2, N×3), .ply, .las/.laz.
    /// 2-column data runs the 2D pipeline, 3D clouds the 2.5D one.
    #[arg(required_unless_present = "demo", conflicts_with = "demo")]
    pub input: Option<PathBuf>,
    /// Run on the built-in demo: 8,000 points sampled inside a shape with three holes.
    #[arg(long)]
    pub demo: bool,
    /// TOML file with parameters (the field names of `polylidar::Config`); flags win.
    #[arg(long, value_name = "FILE")]
    pub config: Option<PathBuf>,
    /// Parameter flags, each overriding the config file.
    #[command(flatten)]
    pub params: ParamArgs,
    /// Write the polygons as a GeoJSON FeatureCollection.
    #[arg(short, long, value_name = "FILE")]
    pub output: Option<PathBuf>,
    /// Draw points, shells and holes into a PNG picture.
    #[arg(long, value_name = "FILE")]
    pub plot: Option<PathBuf>,
    /// Print one JSON object with input, counts and median stage timings on stdout.
    #[arg(long)]
    pub json: bool,
    /// Run the pipeline this many times on the loaded data; timings are medians.
    #[arg(long, default_value_t = 1, value_parser = clap::value_parser!(u32).range(1..))]
    pub repeat: u32,
}

/// Flags named like the fields of `polylidar::Config`, in kebab case.
#[derive(Debug, Args, Default)]
pub struct ParamArgs {
    /// Keep triangles whose circumradius is at most this (0 disables). Input length units.
    #[arg(long, allow_negative_numbers = true)]
    pub alpha: Option<f64>,
    /// Keep triangles whose longest edge is at most this (0 disables). Input length units.
    #[arg(long, allow_negative_numbers = true)]
    pub lmax: Option<f64>,
    /// Drop regions with fewer triangles than this.
    #[arg(long)]
    pub min_triangles: Option<usize>,
    /// Drop holes with fewer vertices than this.
    #[arg(long)]
    pub min_hole_vertices: Option<usize>,
    /// 2.5D: minimum cosine between a triangle normal and the up vector.
    #[arg(long, allow_negative_numbers = true)]
    pub norm_thresh: Option<f64>,
    /// 2.5D: the up vector, as `x,y,z`.
    #[arg(
        long,
        value_delimiter = ',',
        num_args = 3,
        allow_negative_numbers = true
    )]
    pub up: Option<Vec<f64>>,
    /// Worker threads (0: one per core).
    #[arg(long)]
    pub threads: Option<usize>,
}

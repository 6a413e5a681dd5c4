//! Command-line arguments.

use std::path::PathBuf;

use clap::{Args, Parser, Subcommand, ValueEnum};
use polylidar::DecimateFactor;

/// Planes and polygons with holes from 2D point sets, point clouds, range images and meshes.
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
    /// Extract planes and polygons from a file (or a built-in demo) and write them out.
    Extract(ExtractArgs),
    /// Score a planar segmentation of an organized cloud against ground-truth labels.
    Evaluate(EvaluateArgs),
    /// Generate a SynPEB-like organized scan with ground-truth plane labels.
    Generate(GenerateArgs),
    /// Extract the planes, then simplify and texture them into light meshes (Ma et al.
    /// 2013): OBJ + MTL + PNG and PLY.
    Mesh(crate::mesh::MeshArgs),
    /// Extract planes and polygons from a stream of depth frames (a folder or glob of
    /// 16-bit depth PNGs) with one pipeline kept across frames: GeoJSON lines or one file
    /// per frame, per-frame timings and a summary.
    Stream(crate::stream::StreamArgs),
}

/// The built-in inputs of `--demo`.
#[derive(Debug, Clone, Copy, PartialEq, Eq, ValueEnum)]
pub enum Demo {
    /// A generated room with random polyhedra, scanned by a 500 × 500 range sensor with
    /// 1 mdeg noise, run with the `synpeb-auto` preset and scored against its ground truth.
    Scene,
    /// 8,000 2D points sampled inside a shape with three holes (the 2D pipeline).
    Shape,
}

/// How an unorganized 3D cloud is processed (`--mode`).
#[derive(Debug, Clone, Copy, PartialEq, Eq, ValueEnum)]
pub enum Mode {
    /// 3D when the file has normals or the preset asks for it, else 2.5D.
    Auto,
    /// Triangulated along `up` (2.5D).
    #[value(name = "25d")]
    TwoAndHalfD,
    /// Planes in every direction.
    #[value(name = "3d")]
    ThreeD,
}

/// Input and parameters shared by `extract` and `evaluate`.
#[derive(Debug, Args)]
pub struct InputArgs {
    /// Input file. 2D points: .csv/.txt/.xyz or .npy with 2 columns. Unorganized 3D clouds
    /// (2.5D pipeline): 3 columns, .ply/.obj without faces, .las/.laz. Organized clouds:
    /// .pcd with HEIGHT > 1, .npy H×W×3, 16-bit depth .png (camera: `--intrinsics` or its
    /// `_metadata.csv`).
    /// Meshes: .ply/.obj with faces.
    #[arg(required_unless_present = "demo", conflicts_with = "demo")]
    pub input: Option<PathBuf>,
    /// Run on a built-in input instead of a file (`scene` when no value is given).
    #[arg(long, value_enum, num_args = 0..=1, default_missing_value = "scene")]
    pub demo: Option<Demo>,
    /// Start from a named parameter preset of the papers: rgbd, synpeb (the authors' fixed
    /// 8 Laplacian iterations), synpeb-auto (iterations from the measured noise, for range
    /// scanners), rgbd-auto (the same with passes growing with range and missing returns
    /// filled, for depth cameras), rooftop, kitti, kitti-range, mesh-basement,
    /// mesh-mainfloor, room (unorganized indoor clouds, planes in every direction), aerial
    /// (airborne LiDAR on the same 3D path). Their lengths are metres, converted into
    /// `--units`. Default without
    /// `--config`: `rgbd-auto` for depth images, `synpeb-auto` for other organized clouds and
    /// `--demo scene`; none for other inputs (the defaults below, lengths from the data).
    #[arg(long, value_name = "NAME")]
    pub preset: Option<String>,
    /// Unit of the input's coordinates: m, ft (0.3048 m) or us-ft (1200/3937 m). Every
    /// length flag and config value is in this unit; presets are converted into it.
    /// Default: the unit a LAS/LAZ header declares, else metres.
    #[arg(long, value_name = "UNIT")]
    pub units: Option<polylidar_io::LengthUnit>,
    /// TOML file with parameters (the field names of `polylidar::Config`); it overrides the
    /// preset field by field, and flags override both.
    #[arg(long, value_name = "FILE")]
    pub config: Option<PathBuf>,
    /// Unorganized 3D clouds: `25d` triangulates along `--up` (planes facing up only),
    /// `3d` finds planes in every direction (normals read or estimated, dominant
    /// directions, a triangulation per direction). Default `auto`: 3D when the file stores
    /// normals (PCD normal_x/y/z) or the preset is `room` or `aerial`, else 2.5D.
    #[arg(long, value_enum, default_value_t = Mode::Auto)]
    pub mode: Mode,
    /// Organized input: keep every N-th row and column.
    #[arg(long, value_name = "N", default_value_t = 1, allow_negative_numbers = true, value_parser = clap::value_parser!(u32).range(1..))]
    pub stride: u32,
    /// Memory budget of reading the input and running the pipeline on it, e.g. 512M, 4G:
    /// what the file will need (its pixels or points, about 700 bytes each in the
    /// pipeline) is estimated from its header and refused past this before anything is
    /// allocated. Default: scaled to the input file's size, 384 MiB plus 64 bytes per byte
    /// of the file (a file of 1 MiB gets 448 MiB, so a small file that claims gigabytes is
    /// refused early), at most 2G or half of the physical memory, whichever is smaller.
    #[arg(long, value_name = "SIZE", value_parser = polylidar_io::parse_memory_size)]
    pub max_memory: Option<u64>,
    /// Parameter flags, each overriding the preset and the config file.
    #[command(flatten)]
    pub params: ParamArgs,
}

/// The camera of a 16-bit depth PNG. The intrinsics are `--intrinsics` when given, else
/// the RealSense `_metadata.csv` beside the PNG; the depth scale is `--depth-scale` when
/// given, else the CSV's `Depth Units`, else 1000 units per metre.
#[derive(Debug, Args, Default, Clone)]
pub struct CameraArgs {
    /// Depth PNG: the camera's intrinsics, as `fx,fy,cx,cy` in pixels or a file: an
    /// Open3D camera JSON (`width`, `height`, column-major `intrinsic_matrix`; its size
    /// must be the image's) or a RealSense metadata CSV. Default: the RealSense
    /// `_metadata.csv` beside the PNG.
    #[arg(
        long,
        value_name = "FX,FY,CX,CY|FILE",
        allow_hyphen_values = true,
        help_heading = "Depth camera"
    )]
    pub intrinsics: Option<String>,
    /// Depth PNG: depth units per metre (1000: millimetres, RealSense, ICL-NUIM, Kinect
    /// through OpenNI; 5000: the TUM RGB-D benchmark). Default: the metadata CSV's
    /// `Depth Units`, else 1000.
    #[arg(long, value_name = "UNITS", help_heading = "Depth camera")]
    pub depth_scale: Option<f64>,
}

/// Arguments of `polylidar extract`.
#[derive(Debug, Args)]
pub struct ExtractArgs {
    /// The input and its parameters.
    #[command(flatten)]
    pub input: InputArgs,
    /// The camera of a depth PNG input.
    #[command(flatten)]
    pub camera: CameraArgs,
    /// Write the polygons as a GeoJSON FeatureCollection.
    #[arg(short, long, value_name = "FILE", help_heading = "Output")]
    pub output: Option<PathBuf>,
    /// Write the polygons as extracted, even when the parameters post-process them.
    #[arg(long, help_heading = "Output")]
    pub raw: bool,
    /// Draw the polygons into a PNG picture with a legend: over the range image for
    /// organized input, over a hillshade of the heights seen along `up` for unorganized
    /// clouds, an oblique view for meshes, the points for 2D input.
    #[arg(long, value_name = "FILE", help_heading = "Output")]
    pub plot: Option<PathBuf>,
    /// Organized input: write the plane (polygon index) of every pixel as an int32 H×W
    /// .npy, -1 for none.
    #[arg(long, value_name = "FILE", help_heading = "Output")]
    pub labels_out: Option<PathBuf>,
    /// Print one JSON object with input, counts and median stage timings on stdout.
    #[arg(long, help_heading = "Output")]
    pub json: bool,
    /// Run the pipeline this many times on the loaded data; timings are medians.
    #[arg(long, default_value_t = 1, allow_negative_numbers = true, value_parser = clap::value_parser!(u32).range(1..), help_heading = "Output")]
    pub repeat: u32,
    /// Exit with code 3 when nothing, or nearly nothing (under 1 % of the triangles), is
    /// found. Without it the exit code is 0 and the explanation is only printed.
    #[arg(long, help_heading = "Output")]
    pub strict: bool,
}

/// Arguments of `polylidar evaluate`.
#[derive(Debug, Args)]
pub struct EvaluateArgs {
    /// The organized cloud (or `--demo scene`) and the parameters to segment it with.
    #[command(flatten)]
    pub input: InputArgs,
    /// Ground-truth plane per pixel: int32 (or int64) H×W or N .npy, -1 for none.
    /// Default: the demo's ground truth, or a PCD's `label` field (-1 for none) or
    /// `intensity` field with SynPEB's convention (plane ids from 10; smaller values are
    /// no plane).
    #[arg(long, value_name = "FILE")]
    pub labels: Option<PathBuf>,
    /// Draw the ground truth into a PNG: each missed, split or merged plane in the colour
    /// of its cause, correctly found planes in grey-green, spurious planes hatched.
    #[arg(long, value_name = "FILE")]
    pub plot: Option<PathBuf>,
    /// Print one JSON object (input, scores, causes of misses, timings) instead of the
    /// summary.
    #[arg(long)]
    pub json: bool,
    /// Score these predicted labels (same layout as `--labels`) instead of running the
    /// pipeline.
    #[arg(long, value_name = "FILE")]
    pub predicted: Option<PathBuf>,
    /// Overlap both ways for a correct detection (Hoover et al.).
    #[arg(long, default_value_t = 0.8, allow_negative_numbers = true)]
    pub overlap: f64,
}

/// Arguments of `polylidar generate`.
#[derive(Debug, Args)]
pub struct GenerateArgs {
    /// Scene seed (the room's random polyhedra).
    #[arg(long, default_value_t = 0)]
    pub seed: u64,
    /// Tangential (angular) noise in millidegrees; SynPEB uses 0.5, 1, 2 and 4.
    #[arg(long, default_value_t = 1.0, allow_negative_numbers = true)]
    pub noise_mdeg: f64,
    /// Radial noise standard deviation in metres.
    #[arg(long, default_value_t = 0.0, allow_negative_numbers = true)]
    pub noise_radial: f64,
    /// Output cloud: .pcd (binary, organized 500 × 500) or .npy (H×W×3 float64).
    #[arg(short, long, value_name = "FILE")]
    pub output: PathBuf,
    /// Ground-truth plane per pixel as int32 H×W .npy (-1: nothing hit).
    #[arg(long, value_name = "FILE")]
    pub labels_out: PathBuf,
}

/// Flags named like the fields of `polylidar::Config`, in kebab case.
///
/// Which apply: 2D points use `alpha`, `lmax`, `min-triangles`, `min-hole-vertices`;
/// unorganized 3D clouds (2.5D) also `norm-thresh` and `up`; organized clouds and meshes
/// (3D) use `lmax`, `min-triangles`, `min-hole-vertices`, `norm-thresh`, `z-thresh` and,
/// organized only, `no-smoothing` and `gpu`. A flag that does not apply is reported and
/// ignored.
#[derive(Debug, Args, Default)]
pub struct ParamArgs {
    /// 2D / 2.5D: keep triangles whose circumradius is at most this (0 disables), in
    /// `--units`. Default: 2D input: 4.2 × the median point spacing unless `--lmax` is
    /// given; otherwise 0.
    #[arg(
        long,
        allow_negative_numbers = true,
        help_heading = "Parameters (override the preset and --config)"
    )]
    pub alpha: Option<f64>,
    /// Keep triangles whose longest edge is at most this (0 disables), in `--units`.
    /// Default: the preset's; 2.5D input: at least 4 × the median point spacing; 0 (off)
    /// for 2D input without a preset.
    #[arg(
        long,
        allow_negative_numbers = true,
        help_heading = "Parameters (override the preset and --config)"
    )]
    pub lmax: Option<f64>,
    /// Drop regions with fewer triangles than this. Default: the preset's, else 20.
    #[arg(
        long,
        allow_negative_numbers = true,
        help_heading = "Parameters (override the preset and --config)"
    )]
    pub min_triangles: Option<usize>,
    /// 3D with refinement (synpeb-auto): keep a region with fewer triangles than
    /// `--min-triangles` when its area reaches this (square input units): far planes.
    /// Default: the preset's, else 0 (off).
    #[arg(
        long,
        allow_negative_numbers = true,
        help_heading = "Parameters (override the preset and --config)"
    )]
    pub min_area: Option<f64>,
    /// Drop holes with fewer vertices than this. Default: the preset's, else 3.
    #[arg(
        long,
        allow_negative_numbers = true,
        help_heading = "Parameters (override the preset and --config)"
    )]
    pub min_hole_vertices: Option<usize>,
    /// 2.5D / 3D: minimum cosine between a triangle normal and its plane's (2.5D: the up
    /// vector), or the largest angle between them in degrees (`20deg`, `20°`). Default: the
    /// preset's, else 0.9 (about 26°).
    #[arg(
        long,
        allow_negative_numbers = true,
        value_parser = cosine,
        help_heading = "Parameters (override the preset and --config)"
    )]
    pub norm_thresh: Option<f64>,
    /// 3D: largest point-to-plane distance of a triangle's centroid while growing a plane,
    /// in `--units` (0 disables). Default: the preset's, else 0.
    #[arg(
        long,
        allow_negative_numbers = true,
        help_heading = "Parameters (override the preset and --config)"
    )]
    pub z_thresh: Option<f64>,
    /// 2.5D: the up vector, as `0,0,1` or `0 0 1`. Default: 0,0,1.
    #[arg(
        long,
        value_delimiter = ',',
        num_args = 1..=3,
        allow_negative_numbers = true,
        value_name = "X,Y,Z",
        help_heading = "Parameters (override the preset and --config)"
    )]
    pub up: Option<Vec<f64>>,
    /// Worker threads (0: one per core), at most 4 per core. Default: 0.
    #[arg(
        long,
        allow_negative_numbers = true,
        help_heading = "Parameters (override the preset and --config)"
    )]
    pub threads: Option<usize>,
    /// Organized clouds: skip the preset's Laplacian and bilateral smoothing.
    #[arg(long, help_heading = "Parameters (override the preset and --config)")]
    pub no_smoothing: bool,
    /// Organized clouds: merge N × N blocks of pixels into one point before everything
    /// else (`1` or `off`: full resolution; `auto`: to about 424 columns, as the `rgbd`
    /// preset does). Labels stay one per input pixel. Default: the preset's.
    #[arg(
        long,
        value_name = "N|auto|off",
        value_parser = decimate_factor,
        help_heading = "Parameters (override the preset and --config)"
    )]
    pub decimate: Option<DecimateFactor>,
    /// Organized clouds: run the Laplacian and bilateral smoothing on the GPU (wgpu:
    /// Vulkan, Metal, DX12 or GL), in a build with the `gpu` feature
    /// (`cargo install polylidar-cli --features gpu`).
    #[arg(
        long,
        conflicts_with = "no_smoothing",
        help_heading = "Parameters (override the preset and --config)"
    )]
    pub gpu: bool,
}

/// `--decimate`: a block side, `auto`, or `off` (a side of 1).
fn decimate_factor(text: &str) -> Result<DecimateFactor, String> {
    match text.trim() {
        t if t.eq_ignore_ascii_case("auto") => Ok(DecimateFactor::Auto),
        t if t.eq_ignore_ascii_case("off") => Ok(DecimateFactor::Fixed(1)),
        t => match t.parse::<u32>() {
            Ok(n) if (1..=polylidar::MAX_DECIMATE_FACTOR).contains(&n) => {
                Ok(DecimateFactor::Fixed(n))
            }
            _ => Err(format!("{text:?}: a block side 1 to 16, `auto` or `off`")),
        },
    }
}

/// `--norm-thresh`: a cosine or an angle in degrees ([`polylidar::parse_cosine`]).
fn cosine(text: &str) -> Result<f64, String> {
    polylidar::parse_cosine(text)
        .ok_or_else(|| format!("{text:?} is neither a cosine (0.94) nor an angle (20deg)"))
}

//! `polylidar extract`: load, configure, run, write.

use std::path::{Path, PathBuf};

use polylidar::{Config, Extraction, Polylidar, PolylidarError};
use polylidar_io::{InputKind, IoError};

use crate::args::{Cli, Command, ExtractArgs, ParamArgs};
use crate::{geojson, plot, report};

/// Number of points the demo samples.
const DEMO_POINTS: usize = 8000;

/// Everything that can stop the command.
#[derive(Debug, thiserror::Error)]
pub enum CliError {
    /// The input file could not be read.
    #[error(transparent)]
    Input(#[from] IoError),
    /// The input holds something this command does not handle yet.
    #[error("{path}: {what} input is not supported by `extract` yet")]
    Unsupported {
        /// The input path.
        path: PathBuf,
        /// What it holds.
        what: &'static str,
    },
    /// The config file could not be read or parsed.
    #[error("config file {path}: {message}")]
    Config {
        /// The config path.
        path: PathBuf,
        /// What went wrong.
        message: String,
    },
    /// The pipeline failed.
    #[error(transparent)]
    Pipeline(#[from] PolylidarError),
    /// An output file could not be written.
    #[error("cannot write {path}: {message}")]
    Write {
        /// The output path.
        path: PathBuf,
        /// What went wrong.
        message: String,
    },
}

/// The loaded input of one run.
pub enum Input {
    /// A 2D point set.
    Points2d(Vec<[f64; 2]>),
    /// A 3D cloud for the 2.5D pipeline.
    Cloud(Vec<[f64; 3]>),
}

impl Input {
    /// Number of points.
    pub fn len(&self) -> usize {
        match self {
            Input::Points2d(p) => p.len(),
            Input::Cloud(p) => p.len(),
        }
    }

    /// The name used in the JSON report.
    pub fn kind(&self) -> &'static str {
        match self {
            Input::Points2d(_) => "points_2d",
            Input::Cloud(_) => "cloud_2.5d",
        }
    }
}

/// Runs the parsed command line.
pub fn run(cli: Cli) -> Result<(), CliError> {
    match cli.command {
        Command::Extract(args) => extract(&args),
    }
}

fn extract(args: &ExtractArgs) -> Result<(), CliError> {
    let mut config = match &args.config {
        Some(path) => read_config(path)?,
        None if args.demo => demo_config(),
        None => Config::default(),
    };
    apply_flags(&mut config, &args.params);
    let (input, source) = match &args.input {
        Some(path) => (load(path)?, path.display().to_string()),
        None => (demo_points()?, "built-in demo".to_owned()),
    };
    let polylidar = Polylidar::new(config)?;
    let extraction = run_once(&polylidar, &input)?;
    let mut timings = vec![extraction.diagnostics.timings.clone()];
    for _ in 1..args.repeat {
        timings.push(run_once(&polylidar, &input)?.diagnostics.timings);
    }
    if let Some(path) = &args.output {
        let text = geojson::feature_collection(&extraction, matches!(input, Input::Cloud(_)));
        write(path, text.as_bytes())?;
    }
    if let Some(path) = &args.plot {
        let png = plot::render(&input, &extraction, polylidar.config().up).map_err(|message| {
            CliError::Write {
                path: path.clone(),
                message,
            }
        })?;
        write(path, &png)?;
    }
    let counts = &extraction.diagnostics.counts;
    if args.json {
        println!("{}", report::json(&source, &input, counts, &timings));
    } else {
        eprintln!("{}", report::summary(&source, &input, counts, &timings));
    }
    Ok(())
}

fn run_once(polylidar: &Polylidar, input: &Input) -> Result<Extraction, PolylidarError> {
    match input {
        Input::Points2d(points) => polylidar.extract_2d(points),
        Input::Cloud(points) => polylidar.extract_25d(points),
    }
}

fn load(path: &Path) -> Result<Input, CliError> {
    let unsupported = |what| CliError::Unsupported {
        path: path.to_path_buf(),
        what,
    };
    match polylidar_io::read_input(path)? {
        InputKind::Points2d(points) => Ok(Input::Points2d(points)),
        InputKind::Cloud(cloud) if cloud.is_organized() => Err(unsupported("organized cloud")),
        InputKind::Cloud(cloud) => Ok(Input::Cloud(cloud.points)),
        InputKind::Mesh(_) => Err(unsupported("triangle mesh")),
        InputKind::Depth { .. } => Err(unsupported("depth image")),
    }
}

fn demo_points() -> Result<Input, CliError> {
    let shape = polylidar::shapes::demo_shape();
    let points = polylidar::shapes::sample_uniform(&shape, DEMO_POINTS, 1).map_err(|e| {
        CliError::Unsupported {
            path: PathBuf::from(format!("built-in demo ({e})")),
            what: "demo",
        }
    })?;
    Ok(Input::Points2d(points))
}

/// α = 2·√(area / n) for the demo shape, as in the 2D paper's benchmarks.
fn demo_config() -> Config {
    use polylidar::shapes::{demo_shape, paper_alpha};
    Config::new()
        .with_alpha(paper_alpha(&demo_shape(), DEMO_POINTS))
        .with_min_triangles(20)
        .with_min_hole_vertices(6)
}

fn read_config(path: &Path) -> Result<Config, CliError> {
    let error = |message: String| CliError::Config {
        path: path.to_path_buf(),
        message,
    };
    let text = std::fs::read_to_string(path).map_err(|e| error(e.to_string()))?;
    toml::from_str(&text).map_err(|e| error(e.to_string()))
}

fn apply_flags(config: &mut Config, flags: &ParamArgs) {
    let ParamArgs {
        alpha,
        lmax,
        min_triangles,
        min_hole_vertices,
        norm_thresh,
        up,
        threads,
    } = flags;
    if let Some(v) = alpha {
        config.alpha = *v;
    }
    if let Some(v) = lmax {
        config.lmax = *v;
    }
    if let Some(v) = min_triangles {
        config.min_triangles = *v;
    }
    if let Some(v) = min_hole_vertices {
        config.min_hole_vertices = *v;
    }
    if let Some(v) = norm_thresh {
        config.norm_thresh = *v;
    }
    if let Some([x, y, z]) = up.as_deref() {
        config.up = [*x, *y, *z];
    }
    if let Some(v) = threads {
        config.threads = *v;
    }
}

fn write(path: &Path, bytes: &[u8]) -> Result<(), CliError> {
    if let Some(dir) = path.parent().filter(|d| !d.as_os_str().is_empty()) {
        std::fs::create_dir_all(dir).map_err(|e| CliError::Write {
            path: path.to_path_buf(),
            message: e.to_string(),
        })?;
    }
    std::fs::write(path, bytes).map_err(|e| CliError::Write {
        path: path.to_path_buf(),
        message: e.to_string(),
    })
}

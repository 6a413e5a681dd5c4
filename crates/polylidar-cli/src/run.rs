//! The subcommands: load, configure, run, write.

use std::path::{Path, PathBuf};

use polylidar::{Extraction, Polylidar, PolylidarError};
use polylidar_io::IoError;

use crate::args::{Cli, Command, ExtractArgs};
use crate::input::{Input, Loaded, load};
use crate::{evaluate, geojson, params, plot, report};

/// Everything that can stop a command.
#[derive(Debug, thiserror::Error)]
pub enum CliError {
    /// An input file could not be read.
    #[error(transparent)]
    Input(#[from] IoError),
    /// The command needs another kind of input.
    #[error("{what}")]
    Unsupported {
        /// What is missing.
        what: String,
    },
    /// The preset is not known.
    #[error("unknown preset `{name}`; known presets: {known}")]
    Preset {
        /// The name given.
        name: String,
        /// The known names.
        known: String,
    },
    /// The config file could not be read or parsed.
    #[error("config file {path}: {message}")]
    Config {
        /// The config path.
        path: PathBuf,
        /// What went wrong.
        message: String,
    },
    /// A label file does not fit the input.
    #[error("labels {path}: {message}")]
    Labels {
        /// The label path.
        path: PathBuf,
        /// What went wrong.
        message: String,
    },
    /// A built-in input could not be generated.
    #[error("built-in input: {0}")]
    Demo(String),
    /// The pipeline failed.
    #[error(transparent)]
    Pipeline(#[from] PolylidarError),
    /// Scoring failed.
    #[error(transparent)]
    Metrics(#[from] seg_metrics::MetricsError),
    /// An output file could not be written.
    #[error("cannot write {path}: {message}")]
    Write {
        /// The output path.
        path: PathBuf,
        /// What went wrong.
        message: String,
    },
}

impl From<polylidar::OpcError> for CliError {
    fn from(e: polylidar::OpcError) -> Self {
        CliError::Pipeline(e.into())
    }
}

/// Runs the parsed command line.
pub fn run(cli: Cli) -> Result<(), CliError> {
    match cli.command {
        Command::Extract(args) => extract(&args),
        Command::Evaluate(args) => evaluate::evaluate(&args),
        Command::Generate(args) => evaluate::generate(&args),
    }
}

fn extract(args: &ExtractArgs) -> Result<(), CliError> {
    let config = params::config(&args.input)?;
    let stride = args.input.stride as usize;
    let Loaded {
        input,
        source,
        truth,
    } = load(args.input.input.as_deref(), args.input.demo, stride)?;
    let polylidar = Polylidar::new(config)?;
    let extraction = run_once(&polylidar, &input)?;
    let mut timings = vec![extraction.diagnostics.timings.clone()];
    for _ in 1..args.repeat {
        timings.push(run_once(&polylidar, &input)?.diagnostics.timings);
    }
    let processed = !args.raw && polylidar.config().postprocess.is_some();
    if let Some(path) = &args.output {
        let with_z = !matches!(input, Input::Points2d(_));
        let text = geojson::feature_collection(&extraction, with_z, processed);
        write(path, text.as_bytes())?;
    }
    if let Some(path) = &args.plot {
        let png = plot::render(&input, &extraction, polylidar.config().up, processed).map_err(
            |message| CliError::Write {
                path: path.clone(),
                message,
            },
        )?;
        write(path, &png)?;
    }
    if let Some(path) = &args.labels_out {
        let Some((rows, cols)) = input.grid() else {
            return Err(CliError::Unsupported {
                what: "--labels-out needs organized input (an image grid)".to_owned(),
            });
        };
        write_labels(path, rows, cols, &extraction.point_labels())?;
    }
    let score = match &truth {
        Some(truth) => Some(evaluate::score(
            &input,
            truth,
            &extraction.point_labels(),
            0.8,
        )?),
        None => None,
    };
    let counts = &extraction.diagnostics.counts;
    if args.json {
        println!(
            "{}",
            report::json(&source, &input, counts, &timings, score.as_ref())
        );
    } else {
        eprintln!(
            "{}",
            report::summary(&source, &input, counts, &timings, score.as_ref())
        );
    }
    Ok(())
}

/// One pipeline run on the input.
pub fn run_once(polylidar: &Polylidar, input: &Input) -> Result<Extraction, PolylidarError> {
    match input {
        Input::Points2d(points) => polylidar.extract_2d(points),
        Input::Cloud(points) => polylidar.extract_25d(points),
        Input::Organized(cloud) => polylidar.extract_organized(cloud),
        Input::Mesh {
            vertices,
            triangles,
        } => polylidar.extract_mesh(vertices.clone(), triangles.clone()),
    }
}

/// Writes an int32 `rows × cols` label image.
pub fn write_labels(path: &Path, rows: usize, cols: usize, labels: &[i32]) -> Result<(), CliError> {
    create_parent(path)?;
    polylidar_io::write_npy_i32(path, &[rows, cols], labels)?;
    Ok(())
}

/// Writes `bytes` to `path`, creating its directory.
pub fn write(path: &Path, bytes: &[u8]) -> Result<(), CliError> {
    create_parent(path)?;
    std::fs::write(path, bytes).map_err(|e| CliError::Write {
        path: path.to_path_buf(),
        message: e.to_string(),
    })
}

/// Creates the directory `path` will be written into.
pub fn create_parent(path: &Path) -> Result<(), CliError> {
    match path.parent().filter(|d| !d.as_os_str().is_empty()) {
        Some(dir) => std::fs::create_dir_all(dir).map_err(|e| CliError::Write {
            path: path.to_path_buf(),
            message: e.to_string(),
        }),
        None => Ok(()),
    }
}

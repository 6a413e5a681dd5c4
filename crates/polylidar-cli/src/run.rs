//! The subcommands: load, configure, run, write.

use std::path::PathBuf;

use polylidar::output::{PolygonSet, feature_collection};
use polylidar::{Extraction, Polylidar, PolylidarError};
use polylidar_io::IoError;

use crate::args::{Cli, Command, ExtractArgs, InputArgs};
use crate::input::{Input, Loaded, load_with_camera};
use crate::outputs::Outputs;
use crate::{evaluate, params, plot, report};

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
    /// A plane could not be meshed or textured.
    #[error(transparent)]
    Mesh(#[from] polylidar::planar_mesh::PlanarMeshError),
    /// An output file could not be written.
    #[error("cannot write {path}: {message}")]
    Write {
        /// The output path.
        path: PathBuf,
        /// What went wrong.
        message: String,
    },
    /// A step that ran on an input failed ([`CliError::about`]).
    #[error("{input}: {error}")]
    OnInput {
        /// The input's path or the demo's name.
        input: String,
        /// What went wrong.
        #[source]
        error: Box<CliError>,
    },
    /// A mesh file has a degenerate triangle.
    #[error("{input}: triangle {triangle} {vertices:?} is degenerate ({reason}): {advice}")]
    Degenerate {
        /// The mesh file.
        input: String,
        /// The triangle's index in the file.
        triangle: usize,
        /// Its vertex indices.
        vertices: [u32; 3],
        /// Why it is degenerate.
        reason: &'static str,
        /// What to do.
        advice: &'static str,
    },
}

impl CliError {
    /// This error as one of the input `source` (its path or the demo's name): pipeline,
    /// meshing and scoring errors say which input they are about; a degenerate triangle
    /// of a mesh file says how to proceed. Other errors already name their file.
    pub fn about(self, source: &str) -> CliError {
        let on = |error: CliError| CliError::OnInput {
            input: source.to_owned(),
            error: Box::new(error),
        };
        match self {
            CliError::Pipeline(PolylidarError::Mesh(
                polylidar::MeshError::DegenerateTriangle {
                    triangle,
                    vertices,
                    reason,
                },
            )) => CliError::Degenerate {
                input: source.to_owned(),
                triangle,
                vertices,
                advice: if reason.starts_with("too large") {
                    "its coordinates are too large to compute with; move the mesh nearer the \
                     origin or scale it down"
                } else {
                    "the mesh has triangles with a repeated corner or no area; remove them (in \
                     MeshLab: Filters › Cleaning and Repairing › Remove Duplicate Faces and \
                     Remove Zero Area Faces) and run again"
                },
                reason,
            },
            e @ (CliError::Pipeline(_) | CliError::Mesh(_) | CliError::Metrics(_)) => on(e),
            other => other,
        }
    }
}

/// `|e| e.into().about(source)`, for `map_err` on the steps that run on an input.
pub fn on_input<E: Into<CliError>>(source: &str) -> impl Fn(E) -> CliError + '_ {
    move |e| e.into().about(source)
}

impl From<polylidar::OpcError> for CliError {
    fn from(e: polylidar::OpcError) -> Self {
        CliError::Pipeline(e.into())
    }
}

/// How a command that ran without an error ended.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Outcome {
    /// Done.
    Done,
    /// `extract --strict` found nothing, or nearly nothing (exit code
    /// [`EXIT_EMPTY`]).
    Empty,
}

/// The exit code of `extract --strict` when the result is empty or nearly empty.
pub const EXIT_EMPTY: u8 = 3;

/// Runs the parsed command line.
pub fn run(cli: Cli) -> Result<Outcome, CliError> {
    match cli.command {
        Command::Extract(args) => extract(&args),
        Command::Evaluate(args) => evaluate::evaluate(&args).map(|()| Outcome::Done),
        Command::Generate(args) => evaluate::generate(&args).map(|()| Outcome::Done),
        Command::Mesh(args) => crate::mesh::mesh(&args),
        Command::Stream(args) => crate::stream::stream(args),
    }
}

fn extract(args: &ExtractArgs) -> Result<Outcome, CliError> {
    let mut outputs = Outputs::new();
    record_inputs(&mut outputs, &args.input);
    for (flag, path) in [
        ("-o", &args.output),
        ("--plot", &args.plot),
        ("--labels-out", &args.labels_out),
    ] {
        if let Some(path) = path {
            outputs.plan(flag, path)?;
        }
    }
    let stride = args.input.stride as usize;
    let Loaded {
        input,
        source,
        truth,
    } = load_with_camera(
        args.input.input.as_deref(),
        args.input.demo,
        stride,
        args.input.max_memory,
        &crate::input::camera(&args.camera)?,
    )?;
    let header_unit = match args.input.input.as_deref() {
        Some(path) if polylidar_io::format_of(path) == Some(polylidar_io::Format::Las) => {
            polylidar_io::read_las_unit(path)?
        }
        _ => None,
    };
    let grid = input.grid();
    if args.labels_out.is_some() && grid.is_none() {
        return Err(CliError::Unsupported {
            what: format!("{source}: --labels-out needs organized input (an image grid)"),
        });
    }
    let chosen = params::config_for(&args.input, &input, header_unit).map_err(on_input(&source))?;
    params::check_kernels(&chosen.config, &input, &source)?;
    for warning in inapplicable(&args.input, &input) {
        eprintln!("warning: {warning}");
    }
    let polylidar = Polylidar::new(chosen.config.clone())?;
    // The unorganized 3D path takes the normals the file stores.
    let normals = match (&input, args.input.input.as_deref()) {
        (Input::Cloud(points), Some(path)) if chosen.config.unorganized.is_some() => {
            polylidar::unorganized::read_normals(path)?.filter(|n| n.len() == points.len())
        }
        _ => None,
    };
    let run_input = || match (&input, &normals) {
        (Input::Cloud(points), Some(n)) => polylidar.extract_unorganized(points, Some(n)),
        _ => run_once(&polylidar, &input),
    };
    let extraction = run_input().map_err(on_input(&source))?;
    let mut timings = vec![extraction.diagnostics.timings.clone()];
    for _ in 1..args.repeat {
        let again = run_input().map_err(on_input(&source))?;
        timings.push(again.diagnostics.timings);
    }
    let processed = !args.raw && polylidar.config().postprocess.is_some();
    if let Some(path) = &args.output {
        let set = if processed {
            PolygonSet::Postprocessed
        } else {
            PolygonSet::Extracted
        };
        let text = feature_collection(&extraction, input.is_3d(), set);
        outputs.stage("-o", path, text.as_bytes())?;
    }
    if let Some(path) = &args.plot {
        let png = plot::render(&input, &extraction, polylidar.config().up, processed).map_err(
            |message| CliError::Write {
                path: path.clone(),
                message,
            },
        )?;
        outputs.stage("--plot", path, &png)?;
    }
    if let (Some(path), Some((rows, cols))) = (&args.labels_out, grid) {
        let npy = polylidar_io::encode_npy_i32(&[rows, cols], &extraction.point_labels())?;
        outputs.stage("--labels-out", path, &npy)?;
    }
    outputs.commit()?;
    let score = match &truth {
        Some(truth) => Some(
            evaluate::score(&input, truth, &extraction.plane_labels(), 0.8)
                .map_err(on_input(&source))?,
        ),
        None => None,
    };
    let explanation = polylidar::explain::explain(&extraction, polylidar.config(), chosen.spacing);
    let run = report::Run {
        source: &source,
        input: &input,
        chosen: &chosen,
        counts: &extraction.diagnostics.counts,
        runs: &timings,
        score: score.as_ref(),
        explanation: &explanation,
    };
    if args.json {
        println!("{}", report::json(&run));
    } else {
        eprintln!("{}", report::summary(&run));
    }
    if explanation.empty && !args.json {
        eprintln!("{}", report::explanation_text(&run, args.strict));
    }
    Ok(if explanation.empty && args.strict {
        Outcome::Empty
    } else {
        Outcome::Done
    })
}

/// The flags given that do not apply to `input`, as warnings.
fn inapplicable(args: &InputArgs, input: &Input) -> Vec<String> {
    let p = &args.params;
    let kind = match input {
        Input::Points2d(_) => "2D points",
        Input::Cloud(_) => "an unorganized 3D cloud (2.5D)",
        Input::Organized(_) => "an organized cloud (3D)",
        Input::Mesh { .. } => "a mesh (3D)",
    };
    let is_3d = matches!(input, Input::Organized(_) | Input::Mesh { .. });
    let given = [
        ("--alpha", p.alpha.is_some() && is_3d),
        ("--up", p.up.is_some() && !matches!(input, Input::Cloud(_))),
        (
            "--norm-thresh",
            p.norm_thresh.is_some() && matches!(input, Input::Points2d(_)),
        ),
        ("--z-thresh", p.z_thresh.is_some() && !is_3d),
        (
            "--no-smoothing",
            p.no_smoothing && !matches!(input, Input::Organized(_)),
        ),
        ("--gpu", p.gpu && !matches!(input, Input::Organized(_))),
        (
            "--decimate",
            p.decimate.is_some() && !matches!(input, Input::Organized(_)),
        ),
    ];
    given
        .into_iter()
        .filter(|(_, ignored)| *ignored)
        .map(|(flag, _)| format!("{flag} does not apply to {kind}; ignored"))
        .collect()
}

/// Records the files `args` reads as inputs no output may overwrite: the input, the
/// `--config` file and a depth PNG's metadata CSV.
pub fn record_inputs(outputs: &mut Outputs, args: &InputArgs) {
    if let Some(path) = &args.input {
        outputs.input("the input", path);
        if let Ok(csv) = polylidar_io::metadata_path_for(path) {
            outputs.input("the input's metadata CSV", &csv);
        }
    }
    if let Some(path) = &args.config {
        outputs.input("the --config file", path);
    }
}

/// One pipeline run on the input ([`Polylidar::extract`]).
pub fn run_once(polylidar: &Polylidar, input: &Input) -> Result<Extraction, PolylidarError> {
    polylidar.extract(input)
}

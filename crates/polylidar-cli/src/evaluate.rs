//! `polylidar evaluate` (Hoover et al. scores against ground-truth labels) and
//! `polylidar generate` (SynPEB-like scans with labels).

use polylidar::Polylidar;
use polylidar_io::{PcdEncoding, PointCloud};
use seg_metrics::{EvaluateOptions, Evaluation};
use serde_json::json;

use crate::args::{EvaluateArgs, GenerateArgs};
use crate::input::{Input, Loaded, generate_scan, load, read_labels};
use crate::run::{CliError, create_parent, run_once, write_labels};
use crate::{params, report};

/// Scores `predicted` against `truth` on the points of an organized input.
pub fn score(
    input: &Input,
    truth: &[i32],
    predicted: &[i32],
    overlap: f64,
) -> Result<Evaluation, CliError> {
    let Input::Organized(cloud) = input else {
        return Err(CliError::Unsupported {
            what: "scoring needs organized input (one label per pixel)".to_owned(),
        });
    };
    let options = EvaluateOptions::new().with_overlap(overlap);
    Ok(seg_metrics::evaluate(
        cloud.points(),
        truth,
        predicted,
        &options,
    )?)
}

/// `polylidar evaluate`: runs the pipeline (or reads `--predicted`) and prints the scores
/// as one JSON object.
pub fn evaluate(args: &EvaluateArgs) -> Result<(), CliError> {
    let config = params::config(&args.input)?;
    let Loaded {
        input,
        source,
        truth,
    } = load(
        args.input.input.as_deref(),
        args.input.demo,
        args.input.stride as usize,
    )?;
    let Some((rows, cols)) = input.grid() else {
        return Err(CliError::Unsupported {
            what: format!("{source}: `evaluate` needs organized input (an image grid)"),
        });
    };
    let truth = match (&args.labels, truth) {
        (Some(path), _) => read_labels(path, rows * cols)?,
        (None, Some(truth)) => truth,
        (None, None) => {
            return Err(CliError::Unsupported {
                what: "--labels is required for file input".to_owned(),
            });
        }
    };
    let (predicted, timings) = match &args.predicted {
        Some(path) => (read_labels(path, rows * cols)?, None),
        None => {
            let extraction = run_once(&Polylidar::new(config)?, &input)?;
            let timings = extraction.diagnostics.timings.clone();
            (extraction.point_labels(), Some(timings))
        }
    };
    let evaluation = score(&input, &truth, &predicted, args.overlap)?;
    let mut out = json!({
        "input": { "source": source, "rows": rows, "cols": cols, "points": input.len() },
        "metrics": report::metrics_json(&evaluation),
    });
    if let Some(t) = timings {
        out["timings_ms"] = report::timings_json(&[t]);
    }
    println!("{out}");
    Ok(())
}

/// `polylidar generate`: a SynPEB-like scan written as an organized cloud plus labels.
pub fn generate(args: &GenerateArgs) -> Result<(), CliError> {
    let scan = generate_scan(args.seed, args.noise_mdeg, args.noise_radial)?;
    let (rows, cols) = (scan.rows, scan.cols);
    create_parent(&args.output)?;
    match args
        .output
        .extension()
        .and_then(|e| e.to_str())
        .map(str::to_ascii_lowercase)
        .as_deref()
    {
        Some("pcd") => {
            let cloud = PointCloud::organized(rows, cols, scan.points)?;
            polylidar_io::write_pcd(&args.output, &cloud, PcdEncoding::Binary)?;
        }
        Some("npy") => {
            let flat: Vec<f64> = scan.points.iter().flatten().copied().collect();
            polylidar_io::write_npy_f64(&args.output, &[rows, cols, 3], &flat)?;
        }
        _ => {
            return Err(CliError::Unsupported {
                what: format!("{}: write .pcd or .npy", args.output.display()),
            });
        }
    }
    write_labels(&args.labels_out, rows, cols, &scan.labels)?;
    eprintln!(
        "{}: {rows} × {cols} scan of seed {} ({} planes, {} mdeg, {} m radial); labels in {}",
        args.output.display(),
        args.seed,
        scan.planes.len(),
        args.noise_mdeg,
        args.noise_radial,
        args.labels_out.display()
    );
    Ok(())
}

//! `polylidar evaluate` (Hoover et al. scores against ground-truth labels, and why each
//! missed plane was missed) and `polylidar generate` (SynPEB-like scans with labels).

use std::path::Path;

use polylidar::misses::{Miss, MissCause, count_causes, explain_misses};
use polylidar::{Extraction, Polylidar};
use polylidar_io::{PcdEncoding, PcdWriteOptions, PointCloud};
use seg_metrics::{EvaluateOptions, Evaluation, TruthClass};
use serde_json::json;
use tiny_skia::{Pixmap, PremultipliedColorU8};

use crate::args::{EvaluateArgs, GenerateArgs};
use crate::input::{Input, Loaded, generate_scan, load, read_labels};
use crate::outputs::Outputs;
use crate::run::{CliError, on_input, record_inputs, run_once};
use crate::{params, report};

/// Smallest SynPEB plane id in a PCD's `intensity` field; smaller values are no plane.
const SYNPEB_FIRST_PLANE: f64 = 10.0;

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

/// `polylidar evaluate`: runs the pipeline (or reads `--predicted`), scores it, explains
/// every plane it missed, and prints a summary (or `--json`).
pub fn evaluate(args: &EvaluateArgs) -> Result<(), CliError> {
    if args.input.demo == Some(crate::args::Demo::Shape) {
        return Err(CliError::Unsupported {
            what: "`evaluate` scores organized clouds; `--demo shape` is a 2D point set (use \
                   `--demo scene`)"
                .to_owned(),
        });
    }
    let mut outputs = Outputs::new();
    record_inputs(&mut outputs, &args.input);
    for (what, path) in [("--labels", &args.labels), ("--predicted", &args.predicted)] {
        if let Some(path) = path {
            outputs.input(&format!("the {what} file"), path);
        }
    }
    if let Some(path) = &args.plot {
        outputs.plan("--plot", path)?;
    }
    let config = params::config(&args.input)?;
    let Loaded {
        input,
        source,
        truth,
    } = load(
        args.input.input.as_deref(),
        args.input.demo,
        args.input.stride as usize,
        args.input.max_memory,
    )?;
    let Some((rows, cols)) = input.grid() else {
        return Err(CliError::Unsupported {
            what: format!("{source}: `evaluate` needs organized input (an image grid)"),
        });
    };
    if args.predicted.is_none() {
        params::check_kernels(&config, &input, &source)?;
    }
    let truth = match (&args.labels, truth, args.input.input.as_deref()) {
        (Some(path), _, _) => read_labels(path, rows * cols)?,
        (None, Some(truth), _) => truth,
        (None, None, Some(path)) => pcd_labels(path, args.input.stride as usize, cols)?,
        (None, None, None) => {
            return Err(CliError::Unsupported {
                what: "--labels is required".to_owned(),
            });
        }
    };
    let (extraction, predicted) = match &args.predicted {
        Some(path) => (None, read_labels(path, rows * cols)?),
        None => {
            let polylidar = Polylidar::new(config.clone())?;
            let extraction = run_once(&polylidar, &input).map_err(on_input(&source))?;
            let labels = extraction.plane_labels();
            (Some(extraction), labels)
        }
    };
    let evaluation = score(&input, &truth, &predicted, args.overlap).map_err(on_input(&source))?;
    let misses = extraction
        .as_ref()
        .map(|e| explain_misses(e, &config, &truth, &evaluation, args.overlap));
    if let Some(path) = &args.plot {
        let labels = (truth.as_slice(), predicted.as_slice());
        let png = render(rows, cols, &input, labels, &evaluation, misses.as_deref())?;
        outputs.stage("--plot", path, &png)?;
        outputs.commit()?;
        eprintln!("{}", legend(path));
    }
    if args.json {
        let mut out = json!({
            "input": { "source": source, "rows": rows, "cols": cols, "points": input.len() },
            "metrics": report::metrics_json(&evaluation),
        });
        if let Some(misses) = &misses {
            out["causes"] = causes_json(misses);
        }
        if let Some(e) = &extraction {
            out["timings_ms"] = report::timings_json(std::slice::from_ref(&e.diagnostics.timings));
        }
        println!("{out}");
    } else {
        print!(
            "{}",
            summary(&source, &evaluation, extraction.as_ref(), misses.as_deref())
        );
    }
    Ok(())
}

/// Ground truth from a PCD's `label` field (−1: none) or SynPEB's `intensity` field,
/// downsampled like the cloud.
fn pcd_labels(path: &Path, stride: usize, cols: usize) -> Result<Vec<i32>, CliError> {
    let missing = || CliError::Unsupported {
        what: format!(
            "{}: no ground truth; give --labels (the file has no `label` or `intensity` field)",
            path.display()
        ),
    };
    if polylidar_io::format_of(path) != Some(polylidar_io::Format::Pcd) {
        return Err(missing());
    }
    let columns = polylidar_io::read_pcd_fields(path)?;
    let field = |name: &str| columns.names.iter().position(|n| n == name);
    let labels: Vec<i32> = if let Some(k) = field("label") {
        columns.values[k]
            .iter()
            .map(|&v| {
                if v.is_finite() && v >= 0.0 {
                    v as i32
                } else {
                    -1
                }
            })
            .collect()
    } else if let Some(k) = field("intensity") {
        columns.values[k]
            .iter()
            .map(|&v| {
                if v.is_finite() && v >= SYNPEB_FIRST_PLANE {
                    v as i32
                } else {
                    -1
                }
            })
            .collect()
    } else {
        return Err(missing());
    };
    let full_cols = columns.width;
    let kept: Vec<i32> = labels
        .iter()
        .enumerate()
        .filter(|(i, _)| (i / full_cols) % stride == 0 && (i % full_cols) % stride == 0)
        .map(|(_, &l)| l)
        .collect();
    if cols == 0 || !kept.len().is_multiple_of(cols) {
        return Err(CliError::Unsupported {
            what: format!("{}: the labels do not fit the cloud", path.display()),
        });
    }
    Ok(kept)
}

/// The readable summary: scores, counts, causes of misses, one line per missed plane.
fn summary(
    source: &str,
    e: &Evaluation,
    extraction: Option<&Extraction>,
    misses: Option<&[Miss]>,
) -> String {
    let mut s = format!("{source}\n");
    s += &format!(
        "  f {:.1} %  k {:.1} %  ({} of {} found; {} predicted)\n",
        e.f,
        e.k,
        e.correct,
        report::count(e.truth_planes, "ground-truth plane", "ground-truth planes"),
        report::count(e.predicted_planes, "plane", "planes"),
    );
    s += &format!(
        "  split {}  merged {}  missed {}  spurious {}",
        e.over_segmented, e.under_segmented, e.missed, e.spurious
    );
    if let Some(rmse) = e.rmse {
        s += &format!("  RMSE {:.1} mm", rmse * 1e3);
    }
    s += "\n";
    if let Some(x) = extraction {
        let c = &x.diagnostics.counts;
        s += &format!(
            "  pipeline: {}, {} Laplacian {}, {}\n",
            report::count(c.dominant_normals, "dominant normal", "dominant normals"),
            c.laplacian_iterations,
            if c.laplacian_iterations == 1 {
                "pass"
            } else {
                "passes"
            },
            report::count(x.polygons.len(), "polygon", "polygons"),
        );
    }
    let Some(misses) = misses else {
        return s;
    };
    if misses.is_empty() {
        s += "  every ground-truth plane found, nothing spurious\n";
        return s;
    }
    s += "  causes:\n";
    for (name, n) in count_causes(misses) {
        s += &format!("    {n:>4}  {name}\n");
    }
    s += "  planes:\n";
    for m in misses {
        let what = if m.cause.is_spurious() {
            format!("predicted {}", m.id)
        } else {
            format!("truth {}", m.id)
        };
        s += &format!(
            "    {what:<14} {:>7} points  {}\n",
            m.points,
            describe(&m.cause)
        );
    }
    s
}

/// One cause with its numbers.
fn describe(cause: &MissCause) -> String {
    let name = cause.name();
    match *cause {
        MissCause::DroppedByLmax { share } | MissCause::DroppedByNormal { share } => {
            format!("{name} ({:.0} % of its triangles)", share * 100.0)
        }
        MissCause::NoDominantNormal { degrees } => {
            format!("{name} (nearest {degrees:.1}° away)")
        }
        MissCause::Split { pieces } => format!("{name} ({pieces})"),
        MissCause::RegionTooSmall { triangles } => {
            format!("{name} ({triangles} triangles in no polygon)")
        }
        MissCause::MergedIntoNeighbour { predicted } => {
            format!("{name} (predicted plane {predicted})")
        }
        MissCause::LowOverlap {
            of_truth,
            of_predicted,
        } => format!(
            "{name} ({:.0} % of the plane, {:.0} % of the prediction)",
            of_truth * 100.0,
            of_predicted * 100.0
        ),
        MissCause::SpuriousPiece { truth } => format!("{name} (of truth {truth})"),
        MissCause::NoTriangles | MissCause::SpuriousClutter => name.to_owned(),
    }
}

fn causes_json(misses: &[Miss]) -> serde_json::Value {
    let counts: serde_json::Map<String, serde_json::Value> = count_causes(misses)
        .into_iter()
        .map(|(name, n)| (name.to_owned(), json!(n)))
        .collect();
    let planes: Vec<serde_json::Value> = misses
        .iter()
        .map(|m| {
            json!({
                "id": m.id,
                "kind": if m.cause.is_spurious() { "predicted" } else { "truth" },
                "points": m.points,
                "cause": m.cause.name(),
                "detail": describe(&m.cause),
            })
        })
        .collect();
    json!({ "counts": counts, "planes": planes })
}

/// The colour of each cause in `--plot`.
const CAUSE_COLOURS: [(&str, [u8; 3]); 10] = [
    ("no triangles", [90, 90, 90]),
    ("dropped by lmax", [230, 25, 75]),
    ("no dominant normal near it", [245, 130, 48]),
    ("dropped by norm_thresh", [255, 225, 25]),
    ("split into pieces", [0, 130, 200]),
    ("regions below min_triangles", [145, 30, 180]),
    ("merged into a neighbour", [70, 240, 240]),
    ("overlap under the threshold", [240, 50, 230]),
    ("spurious: clutter", [255, 255, 255]),
    ("spurious: piece of a plane", [255, 255, 255]),
];
/// Correctly found planes.
const FOUND: [u8; 3] = [110, 150, 110];
/// Ground-truth planes not found, when no cause is known (scoring `--predicted` labels).
const NOT_FOUND: [u8; 3] = [150, 100, 40];
/// Valid pixels of no ground-truth plane.
const UNLABELLED: [u8; 3] = [45, 45, 45];

fn legend(path: &Path) -> String {
    let mut s = format!(
        "{}: ground truth by outcome; found: grey-green; no plane: dark grey; no return: black; spurious planes: white dots; not found (no cause known with --predicted): rgb(150, 100, 40)",
        path.display()
    );
    for (name, [r, g, b]) in CAUSE_COLOURS
        .iter()
        .filter(|(name, _)| !name.starts_with("spurious"))
    {
        s += &format!("; {name}: rgb({r}, {g}, {b})");
    }
    s
}

/// The ground truth painted by outcome, one block of pixels per cloud pixel.
fn render(
    rows: usize,
    cols: usize,
    input: &Input,
    (truth, predicted): (&[i32], &[i32]),
    evaluation: &Evaluation,
    misses: Option<&[Miss]>,
) -> Result<Vec<u8>, CliError> {
    let Input::Organized(cloud) = input else {
        return Err(CliError::Unsupported {
            what: "--plot needs organized input".to_owned(),
        });
    };
    let found: std::collections::BTreeSet<i32> = evaluation
        .truth_regions
        .iter()
        .filter(|r| matches!(r.class, TruthClass::Correct { .. } | TruthClass::Ignored))
        .map(|r| r.id)
        .collect();
    // The colour of each ground-truth plane that was not found, by its cause.
    let colour_of: std::collections::BTreeMap<i32, [u8; 3]> = misses
        .unwrap_or(&[])
        .iter()
        .filter(|m| !m.cause.is_spurious())
        .filter_map(|m| {
            let colour = CAUSE_COLOURS
                .iter()
                .find(|(name, _)| *name == m.cause.name())?;
            Some((m.id, colour.1))
        })
        .collect();
    let scale = (1200 / rows.max(cols)).max(1);
    let (width, height) = ((cols * scale) as u32, (rows * scale) as u32);
    let bad = |message: String| CliError::Unsupported { what: message };
    let mut pixmap = Pixmap::new(width, height)
        .ok_or_else(|| bad(format!("cannot draw a {width} × {height} picture")))?;
    let points = cloud.points();
    let spurious: std::collections::BTreeSet<i32> = misses
        .unwrap_or(&[])
        .iter()
        .filter(|m| m.cause.is_spurious())
        .map(|m| m.id)
        .collect();
    let pixels = pixmap.pixels_mut();
    for r in 0..rows {
        for c in 0..cols {
            let i = r * cols + c;
            let valid = points[i].iter().all(|v| v.is_finite());
            let label = truth[i];
            let colour = if !valid {
                [0, 0, 0]
            } else if spurious.contains(&predicted[i]) && (r + c) % 3 == 0 {
                [255, 255, 255]
            } else if label < 0 {
                UNLABELLED
            } else if found.contains(&label) {
                FOUND
            } else {
                colour_of.get(&label).copied().unwrap_or(NOT_FOUND)
            };
            for y in 0..scale {
                for x in 0..scale {
                    let p = (r * scale + y) * width as usize + c * scale + x;
                    pixels[p] =
                        PremultipliedColorU8::from_rgba(colour[0], colour[1], colour[2], 255)
                            .unwrap_or(PremultipliedColorU8::TRANSPARENT);
                }
            }
        }
    }
    pixmap
        .encode_png()
        .map_err(|e| bad(format!("cannot encode the picture: {e}")))
}

/// `polylidar generate`: a SynPEB-like scan written as an organized cloud plus labels.
pub fn generate(args: &GenerateArgs) -> Result<(), CliError> {
    let mut outputs = Outputs::new();
    outputs.plan("-o", &args.output)?;
    outputs.plan("--labels-out", &args.labels_out)?;
    let scan = generate_scan(args.seed, args.noise_mdeg, args.noise_radial)?;
    let (rows, cols) = (scan.rows, scan.cols);
    let cloud = match args
        .output
        .extension()
        .and_then(|e| e.to_str())
        .map(str::to_ascii_lowercase)
        .as_deref()
    {
        Some("pcd") => {
            let cloud = PointCloud::organized(rows, cols, scan.points)?;
            polylidar_io::encode_pcd(&cloud, &PcdWriteOptions::new(PcdEncoding::Binary))?
        }
        Some("npy") => {
            let flat: Vec<f64> = scan.points.iter().flatten().copied().collect();
            polylidar_io::encode_npy_f64(&[rows, cols, 3], &flat)?
        }
        _ => {
            return Err(CliError::Unsupported {
                what: format!("{}: write .pcd or .npy", args.output.display()),
            });
        }
    };
    let labels = polylidar_io::encode_npy_i32(&[rows, cols], &scan.labels)?;
    outputs.stage("-o", &args.output, &cloud)?;
    outputs.stage("--labels-out", &args.labels_out, &labels)?;
    outputs.commit()?;
    let seen: std::collections::BTreeSet<i32> =
        scan.labels.iter().copied().filter(|&l| l >= 0).collect();
    eprintln!(
        "{}: {rows} × {cols} scan of seed {} ({} in the scene, {} in view; `evaluate` scores \
         the planes in view), {} mdeg, {} m radial; labels in {}",
        args.output.display(),
        args.seed,
        report::count(scan.planes.len(), "plane", "planes"),
        report::count(seen.len(), "plane", "planes"),
        args.noise_mdeg,
        args.noise_radial,
        args.labels_out.display()
    );
    Ok(())
}

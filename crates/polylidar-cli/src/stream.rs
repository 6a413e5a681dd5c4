//! `polylidar stream`: one pipeline over a stream of depth frames (a folder or glob of
//! 16-bit depth PNGs, or of organized clouds), frames read and decoded on a loader thread
//! while the previous one runs; GeoJSON lines or one file per frame, per-frame timings and
//! a summary of the stages (median, 90th percentile).

use std::io::{IsTerminal, Write};
use std::path::{Path, PathBuf};
use std::time::{Duration, Instant};

use clap::Args;
use polylidar::io::{DepthCamera, Input};
use polylidar::output::{Annotations, PolygonSet, feature_collection_with};
use polylidar::stream::{StreamOptions, StreamedFrame};
use polylidar::{Extraction, OrganizedPointCloud, Polylidar, PolylidarError};
use polylidar_io::ColorImage;
use polylidar_io::atomic::StagedFile;
use serde_json::{Map, Value, json};

use crate::args::{CameraArgs, InputArgs};
use crate::input::{camera, read_with_camera};
use crate::outputs::Outputs;
use crate::params;
use crate::run::{CliError, Outcome, record_inputs};

/// Arguments of `polylidar stream`.
#[derive(Debug, Args)]
pub struct StreamArgs {
    /// The frames (INPUT: a folder or a glob) and the parameters. A folder gives its
    /// `.png` files with `depth` in the name, or all its `.png` files when none has; a
    /// glob (`frames/depth_*.png`; `*` and `?` in the file name only) gives the files it
    /// matches, depth PNGs or organized clouds. Frames run in sorted order of their paths.
    #[command(flatten)]
    pub input: InputArgs,
    /// The camera of the depth PNGs.
    #[command(flatten)]
    pub camera: CameraArgs,
    /// The colour pictures of the frames: a folder (its `.png`/`.jpg` files with `color`
    /// or `rgb` in the name, else all) or a glob; the n-th in sorted order belongs to the
    /// n-th depth frame and must have its size. Each polygon then gets the mean colour of
    /// its pixels as the `color` property (`[r, g, b]`, 0–255).
    #[arg(long, value_name = "FOLDER|GLOB", help_heading = "Stream")]
    pub color: Option<String>,
    /// Write one line per frame: a GeoJSON FeatureCollection with the frame's path as the
    /// `frame` member (GeoJSON lines).
    #[arg(
        short,
        long,
        value_name = "FILE",
        required_unless_present = "out_dir",
        conflicts_with = "out_dir",
        help_heading = "Stream"
    )]
    pub output: Option<PathBuf>,
    /// Write one GeoJSON file per frame into this folder, named after the frame
    /// (`depth_00004.png` → `depth_00004.geojson`).
    #[arg(long, value_name = "DIR", help_heading = "Stream")]
    pub out_dir: Option<PathBuf>,
    /// Write the polygons as extracted, even when the parameters post-process them.
    #[arg(long, help_heading = "Stream")]
    pub raw: bool,
    /// Frames read and decoded ahead on a loader thread (0: read each in turn).
    #[arg(long, value_name = "N", default_value_t = 1, help_heading = "Stream")]
    pub prefetch: usize,
    /// Frames run at once on the pipeline's threads; 0 chooses 1 or 2 by measuring: it
    /// starts with 2 where the parameters refine the planes (the `-auto` presets), else
    /// 1, and every 256 frames times 16 frames with each and keeps the faster. 1 gives
    /// each frame's result soonest. GPU smoothing runs one at a time.
    #[arg(long, value_name = "N", default_value_t = 0,
          value_parser = clap::value_parser!(u16).range(0..=4), help_heading = "Stream")]
    pub in_flight: u16,
    /// Print one JSON object on stdout: each frame's polygons and timings (ms), the
    /// median and 90th percentile of every stage, and the stream's wall time per frame
    /// (`period_ms`).
    #[arg(long, help_heading = "Stream")]
    pub json: bool,
}

/// Runs `polylidar stream`.
///
/// The outputs are checked before the first frame is read (as [`Outputs::plan`]: writable,
/// no output the same file as another or as a frame, a colour picture, `--config` or
/// `--intrinsics`), written to temporary files beside their targets as the frames come,
/// and renamed into place only when every frame has run: a failure leaves the previous
/// files as they were and no temporary file behind.
///
/// # Errors
/// No frames, unreadable first frame, bad parameters, unwritable output; frames that fail
/// are reported on stderr as they come and make the command fail at the end, with nothing
/// written.
pub fn stream(args: StreamArgs) -> Result<Outcome, CliError> {
    if args.input.demo.is_some() {
        return Err(unsupported("stream runs over frames in files, not --demo"));
    }
    let pattern = args
        .input
        .input
        .as_deref()
        .ok_or_else(|| unsupported("stream needs a folder or glob of frames"))?;
    let frames = list_frames(pattern, &["depth"], &["png"])?;
    let colors = match &args.color {
        Some(c) => {
            let colors = list_frames(Path::new(c), &["color", "rgb"], &["png", "jpg", "jpeg"])?;
            if colors.len() != frames.len() {
                return Err(unsupported(&format!(
                    "{} depth frames but {} colour pictures",
                    frames.len(),
                    colors.len()
                )));
            }
            colors.into_iter().map(Some).collect()
        }
        None => vec![None; frames.len()],
    };
    let mut outputs = Outputs::new();
    record_inputs(&mut outputs, &args.input);
    for path in frames.iter().chain(colors.iter().flatten()) {
        outputs.input("a frame", path);
        if let Ok(csv) = polylidar_io::metadata_path_for(path) {
            outputs.input("a frame's metadata CSV", &csv);
        }
    }
    if let Some(path) = args.camera.intrinsics.as_deref().map(Path::new) {
        outputs.input("the --intrinsics file", path);
    }
    let target = Target::plan(&args, &frames, &mut outputs)?;
    let camera = camera(&args.camera)?;
    let max_memory = args.input.max_memory;
    let stride = args.input.stride as usize;
    let first = load_cloud(&frames[0], &camera, max_memory, stride)?;
    let chosen = params::config_for(&args.input, &Input::Organized(first), None)?;
    let polylidar = Polylidar::new(chosen.config)?;
    let set = if !args.raw && polylidar.config().postprocess.is_some() {
        PolygonSet::Postprocessed
    } else {
        PolygonSet::Extracted
    };
    let mut out = Output::open(target, outputs)?;
    let total = frames.len();
    let sources: Vec<(String, (PathBuf, Option<PathBuf>))> = frames
        .into_iter()
        .zip(colors)
        .map(|(depth, color)| (depth.display().to_string(), (depth, color)))
        .collect();
    let load = move |(depth, color): (PathBuf, Option<PathBuf>)| {
        let cloud = load_cloud(&depth, &camera, max_memory, stride).map_err(pipeline_error)?;
        let colors = match color {
            Some(path) => Some(read_color(&path, &cloud, stride).map_err(pipeline_error)?),
            None => None,
        };
        Ok((cloud, colors))
    };
    let options = StreamOptions::default()
        .with_prefetch(args.prefetch)
        .with_in_flight(usize::from(args.in_flight));
    let started = Instant::now();
    let progress = std::io::stderr().is_terminal() && !args.json;
    let mut records = Vec::with_capacity(total);
    let mut failed = 0;
    for frame in polylidar.stream_with(sources, load, options) {
        match &frame.extraction {
            Ok(extraction) => {
                let colors = frame.extra.as_ref().and_then(Option::as_ref);
                out.write_frame(&frame.name, extraction, set, colors, stride)?;
            }
            Err(e) => {
                failed += 1;
                if progress {
                    eprintln!();
                }
                // Input errors already begin with the frame's path.
                let text = e.to_string();
                if text.starts_with(&frame.name) {
                    eprintln!("error: frame {text}");
                } else {
                    eprintln!("error: frame {}: {text}", frame.name);
                }
            }
        }
        if progress {
            eprint!(
                "\r[{}/{total}] {} ms  {}",
                frame.index + 1,
                ms(frame.wait + frame.run),
                frame.name
            );
        }
        records.push(Record::of(&frame));
        // The next frame is meshed into this one's arrays.
        if let Ok(extraction) = frame.extraction {
            polylidar.recycle(extraction);
        }
    }
    let elapsed = started.elapsed();
    if progress {
        eprintln!();
    }
    if failed == 0 {
        out.commit()?;
    }
    if args.json {
        println!("{}", json_report(&records, elapsed));
    } else {
        eprintln!("{}", summary_text(&records, elapsed));
    }
    if failed > 0 {
        return Err(unsupported(&format!(
            "{failed} of {total} frames failed; nothing was written (the outputs are \
             written only when every frame runs)"
        )));
    }
    Ok(Outcome::Done)
}

fn unsupported(what: &str) -> CliError {
    CliError::Unsupported {
        what: what.to_owned(),
    }
}

/// A CLI error as the stream's frame error.
fn pipeline_error(e: CliError) -> PolylidarError {
    match e {
        CliError::Pipeline(e) => e,
        CliError::Input(e) => PolylidarError::Io(e),
        other => PolylidarError::Io(polylidar_io::IoError::new(
            polylidar_io::Format::Unknown,
            polylidar_io::ErrorKind::Unusable(other.to_string()),
        )),
    }
}

/// Reads a frame as an organized cloud, downsampled by `stride`, within `--max-memory` or
/// the default budget of the frame's size.
fn load_cloud(
    path: &Path,
    camera: &DepthCamera,
    max_memory: Option<u64>,
    stride: usize,
) -> Result<OrganizedPointCloud, CliError> {
    let limits = crate::input::limits_for(path, max_memory);
    let (input, _) = read_with_camera(path, camera, &limits)?;
    let Input::Organized(cloud) = input else {
        return Err(unsupported(&format!(
            "{}: a stream frame must be a depth PNG or an organized cloud, not {}",
            path.display(),
            input.kind()
        )));
    };
    Ok(if stride > 1 {
        cloud.downsample(stride)?
    } else {
        cloud
    })
}

/// Reads a colour picture, checked against the frame's size (before the stride).
fn read_color(
    path: &Path,
    cloud: &OrganizedPointCloud,
    stride: usize,
) -> Result<ColorImage, CliError> {
    let image = polylidar_io::read_color_image(path)?;
    let (rows, cols) = (image.height.div_ceil(stride), image.width.div_ceil(stride));
    if (rows, cols) != (cloud.rows(), cloud.cols()) {
        return Err(unsupported(&format!(
            "{}: the colour picture is {} × {}, its depth frame {} × {}",
            path.display(),
            image.width,
            image.height,
            cloud.cols() * stride,
            cloud.rows() * stride
        )));
    }
    Ok(image)
}

/// The frames of `pattern`, sorted: a folder's files with an extension of `extensions`
/// (those whose name contains one of `preferred` when any does), or a glob's matches.
///
/// # Errors
/// An unreadable folder, wildcards outside the file name, no match.
fn list_frames(
    pattern: &Path,
    preferred: &[&str],
    extensions: &[&str],
) -> Result<Vec<PathBuf>, CliError> {
    let read_dir = |dir: &Path| -> Result<Vec<PathBuf>, CliError> {
        let entries = std::fs::read_dir(dir)
            .map_err(|e| unsupported(&format!("cannot list the folder {}: {e}", dir.display())))?;
        Ok(entries
            .filter_map(Result::ok)
            .map(|e| e.path())
            .filter(|p| p.is_file())
            .collect())
    };
    let name_of = |p: &Path| {
        p.file_name()
            .map(|n| n.to_string_lossy().to_ascii_lowercase())
            .unwrap_or_default()
    };
    let mut frames = if pattern.is_dir() {
        let with_extension: Vec<PathBuf> = read_dir(pattern)?
            .into_iter()
            .filter(|p| {
                let name = name_of(p);
                extensions.iter().any(|e| name.ends_with(&format!(".{e}")))
            })
            .collect();
        let is_preferred = |p: &PathBuf| preferred.iter().any(|k| name_of(p).contains(k));
        if with_extension.iter().any(is_preferred) {
            with_extension.into_iter().filter(is_preferred).collect()
        } else {
            with_extension
        }
    } else {
        let text = pattern.to_string_lossy();
        let (dir, glob) = match text.rfind('/') {
            Some(i) => (&text[..=i], &text[i + 1..]),
            None => ("", &*text),
        };
        if dir.contains(['*', '?']) {
            return Err(unsupported(&format!(
                "{text}: wildcards are allowed in the file name only"
            )));
        }
        let folder = if dir.is_empty() {
            Path::new(".")
        } else {
            Path::new(dir)
        };
        let glob: Vec<char> = glob.chars().collect();
        read_dir(folder)?
            .into_iter()
            .filter(|p| {
                let name: Vec<char> = p
                    .file_name()
                    .map(|n| n.to_string_lossy().chars().collect())
                    .unwrap_or_default();
                matches(&glob, &name)
            })
            .map(|p| match dir {
                "" => PathBuf::from(p.file_name().unwrap_or_default()),
                _ => p,
            })
            .collect()
    };
    frames.sort();
    if frames.is_empty() {
        return Err(unsupported(&format!(
            "{}: no frames found",
            pattern.display()
        )));
    }
    Ok(frames)
}

/// Whether `name` matches the glob `pattern` (`*`: any run of characters, `?`: one).
fn matches(pattern: &[char], name: &[char]) -> bool {
    match pattern.split_first() {
        None => name.is_empty(),
        Some(('*', rest)) => (0..=name.len()).any(|k| matches(rest, &name[k..])),
        Some((&c, rest)) => match name.split_first() {
            Some((&n, tail)) => (c == '?' || c == n) && matches(rest, tail),
            None => false,
        },
    }
}

/// Where the frames' polygons go, checked before the first frame is read.
enum Target {
    /// GeoJSON lines in one file (`-o`).
    Lines(PathBuf),
    /// One file per frame in a folder (`--out-dir`): the flag naming each frame's output
    /// in errors, by the frame's name.
    Folder(PathBuf, std::collections::HashMap<String, String>),
}

impl Target {
    /// Checks the output file, or each frame's file in the output folder, with `outputs`.
    fn plan(
        args: &StreamArgs,
        frames: &[PathBuf],
        outputs: &mut Outputs,
    ) -> Result<Self, CliError> {
        match (&args.output, &args.out_dir) {
            (Some(path), _) => {
                outputs.plan("-o", path)?;
                Ok(Self::Lines(path.clone()))
            }
            (None, Some(dir)) => {
                let mut flags = std::collections::HashMap::new();
                for frame in frames {
                    let name = frame.display().to_string();
                    let flag = format!("--out-dir's file for {name}");
                    outputs.plan(&flag, &frame_file(dir, &name))?;
                    flags.insert(name, flag);
                }
                Ok(Self::Folder(dir.clone(), flags))
            }
            (None, None) => Err(unsupported("stream needs -o FILE or --out-dir DIR")),
        }
    }
}

/// The output file of the frame `name` in the folder `dir`: `depth_00004.png` →
/// `dir/depth_00004.geojson`.
fn frame_file(dir: &Path, name: &str) -> PathBuf {
    let stem = Path::new(name)
        .file_stem()
        .map(|s| s.to_string_lossy().into_owned())
        .unwrap_or_else(|| "frame".to_owned());
    dir.join(format!("{stem}.geojson"))
}

/// The outputs being written: nothing replaces a file before [`Output::commit`], and
/// dropping an `Output` removes its temporary files.
struct Output {
    /// The GeoJSON lines' target and its temporary file, when writing `-o`.
    lines: Option<(PathBuf, StagedFile, std::io::BufWriter<std::fs::File>)>,
    /// The folder's per-frame flags, when writing `--out-dir`.
    folder: Option<(PathBuf, std::collections::HashMap<String, String>)>,
    /// The per-frame files staged so far.
    outputs: Outputs,
}

impl Output {
    fn open(target: Target, outputs: Outputs) -> Result<Self, CliError> {
        match target {
            Target::Lines(path) => {
                let cannot = |e: std::io::Error| CliError::Write {
                    path: path.clone(),
                    message: e.to_string(),
                };
                if let Some(dir) = path.parent().filter(|d| !d.as_os_str().is_empty()) {
                    std::fs::create_dir_all(dir).map_err(cannot)?;
                }
                let (staged, file) = StagedFile::create(&path).map_err(cannot)?;
                let file = std::io::BufWriter::new(file);
                Ok(Self {
                    lines: Some((path, staged, file)),
                    folder: None,
                    outputs,
                })
            }
            Target::Folder(dir, flags) => Ok(Self {
                lines: None,
                folder: Some((dir, flags)),
                outputs,
            }),
        }
    }

    fn write_frame(
        &mut self,
        name: &str,
        extraction: &Extraction,
        set: PolygonSet,
        colors: Option<&ColorImage>,
        stride: usize,
    ) -> Result<(), CliError> {
        let text = frame_collection(name, extraction, set, colors, stride);
        if let Some((path, _, file)) = &mut self.lines {
            writeln!(file, "{text}").map_err(|e| CliError::Write {
                path: path.clone(),
                message: e.to_string(),
            })?;
        }
        if let Some((dir, flags)) = &self.folder {
            let flag = flags
                .get(name)
                .cloned()
                .unwrap_or_else(|| format!("--out-dir's file for {name}"));
            self.outputs
                .stage(&flag, &frame_file(dir, name), text.as_bytes())?;
        }
        Ok(())
    }

    /// Renames every output into place.
    fn commit(self) -> Result<(), CliError> {
        if let Some((path, staged, file)) = self.lines {
            let cannot = |e: std::io::Error| CliError::Write {
                path: path.clone(),
                message: e.to_string(),
            };
            let file = file.into_inner().map_err(|e| cannot(e.into_error()))?;
            drop(file);
            staged.commit().map_err(cannot)?;
        }
        self.outputs.commit()?;
        Ok(())
    }
}

/// The frame's FeatureCollection on one line, with the `frame` member and, with colours,
/// each polygon's mean colour.
fn frame_collection(
    name: &str,
    extraction: &Extraction,
    set: PolygonSet,
    colors: Option<&ColorImage>,
    stride: usize,
) -> String {
    let means = colors.map(|image| mean_colors(extraction, image, stride));
    let annotations = Annotations {
        frame: Some(name),
        colors: means.as_deref(),
    };
    feature_collection_with(extraction, true, set, annotations)
}

/// The mean colour of each polygon's pixels (`None` for a polygon without pixels). The
/// colour image may be at full resolution while the cloud is strided: pixel `(i, j)` of
/// the cloud is pixel `(i s, j s)` of the picture.
fn mean_colors(extraction: &Extraction, image: &ColorImage, stride: usize) -> Vec<Option<[u8; 3]>> {
    let labels = extraction.point_labels();
    let n = extraction.polygons.len();
    let mut sums = vec![([0u64; 3], 0u64); n];
    let cloud_cols = image.width.div_ceil(stride);
    for (k, &label) in labels.iter().enumerate() {
        let Ok(polygon) = usize::try_from(label) else {
            continue;
        };
        let (i, j) = (k / cloud_cols * stride, k % cloud_cols * stride);
        let Some(pixel) = image.rgb.get(i * image.width + j) else {
            continue;
        };
        if let Some((sum, count)) = sums.get_mut(polygon) {
            for c in 0..3 {
                sum[c] += u64::from(pixel[c]);
            }
            *count += 1;
        }
    }
    sums.into_iter()
        .map(|(sum, count)| {
            (count > 0).then(|| sum.map(|s| ((s + count / 2) / count).min(255) as u8))
        })
        .collect()
}

/// One frame's line of the report.
struct Record {
    name: String,
    polygons: Option<usize>,
    load: Duration,
    wait: Duration,
    run: Duration,
    stages: Vec<(&'static str, Duration)>,
}

impl Record {
    fn of<X>(frame: &StreamedFrame<X>) -> Self {
        let (polygons, stages) = match &frame.extraction {
            Ok(e) => (
                Some(e.polygons.len()),
                e.diagnostics.timings.stages().to_vec(),
            ),
            Err(_) => (None, Vec::new()),
        };
        Self {
            name: frame.name.clone(),
            polygons,
            load: frame.load,
            wait: frame.wait,
            run: frame.run,
            stages,
        }
    }
}

fn ms(d: Duration) -> String {
    format!("{:.2}", d.as_secs_f64() * 1e3)
}

/// The `p`-th quantile (0–1) of `values`, nearest rank.
fn quantile(values: &mut [f64], p: f64) -> f64 {
    if values.is_empty() {
        return f64::NAN;
    }
    values.sort_by(f64::total_cmp);
    let rank = ((p * values.len() as f64).ceil() as usize).clamp(1, values.len());
    values[rank - 1]
}

/// Median and 90th percentile (ms) of each stage over the frames that ran, stages in the
/// order they first appear, then the frame's wait, run and load.
fn stage_quantiles(records: &[Record]) -> Vec<(String, f64, f64)> {
    let mut names: Vec<&str> = Vec::new();
    for r in records {
        for (stage, _) in &r.stages {
            if !names.contains(stage) {
                names.push(stage);
            }
        }
    }
    let ran: Vec<&Record> = records.iter().filter(|r| r.polygons.is_some()).collect();
    let column = |f: &dyn Fn(&Record) -> f64| -> (f64, f64) {
        let mut values: Vec<f64> = ran.iter().map(|r| f(r)).collect();
        (quantile(&mut values, 0.5), quantile(&mut values, 0.9))
    };
    let mut out: Vec<(String, f64, f64)> = names
        .iter()
        .map(|&name| {
            let (median, p90) = column(&|r: &Record| {
                r.stages
                    .iter()
                    .filter(|(s, _)| *s == name)
                    .map(|(_, d)| d.as_secs_f64() * 1e3)
                    .sum()
            });
            (name.to_owned(), median, p90)
        })
        .collect();
    for (name, f) in [
        (
            "wait for frame",
            &(|r: &Record| r.wait.as_secs_f64() * 1e3) as &dyn Fn(&Record) -> f64,
        ),
        ("pipeline", &|r: &Record| r.run.as_secs_f64() * 1e3),
        ("frame (wait + pipeline)", &|r: &Record| {
            (r.wait + r.run).as_secs_f64() * 1e3
        }),
        ("load (loader thread)", &|r: &Record| {
            r.load.as_secs_f64() * 1e3
        }),
    ] {
        let (median, p90) = column(f);
        out.push((name.to_owned(), median, p90));
    }
    out
}

/// The stream's wall time per frame in ms: what it took from the first frame's load to
/// the last frame's output, over the frames (with frames in flight, less than a frame's
/// own run time).
fn period_ms(records: &[Record], elapsed: Duration) -> f64 {
    elapsed.as_secs_f64() * 1e3 / records.len().max(1) as f64
}

fn json_report(records: &[Record], elapsed: Duration) -> Value {
    let frames: Vec<Value> = records
        .iter()
        .map(|r| {
            let stages: Map<String, Value> = r
                .stages
                .iter()
                .map(|(s, d)| ((*s).to_owned(), json!(d.as_secs_f64() * 1e3)))
                .collect();
            json!({
                "frame": r.name,
                "polygons": r.polygons,
                "load_ms": r.load.as_secs_f64() * 1e3,
                "wait_ms": r.wait.as_secs_f64() * 1e3,
                "run_ms": r.run.as_secs_f64() * 1e3,
                "stages_ms": stages,
            })
        })
        .collect();
    let summary: Vec<Value> = stage_quantiles(records)
        .into_iter()
        .map(|(stage, median, p90)| json!({"stage": stage, "median_ms": median, "p90_ms": p90}))
        .collect();
    json!({
        "frames": frames,
        "failed": records.iter().filter(|r| r.polygons.is_none()).count(),
        "period_ms": period_ms(records, elapsed),
        "summary": summary,
    })
}

fn summary_text(records: &[Record], elapsed: Duration) -> String {
    let ran = records.iter().filter(|r| r.polygons.is_some()).count();
    let period = period_ms(records, elapsed);
    let mut text = format!(
        "{ran} of {} frames ran in {:.2} s, {period:.2} ms a frame ({:.1} frames/s); per frame \
         (ms):\n{:<26} {:>9} {:>9}\n",
        records.len(),
        elapsed.as_secs_f64(),
        1e3 / period,
        "stage",
        "median",
        "p90"
    );
    for (stage, median, p90) in stage_quantiles(records) {
        text.push_str(&format!("{stage:<26} {median:>9.2} {p90:>9.2}\n"));
    }
    text.pop();
    text
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn glob_matching() {
        let m = |p: &str, n: &str| {
            matches(
                &p.chars().collect::<Vec<_>>(),
                &n.chars().collect::<Vec<_>>(),
            )
        };
        assert!(m("depth_*.png", "depth_00004.png"));
        assert!(m("*", ""));
        assert!(m("d?pth*", "depth"));
        assert!(!m("depth_*.png", "color_00004.png"));
        assert!(!m("*.png", "a.png.bak"));
        assert!(m("*a*b", "xxaxxb"));
    }

    #[test]
    fn quantiles_by_nearest_rank() {
        let mut v: Vec<f64> = (1..=10).map(f64::from).collect();
        assert_eq!(quantile(&mut v, 0.5), 5.0);
        assert_eq!(quantile(&mut v, 0.9), 9.0);
        assert!(quantile(&mut [], 0.5).is_nan());
    }
}

//! Table 8, second part: full-resolution depth frames at camera rate (issue "RGB-D frames
//! at camera rate"): the metric ICL-NUIM and TUM frames at 640 × 480 and the RealSense
//! frames at 848 × 480 and 424 × 240, presets `rgbd` and `rgbd-auto`, per-stage medians
//! over a stream of 30 frames (the available frames repeated), the memory a frame takes,
//! and the paper's, CAPE's and the figures beside them.

use std::fmt::Write as _;
use std::time::Instant;

use opc_mesh::{DepthOptions, Intrinsics};
use polylidar::stream::StreamOptions;
use polylidar::{Config, OrganizedPointCloud, Polylidar, SmoothingBackend};

use crate::bench::Ctx;
use crate::error::{Result, msg};
use crate::report::Table;
use crate::tables::pipeline::STAGES;
use crate::tables::rgbd_accuracy::{PAPER_COLUMNS, paper_grid};
use crate::tables::smoothing::{GPU_HINT, gpu_adapter};
use crate::timing::{Stats, median_of, ms};

/// Depth range (mm) assumed for the colorized RealSense pictures (as the first part).
const NEAR_MM: u16 = 300;
const FAR_MM: u16 = 3000;

/// Stages timed beside the pipeline's [`STAGES`]: rgbd-auto's filling of missing returns
/// and the `rgbd` preset's decimation of camera-resolution frames.
const EXTRA_STAGES: [&str; 2] = ["fill", "decimate"];

/// Frames in the stream each row times.
const STREAM_FRAMES: usize = 30;

/// A frame size's frames and the must / target (ms, 2 threads).
struct Size {
    name: String,
    frames: Vec<OrganizedPointCloud>,
    must: f64,
    target: f64,
}

/// The frames, by size; missing fixtures are named in `notes`.
fn sizes(ctx: &Ctx, notes: &mut String) -> Result<Vec<Size>> {
    let mut out = Vec::new();
    // ICL-NUIM and TUM: 16-bit depth, PrimeSense intrinsics, 1000 and 5000 units per metre.
    let camera = ctx.fixtures.path("rgbd/camera_primesense.json");
    let mut metric = Vec::new();
    let mut names = Vec::new();
    for (file, units) in [
        ("rgbd/icl_living_depth_00000.png", 1000.0),
        ("rgbd/icl_living_depth_00004.png", 1000.0),
        ("rgbd/tum_depth.png", 5000.0),
    ] {
        let (Some(png), Some(json)) = (ctx.fixtures.path(file), camera.as_ref()) else {
            let _ = writeln!(notes, "* `{file}` or its camera is missing: left out.");
            continue;
        };
        let k = polylidar_io::read_open3d_camera(json)?;
        let image = polylidar_io::read_depth_png(&png)?;
        let options = DepthOptions::new(Intrinsics::new(k.fx, k.fy, k.ppx, k.ppy))
            .with_depth_scale(1.0 / units);
        metric.push(OrganizedPointCloud::from_depth_image(
            &image.data,
            image.height,
            image.width,
            &options,
        )?);
        names.push(file.trim_start_matches("rgbd/").trim_end_matches(".png"));
    }
    if !metric.is_empty() {
        out.push(Size {
            name: format!("ICL / TUM 640 × 480 ({})", names.join(", ")),
            frames: metric,
            must: 16.0,
            target: 8.0,
        });
    }
    // RealSense: colorized pictures at full resolution (approximate geometry).
    for (file, must, target) in [("001_big", 20.0, 10.0), ("001_small", 5.0, 2.5)] {
        let (Some(png), Some(csv)) = (
            ctx.fixtures.path(&format!("realsense/{file}_depth.png")),
            ctx.fixtures
                .path(&format!("realsense/{file}_depth_metadata.csv")),
        ) else {
            let _ = writeln!(
                notes,
                "* `realsense/{file}_depth.png` is missing: left out."
            );
            continue;
        };
        let picture = polylidar_io::read_colorized_depth_png(&png)?;
        let k = polylidar_io::read_realsense_intrinsics(&csv)?;
        let depth = picture.to_depth_image(NEAR_MM, FAR_MM);
        let options = DepthOptions::new(Intrinsics::new(k.fx, k.fy, k.ppx, k.ppy));
        let cloud = OrganizedPointCloud::from_depth_image(
            &depth.data,
            depth.height,
            depth.width,
            &options,
        )?;
        out.push(Size {
            name: format!(
                "RealSense {} × {} ({file}_depth, colorized)",
                depth.width, depth.height
            ),
            frames: vec![cloud],
            must,
            target,
        });
    }
    Ok(out)
}

/// Resident and peak resident memory of this process (bytes), from `/proc/self/status`.
fn rss() -> Option<(u64, u64)> {
    let status = std::fs::read_to_string("/proc/self/status").ok()?;
    let field = |name: &str| -> Option<u64> {
        let line = status.lines().find(|l| l.starts_with(name))?;
        let kb: u64 = line.split_whitespace().nth(1)?.parse().ok()?;
        Some(kb * 1024)
    };
    Some((field("VmRSS:")?, field("VmHWM:")?))
}

/// The growth of this process's peak resident memory while `f` runs (Linux: the peak is
/// reset first through `/proc/self/clear_refs`); `None` where that is not available.
fn peak_growth<T>(f: impl FnOnce() -> T) -> (T, Option<u64>) {
    let reset = std::fs::write("/proc/self/clear_refs", "5").is_ok();
    let before = rss();
    let out = f();
    let after = rss();
    let growth = match (reset, before, after) {
        (true, Some((rss_before, _)), Some((_, peak))) => Some(peak.saturating_sub(rss_before)),
        _ => None,
    };
    (out, growth)
}

fn mib(bytes: u64) -> String {
    format!("{:.1} MiB", bytes as f64 / (1024.0 * 1024.0))
}

/// Renders the second part of Table 8.
///
/// # Errors
/// Unreadable fixtures or a pipeline error.
pub fn section(ctx: &Ctx) -> Result<String> {
    let mut notes = String::new();
    let sizes = sizes(ctx, &mut notes)?;
    if sizes.is_empty() {
        return Err(msg("no RGB-D frame in the fixtures"));
    }
    let frames = if ctx.quick { 6 } else { STREAM_FRAMES };
    let threads = 2;
    let mut header = vec!["frame".to_owned(), "preset".to_owned()];
    header.extend(STAGES.iter().map(|(_, title)| (*title).to_owned()));
    header.extend(
        [
            "fill",
            "decimate",
            "total (wall)",
            "p90 (wall)",
            "stream period, 1 / 2 at once",
            "must / target",
            "input cloud",
            "peak RSS Δ",
            "polygons",
        ]
        .map(str::to_owned),
    );
    let mut table = Table::new(header);
    let (variants, gpu_note) = variants(threads)?;
    let mut rows = Vec::new();
    for size in &sizes {
        for (preset, config) in &variants {
            let polylidar = Polylidar::new(config.clone())?;
            // Warm-up: one pass over the frames (thread pool, FastGA, buffers). Each
            // extraction is handed back, as a stream does, for the next frame's mesh.
            for cloud in &size.frames {
                polylidar.recycle(polylidar.extract_organized(cloud)?);
            }
            let (first, growth) = peak_growth(|| polylidar.extract_organized(&size.frames[0]));
            polylidar.recycle(first?);
            let mut per_stage: Vec<Vec<f64>> = vec![Vec::new(); STAGES.len() + EXTRA_STAGES.len()];
            let mut wall = Vec::with_capacity(frames);
            let mut polygons = Vec::with_capacity(frames);
            for k in 0..frames {
                let cloud = &size.frames[k % size.frames.len()];
                let start = Instant::now();
                let extraction = polylidar.extract_organized(cloud)?;
                wall.push(start.elapsed().as_secs_f64() * 1e3);
                let timings = &extraction.diagnostics.timings;
                for (j, stage) in STAGES
                    .iter()
                    .map(|(s, _)| *s)
                    .chain(EXTRA_STAGES)
                    .enumerate()
                {
                    if let Some(d) = timings.get(stage) {
                        per_stage[j].push(d.as_secs_f64() * 1e3);
                    }
                }
                polygons.push(if extraction.postprocessed.is_empty() {
                    extraction.polygons.len()
                } else {
                    extraction.postprocessed.len()
                } as f64);
                polylidar.recycle(extraction);
            }
            let p90 = nearest_rank(&wall, 0.9);
            let wall = Stats::from_samples(wall).ok_or_else(|| msg("no timed frames"))?;
            let mut row = vec![size.name.clone(), preset.clone()];
            row.extend(
                per_stage
                    .iter()
                    .map(|v| median_of(v.clone()).map_or_else(|| "–".to_owned(), ms)),
            );
            let points = size.frames[0].rows() * size.frames[0].cols();
            row.extend([
                wall.cell(),
                ms(p90),
                String::new(),
                format!("≤ {} / ≤ {}", ms(size.must), ms(size.target)),
                mib((points * 24) as u64),
                growth.map_or_else(|| "–".to_owned(), mib),
                median_of(polygons).map_or_else(|| "–".to_owned(), |p| format!("{p}")),
            ]);
            rows.push(row);
        }
    }
    // The streams after every row's peak memory: their frames, copied up front, would
    // move the next row's baseline.
    let period_column = 2 + STAGES.len() + EXTRA_STAGES.len() + 2;
    let mut rows = rows.into_iter();
    for size in &sizes {
        for (_, config) in &variants {
            let polylidar = Polylidar::new(config.clone())?;
            let mut row = rows.next().ok_or_else(|| msg("a row per variant"))?;
            let [one, two] = [1, 2].map(|n| stream_period(&polylidar, &size.frames, frames, n));
            row[period_column] = format!("{} / {}", ms(one?), ms(two?));
            table.row(row);
        }
    }
    let blank = || vec![String::new(); STAGES.len() + EXTRA_STAGES.len()];
    let mut paper = vec![
        "paper: D435i 424 × 240, SDK-decimated to 212 × 120 (Basement / Main Floor means)"
            .to_owned(),
        "Table 7 (GPU smoothing + 4 threads)".to_owned(),
    ];
    paper.extend(
        [0.4, 0.4, 0.5, 1.25, 1.65, 4.95]
            .map(ms)
            .into_iter()
            .chain(EXTRA_STAGES.map(|_| String::new())),
    );
    paper.extend([
        "11.4 / 11.7 (incl. 2.4 SDK filters)".to_owned(),
        String::new(),
        String::new(),
        String::new(),
        String::new(),
        String::new(),
        String::new(),
    ]);
    table.row(paper);
    let mut cape = vec![
        "CAPE (Proença & Gao 2018), 640 × 480".to_owned(),
        "planes + cylinders, no polygons; 1 core".to_owned(),
    ];
    cape.extend(blank());
    cape.extend(
        ["≈ 3.3 (≈ 300 Hz)", "", "", "", "", "", ""]
            .into_iter()
            .map(str::to_owned),
    );
    table.row(cape);

    let mut body = String::new();
    let _ = writeln!(
        body,
        "\n## Full-resolution depth frames (camera rate)\n\n\
         `Polylidar::extract_organized` on {threads} threads over a stream of {frames} frames \
         (the frames of a size repeated in turn; one warm-up pass first), one `Polylidar` kept \
         across the stream and each frame's extraction handed back with `Polylidar::recycle` \
         (the next frame is meshed into its arrays), the frame already in memory. Stage columns are medians over the \
         stream (ms); `fill` is rgbd-auto's filling of missing returns, `decimate` the `rgbd` preset's \
         merging of 2 × 2 pixel blocks at 640 × 480 and 848 × 480 (its other stages then run on \
         the 320 × 240 and 424 × 240 grids) and, in the rows on the paper's grid, of blocks \
         of 2, 3 or 4 pixels a side (to about {PAPER_COLUMNS} columns, as the RealSense SDK's \
         decimation by 2 made the paper's 424 × 240 frames 212 × 120; Table 10b gives the \
         accuracy this costs). Total is the median \
         wall time of a frame (min–max), p90 its 90th percentile. *Stream period* is the \
         wall time per frame of the same {frames} frames through `Polylidar::stream`, one \
         frame at a time and two at once (`StreamOptions::in_flight`; by default a stream \
         measures both as it goes and keeps the faster, and with GPU smoothing it runs one \
         at a time either way), the frames already in memory \
         (handed over by the stream's loader thread as they are) and each recycled after \
         use, after a warm-up of eight (a fresh `Polylidar` per row, after every row's other \
         columns). Frames in flight start in pairs: where the two \
         frames of a pair differ much in cost (the ICL / TUM row alternates three \
         different frames; TUM's takes half as long again as ICL's) the sooner one's \
         thread waits through the other's sequential stretches and the pair gains little, \
         where consecutive frames are alike, as a camera's are, it gains most. *Input cloud* is the \
         organized cloud of one frame (24 bytes a pixel); *peak RSS Δ* is how far one frame \
         raised the process's peak resident memory above what it held before (Linux \
         `VmHWM` after resetting it through `/proc/self/clear_refs`): the frame's mesh, \
         normals, smoothed copies and polygons, less the buffers the pipeline keeps from \
         earlier frames. *Must / target* are the issue's (2 threads, CPU only).\n"
    );
    body.push_str(&table.render());
    let _ = writeln!(
        body,
        "\n* The ICL-NUIM and TUM frames are 16-bit metric depth with the PrimeSense \
         intrinsics (`rgbd/camera_primesense.json`; TUM at 5000 units per metre). The \
         848 × 480 and 424 × 240 rows use the RealSense *colorized* pictures mapped to \
         {NEAR_MM}–{FAR_MM} mm (see above): real frame sizes, approximate geometry.\n\
         * CAPE's figure is from its paper (640 × 480 Kinect frames, one core of its \
         authors' machine); it finds planes and cylinders as cell-grid segments and makes \
         no polygons, so it is context, not a like-for-like comparison. The paper's row is \
         Polylidar3D's Table 8 (stage means of whole recorded scenes, smoothing on the GPU, \
         4 threads for planes and polygons).\n{gpu_note}\n{notes}"
    );
    Ok(body)
}

/// The wall time per frame (ms) of `frames` frames (`clouds` in turn) through
/// [`Polylidar::stream`] with `in_flight` frames at once and the other options the
/// defaults, each recycled after use, after a warm-up stream of eight. The frames are
/// copied before the clock starts and the loader hands each over as it is, so that the
/// frame is already in memory, as for the other columns.
///
/// # Errors
/// A frame's pipeline error.
fn stream_period(
    polylidar: &Polylidar,
    clouds: &[OrganizedPointCloud],
    frames: usize,
    in_flight: usize,
) -> Result<f64> {
    let options = StreamOptions::default().with_in_flight(in_flight);
    let run = |n: usize| -> Result<f64> {
        let mut ready: Vec<Option<OrganizedPointCloud>> = (0..n)
            .map(|k| Some(clouds[k % clouds.len()].clone()))
            .collect();
        let sources = (0..n).map(|k| (k.to_string(), k)).collect();
        let load = move |k: usize| {
            ready[k]
                .take()
                .ok_or_else(|| polylidar::PolylidarError::Config {
                    field: "frame",
                    value: k.to_string(),
                    reason: "handed over twice",
                })
        };
        let start = Instant::now();
        for frame in polylidar.stream(sources, load, options) {
            polylidar.recycle(frame.extraction?);
        }
        Ok(start.elapsed().as_secs_f64() * 1e3 / n as f64)
    };
    run(8)?;
    run(frames)
}

/// The configurations each frame size runs, by name: presets `rgbd` and `rgbd-auto` on
/// `threads` CPU threads, and both again with their smoothing on the GPU where a hardware
/// adapter exists; and a note on the GPU rows.
fn variants(threads: usize) -> Result<(Vec<(String, Config)>, String)> {
    let preset = |name: &str| {
        Config::preset(name)
            .map(|c| c.with_threads(threads))
            .ok_or_else(|| msg(format!("no {name} preset")))
    };
    let mut variants = vec![
        ("rgbd".to_owned(), preset("rgbd")?),
        ("rgbd-auto".to_owned(), preset("rgbd-auto")?),
        (
            format!("rgbd, decimated to {PAPER_COLUMNS} columns (paper's grid)"),
            paper_grid(threads)?,
        ),
    ];
    let note = match gpu_adapter() {
        Ok((_, summary, false)) => {
            for name in ["rgbd", "rgbd-auto"] {
                variants.push((
                    format!("{name}, GPU smoothing"),
                    preset(name)?.with_smoothing_backend(SmoothingBackend::Gpu),
                ));
            }
            format!(
                "* *GPU smoothing* rows run both filters on the adapter {summary} (upload \
                 and read-back included), everything else on {threads} CPU threads."
            )
        }
        Ok((_, summary, true)) => format!(
            "* No GPU rows: the only adapter, {summary}, is a software rasterizer on the CPU."
        ),
        Err(e) => format!("* No GPU rows: {e}. {GPU_HINT}"),
    };
    Ok((variants, note))
}

/// The `p`-th quantile (0–1) of `samples`, nearest rank.
fn nearest_rank(samples: &[f64], p: f64) -> f64 {
    let mut sorted = samples.to_vec();
    sorted.sort_by(f64::total_cmp);
    if sorted.is_empty() {
        return f64::NAN;
    }
    let rank = ((p * sorted.len() as f64).ceil() as usize).clamp(1, sorted.len());
    sorted[rank - 1]
}

//! Table 11: per-stage timings and f of the `synpeb` preset at 500 × 500 and 250 × 250
//! (stride 2), on SynPEB pc_01 and on the synthetic SynPEB-like suite.

use std::fmt::Write as _;

use polylidar::{Config, LaplacianIterations, Polylidar};

use crate::bench::Ctx;
use crate::data::{
    FIXTURES_NAME, LabelledCloud, SYNTHETIC_RADIAL_SIGMA, read_synpeb, synthetic_frame,
};
use crate::error::{Result, msg};
use crate::report::{PAPER_HARDWARE, Section, Table};
use crate::tables::accuracy::score;
use crate::tables::pipeline::{PipelineStats, time_pipeline};
use crate::timing::ms;

/// The stages of the paper's Table 11, in its column order.
const COLUMNS: [(&str, &str); 5] = [
    ("mesh", "mesh"),
    ("laplacian", "Laplacian"),
    ("bilateral", "bilateral"),
    ("fastga", "FastGA"),
    ("planes_polygons", "planes + polygons"),
];

/// Tangential noise of the synthetic rows (the paper's Table 10 test set).
const SUITE_MDEG: f64 = 1.0;

/// Runs Table 11.
///
/// # Errors
/// Pipeline, scoring or scene errors.
pub fn run(ctx: &Ctx) -> Result<Section> {
    let auto = Config::preset("synpeb-auto").ok_or_else(|| msg("no synpeb-auto preset"))?;
    let fixed = Config::preset("synpeb").ok_or_else(|| msg("no synpeb preset"))?;
    let parallel = ctx.parallel_threads();
    let runs = ctx.runs(2, 20, 4);
    let suite_runs = ctx.runs(1, 5, 2);
    let seeds: Vec<u64> = if ctx.quick {
        vec![1]
    } else {
        (1..=10).collect()
    };

    let mut header = vec![
        "point cloud".to_owned(),
        "preset".to_owned(),
        "threads".to_owned(),
        "Laplacian it.".to_owned(),
    ];
    header.extend(COLUMNS.iter().map(|(_, t)| (*t).to_owned()));
    header.extend(["total (wall)".to_owned(), "f [%]".to_owned()]);
    let mut table = Table::new(header);
    let mut notes = String::new();

    match ctx.fixtures.path("synpeb/pc_01.pcd") {
        Some(path) => {
            let full = read_synpeb(&path)?;
            let half = full.downsample(2)?;
            let cases = [
                (&full, "synpeb-auto", &auto, 1),
                (&full, "synpeb-auto", &auto, parallel),
                (&full, "synpeb", &fixed, 1),
                (&full, "synpeb", &fixed, parallel),
                (&half, "synpeb-auto", &auto, 1),
                (&half, "synpeb-auto", &auto, parallel),
                (&half, "synpeb", &fixed, parallel),
            ];
            for (frame, preset, config, threads) in cases {
                let stride = full.cloud.rows() / frame.cloud.rows();
                // The adapting preset runs as it is at every resolution.
                let config = if preset == "synpeb" {
                    for_stride(config, stride)
                } else {
                    config.clone()
                };
                let polylidar = Polylidar::new(config.with_threads(threads))?;
                let stats = time_pipeline(&polylidar, &frame.cloud, runs)?;
                let f = score(frame, &stats.last)?.f;
                table.row(row(
                    &format!("pc_01, {}", size(frame)),
                    preset,
                    threads,
                    &[&stats],
                    Some(f),
                ));
            }
        }
        None => {
            let _ = writeln!(
                notes,
                "* `{FIXTURES_NAME}/synpeb/pc_01.pcd` is missing: rows skipped."
            );
        }
    }

    for stride in [1, 2] {
        let polylidar = Polylidar::new(for_stride(&auto, stride).with_threads(parallel))?;
        let mut all = Vec::new();
        let mut fs = Vec::new();
        let mut shape = String::new();
        for &seed in &seeds {
            let frame = synthetic_frame(seed, SYNTHETIC_RADIAL_SIGMA, SUITE_MDEG)?;
            let frame = if stride == 1 {
                frame
            } else {
                frame.downsample(stride)?
            };
            shape = size(&frame);
            let stats = time_pipeline(&polylidar, &frame.cloud, suite_runs)?;
            fs.push(score(&frame, &stats.last)?.f);
            all.push(stats);
        }
        let refs: Vec<&PipelineStats> = all.iter().collect();
        let f = fs.iter().sum::<f64>() / fs.len().max(1) as f64;
        table.row(row(
            &format!("synthetic suite ({} frames), {shape}", seeds.len()),
            "synpeb-auto",
            parallel,
            &refs,
            Some(f),
        ));
    }

    for (name, values, f) in [
        (
            "paper: SynPEB 500 × 500",
            [9.3, 1.1, 3.0, 6.6, 14.9, 33.9],
            47.3,
        ),
        (
            "paper: SynPEB 250 × 250",
            [2.0, 0.5, 0.7, 2.5, 4.1, 9.8],
            44.6,
        ),
    ] {
        let mut r = vec![
            name.to_owned(),
            "Table 9".to_owned(),
            "GPU + 4".to_owned(),
            "predicted".to_owned(),
        ];
        r.extend(values.iter().map(|v| ms(*v)));
        r.push(format!("{f:.1}"));
        table.row(r);
    }

    let mut body = String::new();
    let _ = writeln!(
        body,
        "`Polylidar::extract_organized` with the SynPEB presets: `synpeb-auto` (Table 9: \
         Laplacian k 5, λ 1, iterations predicted per cloud from its estimated noise and its \
         correlation — the count used is in the \"Laplacian it.\" column and the noise \
         estimate is timed with the Laplacian; refinement of the segments, timed in \
         planes + polygons; min 250 triangles or 0.015 m²) and `synpeb` (the paper's \
         algorithm, always 8 iterations, min 1000 triangles: the authors' released benchmark \
         configuration); both: bilateral k 3, σ 0.1 / 0.1, 2 it; FastGA level 5, 12 % \
         sample; lmax 0.1, z 0.07; no polygon filtering. Smoothing runs on the CPU \
         (`CpuParallel`) with the pipeline's threads. 250 × 250 rows take every second row \
         and column; `synpeb-auto` runs unchanged, `synpeb` is scaled to the coarser grid: \
         `min_triangles` / 4 (250), `lmax` × 2 (0.2 m) and Laplacian iterations / 4 (2, the \
         same smoothing distance); with the 500 × 500 values unchanged its f drops to about \
         10 % (8 iterations of a k 5 kernel at twice the spacing flatten the small planes). pc_01 \
         rows: stage medians of {}; wall total median \
         (min–max). Synthetic suite rows: `synthscan::synpeb_like` scenes (seeds {}), \
         {SUITE_MDEG} mdeg tangential and {} mm radial noise, each frame {}, averaged over \
         the frames. f = % of ground-truth planes found (`seg-metrics`, Hoover 80 % overlap, \
         labels from `Extraction::plane_labels`); pc_01's ground truth is the plane label \
         SynPEB stores in the PCD's `intensity` field. Times in ms.\n",
        runs.describe(),
        seeds
            .iter()
            .map(u64::to_string)
            .collect::<Vec<_>>()
            .join(", "),
        SYNTHETIC_RADIAL_SIGMA * 1e3,
        suite_runs.describe()
    );
    body.push_str(&table.render());
    let _ = writeln!(
        body,
        "\nThe paper's rows are means over the SynPEB test set, with the Laplacian and \
         bilateral filters on the GPU and plane/polygon extraction on up to 4 threads, other \
         stages single-threaded, and the Laplacian iteration count predicted per cloud. The \
         issue gives the C++ original's OPC meshing with normals on pc_01 on this kind of \
         machine as 30.5 ms (our \"mesh\" column).\n{notes}\n{PAPER_HARDWARE}"
    );
    Ok(Section {
        file: "table11_synpeb_timing.md",
        title: "Table 11 — SynPEB per-stage timings and f".to_owned(),
        body,
    })
}

/// The preset for a cloud thinned by `stride`: triangle counts shrink by `stride²` and
/// triangle edges grow by `stride`, so `min_triangles` and `lmax` follow; the Laplacian's
/// reach grows with the pixel spacing times √iterations, so the iterations shrink by
/// `stride²` to smooth over the same distance.
fn for_stride(config: &Config, stride: usize) -> Config {
    let mut c = config.clone();
    let area = stride * stride;
    c.min_triangles = (config.min_triangles / area).max(1);
    c.lmax = config.lmax * stride as f64;
    if let Some(l) = c.laplacian.as_mut()
        && let Some(n) = l.iterations.fixed()
    {
        l.iterations = LaplacianIterations::Fixed((n / area as u32).max(1));
    }
    c
}

/// "500 × 500".
fn size(frame: &LabelledCloud) -> String {
    format!("{} × {}", frame.cloud.rows(), frame.cloud.cols())
}

/// A table row: stage medians (averaged over `stats`), wall total and f.
fn row(
    name: &str,
    preset: &str,
    threads: usize,
    stats: &[&PipelineStats],
    f: Option<f64>,
) -> Vec<String> {
    let mean = |values: Vec<f64>| -> Option<f64> {
        (!values.is_empty()).then(|| values.iter().sum::<f64>() / values.len() as f64)
    };
    let mut iterations: Vec<u32> = stats
        .iter()
        .map(|s| s.last.diagnostics.counts.laplacian_iterations)
        .collect();
    iterations.sort_unstable();
    iterations.dedup();
    let iterations = match iterations.as_slice() {
        [one] => one.to_string(),
        [lo, .., hi] => format!("{lo}–{hi}"),
        [] => "–".to_owned(),
    };
    let mut r = vec![
        name.to_owned(),
        format!("`{preset}`"),
        threads.to_string(),
        iterations,
    ];
    for (stage, _) in COLUMNS {
        let v = mean(stats.iter().filter_map(|s| s.stage(stage)).collect());
        r.push(v.map_or_else(|| "–".to_owned(), ms));
    }
    if let [one] = stats {
        r.push(one.wall.cell());
    } else {
        let v = mean(stats.iter().map(|s| s.wall.median).collect());
        r.push(v.map_or_else(|| "–".to_owned(), ms));
    }
    r.push(f.map_or_else(String::new, |f| format!("{f:.1}")));
    r
}

//! Tables 12–13: Laplacian and bilateral filtering of organized clouds by backend, for one
//! and five iterations, plus the pc_01 rows against the C++ original.

use std::fmt::Write as _;

use mesh_smooth_gpu::{BilateralOptions, CpuSmoother, GpuSmoother, LaplacianOptions, SmoothError};
use opc_mesh::OrganizedPointCloud;

use crate::bench::Ctx;
use crate::data::{FIXTURES_NAME, read_npy_cloud, read_synpeb};
use crate::error::Result;
use crate::report::{PAPER_HARDWARE, Section, Table};
use crate::timing::{Runs, Stats, measure};

/// The paper's (CPU-S, CPU-M with 4 threads, GPU) figures for (1 it, 5 it), as printed.
type PaperRow = [(f64, f64); 3];

const LAPLACIAN_PC01: PaperRow = [(7.0, 35.0), (2.0, 9.2), (0.8, 0.9)];
const LAPLACIAN_RGBD: PaperRow = [(0.7, 3.5), (0.2, 0.9), (0.1, 0.2)];
const BILATERAL_PC01: PaperRow = [(73.0, 354.0), (19.4, 90.9), (3.2, 4.4)];
const BILATERAL_RGBD: PaperRow = [(7.2, 35.0), (1.9, 9.2), (0.5, 0.5)];

/// A backend to time: the CPU on one thread or on a rayon pool of that many, or the GPU.
#[derive(Clone, Copy)]
enum Runner {
    Serial,
    Parallel(usize),
    Gpu,
}

impl Runner {
    /// The threads column.
    fn threads(self) -> String {
        match self {
            Runner::Serial => "1".to_owned(),
            Runner::Parallel(threads) => threads.to_string(),
            Runner::Gpu => "–".to_owned(),
        }
    }
}

/// The filters' inputs and the GPU, if there is one.
struct Setup {
    clouds: Vec<(String, OrganizedPointCloud, [PaperRow; 2])>,
    gpu: Option<GpuSmoother>,
    gpu_note: String,
}

/// Runs Tables 12 and 13.
///
/// # Errors
/// Fixture reading or a filter failing.
pub fn run(ctx: &Ctx) -> Result<Section> {
    let mut setup = setup(ctx)?;
    let threads = ctx.parallel_threads();
    let mut runners = vec![
        ("CPU, 1 thread", Runner::Serial),
        ("CPU, rayon", Runner::Parallel(threads)),
    ];
    if setup.gpu.is_some() {
        runners.push(("GPU", Runner::Gpu));
    }
    let cpu_runs = ctx.runs(3, 30, 5);
    let gpu_runs = ctx.runs(2, 10, 3);

    let mut body = String::new();
    let _ = writeln!(
        body,
        "Organized-cloud filters of `mesh-smooth-gpu`, kernel 3 (as in the paper), λ 1 for the \
         Laplacian, σ_l = σ_a = 0.1 for the bilateral filter (whose timings include computing \
         the triangle normals and centroids, as in the paper). CPU rows reuse one `CpuSmoother` \
         (buffers kept) and return a new cloud / new normals each call; GPU rows reuse one \
         `GpuSmoother` and include the upload and read-back. CPU: {}; GPU: {}. \"rayon\" rows \
         run on {threads} threads (the paper's CPU-M used 4). Cells: median (min–max) in ms.\n",
        cpu_runs.describe(),
        gpu_runs.describe()
    );
    let _ = writeln!(body, "{}\n", setup.gpu_note);

    for (filter, title) in [
        (Filter::Laplacian, "Table 12 — Laplacian filter"),
        (Filter::Bilateral, "Table 13 — bilateral normal filter"),
    ] {
        let mut table = Table::new([
            "cloud",
            "backend",
            "threads",
            "ours: 1 iteration",
            "ours: 5 iterations",
            "paper: 1 it; 5 it",
        ]);
        for (name, cloud, paper) in &setup.clouds {
            let paper = paper[filter as usize];
            for (k, (label, runner)) in runners.iter().enumerate() {
                let mut cells = Vec::new();
                for iterations in [1, 5] {
                    let options = FilterOptions::paper(filter, iterations);
                    let runs = if matches!(runner, Runner::Gpu) {
                        gpu_runs
                    } else {
                        cpu_runs
                    };
                    let stats = time_filter(ctx, *runner, &mut setup.gpu, cloud, &options, runs)?;
                    cells.push(stats.cell());
                }
                let (p1, p5) = paper[k.min(2)];
                table.row([
                    name.clone(),
                    (*label).to_owned(),
                    runner.threads(),
                    cells[0].clone(),
                    cells[1].clone(),
                    format!("{p1:.1}; {p5:.1}"),
                ]);
            }
        }
        let _ = writeln!(body, "## {title}\n\n{}", table.render());
    }

    if let Some((name, cloud, _)) = setup.clouds.first() {
        let mut table = Table::new([
            "filter",
            "backend",
            "threads",
            "ours: median (min–max) ms",
            "C++ original, this machine (issue) ms",
        ]);
        for (filter, label, original) in [
            (
                FilterOptions::Laplacian(
                    LaplacianOptions::new()
                        .with_kernel(5)
                        .with_lambda(1.0)
                        .with_iterations(8),
                ),
                "Laplacian k 5, λ 1, 8 it",
                "77.9",
            ),
            (
                FilterOptions::Bilateral(
                    BilateralOptions::new()
                        .with_kernel(3)
                        .with_sigma_length(0.1)
                        .with_sigma_angle(0.1)
                        .with_iterations(2),
                ),
                "bilateral k 3, σ 0.1 / 0.1, 2 it",
                "108.6",
            ),
        ] {
            for (backend, runner) in &runners {
                let runs = if matches!(runner, Runner::Gpu) {
                    gpu_runs
                } else {
                    cpu_runs
                };
                let stats = time_filter(ctx, *runner, &mut setup.gpu, cloud, &filter, runs)?;
                table.row([
                    label.to_owned(),
                    (*backend).to_owned(),
                    runner.threads(),
                    stats.cell(),
                    if matches!(runner, Runner::Parallel(_)) {
                        original.to_owned()
                    } else {
                        String::new()
                    },
                ]);
            }
        }
        let _ = writeln!(
            body,
            "## The SynPEB preset's smoothing on {name}\n\nThe issue's reference rows: the \
             C++ original's figures were measured with 2 threads on this kind of machine.\n\n{}",
            table.render()
        );
    }
    let _ = writeln!(body, "{PAPER_HARDWARE}");
    Ok(Section {
        file: "table12_13_smoothing.md",
        title: "Tables 12–13 — Laplacian and bilateral filtering by backend".to_owned(),
        body,
    })
}

/// Which filter a paper table is about (also the index into the paper rows).
#[derive(Clone, Copy)]
enum Filter {
    Laplacian = 0,
    Bilateral = 1,
}

/// Options of one filter.
enum FilterOptions {
    Laplacian(LaplacianOptions),
    Bilateral(BilateralOptions),
}

impl FilterOptions {
    /// Kernel 3 and the given iterations (Tables 12–13).
    fn paper(filter: Filter, iterations: u32) -> Self {
        match filter {
            Filter::Laplacian => Self::Laplacian(
                LaplacianOptions::new()
                    .with_kernel(3)
                    .with_lambda(1.0)
                    .with_iterations(iterations),
            ),
            Filter::Bilateral => Self::Bilateral(
                BilateralOptions::new()
                    .with_kernel(3)
                    .with_sigma_length(0.1)
                    .with_sigma_angle(0.1)
                    .with_iterations(iterations),
            ),
        }
    }
}

/// Times one filter on one backend.
fn time_filter(
    ctx: &Ctx,
    runner: Runner,
    gpu: &mut Option<GpuSmoother>,
    cloud: &OrganizedPointCloud,
    options: &FilterOptions,
    runs: Runs,
) -> Result<Stats> {
    match runner {
        Runner::Serial | Runner::Parallel(_) => {
            let (threads, mut smoother) = match runner {
                Runner::Parallel(threads) => (threads, CpuSmoother::new()),
                _ => (1, CpuSmoother::serial()),
            };
            ctx.on_threads(threads, || match options {
                FilterOptions::Laplacian(o) => measure(runs, || Ok(smoother.laplacian(cloud, o)?)),
                FilterOptions::Bilateral(o) => measure(runs, || Ok(smoother.bilateral(cloud, o)?)),
            })
        }
        Runner::Gpu => {
            let Some(gpu) = gpu.as_mut() else {
                return Err(crate::error::msg("no GPU adapter"));
            };
            match options {
                FilterOptions::Laplacian(o) => measure(runs, || Ok(gpu.laplacian(cloud, o)?)),
                FilterOptions::Bilateral(o) => measure(runs, || Ok(gpu.bilateral(cloud, o)?)),
            }
        }
    }
}

/// The clouds (pc_01 and rgbd_opc when present) and the GPU.
fn setup(ctx: &Ctx) -> Result<Setup> {
    let mut clouds = Vec::new();
    if let Some(path) = ctx.fixtures.path("synpeb/pc_01.pcd") {
        clouds.push((
            "SynPEB pc_01, 500 × 500".to_owned(),
            read_synpeb(&path)?.cloud,
            [LAPLACIAN_PC01, BILATERAL_PC01],
        ));
    }
    if let Some(path) = ctx.fixtures.path("realsense/rgbd_opc.npy") {
        let cloud = read_npy_cloud(&path)?;
        clouds.push((
            format!("RealSense rgbd_opc, {} × {}", cloud.rows(), cloud.cols()),
            cloud,
            [LAPLACIAN_RGBD, BILATERAL_RGBD],
        ));
    }
    if clouds.is_empty() {
        return Err(crate::error::msg(format!(
            "neither {FIXTURES_NAME}/synpeb/pc_01.pcd nor realsense/rgbd_opc.npy exists"
        )));
    }
    let (gpu, gpu_note) = match gpu_adapter() {
        Ok((gpu, summary, software)) => {
            let note = format!(
                "GPU rows: adapter {summary}{}.",
                if software {
                    " — **a software rasterizer running on the CPU (Mesa lavapipe), not a \
                     GPU**: its rows show the backend works, not GPU speed"
                } else {
                    ""
                }
            );
            (Some(gpu), note)
        }
        Err(e) => (None, format!("No GPU rows: {e}. {GPU_HINT}")),
    };
    Ok(Setup {
        clouds,
        gpu,
        gpu_note,
    })
}

/// How to get GPU rows where a table has none.
pub(crate) const GPU_HINT: &str = "Build with `cargo run -p xtask --release --features gpu -- bench` \
     on a machine with a Vulkan, Metal, DX12 or GL adapter to add them.";

/// The GPU smoother on the adapter wgpu picks, its summary, and whether that adapter is
/// a CPU (software) implementation.
///
/// # Errors
/// No adapter, or a build without the `gpu` feature.
pub(crate) fn gpu_adapter() -> std::result::Result<(GpuSmoother, String, bool), SmoothError> {
    let gpu = GpuSmoother::new()?;
    let summary = gpu.adapter_summary();
    let software = is_software(&summary);
    Ok((gpu, summary, software))
}

/// Whether an adapter summary names a CPU (software) implementation.
fn is_software(summary: &str) -> bool {
    let s = summary.to_lowercase();
    s.contains("llvmpipe")
        || s.contains("lavapipe")
        || s.contains("(cpu,")
        || s.contains("swiftshader")
}

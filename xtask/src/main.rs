//! Project automation for polylidar-rs.
//!
//! `cargo xtask bench [--quick] [--publish | --out DIR] [--fixtures DIR] [--threads 1,2,4]
//! [--only TABLE,…]` measures the pipeline stages the way the Polylidar3D and Polylidar
//! (2D) papers' tables do and writes markdown tables and PNG charts to `target/bench/`
//! (the committed `docs/bench/` only with `--publish`, so a trial run leaves the checkout
//! clean), with
//! the machine, thread counts, run counts and the paper's figures beside ours. The
//! `cargo xtask` alias builds in release mode. Add `--features gpu` (run it as
//! `cargo run -p xtask --release --features gpu -- bench`) for the GPU smoothing rows.

mod bench;
mod chart;
mod city;
mod city_extract;
mod data;
mod error;
mod machine;
mod report;
mod tables;
mod timing;

use std::path::PathBuf;
use std::time::Instant;

use clap::{Parser, Subcommand};

use crate::bench::{Ctx, default_threads, parse_threads};
use crate::data::{Fixtures, default_fixtures};
use crate::error::{Result, msg};
use crate::machine::{CpuSample, Machine, load_average};
use crate::report::{RunInfo, header, write};

/// The allocator the `polylidar` command line uses (see its `main.rs`), so that the tables
/// time what the command runs.
#[global_allocator]
static GLOBAL: mimalloc::MiMalloc = mimalloc::MiMalloc;

/// polylidar-rs project tasks.
#[derive(Debug, Parser)]
#[command(name = "cargo xtask", version, about)]
struct Cli {
    #[command(subcommand)]
    command: Command,
}

/// The tasks.
#[derive(Debug, Subcommand)]
enum Command {
    /// Reproduce the papers' timing and accuracy tables into target/bench/ (docs/bench/
    /// with --publish).
    Bench(BenchArgs),
    /// Write a synthetic city (synthscan::City) as LAS/LAZ tiles with ground-truth labels.
    City(city::CityArgs),
}

/// Options of `cargo xtask bench`.
#[derive(Debug, clap::Args)]
struct BenchArgs {
    /// Fewer runs and sizes: under a minute on two cores (as docs/bench/README.md says).
    #[arg(long)]
    quick: bool,
    /// Write into the committed docs/bench/ of the workspace instead of target/bench/.
    #[arg(long, conflicts_with = "out")]
    publish: bool,
    /// Output folder (default: target/bench in the workspace; docs/bench with --publish).
    #[arg(long)]
    out: Option<PathBuf>,
    /// Shared fixtures folder (default: ../shared/fixtures next to the workspace).
    #[arg(long)]
    fixtures: Option<PathBuf>,
    /// Thread counts for the speed-up chart, e.g. 1,2,4 (default: 1–4, and powers of two
    /// up to the core count). The "all cores" rows use the largest count not above the
    /// number of cores.
    #[arg(long)]
    threads: Option<String>,
    /// Only these tables (comma-separated): fastga (2), smoothing (12, 13), realsense (8),
    /// shapes (2d), scaling (21), synpeb-timing (11), synpeb-accuracy (10), planar-mesh
    /// (Ma et al. 2013, I–III).
    #[arg(long)]
    only: Option<String>,
}

fn main() -> std::process::ExitCode {
    match run(Cli::parse()) {
        Ok(()) => std::process::ExitCode::SUCCESS,
        Err(e) => {
            eprintln!("error: {e}");
            std::process::ExitCode::FAILURE
        }
    }
}

fn run(cli: Cli) -> Result<()> {
    match cli.command {
        Command::Bench(args) => bench(args),
        Command::City(args) => city::city(&args),
    }
}

fn bench(args: BenchArgs) -> Result<()> {
    let started = Instant::now();
    let machine = Machine::detect();
    let threads = match &args.threads {
        Some(list) => parse_threads(list)?,
        None => default_threads(machine.cores),
    };
    let workspace = PathBuf::from(env!("CARGO_MANIFEST_DIR"))
        .parent()
        .map(PathBuf::from)
        .ok_or_else(|| msg("the xtask is not inside a workspace"))?;
    let out = match (&args.out, args.publish) {
        (Some(out), _) => out.clone(),
        (None, true) => workspace.join("docs").join("bench"),
        (None, false) => workspace.join("target").join("bench"),
    };
    let ctx = Ctx {
        quick: args.quick,
        out,
        fixtures: Fixtures::new(args.fixtures.clone().unwrap_or_else(default_fixtures)),
        threads,
        machine,
    };
    let selected = tables::select(args.only.as_deref())?;
    eprintln!(
        "bench{}: {} on {} ({} cores); threads {:?}",
        if ctx.quick { " --quick" } else { "" },
        selected
            .iter()
            .map(|t| t.key)
            .collect::<Vec<_>>()
            .join(", "),
        ctx.machine.cpu,
        ctx.machine.cores,
        ctx.threads
    );
    for table in selected {
        let load_before = load_average();
        let cpu_before = CpuSample::now();
        let start = Instant::now();
        eprintln!(
            "[{:>5.1} s] {} …",
            started.elapsed().as_secs_f64(),
            table.key
        );
        let section = (table.run)(&ctx).map_err(|e| msg(format!("{}: {e}", table.key)))?;
        let info = RunInfo {
            machine: &ctx.machine,
            quick: ctx.quick,
            load: (load_before, load_average()),
            others: cpu_before
                .zip(CpuSample::now())
                .and_then(|(a, b)| a.others_cores(&b)),
            seconds: start.elapsed().as_secs_f64(),
        };
        let text = format!("{}{}", header(&section.title, &info), section.body);
        write(&ctx.out.join(section.file), &text)?;
        eprintln!(
            "[{:>5.1} s] wrote {} ({:.1} s)",
            started.elapsed().as_secs_f64(),
            section.file,
            info.seconds
        );
    }
    tables::write_index(&ctx)?;
    eprintln!(
        "done in {:.1} s; results in {}",
        started.elapsed().as_secs_f64(),
        ctx.out.display()
    );
    Ok(())
}

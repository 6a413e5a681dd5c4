//! `polylidar`: planes and polygons with holes from point files.
//!
//! ```text
//! polylidar extract --demo -o demo.geojson --plot demo.png
//! polylidar extract scan.pcd --preset synpeb --json --repeat 20
//! polylidar extract points.csv --alpha 0.5 --plot points.png
//! polylidar evaluate scan.pcd --labels truth.npy --preset synpeb
//! polylidar generate --seed 3 --noise-mdeg 2 -o scan.pcd --labels-out truth.npy
//! polylidar mesh depth.png --intrinsics camera.json --preset rgbd --texture -o room.obj
//! polylidar extract tum_depth.png --intrinsics 525,525,319.5,239.5 --depth-scale 5000
//! polylidar stream 'frames/depth_*.png' --intrinsics camera.json --preset rgbd-auto -o planes.geojsonl
//! ```
//!
//! Exit codes: 0 done (also when nothing was found, unless `--strict`), 1 an error
//! (unreadable input, bad parameters, unwritable output), 2 a usage error, 3 `extract
//! --strict` found nothing or nearly nothing.

mod args;
mod evaluate;
mod input;
mod mesh;
mod outputs;
mod params;
mod plot;
mod report;
mod run;
mod stream;

use std::process::ExitCode;

use clap::Parser;

/// An allocator that keeps freed memory for reuse. With the system allocator (glibc), the
/// large per-frame buffers (the mesh, its normals, the filtered cloud) go back to the
/// kernel when freed and come back as fresh zeroed pages on the next frame (the polylidar
/// crate's README, "Frame after frame", says what that page faulting costs).
#[global_allocator]
static GLOBAL: mimalloc::MiMalloc = mimalloc::MiMalloc;

fn main() -> ExitCode {
    #[cfg(unix)]
    ignore_file_size_signal();
    let cli = args::Cli::parse();
    match run::run(cli) {
        Ok(run::Outcome::Done) => ExitCode::SUCCESS,
        Ok(run::Outcome::Empty) => ExitCode::from(run::EXIT_EMPTY),
        Err(e) => {
            eprint!("{}", error_text(&e));
            ExitCode::FAILURE
        }
    }
}

/// `error: …` and a `caused by: …` line for each cause whose text the lines above do not
/// already hold (most errors name their cause in their own message).
fn error_text(e: &run::CliError) -> String {
    let mut text = format!("error: {e}\n");
    let mut source = std::error::Error::source(e);
    while let Some(cause) = source {
        let line = cause.to_string();
        if !text.contains(&line) {
            text.push_str(&format!("  caused by: {line}\n"));
        }
        source = cause.source();
    }
    text
}

/// Ignores `SIGXFSZ`, so that a write past the file size limit (`ulimit -f`) fails with an
/// error (`EFBIG`) that the writers handle — the temporary file removed, the previous file
/// kept — instead of killing the process with the temporary file left behind. CPython
/// does the same at start-up.
#[cfg(unix)]
#[allow(unsafe_code)]
fn ignore_file_size_signal() {
    // SAFETY: `signal` with `SIG_IGN` installs no handler code; it runs first thing in
    // `main`, before any other thread exists.
    unsafe {
        libc::signal(libc::SIGXFSZ, libc::SIG_IGN);
    }
}

//! `polylidar`: planes and polygons with holes from point files.
//!
//! ```text
//! polylidar extract --demo -o demo.geojson --plot demo.png
//! polylidar extract points.csv --alpha 0.5 --json --repeat 20
//! ```

mod args;
mod geojson;
mod plot;
mod report;
mod run;

use std::process::ExitCode;

use clap::Parser;

fn main() -> ExitCode {
    let cli = args::Cli::parse();
    match run::run(cli) {
        Ok(()) => ExitCode::SUCCESS,
        Err(e) => {
            eprintln!("error: {e}");
            let mut source = std::error::Error::source(&e);
            while let Some(cause) = source {
                eprintln!("  caused by: {cause}");
                source = cause.source();
            }
            ExitCode::FAILURE
        }
    }
}

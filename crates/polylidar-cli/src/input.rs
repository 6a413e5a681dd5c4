//! Loading inputs: files by extension, and the built-in demos.

use std::path::{Path, PathBuf};

use polylidar::OrganizedPointCloud;
pub use polylidar::io::Input;
use polylidar::io::Limits;

use crate::args::Demo;
use crate::run::CliError;

/// Points the 2D demo samples.
pub const DEMO_SHAPE_POINTS: usize = 8000;
/// Seed and tangential noise (mdeg) of the scene demo.
pub const DEMO_SCENE: (u64, f64) = (0, 1.0);

/// A loaded input with where it came from and, for generated scenes, the ground truth.
pub struct Loaded {
    /// The data.
    pub input: Input,
    /// The path or the demo's name.
    pub source: String,
    /// Ground-truth plane label per point (generated scenes only).
    pub truth: Option<Vec<i32>>,
}

/// Loads `path`, or the demo, with organized input (and its ground truth) downsampled by
/// `stride`, within `max_memory` bytes (`--max-memory`; default: [`Limits::default`]).
/// Invalid (NaN) points skipped from an unorganized cloud are reported on stderr.
///
/// # Errors
/// Unreadable input, an input past the memory budget, or `stride > 1` for input that is
/// not organized.
pub fn load(
    path: Option<&Path>,
    demo: Option<Demo>,
    stride: usize,
    max_memory: Option<u64>,
) -> Result<Loaded, CliError> {
    let mut loaded = match (path, demo) {
        (Some(path), _) => {
            let limits = max_memory.map_or_else(Limits::default, |bytes| {
                Limits::default().with_max_memory(bytes)
            });
            let (input, notes) = Input::read_with(path, &limits)?;
            if notes.invalid_skipped > 0 {
                eprintln!(
                    "note: {}: {} skipped (a NaN coordinate marks an invalid point)",
                    path.display(),
                    crate::report::count(notes.invalid_skipped, "invalid point", "invalid points")
                );
            }
            Loaded {
                input,
                source: path.display().to_string(),
                truth: None,
            }
        }
        (None, Some(Demo::Shape)) => Loaded {
            input: demo_shape()?,
            source: "built-in demo: shape".to_owned(),
            truth: None,
        },
        (None, _) => demo_scene()?,
    };
    if stride > 1 {
        let Input::Organized(cloud) = &loaded.input else {
            return Err(CliError::Unsupported {
                what: format!("{}: --stride needs organized input", loaded.source),
            });
        };
        let cols = cloud.cols();
        loaded.truth = loaded.truth.map(|t| {
            t.iter()
                .enumerate()
                .filter(|(i, _)| (i / cols) % stride == 0 && (i % cols) % stride == 0)
                .map(|(_, &l)| l)
                .collect()
        });
        loaded.input = Input::Organized(cloud.downsample(stride)?);
    }
    Ok(loaded)
}

fn demo_shape() -> Result<Input, CliError> {
    let shape = polylidar::shapes::demo_shape();
    let points = polylidar::shapes::sample_uniform(&shape, DEMO_SHAPE_POINTS, 1)
        .map_err(|e| CliError::Demo(e.to_string()))?;
    Ok(Input::Points2d(points))
}

/// The SynPEB-like demo scan and its labels.
fn demo_scene() -> Result<Loaded, CliError> {
    let (seed, mdeg) = DEMO_SCENE;
    let scan = generate_scan(seed, mdeg, 0.0)?;
    let cloud = OrganizedPointCloud::new(scan.rows, scan.cols, scan.points)?;
    Ok(Loaded {
        input: Input::Organized(cloud),
        source: format!("built-in demo: scene (seed {seed}, {mdeg} mdeg noise)"),
        truth: Some(scan.labels),
    })
}

/// A SynPEB-like scan: the room of `seed` scanned with the given noise.
pub fn generate_scan(seed: u64, mdeg: f64, radial: f64) -> Result<synthscan::ScanResult, CliError> {
    let demo = |e: synthscan::SceneError| CliError::Demo(e.to_string());
    let (scene, sensor) = synthscan::synpeb_like(seed).map_err(demo)?;
    let noise = synthscan::Noise::new(radial, mdeg, seed);
    scene.scan(&sensor, &noise).map_err(demo)
}

/// Reads an integer label array (int32 or int64 .npy) with `expected` entries.
pub fn read_labels(path: &Path, expected: usize) -> Result<Vec<i32>, CliError> {
    let bad = |message: String| CliError::Labels {
        path: PathBuf::from(path),
        message,
    };
    let array = polylidar_io::read_npy(path)?;
    let labels = array
        .data
        .iter()
        .enumerate()
        .map(|(i, &v)| {
            if v.fract() == 0.0 && (-1.0..=f64::from(i32::MAX)).contains(&v) {
                Ok(v as i32)
            } else {
                Err(bad(format!(
                    "entry {i} is {v}, not a label (-1 or a plane id ≥ 0)"
                )))
            }
        })
        .collect::<Result<Vec<i32>, CliError>>()?;
    if labels.len() != expected {
        return Err(bad(format!(
            "{} labels for {expected} points",
            labels.len()
        )));
    }
    Ok(labels)
}

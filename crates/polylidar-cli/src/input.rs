//! Loading inputs: files by extension, and the built-in demos.

use std::path::{Path, PathBuf};

pub use polylidar::io::Input;
use polylidar::io::{CameraSource, DepthCamera, Limits, ReadNotes, is_missing_intrinsics};
use polylidar::{Intrinsics, OrganizedPointCloud, PolylidarError};

use crate::args::{CameraArgs, Demo};
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

/// The memory budget of reading `path`: `--max-memory` when given, else the default budget
/// of the file's size ([`Limits::for_path`]: 384 MiB plus 64 bytes per byte of the file,
/// at most 2 GiB or half the physical memory).
pub fn limits_for(path: &Path, max_memory: Option<u64>) -> Limits {
    max_memory.map_or_else(
        || Limits::for_path(path),
        |bytes| Limits::default().with_max_memory(bytes),
    )
}

/// Loads `path`, or the demo, with organized input (and its ground truth) downsampled by
/// `stride`, within `max_memory` bytes (`--max-memory`; default: [`limits_for`]).
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
    load_with_camera(path, demo, stride, max_memory, &DepthCamera::default())
}

/// [`load`], reading a depth PNG with `camera`.
///
/// # Errors
/// As [`load`]; no camera intrinsics for a depth PNG ([`read_with_camera`]).
pub fn load_with_camera(
    path: Option<&Path>,
    demo: Option<Demo>,
    stride: usize,
    max_memory: Option<u64>,
    camera: &DepthCamera,
) -> Result<Loaded, CliError> {
    let mut loaded = match (path, demo) {
        (Some(path), _) => {
            let (input, notes) = read_with_camera(path, camera, &limits_for(path, max_memory))?;
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

/// The camera of `--intrinsics` and `--depth-scale`: numbers `fx,fy,cx,cy`, else a
/// camera file; without `--intrinsics`, the RealSense CSV beside the PNG.
///
/// # Errors
/// Numbers that are not four finite values.
pub fn camera(args: &CameraArgs) -> Result<DepthCamera, CliError> {
    let source = match args.intrinsics.as_deref() {
        None => CameraSource::Beside,
        Some(text) if text.contains(',') => {
            let numbers: Vec<f64> = text
                .split(',')
                .map(|v| v.trim().parse::<f64>())
                .collect::<Result<_, _>>()
                .map_err(|_| bad_intrinsics(text))?;
            let [fx, fy, cx, cy] = numbers[..] else {
                return Err(bad_intrinsics(text));
            };
            CameraSource::Pinhole(Intrinsics::new(fx, fy, cx, cy))
        }
        Some(file) => CameraSource::File(PathBuf::from(file)),
    };
    let camera = DepthCamera::new(source);
    Ok(match args.depth_scale {
        Some(units) => camera.with_units_per_metre(units),
        None => camera,
    })
}

fn bad_intrinsics(text: &str) -> CliError {
    CliError::Unsupported {
        what: format!(
            "--intrinsics {text}: expected four numbers fx,fy,cx,cy (pixels) or a camera file"
        ),
    }
}

/// Reads `path` within `limits` ([`Input::read_with_camera`]); a depth PNG without
/// intrinsics gets an error naming the ways to give them.
///
/// # Errors
/// Unreadable input; no camera intrinsics for a depth PNG.
pub fn read_with_camera(
    path: &Path,
    camera: &DepthCamera,
    limits: &Limits,
) -> Result<(Input, ReadNotes), CliError> {
    Input::read_with_camera(path, camera, limits).map_err(|e| match e {
        e if is_missing_intrinsics(&e) => CliError::Unsupported {
            what: format!(
                "{}: no camera intrinsics: pass --intrinsics fx,fy,cx,cy and --depth-scale, \
                 or an Open3D camera JSON, or put the RealSense _metadata.csv beside it",
                path.display()
            ),
        },
        PolylidarError::Io(e) => CliError::Input(e),
        e => CliError::Pipeline(e),
    })
}

fn demo_shape() -> Result<Input, CliError> {
    let shape = synthscan::shapes::demo_shape();
    let points = synthscan::shapes::sample_uniform(&shape, DEMO_SHAPE_POINTS, 1)
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

//! The benchmark inputs: the shared fixtures (`../shared/fixtures` next to the workspace)
//! and synthetic data generated on the spot.

use std::path::{Path, PathBuf};

use opc_mesh::OrganizedPointCloud;

use crate::error::{Result, msg};

/// How the fixtures folder is named in the generated markdown (never a machine path).
pub const FIXTURES_NAME: &str = "../shared/fixtures";

/// The default fixtures folder: `<workspace root>/../shared/fixtures`.
pub fn default_fixtures() -> PathBuf {
    let xtask = Path::new(env!("CARGO_MANIFEST_DIR"));
    let root = xtask.parent().unwrap_or(xtask);
    root.join("..").join("shared").join("fixtures")
}

/// The fixtures folder and whether files in it exist.
#[derive(Debug, Clone)]
pub struct Fixtures {
    dir: PathBuf,
}

impl Fixtures {
    /// Fixtures under `dir`.
    pub fn new(dir: PathBuf) -> Self {
        Self { dir }
    }

    /// The path of `relative` if the file exists.
    pub fn path(&self, relative: &str) -> Option<PathBuf> {
        let path = self.dir.join(relative);
        path.is_file().then_some(path)
    }

    /// The path of `relative`, or an error saying it is missing.
    ///
    /// # Errors
    /// The file does not exist.
    pub fn require(&self, relative: &str) -> Result<PathBuf> {
        self.path(relative)
            .ok_or_else(|| msg(format!("fixture {FIXTURES_NAME}/{relative} is missing")))
    }

    /// The `*.geojson` files of `shapes/`, sorted by name.
    pub fn shapes(&self) -> Vec<(String, PathBuf)> {
        let mut out: Vec<(String, PathBuf)> = std::fs::read_dir(self.dir.join("shapes"))
            .map(|dir| {
                dir.filter_map(|e| e.ok().map(|e| e.path()))
                    .filter(|p| p.extension().is_some_and(|e| e == "geojson"))
                    .filter_map(|p| {
                        let stem = p.file_stem()?.to_str()?.to_owned();
                        Some((stem, p))
                    })
                    .collect()
            })
            .unwrap_or_default();
        out.sort();
        out
    }
}

/// A SynPEB frame with its ground-truth labels.
#[derive(Debug, Clone)]
pub struct LabelledCloud {
    /// The organized cloud.
    pub cloud: OrganizedPointCloud,
    /// Ground-truth plane label per point, `-1` for none.
    pub labels: Vec<i32>,
}

impl LabelledCloud {
    /// Every `stride`-th row and column of the cloud and its labels.
    ///
    /// # Errors
    /// A stride of 0 or one that leaves fewer than 2 rows or columns.
    pub fn downsample(&self, stride: usize) -> Result<Self> {
        let cloud = self.cloud.downsample(stride)?;
        let cols = self.cloud.cols();
        let labels = (0..self.cloud.rows())
            .step_by(stride)
            .flat_map(|r| {
                (0..cols)
                    .step_by(stride)
                    .map(move |c| self.labels[r * cols + c])
            })
            .collect();
        Ok(Self { cloud, labels })
    }
}

/// Smallest SynPEB label that names a plane; smaller values (pc_01 has a few points
/// labelled 3) are not planes.
const SYNPEB_FIRST_PLANE_LABEL: f64 = 10.0;

/// A SynPEB PCD (`synpeb/pc_01.pcd`, …): points and the plane label SynPEB stores in the
/// `intensity` field (≥ 10 for planes; other values become `-1`).
///
/// # Errors
/// Unreadable file or a cloud that is not organized.
pub fn read_synpeb(path: &Path) -> Result<LabelledCloud> {
    let columns = polylidar_io::read_pcd_fields(path)?;
    let column = |name: &str| -> Result<&Vec<f64>> {
        columns
            .names
            .iter()
            .position(|n| n == name)
            .map(|k| &columns.values[k])
            .ok_or_else(|| msg(format!("{}: no field {name}", path.display())))
    };
    let (x, y, z) = (column("x")?, column("y")?, column("z")?);
    let points = (0..x.len()).map(|i| [x[i], y[i], z[i]]).collect();
    let labels = column("intensity")?
        .iter()
        .map(|&v| {
            if v.is_finite() && v >= SYNPEB_FIRST_PLANE_LABEL {
                v as i32
            } else {
                -1
            }
        })
        .collect();
    let cloud = OrganizedPointCloud::new(columns.height, columns.width, points)?;
    Ok(LabelledCloud { cloud, labels })
}

/// An organized cloud stored as an `(H, W, 3)` NumPy array.
///
/// # Errors
/// Unreadable file or a wrong shape.
pub fn read_npy_cloud(path: &Path) -> Result<OrganizedPointCloud> {
    let pc = polylidar_io::read_npy(path)?.into_point_cloud()?;
    Ok(OrganizedPointCloud::new(pc.rows, pc.cols, pc.points)?)
}

/// Radial (range) noise of the synthetic suite, metres: chosen so that the ground-truth
/// planes of the synthetic frames deviate from flat as much as those of the real SynPEB
/// frames (plane-fit RMSE ≈ 14 mm against pc_01's 14.5 mm). `synthscan`'s tangential
/// noise alone (0.5–4 mdeg) moves points by well under a millimetre.
pub const SYNTHETIC_RADIAL_SIGMA: f64 = 0.02;

/// A SynPEB-like frame from `synthscan`: scene `seed`, 500 × 500 spherical scan with
/// `radial` metres of range noise and `mdeg` tangential noise, and its labels.
///
/// # Errors
/// Scene placement or scanning errors.
pub fn synthetic_frame(seed: u64, radial: f64, mdeg: f64) -> Result<LabelledCloud> {
    let (scene, sensor) = synthscan::synpeb_like(seed)?;
    let scan = scene.scan(&sensor, &synthscan::Noise::new(radial, mdeg, seed))?;
    let cloud = OrganizedPointCloud::new(scan.rows, scan.cols, scan.points)?;
    Ok(LabelledCloud {
        cloud,
        labels: scan.labels,
    })
}

/// Root mean square distance of the labelled points to their own ground-truth plane's
/// least-squares fit (planes of at least 50 points): how noisy a frame is, in metres.
pub fn truth_plane_rmse(frame: &LabelledCloud) -> Option<f64> {
    let mut by_label: std::collections::BTreeMap<i32, Vec<[f64; 3]>> = Default::default();
    for (p, &l) in frame.cloud.points().iter().zip(&frame.labels) {
        if l >= 0 && p.iter().all(|c| c.is_finite()) {
            by_label.entry(l).or_default().push(*p);
        }
    }
    let (mut sse, mut n) = (0.0, 0usize);
    for points in by_label.values().filter(|p| p.len() >= 50) {
        if let Some(rmse) = seg_metrics::fit_plane_rmse(points) {
            sse += rmse * rmse * points.len() as f64;
            n += points.len();
        }
    }
    (n > 0).then(|| (sse / n as f64).sqrt())
}

/// An RGB-D frame from `synthscan`: the furnished room `seed` of `synthscan::rgbd_like`,
/// scanned by the depth camera `kind` with its error model (noise seeded by `seed`), and its
/// labels.
///
/// # Errors
/// Scene placement or scanning errors.
pub fn rgbd_frame(seed: u64, kind: synthscan::DepthCameraKind) -> Result<LabelledCloud> {
    rgbd_frame_with(seed, kind, kind.model())
}

/// As [`rgbd_frame`], with the depth camera's error `model` replaced (e.g.
/// `synthscan::DepthModel::ideal()` for error-free depth).
///
/// # Errors
/// Scene placement or scanning errors, or an invalid model.
pub fn rgbd_frame_with(
    seed: u64,
    kind: synthscan::DepthCameraKind,
    model: synthscan::DepthModel,
) -> Result<LabelledCloud> {
    let (scene, camera) = synthscan::rgbd_like(seed, kind)?;
    let scan = scene.scan_depth(&camera.with_model(model)?, seed)?;
    let cloud = OrganizedPointCloud::new(scan.rows, scan.cols, scan.points)?;
    Ok(LabelledCloud {
        cloud,
        labels: scan.labels,
    })
}

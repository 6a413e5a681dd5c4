//! Pipeline parameters, with units and defaults, loadable from TOML.

use fastga::FastGaConfig;
use mesh_smooth_gpu::{BilateralOptions, LaplacianOptions, SmoothError};
use opc_mesh::{FillConfig, OpcError};
use planeseg::SegmentationConfig;
use polypost::PostprocessConfig;
use serde::{Deserialize, Serialize};

use crate::{DecimateConfig, PolylidarError, Preset, ScanConfig};

/// `with_<field>` builders, one per listed field, each documented as setting it: the
/// configuration structs are `#[non_exhaustive]`, so code outside this crate builds them
/// from `Default` through these.
macro_rules! setters {
    ($ty:ty { $($setter:ident => $field:ident: $t:ty),* $(,)? }) => {
        impl $ty {
            $(
                #[doc = concat!("Sets [`Self::", stringify!($field), "`].")]
                #[must_use]
                pub fn $setter(mut self, $field: $t) -> Self {
                    self.$field = $field;
                    self
                }
            )*
        }
    };
}
pub(crate) use setters;

setters!(Config {
    with_min_area => min_area: f64,
    with_refine => refine: bool,
    with_scan => scan: Option<ScanConfig>,
});

setters!(LaplacianConfig {
    with_kernel => kernel: u32,
    with_lambda => lambda: f32,
    with_iterations => iterations: LaplacianIterations,
    with_range_exponent => range_exponent: f64,
    with_backend => backend: SmoothingBackend,
});

setters!(BilateralConfig {
    with_kernel => kernel: u32,
    with_sigma_length => sigma_length: f32,
    with_sigma_angle => sigma_angle: f32,
    with_iterations => iterations: u32,
    with_backend => backend: SmoothingBackend,
});

setters!(DominantNormalsConfig {
    with_level => level: u32,
    with_sample_fraction => sample_fraction: f64,
    with_min_samples => min_samples: usize,
    with_value_threshold => value_threshold: f64,
    with_cluster_distance => cluster_distance: f64,
    with_min_cluster_weight => min_cluster_weight: f64,
});

/// Parameters of the 2D and 2.5D pipelines. Field names follow the papers and are the TOML
/// keys and (in kebab case) the command-line flags.
///
/// Lengths are in the units of the input coordinates (metres for most point clouds).
///
/// ```
/// use polylidar::Config;
/// let config: Config = toml::from_str("alpha = 0.5\nmin_triangles = 10").unwrap();
/// assert_eq!(config.alpha, 0.5);
/// assert_eq!(config.min_hole_vertices, Config::default().min_hole_vertices);
/// config.validate().unwrap();
/// ```
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
#[non_exhaustive]
pub struct Config {
    /// Keep a triangle only if its circumradius is at most `alpha` (the α-shape test);
    /// `0` disables the test. Length unit.
    pub alpha: f64,
    /// Keep a triangle only if its longest edge is at most `lmax`; `0` disables the test.
    /// Length unit.
    pub lmax: f64,
    /// Drop regions (and so polygons) made of fewer triangles than this.
    pub min_triangles: usize,
    /// 3D with [`Config::refine`]: keep a region of fewer than `min_triangles` triangles
    /// when its area reaches this (square length unit): a large plane far from the
    /// sensor, seen by few pixels. `0` keeps by count only.
    pub min_area: f64,
    /// Drop holes with fewer vertices than this (the hole is filled).
    pub min_hole_vertices: usize,
    /// 2.5D only: keep a triangle only if the cosine between its normal and `up` is at
    /// least `norm_thresh` (the papers' ang_min as a cosine; `0.94` ≈ 20°). `-1` keeps all.
    /// In TOML also an angle in degrees, `norm_thresh = "20deg"` (see [`parse_cosine`]);
    /// in code [`Config::with_norm_thresh_degrees`].
    #[serde(deserialize_with = "cosine_or_degrees")]
    pub norm_thresh: f64,
    /// 2.5D only: the direction the cloud is triangulated along and polygons are viewed
    /// from (unit or not; must be non-zero).
    pub up: [f64; 3],
    /// 3D: maximum distance from a triangle's centroid to its segment's plane (the
    /// paper's ptp_max); `0` disables the test. Length unit.
    pub z_thresh: f64,
    /// Worker threads; `0` uses rayon's default (one per core). At most [`max_threads`]
    /// ([`MAX_THREADS_PER_CORE`] per core of the machine). Results are identical whatever
    /// the count. While a run called from outside the pool lasts, a second worker polls
    /// for work instead of sleeping between parallel stages (it gives up after 0.5 ms
    /// without work): waking a sleeping worker can take longer than a stage.
    pub threads: usize,
    /// Organized clouds: Laplacian vertex smoothing before meshing; absent = off.
    pub laplacian: Option<LaplacianConfig>,
    /// Organized clouds: bilateral normal smoothing after meshing; absent = off.
    pub bilateral: Option<BilateralConfig>,
    /// 3D: dominant-normal detection (FastGA) on the triangle normals.
    pub fastga: DominantNormalsConfig,
    /// Polygon post-processing (simplify, buffer, area filters); absent = off.
    pub postprocess: Option<PostprocessConfig>,
    /// 3D: refine the planar segments before their polygons are extracted (absorb the
    /// triangles that fit a segment's plane, grow planes that no dominant normal
    /// explains, merge neighbouring segments of one plane; see
    /// [`planeseg::SegmentationConfig::refine`]). Off in the papers' presets.
    pub refine: bool,
    /// Organized clouds: fill isolated missing returns before smoothing and meshing (see
    /// [`opc_mesh::OrganizedPointCloud::fill_missing`]); their labels stay `-1` in
    /// [`crate::Extraction::point_labels`] and [`crate::Extraction::plane_labels`], as the
    /// input has no measurement there. Absent = off.
    pub fill_missing: Option<FillConfig>,
    /// Organized clouds: merge blocks of pixels into one point each before everything
    /// else (see [`DecimateConfig`]); the labels of
    /// [`crate::Extraction::point_labels`] and [`crate::Extraction::plane_labels`] are
    /// still one per input pixel. Absent = full resolution.
    pub decimate: Option<DecimateConfig>,
    /// Unorganized clouds: treat the cloud as one frame of a rotating LiDAR (thinning,
    /// beam outliers, optionally the range image; see [`ScanConfig`] and
    /// [`crate::Polylidar::extract_scan`]); absent = the points are taken as given.
    pub scan: Option<ScanConfig>,
    /// Unorganized clouds: take the 3D path, planes in every direction (normals, dominant
    /// directions, a triangulation per direction; see
    /// [`crate::Polylidar::extract_unorganized`] and [`crate::UnorganizedConfig`]);
    /// absent = the 2.5D path along [`Config::up`].
    pub unorganized: Option<crate::UnorganizedConfig>,
}

/// Most worker threads per core: [`Config::threads`] is at most this many times the
/// machine's cores ([`max_threads`]). More threads than cores only add start-up time and
/// memory; tens of thousands can exhaust the process table.
pub const MAX_THREADS_PER_CORE: usize = 4;

/// The largest [`Config::threads`] accepted on this machine: [`MAX_THREADS_PER_CORE`]
/// times [`std::thread::available_parallelism`] (1 core when it is unknown).
///
/// ```
/// use polylidar::{Config, Polylidar, max_threads};
/// assert!(max_threads() >= polylidar::MAX_THREADS_PER_CORE);
/// assert!(Polylidar::new(Config::new().with_threads(max_threads())).is_ok());
/// assert!(Polylidar::new(Config::new().with_threads(max_threads() + 1)).is_err());
/// ```
pub fn max_threads() -> usize {
    MAX_THREADS_PER_CORE * std::thread::available_parallelism().map_or(1, |n| n.get())
}

/// Laplacian vertex filter parameters (Polylidar3D Eq. 1–2).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
#[non_exhaustive]
pub struct LaplacianConfig {
    /// Odd pixel neighbourhood side, 3 to [`mesh_smooth_gpu::MAX_KERNEL`] (15).
    pub kernel: u32,
    /// Step towards the weighted neighbour mean, in (0, 1] (1 moves to the mean; larger
    /// steps overshoot and negative ones roughen the surface).
    pub lambda: f32,
    /// Passes: a count up to [`mesh_smooth_gpu::MAX_ITERATIONS`] (1000; `iterations = 8`;
    /// 0 skips the filter), or `"auto"` to predict it
    /// per cloud from its estimated noise ([`crate::estimate_noise`] through the trained
    /// linear model of [`crate::predict_laplacian_iterations`]).
    pub iterations: LaplacianIterations,
    /// How the passes grow with range, for sensors whose noise relative to the point
    /// spacing grows with it (an RGB-D camera's depth error grows with z², its spacing
    /// with z: exponent 1). A pixel at range `r` takes `n · (r / r_median)^e` passes,
    /// rounded and clamped to `1..=max(n, MAX_AUTO_ITERATIONS)`, where `n` is the count
    /// [`Self::iterations`] fixes or predicts and `r_median` the median range of the
    /// cloud's points; range is the distance from the origin of the cloud's frame (the
    /// sensor, for clouds in camera coordinates). 0 (the default): `n` passes everywhere.
    /// In `[0, 4]`.
    pub range_exponent: f64,
    /// Where to run.
    pub backend: SmoothingBackend,
}

impl Default for LaplacianConfig {
    /// The filter's own defaults ([`LaplacianOptions::default`]).
    fn default() -> Self {
        let o = LaplacianOptions::default();
        Self {
            kernel: o.kernel,
            lambda: o.lambda,
            iterations: LaplacianIterations::Fixed(o.iterations),
            range_exponent: 0.0,
            backend: SmoothingBackend::default(),
        }
    }
}

impl LaplacianConfig {
    /// The filter options for `iterations` passes (the count [`Self::iterations`] fixes
    /// or predicts).
    pub fn options(&self, iterations: u32) -> LaplacianOptions {
        LaplacianOptions::new()
            .with_kernel(self.kernel)
            .with_lambda(self.lambda)
            .with_iterations(iterations)
    }
}

/// Largest [`LaplacianConfig::range_exponent`].
pub const MAX_RANGE_EXPONENT: f64 = 4.0;

/// How many Laplacian passes run: a fixed count, or `Auto`, predicted per cloud from its
/// estimated point noise (the 3D paper's SynPEB setting, §9.3.2 and Table 9: "iterations =
/// varies (predicted)").
///
/// In TOML a count is written as a number and `Auto` as the string `"auto"`:
///
/// ```
/// use polylidar::{LaplacianConfig, LaplacianIterations};
/// let auto: LaplacianConfig = toml::from_str(r#"iterations = "auto""#).unwrap();
/// assert_eq!(auto.iterations, LaplacianIterations::Auto);
/// let fixed: LaplacianConfig = toml::from_str("iterations = 8").unwrap();
/// assert_eq!(fixed.iterations, LaplacianIterations::Fixed(8));
/// assert_eq!(fixed.iterations, 8.into());
/// ```
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum LaplacianIterations {
    /// Exactly this many passes (0: none).
    Fixed(u32),
    /// Predicted from [`crate::estimate_noise`] of each input cloud by
    /// [`crate::predict_laplacian_iterations`]; the count used is reported in
    /// [`crate::Counts::laplacian_iterations`].
    Auto,
}

impl LaplacianIterations {
    /// The fixed count, or `None` for [`LaplacianIterations::Auto`].
    pub fn fixed(self) -> Option<u32> {
        match self {
            Self::Fixed(n) => Some(n),
            Self::Auto => None,
        }
    }
}

impl From<u32> for LaplacianIterations {
    fn from(n: u32) -> Self {
        Self::Fixed(n)
    }
}

impl std::fmt::Display for LaplacianIterations {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            Self::Fixed(n) => write!(f, "{n}"),
            Self::Auto => f.write_str("auto"),
        }
    }
}

impl Serialize for LaplacianIterations {
    fn serialize<S: serde::Serializer>(&self, serializer: S) -> Result<S::Ok, S::Error> {
        serialize_count_or_auto(self.fixed(), serializer)
    }
}

impl<'de> Deserialize<'de> for LaplacianIterations {
    fn deserialize<D: serde::Deserializer<'de>>(deserializer: D) -> Result<Self, D::Error> {
        Ok(
            deserialize_count_or_auto(deserializer, "an iteration count (0 or more)")?
                .map_or(Self::Auto, Self::Fixed),
        )
    }
}

/// A count, or `"auto"` for `None`, as TOML and JSON write it.
pub(crate) fn serialize_count_or_auto<S: serde::Serializer>(
    count: Option<u32>,
    serializer: S,
) -> Result<S::Ok, S::Error> {
    match count {
        Some(n) => serializer.serialize_u32(n),
        None => serializer.serialize_str("auto"),
    }
}

/// A count (`what`, in the error message) or the string `"auto"` (any case), read as
/// `None`.
pub(crate) fn deserialize_count_or_auto<'de, D: serde::Deserializer<'de>>(
    deserializer: D,
    what: &'static str,
) -> Result<Option<u32>, D::Error> {
    struct Visitor(&'static str);
    impl serde::de::Visitor<'_> for Visitor {
        type Value = Option<u32>;

        fn expecting(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
            write!(f, r#"{} or "auto""#, self.0)
        }

        fn visit_u64<E: serde::de::Error>(self, v: u64) -> Result<Self::Value, E> {
            u32::try_from(v)
                .map(Some)
                .map_err(|_| E::invalid_value(serde::de::Unexpected::Unsigned(v), &self))
        }

        fn visit_i64<E: serde::de::Error>(self, v: i64) -> Result<Self::Value, E> {
            u32::try_from(v)
                .map(Some)
                .map_err(|_| E::invalid_value(serde::de::Unexpected::Signed(v), &self))
        }

        fn visit_str<E: serde::de::Error>(self, v: &str) -> Result<Self::Value, E> {
            if v.eq_ignore_ascii_case("auto") {
                Ok(None)
            } else {
                Err(E::invalid_value(serde::de::Unexpected::Str(v), &self))
            }
        }
    }
    deserializer.deserialize_any(Visitor(what))
}

/// Bilateral normal filter parameters (Polylidar3D Eq. 3–5).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
#[non_exhaustive]
pub struct BilateralConfig {
    /// Odd cell neighbourhood side, 3 to [`mesh_smooth_gpu::MAX_KERNEL`] (15).
    pub kernel: u32,
    /// σ_l: spatial scale between triangle centroids, finite and > 0. Length unit.
    pub sigma_length: f32,
    /// σ_a: scale of the Euclidean distance between unit normals, finite and > 0.
    pub sigma_angle: f32,
    /// Passes, 0 to [`mesh_smooth_gpu::MAX_ITERATIONS`] (1000).
    pub iterations: u32,
    /// Where to run.
    pub backend: SmoothingBackend,
}

impl Default for BilateralConfig {
    /// The filter's own defaults ([`BilateralOptions::default`]).
    fn default() -> Self {
        let o = BilateralOptions::default();
        Self {
            kernel: o.kernel,
            sigma_length: o.sigma_length,
            sigma_angle: o.sigma_angle,
            iterations: o.iterations,
            backend: SmoothingBackend::default(),
        }
    }
}

impl BilateralConfig {
    /// The filter options.
    pub fn options(&self) -> BilateralOptions {
        BilateralOptions::new()
            .with_kernel(self.kernel)
            .with_sigma_length(self.sigma_length)
            .with_sigma_angle(self.sigma_angle)
            .with_iterations(self.iterations)
    }
}

/// Where a smoothing filter runs: which smoother the pipeline keeps for it
/// (`mesh_smooth_gpu::CpuSmoother::new`, `CpuSmoother::serial` or `GpuSmoother`).
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum SmoothingBackend {
    /// One CPU thread.
    Cpu,
    /// All worker threads of the pipeline's pool.
    #[default]
    CpuParallel,
    /// The GPU through wgpu (needs the `gpu` feature of this crate).
    Gpu,
}

/// Dominant-normal detection as the pipeline runs it (FastGA, Polylidar3D §6; the TOML
/// table `[fastga]`): the detector's parameters ([`FastGaConfig`]) with the pipeline's
/// sampling, 12 % of the triangle normals but at least [`Self::min_samples`], which
/// [`Self::config_for`] turns into the detector's configuration for a mesh. Not a copy
/// of [`FastGaConfig`], whose standalone default integrates every normal.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
#[non_exhaustive]
pub struct DominantNormalsConfig {
    /// Icosahedron refinement level (0–7).
    pub level: u32,
    /// Fraction of the triangle normals integrated, in (0, 1] (raised for small meshes
    /// so that at least `min_samples` are integrated).
    pub sample_fraction: f64,
    /// At least this many normals are integrated (when the mesh has them).
    pub min_samples: usize,
    /// Smallest peak on the 0–255 image scale (the paper's v_min), in [0, 255].
    pub value_threshold: f64,
    /// Peaks closer than this (Euclidean, unit normals) merge (the paper's d_peak), in
    /// [0, 2].
    pub cluster_distance: f64,
    /// Clusters lighter than this normalised weight are dropped; finite and ≥ 0.
    pub min_cluster_weight: f64,
}

impl Default for DominantNormalsConfig {
    /// FastGA's own defaults ([`FastGaConfig::default`]), sampling the paper's 12 % of at
    /// least 10,000 normals.
    fn default() -> Self {
        let o = FastGaConfig::default();
        Self {
            level: o.level,
            sample_fraction: 0.12,
            min_samples: 10_000,
            value_threshold: o.value_threshold,
            cluster_distance: o.cluster_distance,
            min_cluster_weight: o.min_cluster_weight,
        }
    }
}

impl From<FastGaConfig> for DominantNormalsConfig {
    /// The section of a FastGA configuration (a preset such as [`FastGaConfig::rgbd`]):
    /// its level, sample fraction, thresholds and cluster weight, with the default
    /// `min_samples` (10,000). The search, parallelism and unit tolerance are the
    /// detector's defaults in the pipeline.
    fn from(c: FastGaConfig) -> Self {
        Self {
            level: c.level,
            sample_fraction: c.sample_fraction,
            value_threshold: c.value_threshold,
            cluster_distance: c.cluster_distance,
            min_cluster_weight: c.min_cluster_weight,
            ..Self::default()
        }
    }
}

impl DominantNormalsConfig {
    /// The detector configuration for a mesh of `normals` triangle normals: the sample
    /// fraction is raised so that at least `min_samples` normals are integrated.
    pub fn config_for(&self, normals: usize) -> FastGaConfig {
        let floor = self.min_samples as f64 / normals.max(1) as f64;
        self.config(self.sample_fraction.max(floor).min(1.0))
    }

    /// Checks every field with FastGA's own rules ([`FastGaConfig::validate`]), the sample
    /// fraction as given (before [`Self::config_for`] raises it).
    ///
    /// # Errors
    /// The first out-of-range field, as FastGA names it.
    pub fn validate(&self) -> Result<(), fastga::FastGaError> {
        self.config(self.sample_fraction).validate()
    }

    fn config(&self, sample_fraction: f64) -> FastGaConfig {
        FastGaConfig::default()
            .with_level(self.level)
            .with_sample_fraction(sample_fraction)
            .with_value_threshold(self.value_threshold)
            .with_cluster_distance(self.cluster_distance)
            .with_min_cluster_weight(self.min_cluster_weight)
    }
}

impl Default for Config {
    fn default() -> Self {
        Self {
            alpha: 0.0,
            lmax: 0.0,
            min_triangles: 20,
            min_area: 0.0,
            min_hole_vertices: 3,
            norm_thresh: 0.9,
            up: [0.0, 0.0, 1.0],
            z_thresh: 0.0,
            threads: 0,
            laplacian: None,
            bilateral: None,
            fastga: DominantNormalsConfig::default(),
            postprocess: None,
            refine: false,
            fill_missing: None,
            decimate: None,
            scan: None,
            unorganized: None,
        }
    }
}

impl Config {
    /// The planar segmentation parameters of this configuration (3D pipelines).
    pub fn segmentation(&self) -> SegmentationConfig {
        SegmentationConfig::new()
            .with_lmax(self.lmax)
            .with_norm_thresh(self.norm_thresh)
            .with_z_thresh(self.z_thresh)
            .with_min_triangles(self.min_triangles)
            .with_min_area(self.min_area)
            .with_min_hole_vertices(self.min_hole_vertices)
            .with_refine(self.refine)
    }

    /// The defaults; see each field.
    pub fn new() -> Self {
        Self::default()
    }

    /// Sets [`Config::alpha`].
    pub fn with_alpha(mut self, alpha: f64) -> Self {
        self.alpha = alpha;
        self
    }

    /// Sets [`Config::lmax`].
    pub fn with_lmax(mut self, lmax: f64) -> Self {
        self.lmax = lmax;
        self
    }

    /// Sets [`Config::min_triangles`].
    pub fn with_min_triangles(mut self, min_triangles: usize) -> Self {
        self.min_triangles = min_triangles;
        self
    }

    /// Sets [`Config::min_hole_vertices`].
    pub fn with_min_hole_vertices(mut self, min_hole_vertices: usize) -> Self {
        self.min_hole_vertices = min_hole_vertices;
        self
    }

    /// Sets [`Config::norm_thresh`].
    pub fn with_norm_thresh(mut self, norm_thresh: f64) -> Self {
        self.norm_thresh = norm_thresh;
        self
    }

    /// Sets [`Config::norm_thresh`] from an angle in degrees (its cosine).
    ///
    /// ```
    /// let config = polylidar::Config::new().with_norm_thresh_degrees(60.0);
    /// assert!((config.norm_thresh - 0.5).abs() < 1e-12);
    /// ```
    pub fn with_norm_thresh_degrees(self, degrees: f64) -> Self {
        self.with_norm_thresh(degrees.to_radians().cos())
    }

    /// Sets [`Config::up`].
    pub fn with_up(mut self, up: [f64; 3]) -> Self {
        self.up = up;
        self
    }

    /// Sets [`Config::threads`].
    pub fn with_threads(mut self, threads: usize) -> Self {
        self.threads = threads;
        self
    }

    /// Runs both smoothing filters (those the config has) on `backend`.
    ///
    /// ```
    /// use polylidar::{Config, SmoothingBackend};
    ///
    /// let config = Config::preset("rgbd")
    ///     .expect("rgbd preset")
    ///     .with_smoothing_backend(SmoothingBackend::Cpu);
    /// assert_eq!(config.bilateral.map(|b| b.backend), Some(SmoothingBackend::Cpu));
    /// ```
    pub fn with_smoothing_backend(mut self, backend: SmoothingBackend) -> Self {
        if let Some(l) = self.laplacian.as_mut() {
            l.backend = backend;
        }
        if let Some(b) = self.bilateral.as_mut() {
            b.backend = backend;
        }
        self
    }

    /// Sets [`Config::z_thresh`].
    pub fn with_z_thresh(mut self, z_thresh: f64) -> Self {
        self.z_thresh = z_thresh;
        self
    }

    /// Sets [`Config::laplacian`] (`None`: no Laplacian smoothing).
    pub fn with_laplacian(mut self, laplacian: Option<LaplacianConfig>) -> Self {
        self.laplacian = laplacian;
        self
    }

    /// Sets [`Config::bilateral`] (`None`: no bilateral normal smoothing).
    pub fn with_bilateral(mut self, bilateral: Option<BilateralConfig>) -> Self {
        self.bilateral = bilateral;
        self
    }

    /// Sets [`Config::fastga`].
    pub fn with_fastga(mut self, fastga: DominantNormalsConfig) -> Self {
        self.fastga = fastga;
        self
    }

    /// Sets [`Config::postprocess`] (`None`: polygons are returned as extracted).
    pub fn with_postprocess(mut self, postprocess: Option<PostprocessConfig>) -> Self {
        self.postprocess = postprocess;
        self
    }

    /// Sets [`Config::fill_missing`] (`None`: missing returns stay missing).
    pub fn with_fill_missing(mut self, fill_missing: Option<FillConfig>) -> Self {
        self.fill_missing = fill_missing;
        self
    }

    /// Sets [`Config::decimate`] (`None`: full resolution).
    pub fn with_decimate(mut self, decimate: Option<DecimateConfig>) -> Self {
        self.decimate = decimate;
        self
    }

    /// The parameters of a named preset (see [`Preset`], whose names these are), or
    /// `None` for a name that is none of them.
    ///
    /// ```
    /// use polylidar::{Config, Preset};
    /// assert_eq!(Config::preset("kitti"), Some(Preset::Kitti.config()));
    /// assert_eq!(Config::preset("no such preset"), None);
    /// ```
    pub fn preset(name: &str) -> Option<Self> {
        name.parse::<Preset>().ok().map(Preset::config)
    }

    /// Checks every field's range, with the rules of the stage each field goes to (the
    /// segmentation's, the smoothing filters', FastGA's, the post-processor's) plus those
    /// of the fields only this crate reads. [`crate::Polylidar::new`] calls it, so a bad
    /// value is refused before any input is read.
    ///
    /// ```
    /// use polylidar::{Config, LaplacianConfig, PolylidarError};
    /// let steep = LaplacianConfig::default().with_lambda(2.0);
    /// let err = Config::new().with_laplacian(Some(steep)).validate().unwrap_err();
    /// assert!(matches!(err, PolylidarError::Config { field: "laplacian.lambda", .. }));
    /// ```
    ///
    /// # Errors
    /// [`PolylidarError::Config`] naming the first bad field (FastGA and post-processing
    /// fields: [`PolylidarError::FastGa`] and [`PolylidarError::Postprocess`], which name
    /// the field too); [`PolylidarError::ThreadPool`] for more threads than
    /// [`max_threads`].
    pub fn validate(&self) -> Result<(), PolylidarError> {
        let bad = PolylidarError::config;
        if !(self.alpha.is_finite() && self.alpha >= 0.0) {
            return bad(
                "alpha",
                self.alpha.to_string(),
                "must be a finite length ≥ 0",
            );
        }
        self.segmentation().validate().map_err(|e| match e {
            planeseg::SegmentError::Config {
                field,
                value,
                reason,
            } => PolylidarError::Config {
                field,
                value: value.to_string(),
                reason,
            },
            other => PolylidarError::Segment(other),
        })?;
        let limit = max_threads();
        if self.threads > limit {
            return Err(PolylidarError::ThreadPool {
                threads: self.threads,
                message: format!(
                    "at most {limit} are allowed ({MAX_THREADS_PER_CORE} per core of this \
                     machine); 0 starts one per core"
                ),
            });
        }
        if let Some(l) = &self.laplacian {
            if !(0.0..=MAX_RANGE_EXPONENT).contains(&l.range_exponent) {
                return bad(
                    "laplacian.range_exponent",
                    l.range_exponent.to_string(),
                    "must be in [0, 4]",
                );
            }
            let iterations = l.iterations.fixed().unwrap_or(1);
            l.options(iterations)
                .validate()
                .map_err(|e| smoothing_error("laplacian", e))?;
            backend_available("laplacian.backend", l.backend)?;
        }
        if let Some(b) = &self.bilateral {
            b.options()
                .validate()
                .map_err(|e| smoothing_error("bilateral", e))?;
            backend_available("bilateral.backend", b.backend)?;
        }
        self.fastga.validate()?;
        if let Some(p) = &self.postprocess {
            p.validate()?;
        }
        if let Some(f) = &self.fill_missing {
            f.validate().map_err(fill_error)?;
        }
        if let Some(d) = &self.decimate {
            d.validate()?;
        }
        if let Some(scan) = &self.scan {
            scan.validate()?;
        }
        if let Some(unorganized) = &self.unorganized {
            unorganized.validate()?;
        }
        let up_len2: f64 = self.up.iter().map(|c| c * c).sum();
        if !(up_len2.is_finite() && up_len2 > 0.0) {
            return bad(
                "up",
                format!("{:?}", self.up),
                "must be finite and non-zero",
            );
        }
        Ok(())
    }
}

/// Refuses [`SmoothingBackend::Gpu`] in a build without this crate's `gpu` feature, where
/// the filter would fail on the first frame instead.
fn backend_available(field: &'static str, backend: SmoothingBackend) -> Result<(), PolylidarError> {
    if backend == SmoothingBackend::Gpu && !cfg!(feature = "gpu") {
        return Err(PolylidarError::Config {
            field,
            value: "gpu".to_owned(),
            reason: "needs the `gpu` feature of the polylidar crate (cpu or cpu_parallel run \
                     without it)",
        });
    }
    Ok(())
}

/// A smoothing filter's option error as a [`PolylidarError::Config`] naming the TOML
/// field (`laplacian.kernel`, `bilateral.sigma_angle`, …).
/// A cosine threshold written as a cosine (`"0.94"`) or as an angle in degrees
/// (`"20deg"`, `"20 deg"`, `"20°"`, 0 to 180): the cosine, or `None` for anything else.
///
/// ```
/// use polylidar::parse_cosine;
///
/// assert_eq!(parse_cosine("0.94"), Some(0.94));
/// assert!((parse_cosine("60deg").unwrap() - 0.5).abs() < 1e-12);
/// assert!((parse_cosine("60°").unwrap() - 0.5).abs() < 1e-12);
/// assert_eq!(parse_cosine("200deg"), None);
/// assert_eq!(parse_cosine("steep"), None);
/// ```
pub fn parse_cosine(text: &str) -> Option<f64> {
    let text = text.trim();
    let degrees = text
        .strip_suffix("deg")
        .or_else(|| text.strip_suffix('°'))
        .map(str::trim_end);
    match degrees {
        Some(d) => {
            let d: f64 = d.parse().ok()?;
            (0.0..=180.0).contains(&d).then(|| d.to_radians().cos())
        }
        None => text.parse().ok(),
    }
}

/// `norm_thresh` from TOML or JSON: a number (a cosine) or a string [`parse_cosine`] reads.
fn cosine_or_degrees<'de, D: serde::Deserializer<'de>>(deserializer: D) -> Result<f64, D::Error> {
    #[derive(Deserialize)]
    #[serde(untagged)]
    enum Written {
        Cosine(f64),
        Text(String),
    }
    match Written::deserialize(deserializer)? {
        Written::Cosine(c) => Ok(c),
        Written::Text(text) => parse_cosine(&text).ok_or_else(|| {
            serde::de::Error::custom(format!(
                "norm_thresh {text:?}: a cosine such as 0.94 or an angle such as \"20deg\""
            ))
        }),
    }
}

/// A fill option's error with the field named as in the TOML (`fill_missing.…`).
fn fill_error(error: OpcError) -> PolylidarError {
    match error {
        OpcError::InvalidParameter {
            name,
            value,
            expected,
        } => PolylidarError::Config {
            field: match name {
                "min_neighbours" => "fill_missing.min_neighbours",
                "max_spread" => "fill_missing.max_spread",
                _ => "fill_missing",
            },
            value,
            reason: expected,
        },
        other => PolylidarError::Organized(other),
    }
}

fn smoothing_error(section: &'static str, error: SmoothError) -> PolylidarError {
    let field = |name: &str| -> &'static str {
        match (section, name) {
            ("laplacian", "kernel") => "laplacian.kernel",
            ("laplacian", "lambda") => "laplacian.lambda",
            ("laplacian", "iterations") => "laplacian.iterations",
            ("laplacian", _) => "laplacian",
            ("bilateral", "kernel") => "bilateral.kernel",
            ("bilateral", "sigma_length") => "bilateral.sigma_length",
            ("bilateral", "sigma_angle") => "bilateral.sigma_angle",
            ("bilateral", "iterations") => "bilateral.iterations",
            _ => "bilateral",
        }
    };
    match error {
        SmoothError::InvalidKernel { kernel } => PolylidarError::Config {
            field: field("kernel"),
            value: kernel.to_string(),
            reason: "must be odd, from 3 to 15",
        },
        SmoothError::InvalidParameter {
            name,
            value,
            reason,
        } => PolylidarError::Config {
            field: field(name),
            value: short_number(value),
            reason,
        },
        other => PolylidarError::Smooth(other),
    }
}

/// A filter option's value (an `f32` widened to `f64`) as short text: `1e30`, not the
/// 31 digits of its exact value.
fn short_number(value: f64) -> String {
    let single = value as f32;
    if single != 0.0 && !(1e-4..1e6).contains(&single.abs()) {
        format!("{single:e}")
    } else {
        single.to_string()
    }
}

#[cfg(test)]
mod tests {
    use polypost::BufferJoin;

    use super::*;

    /// The field a config error names (or the stage error's text), for every rule.
    fn refused(config: Config) -> String {
        match config.validate() {
            Err(PolylidarError::Config { field, .. }) => field.to_owned(),
            Err(other) => other.to_string(),
            Ok(()) => "accepted".to_owned(),
        }
    }

    fn laplacian(l: LaplacianConfig) -> Config {
        Config::new().with_laplacian(Some(l))
    }

    fn bilateral(b: BilateralConfig) -> Config {
        Config::new().with_bilateral(Some(b))
    }

    #[test]
    fn laplacian_lambda_is_a_step_in_zero_to_one() {
        for lambda in [0.0, -1.0, 2.0, 10.0, 1e30, -1e30, f32::NAN] {
            let config = laplacian(LaplacianConfig {
                lambda,
                ..LaplacianConfig::default()
            });
            assert_eq!(refused(config), "laplacian.lambda", "{lambda}");
        }
        let huge = laplacian(LaplacianConfig {
            lambda: 1e30,
            ..LaplacianConfig::default()
        });
        assert!(huge.validate().unwrap_err().to_string().contains("= 1e30 "));
        let half = laplacian(LaplacianConfig {
            lambda: 0.5,
            ..LaplacianConfig::default()
        });
        assert_eq!(refused(half), "accepted");
    }

    #[test]
    fn iterations_are_bounded() {
        let many = laplacian(LaplacianConfig {
            iterations: LaplacianIterations::Fixed(u32::MAX),
            ..LaplacianConfig::default()
        });
        assert_eq!(refused(many), "laplacian.iterations");
        let many = bilateral(BilateralConfig {
            iterations: mesh_smooth_gpu::MAX_ITERATIONS + 1,
            ..BilateralConfig::default()
        });
        assert_eq!(refused(many), "bilateral.iterations");
        let auto = laplacian(LaplacianConfig {
            iterations: LaplacianIterations::Auto,
            ..LaplacianConfig::default()
        });
        assert_eq!(refused(auto), "accepted");
    }

    #[test]
    fn kernels_are_odd_and_bounded() {
        for kernel in [0, 1, 4, 17, 999_999] {
            let l = laplacian(LaplacianConfig {
                kernel,
                ..LaplacianConfig::default()
            });
            assert_eq!(refused(l), "laplacian.kernel", "{kernel}");
            let b = bilateral(BilateralConfig {
                kernel,
                ..BilateralConfig::default()
            });
            assert_eq!(refused(b), "bilateral.kernel", "{kernel}");
        }
    }

    #[test]
    fn bilateral_sigmas_are_positive() {
        for sigma in [0.0, -0.1, f32::INFINITY, f32::NAN] {
            let b = bilateral(BilateralConfig {
                sigma_length: sigma,
                ..BilateralConfig::default()
            });
            assert_eq!(refused(b), "bilateral.sigma_length", "{sigma}");
            let b = bilateral(BilateralConfig {
                sigma_angle: sigma,
                ..BilateralConfig::default()
            });
            assert_eq!(refused(b), "bilateral.sigma_angle", "{sigma}");
        }
    }

    #[test]
    fn fastga_sample_fraction_is_in_zero_to_one() {
        for sample_fraction in [0.0, -0.5, 1.5, f64::NAN] {
            let config = Config::new().with_fastga(DominantNormalsConfig {
                sample_fraction,
                ..DominantNormalsConfig::default()
            });
            assert!(
                refused(config).contains("sample_fraction"),
                "{sample_fraction}"
            );
        }
        let config = Config::new().with_fastga(DominantNormalsConfig {
            level: 99,
            ..DominantNormalsConfig::default()
        });
        assert!(refused(config).contains("level 99"));
    }

    #[test]
    fn postprocess_lengths_are_checked_with_the_config() {
        let config =
            Config::new().with_postprocess(Some(PostprocessConfig::default().with_beta_neg(-1.0)));
        assert!(refused(config).contains("beta_neg"));
    }

    #[test]
    fn segmentation_rules_are_the_stage_rules() {
        assert_eq!(refused(Config::new().with_z_thresh(-1.0)), "z_thresh");
        assert_eq!(refused(Config::new().with_lmax(f64::INFINITY)), "lmax");
        assert_eq!(refused(Config::new().with_norm_thresh(2.0)), "norm_thresh");
        let config = Config {
            min_area: -1.0,
            ..Config::default()
        };
        assert_eq!(refused(config), "min_area");
    }

    /// `Polylidar::new` refuses a bad value in every section before any input is read,
    /// and the error names the field.
    #[test]
    fn polylidar_new_refuses_a_bad_value_in_every_section() {
        use crate::{BeamOutlierConfig, FieldOfViewConfig, UnorganizedConfig};
        let scan = |s: ScanConfig| Config::new().with_scan(Some(s));
        let unorganized = |u: UnorganizedConfig| Config::new().with_unorganized(Some(u));
        let fill = |f: FillConfig| Config::new().with_fill_missing(Some(f));
        let cases = [
            (Config::new().with_alpha(-1.0), "alpha"),
            (Config::new().with_z_thresh(f64::NAN), "z_thresh"),
            (Config::new().with_up([0.0; 3]), "up"),
            (
                laplacian(LaplacianConfig::default().with_kernel(4)),
                "laplacian.kernel",
            ),
            (
                laplacian(LaplacianConfig::default().with_range_exponent(5.0)),
                "laplacian.range_exponent",
            ),
            (
                bilateral(BilateralConfig::default().with_sigma_angle(-1.0)),
                "bilateral.sigma_angle",
            ),
            (
                fill(FillConfig::default().with_min_neighbours(9)),
                "fill_missing.min_neighbours",
            ),
            (
                fill(FillConfig::default().with_max_spread(f64::NAN)),
                "fill_missing.max_spread",
            ),
            (
                Config::new()
                    .with_fastga(DominantNormalsConfig::default().with_value_threshold(300.0)),
                "value_threshold 300",
            ),
            (
                Config::new()
                    .with_postprocess(Some(PostprocessConfig::default().with_min_hole_area(-1.0))),
                "min_hole_area",
            ),
            (
                scan(ScanConfig::default().with_keep_every(0)),
                "scan.keep_every",
            ),
            (
                scan(
                    ScanConfig::default().with_field_of_view(Some(FieldOfViewConfig::new(
                        [-40.0, 40.0],
                        [-15.0, 95.0],
                    ))),
                ),
                "elevation",
            ),
            (
                scan(ScanConfig::default().with_beam_outliers(Some(
                    BeamOutlierConfig::default().with_min_deviation(-1.0),
                ))),
                "min_deviation",
            ),
            (
                unorganized(UnorganizedConfig::default().with_k(2)),
                "unorganized.k",
            ),
            (
                unorganized(UnorganizedConfig::default().with_smoothing(1001.into())),
                "unorganized.smoothing",
            ),
        ];
        for (config, field) in cases {
            let text = match crate::Polylidar::new(config) {
                Err(e) => e.to_string(),
                Ok(_) => "accepted".to_owned(),
            };
            assert!(text.contains(field), "{field}: {text}");
        }
    }

    #[test]
    fn the_gpu_backend_needs_the_gpu_feature() {
        let cases = [
            (
                laplacian(LaplacianConfig::default().with_backend(SmoothingBackend::Gpu)),
                "laplacian.backend",
            ),
            (
                bilateral(BilateralConfig::default().with_backend(SmoothingBackend::Gpu)),
                "bilateral.backend",
            ),
        ];
        for (gpu, field) in cases {
            let expected = if cfg!(feature = "gpu") {
                "accepted"
            } else {
                field
            };
            assert_eq!(refused(gpu), expected);
        }
    }

    #[test]
    fn threads_are_bounded_by_the_cores() {
        assert_eq!(
            refused(Config::new().with_threads(max_threads())),
            "accepted"
        );
        for threads in [max_threads() + 1, 100_000, usize::MAX] {
            let text = refused(Config::new().with_threads(threads));
            assert!(
                text.contains(&format!("at most {}", max_threads())),
                "{threads}: {text}"
            );
        }
    }

    #[test]
    fn norm_thresh_reads_a_cosine_or_degrees_from_toml() {
        let cosine = |text: &str| toml::from_str::<Config>(text).map(|c| c.norm_thresh);
        assert_eq!(cosine("norm_thresh = 0.5").unwrap(), 0.5);
        assert_eq!(cosine("norm_thresh = 1").unwrap(), 1.0);
        for text in ["norm_thresh = \"60deg\"", "norm_thresh = \"60 °\""] {
            assert!((cosine(text).unwrap() - 0.5).abs() < 1e-12, "{text}");
        }
        let error = cosine("norm_thresh = \"steep\"").unwrap_err().to_string();
        assert!(error.contains("20deg"), "{error}");
        // Written back, it is the cosine.
        let config = Config::new().with_norm_thresh_degrees(60.0);
        let text = toml::to_string(&config).unwrap();
        assert!((cosine(&text).unwrap() - 0.5).abs() < 1e-12);
    }

    /// The stage configurations the config holds as they are keep their TOML form: every
    /// preset survives a round trip, the post-processing corner style is a key, and an
    /// unknown key in a stage's table is refused.
    #[test]
    fn stage_sections_round_trip_through_toml() {
        for preset in Preset::all() {
            let config = preset.config();
            let text = toml::to_string(&config).unwrap();
            let back: Config = toml::from_str(&text).unwrap();
            assert_eq!(back, config, "{preset}:\n{text}");
        }
        let config: Config = toml::from_str(
            "[postprocess]\nalpha = 0.02\nbuffer_join = { round = { max_angle = 0.3 } }\n\
             [fill_missing]\nmin_neighbours = 5\n\
             [scan]\nbeam_outliers = { min_deviation = 0.25 }\n",
        )
        .unwrap();
        let post = config.postprocess.unwrap();
        assert_eq!(post.alpha, 0.02);
        assert_eq!(post.buffer_join, BufferJoin::Round { max_angle: 0.3 });
        let fill = config.fill_missing.unwrap();
        assert_eq!((fill.min_neighbours, fill.max_spread), (5, 0.03));
        let outliers = config.scan.and_then(|s| s.beam_outliers).unwrap();
        assert_eq!((outliers.min_deviation, outliers.neighbours), (0.25, 2));
        let bevel: Config = toml::from_str("[postprocess]\nbuffer_join = \"bevel\"").unwrap();
        assert_eq!(bevel.postprocess.unwrap().buffer_join, BufferJoin::Bevel);
        for text in [
            "[fill_missing]\nneighbours = 5",
            "[postprocess]\nbeta = 0.1",
            "[scan]\nbeam_outliers = { gap = 1.0 }",
        ] {
            assert!(toml::from_str::<Config>(text).is_err(), "{text}");
        }
    }
}

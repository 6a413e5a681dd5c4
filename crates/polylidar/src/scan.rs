//! Rotating LiDAR frames (KITTI's Velodyne, §9.2.2 of the 3D paper): the scan is thinned
//! and cleaned beam by beam ([`rotating_scan`]), then either triangulated along `up` (the
//! paper's 2.5D path: ground and the obstacles on it) or rebuilt into its organized range
//! image for the organized 3D path (every plane direction: walls, kerbs, façades).

use rotating_scan::{BeamOutlierConfig, ElevationBins, FieldOfView, RangeImage, Rings};
use serde::{Deserialize, Serialize};

use crate::config::setters;
use crate::{Extraction, OrganizedPointCloud, Polylidar, PolylidarError, Timings};

/// How a scan's beams (rings) are recovered.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize, Default)]
#[serde(tag = "from", rename_all = "snake_case", deny_unknown_fields)]
pub enum BeamSource {
    /// From the order the points were fired in ([`Rings::from_firing_order`]): exact for
    /// frames stored as the sensor sent them (KITTI `.bin`).
    #[default]
    FiringOrder,
    /// From each point's elevation, `count` beams evenly spaced from `highest_deg` down to
    /// `lowest_deg` ([`Rings::from_elevation`]): for scans whose order is lost;
    /// approximate on real sensors, whose lasers sit off the axis.
    Elevation {
        /// Number of beams.
        count: usize,
        /// Elevation of the lowest beam, degrees.
        lowest_deg: f64,
        /// Elevation of the highest beam, degrees.
        highest_deg: f64,
    },
}

/// The window of a scan to keep, seen from the sensor (degrees; see [`FieldOfView`]).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
#[non_exhaustive]
pub struct FieldOfViewConfig {
    /// Azimuth from +x (forward), counter-clockwise: `[from, to]` within −180–180.
    pub azimuth_deg: [f64; 2],
    /// Elevation above the horizontal: `[lowest, highest]` within −90–90.
    pub elevation_deg: [f64; 2],
}

impl FieldOfViewConfig {
    /// The window `azimuth_deg` × `elevation_deg` (see the fields).
    pub fn new(azimuth_deg: [f64; 2], elevation_deg: [f64; 2]) -> Self {
        Self {
            azimuth_deg,
            elevation_deg,
        }
    }
}

/// Treat an unorganized cloud as one frame of a rotating LiDAR (a Velodyne as in KITTI):
/// thin it and drop beam outliers before extraction (§9.2.2), and optionally rebuild its
/// range image for the organized 3D path. Used by [`Polylidar::extract_scan`], and by
/// `Polylidar::extract` (feature `io`) for clouds when [`crate::Config::scan`] is set;
/// [`Polylidar::extract_25d`] always takes the points as given.
///
/// ```
/// use polylidar::{Config, ScanConfig};
/// let config: Config = toml::from_str(r#"
///     lmax = 1.25
///     [scan]
///     keep_every = 2
///     field_of_view = { azimuth_deg = [-40.7, 40.7], elevation_deg = [-15.6, 13.5] }
///     beam_outliers = { min_deviation = 0.25 }
/// "#).unwrap();
/// let scan = config.scan.unwrap();
/// assert_eq!(scan.keep_every, 2);
/// assert_eq!(scan.beam_outliers.unwrap().neighbours, 2);
/// assert_eq!(scan.range_image_columns, None);
/// ```
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
#[non_exhaustive]
pub struct ScanConfig {
    /// Keep every n-th point in firing order (2: the paper's halving; 1 keeps all).
    pub keep_every: usize,
    /// How the beams are recovered.
    pub beams: BeamSource,
    /// Keep only this window (KITTI: what the front camera sees); absent keeps all.
    pub field_of_view: Option<FieldOfViewConfig>,
    /// Drop beam outliers; absent keeps them.
    pub beam_outliers: Option<BeamOutlierConfig>,
    /// Rebuild the `beams × columns` range image (`0`: as many columns as the median beam
    /// has points) and run the organized 3D path on it instead of 2.5D triangulation.
    pub range_image_columns: Option<usize>,
}

impl Default for ScanConfig {
    fn default() -> Self {
        Self {
            keep_every: 1,
            beams: BeamSource::FiringOrder,
            field_of_view: None,
            beam_outliers: None,
            range_image_columns: None,
        }
    }
}

setters!(ScanConfig {
    with_keep_every => keep_every: usize,
    with_beams => beams: BeamSource,
    with_field_of_view => field_of_view: Option<FieldOfViewConfig>,
    with_beam_outliers => beam_outliers: Option<BeamOutlierConfig>,
    with_range_image_columns => range_image_columns: Option<usize>,
});

/// The points of a scan that survive [`ScanConfig`]'s thinning and outlier removal.
#[derive(Debug, Clone, PartialEq)]
pub struct PreparedScan {
    /// The beams, with only the kept points, in sweep order.
    pub rings: Rings,
    /// Points left out by `keep_every` and the field of view.
    pub thinned: usize,
    /// Points dropped as beam outliers.
    pub outliers: usize,
}

impl PreparedScan {
    /// Indices of the kept points, beam after beam in sweep order.
    pub fn kept(&self) -> impl Iterator<Item = u32> + '_ {
        self.rings.iter().flatten().copied()
    }
}

fn scan_error(e: rotating_scan::ScanError) -> PolylidarError {
    PolylidarError::Scan(e)
}

impl ScanConfig {
    /// Checks every field.
    ///
    /// # Errors
    /// [`PolylidarError::Config`] for `keep_every = 0`, [`PolylidarError::Scan`] naming a
    /// bad window, beam table or outlier parameter.
    pub fn validate(&self) -> Result<(), PolylidarError> {
        if self.keep_every == 0 {
            return Err(PolylidarError::Config {
                field: "scan.keep_every",
                value: "0".to_owned(),
                reason: "must be ≥ 1 (1 keeps every point)",
            });
        }
        self.window()?;
        self.bins()?;
        if let Some(o) = &self.beam_outliers {
            o.validate().map_err(scan_error)?;
        }
        Ok(())
    }

    fn window(&self) -> Result<Option<FieldOfView>, PolylidarError> {
        self.field_of_view
            .map(|f| FieldOfView::new(f.azimuth_deg, f.elevation_deg))
            .transpose()
            .map_err(scan_error)
    }

    fn bins(&self) -> Result<Option<ElevationBins>, PolylidarError> {
        match self.beams {
            BeamSource::FiringOrder => Ok(None),
            BeamSource::Elevation {
                count,
                lowest_deg,
                highest_deg,
            } => ElevationBins::uniform(count, lowest_deg, highest_deg)
                .map(Some)
                .map_err(scan_error),
        }
    }

    /// Recovers the beams of `points`, thins them and drops the beam outliers.
    ///
    /// ```
    /// use polylidar::ScanConfig;
    /// // One beam over flat ground, 720 samples, one spurious return.
    /// let mut points: Vec<[f64; 3]> = (0..720)
    ///     .map(|k| { let a = (k as f64 * 0.5 + 0.2).to_radians(); [9.0 * a.cos(), 9.0 * a.sin(), -1.7] })
    ///     .collect();
    /// points[100][2] = -1.0;
    /// let section = ScanConfig::default()
    ///     .with_keep_every(2)
    ///     .with_beam_outliers(Some(Default::default()));
    /// let prepared = section.prepare(&points)?;
    /// assert_eq!((prepared.thinned, prepared.outliers), (360, 1));
    /// assert_eq!(prepared.kept().count(), 359);
    /// # Ok::<(), polylidar::PolylidarError>(())
    /// ```
    ///
    /// # Errors
    /// [`Self::validate`]'s, and [`PolylidarError::Scan`] for non-finite points or points
    /// that are not in firing order.
    pub fn prepare(&self, points: &[[f64; 3]]) -> Result<PreparedScan, PolylidarError> {
        self.validate()?;
        let n = self.keep_every;
        // Firing order is read from the kept points only; elevation bins every point.
        let (rings, every) = match self.bins()? {
            None => (Rings::from_firing_order_every(points, n), 1),
            Some(bins) => (Rings::from_elevation(points, &bins), n),
        };
        let rings = rings.map_err(scan_error)?;
        let window = self.window()?;
        let thinned_rings = rings.retain(|i| {
            rotating_scan::keep_every(every, i as usize)
                && window.is_none_or(|w| w.contains(&points[i as usize]))
        });
        let thinned = points.len() - thinned_rings.num_points();
        let Some(outlier_config) = self.beam_outliers else {
            return Ok(PreparedScan {
                rings: thinned_rings,
                thinned,
                outliers: 0,
            });
        };
        let mut drop = rotating_scan::beam_outliers(points, &thinned_rings, &outlier_config)
            .map_err(scan_error)?;
        drop.sort_unstable();
        let rings = thinned_rings.retain(|i| drop.binary_search(&i).is_err());
        Ok(PreparedScan {
            rings,
            thinned,
            outliers: drop.len(),
        })
    }
}

impl Polylidar {
    /// Extracts polygons from one frame of a rotating LiDAR (points in firing order, e.g.
    /// a KITTI `.bin`), as [`crate::Config::scan`] says (its defaults when absent):
    ///
    /// 1. stage `outliers`: beams recovered, every n-th point kept, the field of view
    ///    cropped, beam outliers dropped ([`ScanConfig::prepare`]);
    /// 2. without [`ScanConfig::range_image_columns`]: [`Self::extract_25d`] on the kept
    ///    points (§9.2.2: the ground as a polygon, obstacles on it as holes); with it,
    ///    stage `range_image` rebuilds the organized image and
    ///    [`Self::extract_organized`] runs on it (every plane direction).
    ///
    /// Point indices in the result (polygon rings, mesh vertices) refer to the kept
    /// points: in the 2.5D path those of [`PreparedScan::kept`], in the range-image path
    /// the pixels of the image. [`crate::Counts`] reports the points thinned and the
    /// outliers dropped.
    ///
    /// ```
    /// use polylidar::{Config, Polylidar};
    /// // Sixteen beams over flat ground, in firing order.
    /// let mut points = Vec::new();
    /// for beam in 0..16 {
    ///     let range = 6.0 + 0.5 * beam as f64;
    ///     for k in 0..360 {
    ///         let a = (k as f64 + 0.3).to_radians();
    ///         points.push([range * a.cos(), range * a.sin(), -1.7]);
    ///     }
    /// }
    /// let mut config = Config::preset("kitti").unwrap();
    /// config.min_triangles = 100;
    /// config.postprocess = None;
    /// let extraction = Polylidar::new(config)?.extract_scan(&points)?;
    /// assert_eq!(extraction.polygons.len(), 1);
    /// assert!(extraction.diagnostics.timings.get("outliers").is_some());
    /// # Ok::<(), polylidar::PolylidarError>(())
    /// ```
    ///
    /// # Errors
    /// [`ScanConfig::prepare`]'s, then those of the pipeline run.
    pub fn extract_scan(&self, points: &[[f64; 3]]) -> Result<Extraction, PolylidarError> {
        let section = self.config().scan.unwrap_or_default();
        let mut timings = Timings::default();
        // The scan's own stages run in parallel on the pipeline's pool, as the later ones.
        let prepared = timings.time("outliers", || self.install(|| section.prepare(points)))?;
        let mut extraction = match section.range_image_columns {
            None => {
                let kept: Vec<[f64; 3]> = prepared.kept().map(|i| points[i as usize]).collect();
                self.extract_25d(&kept)?
            }
            Some(columns) => {
                let cloud = timings.time("range_image", || {
                    let image = self
                        .install(|| RangeImage::build(points, &prepared.rings, columns))
                        .map_err(scan_error)?;
                    Ok::<_, PolylidarError>(OrganizedPointCloud::new(
                        image.rows,
                        image.cols,
                        image.points,
                    )?)
                })?;
                self.extract_organized(&cloud)?
            }
        };
        let counts = &mut extraction.diagnostics.counts;
        counts.scan_thinned = prepared.thinned;
        counts.beam_outliers = prepared.outliers;
        extraction.diagnostics.timings.prepend(timings);
        Ok(extraction)
    }
}

//! Pipeline parameters, with units and defaults, loadable from TOML.

use serde::{Deserialize, Serialize};

use crate::PolylidarError;

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
pub struct Config {
    /// Keep a triangle only if its circumradius is at most `alpha` (the α-shape test);
    /// `0` disables the test. Length unit.
    pub alpha: f64,
    /// Keep a triangle only if its longest edge is at most `lmax`; `0` disables the test.
    /// Length unit.
    pub lmax: f64,
    /// Drop regions (and so polygons) made of fewer triangles than this.
    pub min_triangles: usize,
    /// Drop holes with fewer vertices than this (the hole is filled).
    pub min_hole_vertices: usize,
    /// 2.5D only: keep a triangle only if the cosine between its normal and `up` is at
    /// least `norm_thresh` (the papers' ang_min as a cosine; `0.94` ≈ 20°). `-1` keeps all.
    pub norm_thresh: f64,
    /// 2.5D only: the direction the cloud is triangulated along and polygons are viewed
    /// from (unit or not; must be non-zero).
    pub up: [f64; 3],
    /// Worker threads; `0` uses rayon's default (one per core). Results are identical
    /// whatever the count.
    pub threads: usize,
}

impl Default for Config {
    fn default() -> Self {
        Self {
            alpha: 0.0,
            lmax: 0.0,
            min_triangles: 20,
            min_hole_vertices: 3,
            norm_thresh: 0.9,
            up: [0.0, 0.0, 1.0],
            threads: 0,
        }
    }
}

impl Config {
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

    /// Checks every field's range.
    ///
    /// # Errors
    /// [`PolylidarError::Config`] naming the first bad field.
    pub fn validate(&self) -> Result<(), PolylidarError> {
        let bad = |field, value: String, reason| {
            Err(PolylidarError::Config {
                field,
                value,
                reason,
            })
        };
        if !(self.alpha.is_finite() && self.alpha >= 0.0) {
            return bad(
                "alpha",
                self.alpha.to_string(),
                "must be a finite length ≥ 0",
            );
        }
        if !(self.lmax.is_finite() && self.lmax >= 0.0) {
            return bad("lmax", self.lmax.to_string(), "must be a finite length ≥ 0");
        }
        if !(-1.0..=1.0).contains(&self.norm_thresh) {
            return bad(
                "norm_thresh",
                self.norm_thresh.to_string(),
                "must be a cosine in [-1, 1]",
            );
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

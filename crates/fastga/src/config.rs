//! The one-call pipeline: configuration, presets from the paper, and [`FastGa`].

use crate::accumulator::{GaussianAccumulator, Search};
use crate::integrate::{AsNormal, IntegrateStats, Parallelism};
use crate::peaks::{DominantNormal, Peak, cluster_peaks};
use crate::{FastGaError, MAX_LEVEL};

/// Parameters of dominant-normal detection, named as in the paper and `DESIGN.md`.
#[derive(Debug, Clone, Copy, PartialEq)]
#[non_exhaustive]
pub struct FastGaConfig {
    /// Icosahedron refinement level, 0–7: `20·4^level` cells (level 4: 5,120 cells, about 4°
    /// between neighbouring vertices). Default 4.
    pub level: u32,
    /// Fraction of the input normals integrated, in (0, 1]; chosen deterministically by index.
    /// Default 1 (all); the paper uses 0.12 on meshes.
    pub sample_fraction: f64,
    /// Smallest peak value on the image's 0–255 scale (the paper's `v_min`). Default 15.
    pub value_threshold: f64,
    /// Peaks whose normals are at most this Euclidean distance apart are merged
    /// (single linkage; the paper's `d_peak`; 0.1 ≈ 5.7°). Default 0.1.
    pub cluster_distance: f64,
    /// Clusters with a total normalised weight (sum of peak values / 255) below this are
    /// dropped. Default 0.15.
    pub min_cluster_weight: f64,
    /// Tolerance on `|‖n‖² − 1|` beyond which an input normal is skipped. Default 1e-4.
    pub unit_tolerance: f64,
    /// Sequential or rayon integration; results are identical. Default [`Parallelism::Rayon`].
    pub parallelism: Parallelism,
    /// How normals are matched to cells; results are identical. Default
    /// [`Search::Adaptive`].
    pub search: Search,
}

impl Default for FastGaConfig {
    fn default() -> Self {
        Self {
            level: 4,
            sample_fraction: 1.0,
            value_threshold: 15.0,
            cluster_distance: 0.1,
            min_cluster_weight: 0.15,
            unit_tolerance: crate::accumulator::DEFAULT_UNIT_TOLERANCE,
            parallelism: Parallelism::Rayon,
            search: Search::Adaptive,
        }
    }
}

impl FastGaConfig {
    /// The paper's RealSense RGB-D preset (Table 7): level 3, `v_min` 50, `d_peak` 0.28, 12 %.
    pub fn rgbd() -> Self {
        Self::default()
            .with_level(3)
            .with_value_threshold(50.0)
            .with_cluster_distance(0.28)
            .with_sample_fraction(0.12)
    }

    /// The paper's SynPEB preset (Table 9): level 5, `v_min` 2, `d_peak` 0.1, 12 %.
    ///
    /// The facade's `synpeb` presets use [`Self::synpeb_benchmark`] instead.
    pub fn synpeb() -> Self {
        Self::default()
            .with_level(5)
            .with_value_threshold(2.0)
            .with_cluster_distance(0.1)
            .with_sample_fraction(0.12)
    }

    /// The SynPEB values of the authors' benchmark scripts, which the timing comparisons
    /// with the original ran: [`Self::synpeb`] with `v_min` 3 instead of 2 and clusters
    /// kept down to a normalised weight of 0.01 (the default 0.15 drops the light
    /// directions of small planes): level 5, `v_min` 3, `d_peak` 0.1, weight 0.01, 12 %.
    pub fn synpeb_benchmark() -> Self {
        Self::synpeb()
            .with_value_threshold(3.0)
            .with_min_cluster_weight(0.01)
    }

    /// The paper's mesh preset (Tables 14–15): level 4, `v_min` 15, `d_peak` 0.1, 12 %.
    pub fn mesh() -> Self {
        Self::default()
            .with_level(4)
            .with_value_threshold(15.0)
            .with_cluster_distance(0.1)
            .with_sample_fraction(0.12)
    }

    /// Sets [`level`](Self::level).
    pub fn with_level(mut self, level: u32) -> Self {
        self.level = level;
        self
    }

    /// Sets [`sample_fraction`](Self::sample_fraction).
    pub fn with_sample_fraction(mut self, sample_fraction: f64) -> Self {
        self.sample_fraction = sample_fraction;
        self
    }

    /// Sets [`value_threshold`](Self::value_threshold).
    pub fn with_value_threshold(mut self, value_threshold: f64) -> Self {
        self.value_threshold = value_threshold;
        self
    }

    /// Sets [`cluster_distance`](Self::cluster_distance).
    pub fn with_cluster_distance(mut self, cluster_distance: f64) -> Self {
        self.cluster_distance = cluster_distance;
        self
    }

    /// Sets [`cluster_distance`](Self::cluster_distance) from an angle in degrees between
    /// unit normals (chord length `2 sin(θ/2)`).
    pub fn with_cluster_angle_deg(mut self, degrees: f64) -> Self {
        self.cluster_distance = 2.0 * (degrees.to_radians() / 2.0).sin();
        self
    }

    /// Sets [`min_cluster_weight`](Self::min_cluster_weight).
    pub fn with_min_cluster_weight(mut self, min_cluster_weight: f64) -> Self {
        self.min_cluster_weight = min_cluster_weight;
        self
    }

    /// Sets [`unit_tolerance`](Self::unit_tolerance).
    pub fn with_unit_tolerance(mut self, unit_tolerance: f64) -> Self {
        self.unit_tolerance = unit_tolerance;
        self
    }

    /// Sets [`parallelism`](Self::parallelism).
    pub fn with_parallelism(mut self, parallelism: Parallelism) -> Self {
        self.parallelism = parallelism;
        self
    }

    /// Sets [`search`](Self::search).
    pub fn with_search(mut self, search: Search) -> Self {
        self.search = search;
        self
    }

    /// Checks every field's range.
    ///
    /// # Errors
    /// The first field out of range, as its [`FastGaError`] variant.
    pub fn validate(&self) -> Result<(), FastGaError> {
        if self.level > MAX_LEVEL {
            return Err(FastGaError::LevelOutOfRange {
                level: self.level,
                max: MAX_LEVEL,
            });
        }
        if !(self.sample_fraction > 0.0 && self.sample_fraction <= 1.0) {
            return Err(FastGaError::InvalidSampleFraction(self.sample_fraction));
        }
        if !(0.0..=255.0).contains(&self.value_threshold) {
            return Err(FastGaError::InvalidValueThreshold(self.value_threshold));
        }
        if !(0.0..=2.0).contains(&self.cluster_distance) {
            return Err(FastGaError::InvalidClusterDistance(self.cluster_distance));
        }
        if !(self.min_cluster_weight >= 0.0 && self.min_cluster_weight.is_finite()) {
            return Err(FastGaError::InvalidMinClusterWeight(
                self.min_cluster_weight,
            ));
        }
        crate::unit_tolerance_checked(self.unit_tolerance)?;
        Ok(())
    }
}

/// What [`FastGa::detect`] found.
#[derive(Debug, Clone, PartialEq)]
pub struct Detection {
    /// Dominant normals, strongest first.
    pub normals: Vec<DominantNormal>,
    /// All peaks before clustering, strongest first.
    pub peaks: Vec<Peak>,
    /// What happened to the input normals.
    pub stats: IntegrateStats,
}

/// Dominant plane normals of sets of unit normals: an accumulator built once for a
/// configuration and reused for every call.
///
/// ```
/// use fastga::{FastGa, FastGaConfig};
///
/// let mut fastga = FastGa::new(FastGaConfig::default())?;
/// let mut normals = vec![[0.0, 0.0, 1.0]; 600];
/// normals.extend(vec![[1.0, 0.0, 0.0]; 400]);
/// let found = fastga.detect(&normals)?;
/// assert_eq!(found.normals.len(), 2);
/// assert!(found.normals[0].normal[2] > 0.999);
/// # Ok::<(), fastga::FastGaError>(())
/// ```
#[derive(Debug, Clone)]
pub struct FastGa {
    config: FastGaConfig,
    accumulator: GaussianAccumulator,
}

impl FastGa {
    /// Validates `config` and builds its accumulator.
    ///
    /// # Errors
    /// The first out-of-range field of `config`.
    pub fn new(config: FastGaConfig) -> Result<Self, FastGaError> {
        config.validate()?;
        let mut accumulator = GaussianAccumulator::with_search(config.level, config.search)?;
        accumulator.set_unit_tolerance(config.unit_tolerance)?;
        Ok(Self {
            config,
            accumulator,
        })
    }

    /// The configuration.
    pub fn config(&self) -> &FastGaConfig {
        &self.config
    }

    /// Sets the fraction of the normals that the next [`detect`](Self::detect) calls
    /// integrate, keeping the accumulator (which is what costs to build).
    ///
    /// # Errors
    /// [`FastGaError`] for a fraction outside `(0, 1]`; the detector is then unchanged.
    pub fn set_sample_fraction(&mut self, sample_fraction: f64) -> Result<(), FastGaError> {
        let config = self.config.with_sample_fraction(sample_fraction);
        config.validate()?;
        self.config = config;
        Ok(())
    }

    /// The accumulator as left by the last call (for its counts or image).
    pub fn accumulator(&self) -> &GaussianAccumulator {
        &self.accumulator
    }

    /// Empties the accumulator, integrates `normals`, and finds the dominant normals.
    ///
    /// # Errors
    /// None with a validated configuration; the signature leaves room for input checks.
    pub fn detect<N: AsNormal>(&mut self, normals: &[N]) -> Result<Detection, FastGaError> {
        self.accumulator.clear();
        let stats = self.accumulator.integrate(
            normals,
            self.config.sample_fraction,
            self.config.parallelism,
        )?;
        let peaks = self.accumulator.find_peaks(self.config.value_threshold);
        let normals = cluster_peaks(
            &peaks,
            self.config.cluster_distance,
            self.config.min_cluster_weight,
        );
        Ok(Detection {
            normals,
            peaks,
            stats,
        })
    }
}

/// One-shot dominant plane normals of `normals` with `config` (builds the accumulator; reuse
/// a [`FastGa`] for repeated calls).
///
/// # Errors
/// The first out-of-range field of `config`.
pub fn dominant_normals<N: AsNormal>(
    normals: &[N],
    config: &FastGaConfig,
) -> Result<Vec<DominantNormal>, FastGaError> {
    Ok(FastGa::new(*config)?.detect(normals)?.normals)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn values(c: FastGaConfig) -> (u32, f64, f64, f64, f64) {
        (
            c.level,
            c.value_threshold,
            c.cluster_distance,
            c.min_cluster_weight,
            c.sample_fraction,
        )
    }

    #[test]
    fn presets_carry_the_paper_values() {
        assert_eq!(values(FastGaConfig::rgbd()), (3, 50.0, 0.28, 0.15, 0.12));
        assert_eq!(values(FastGaConfig::synpeb()), (5, 2.0, 0.1, 0.15, 0.12));
        assert_eq!(values(FastGaConfig::mesh()), (4, 15.0, 0.1, 0.15, 0.12));
        assert_eq!(
            values(FastGaConfig::synpeb_benchmark()),
            (5, 3.0, 0.1, 0.01, 0.12)
        );
    }
}

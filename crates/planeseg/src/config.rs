//! Segmentation parameters.

use crate::SegmentError;

/// Parameters of planar segmentation, named as in the papers. Lengths are in the units of
/// the mesh coordinates (metres for most sensors).
#[derive(Debug, Clone, Copy, PartialEq)]
#[non_exhaustive]
pub struct SegmentationConfig {
    /// Drop triangles whose longest edge exceeds this; `0` disables the test.
    pub lmax: f64,
    /// Minimum cosine between a triangle normal and its nearest dominant normal (the
    /// paper's ang_min: `0.96` allows about 16°). Default 0.95.
    pub norm_thresh: f64,
    /// Maximum distance from a triangle's centroid to the segment's plane (through the seed
    /// triangle's centroid, orthogonal to the dominant normal); `0` disables the test.
    pub z_thresh: f64,
    /// Keep segments of at least this many triangles. Default 20.
    pub min_triangles: usize,
    /// With [`Self::refine`]: also keep a segment of fewer than `min_triangles`
    /// triangles when its area reaches this (square length unit), so that a large plane
    /// far from the sensor, sampled by few pixels, is not lost; `0` (the default) keeps
    /// by count only.
    pub min_area: f64,
    /// Keep holes of at least this many vertices. Default 3.
    pub min_hole_vertices: usize,
    /// Refine the grown segments before their polygons are extracted: absorb the
    /// neighbouring triangles that fit a segment's plane, grow planes that no dominant
    /// normal explains from the triangles left over, and merge neighbouring segments that
    /// fit one plane (see the crate docs). Default off: the paper's Alg. 5 as published.
    pub refine: bool,
}

impl Default for SegmentationConfig {
    fn default() -> Self {
        Self {
            lmax: 0.0,
            norm_thresh: 0.95,
            z_thresh: 0.0,
            min_triangles: 20,
            min_area: 0.0,
            min_hole_vertices: 3,
            refine: false,
        }
    }
}

impl SegmentationConfig {
    /// The defaults.
    pub fn new() -> Self {
        Self::default()
    }

    /// Sets [`Self::lmax`].
    pub fn with_lmax(mut self, lmax: f64) -> Self {
        self.lmax = lmax;
        self
    }

    /// Sets [`Self::norm_thresh`].
    pub fn with_norm_thresh(mut self, norm_thresh: f64) -> Self {
        self.norm_thresh = norm_thresh;
        self
    }

    /// Sets [`Self::norm_thresh`] from an angle in degrees (its cosine).
    ///
    /// ```
    /// let config = planeseg::SegmentationConfig::new().with_norm_thresh_degrees(60.0);
    /// assert!((config.norm_thresh - 0.5).abs() < 1e-12);
    /// ```
    pub fn with_norm_thresh_degrees(self, degrees: f64) -> Self {
        self.with_norm_thresh(degrees.to_radians().cos())
    }

    /// Sets [`Self::z_thresh`].
    pub fn with_z_thresh(mut self, z_thresh: f64) -> Self {
        self.z_thresh = z_thresh;
        self
    }

    /// Sets [`Self::min_triangles`].
    pub fn with_min_triangles(mut self, min_triangles: usize) -> Self {
        self.min_triangles = min_triangles;
        self
    }

    /// Sets [`Self::min_area`].
    pub fn with_min_area(mut self, min_area: f64) -> Self {
        self.min_area = min_area;
        self
    }

    /// Sets [`Self::min_hole_vertices`].
    pub fn with_min_hole_vertices(mut self, min_hole_vertices: usize) -> Self {
        self.min_hole_vertices = min_hole_vertices;
        self
    }

    /// Sets [`Self::refine`].
    pub fn with_refine(mut self, refine: bool) -> Self {
        self.refine = refine;
        self
    }

    /// Checks the ranges.
    ///
    /// # Errors
    /// [`SegmentError::Config`] naming the first bad field.
    pub fn validate(&self) -> Result<(), SegmentError> {
        let bad = |field, value, reason| {
            Err(SegmentError::Config {
                field,
                value,
                reason,
            })
        };
        if !(self.lmax.is_finite() && self.lmax >= 0.0) {
            return bad("lmax", self.lmax, "must be a finite length ≥ 0");
        }
        if !(-1.0..=1.0).contains(&self.norm_thresh) {
            return bad(
                "norm_thresh",
                self.norm_thresh,
                "must be a cosine in [-1, 1]",
            );
        }
        if !(self.z_thresh.is_finite() && self.z_thresh >= 0.0) {
            return bad("z_thresh", self.z_thresh, "must be a finite length ≥ 0");
        }
        if !(self.min_area.is_finite() && self.min_area >= 0.0) {
            return bad("min_area", self.min_area, "must be a finite area ≥ 0");
        }
        Ok(())
    }
}

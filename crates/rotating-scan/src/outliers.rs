//! Beam-neighbour outlier removal (Polylidar3D §9.2.2): a point whose neighbours on its
//! own beam lie on one flat surface, and which itself lies far off that surface, is a
//! spurious return.

use rayon::prelude::*;

use crate::{Rings, ScanError};

/// Parameters of [`beam_outliers`]. Lengths in the cloud's unit (metres for LiDAR).
///
/// Along one beam, the neighbours on each side of a point are tested: when they lie on one
/// straight line (the beam's trace over a flat surface: road, wall) within
/// `flat_tolerance`, with no gap wider than `max_gap` between consecutive samples, and the
/// point lies farther than `min_deviation` from that line, the point is an outlier.
///
/// ```
/// use rotating_scan::BeamOutlierConfig;
/// let config = BeamOutlierConfig::default().with_min_deviation(0.3);
/// assert_eq!(config.neighbours, 2);
/// assert!(config.validate().is_ok());
/// ```
#[derive(Debug, Clone, Copy, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
#[cfg_attr(feature = "serde", serde(default, deny_unknown_fields))]
#[non_exhaustive]
pub struct BeamOutlierConfig {
    /// Neighbours tested on each side of a point (≥ 1). With 1 the two neighbours are
    /// taken as the surface without a flatness test.
    pub neighbours: usize,
    /// Largest distance between consecutive samples along the beam that still counts as
    /// one surface; the two samples either side of the point may be twice this apart.
    /// Default 1.0.
    pub max_gap: f64,
    /// The neighbours lie on one flat surface when each is within this distance of the
    /// line through the two nearest neighbours. Default 0.06.
    pub flat_tolerance: f64,
    /// A point farther than this from that line deviates strongly. Default 0.2.
    pub min_deviation: f64,
}

impl Default for BeamOutlierConfig {
    fn default() -> Self {
        Self {
            neighbours: 2,
            max_gap: 1.0,
            flat_tolerance: 0.06,
            min_deviation: 0.2,
        }
    }
}

impl BeamOutlierConfig {
    /// Sets [`Self::neighbours`].
    #[must_use]
    pub fn with_neighbours(mut self, neighbours: usize) -> Self {
        self.neighbours = neighbours;
        self
    }

    /// Sets [`Self::max_gap`].
    #[must_use]
    pub fn with_max_gap(mut self, max_gap: f64) -> Self {
        self.max_gap = max_gap;
        self
    }

    /// Sets [`Self::flat_tolerance`].
    #[must_use]
    pub fn with_flat_tolerance(mut self, flat_tolerance: f64) -> Self {
        self.flat_tolerance = flat_tolerance;
        self
    }

    /// Sets [`Self::min_deviation`].
    #[must_use]
    pub fn with_min_deviation(mut self, min_deviation: f64) -> Self {
        self.min_deviation = min_deviation;
        self
    }

    /// Checks every field.
    ///
    /// # Errors
    /// [`ScanError::Parameter`] for `neighbours` outside 1–16 or a length that is not
    /// finite and positive.
    pub fn validate(&self) -> Result<(), ScanError> {
        if !(1..=16).contains(&self.neighbours) {
            return Err(ScanError::Parameter {
                field: "neighbours",
                value: self.neighbours.to_string(),
                reason: "must be 1 to 16",
            });
        }
        for (field, v) in [
            ("max_gap", self.max_gap),
            ("flat_tolerance", self.flat_tolerance),
            ("min_deviation", self.min_deviation),
        ] {
            if !(v.is_finite() && v > 0.0) {
                return Err(ScanError::Parameter {
                    field,
                    value: v.to_string(),
                    reason: "must be a finite length > 0",
                });
            }
        }
        Ok(())
    }
}

/// The outliers of a scan: indices of the points of `rings` that deviate strongly from the
/// flat surface their beam neighbours lie on ([`BeamOutlierConfig`]), in ring order.
///
/// Every point is judged against the input (an outlier's neighbour is not judged without
/// it), so the result does not depend on the order points are visited in. The first and
/// last `neighbours` points of a beam are never outliers. Beams are judged in parallel on
/// the current rayon pool; the result is the same for any number of threads.
///
/// ```
/// use rotating_scan::{BeamOutlierConfig, Rings, beam_outliers};
/// // One beam sweeping across flat ground 1.7 m below the sensor, one sample 0.5 m too high.
/// let mut points: Vec<[f64; 3]> = (0..50)
///     .map(|k| { let a = (k as f64 * 0.4).to_radians(); [10.0 * a.cos(), 10.0 * a.sin(), -1.7] })
///     .collect();
/// points[20][2] += 0.5;
/// let rings = Rings::from_members(&[(0..50).collect()], points.len())?;
/// assert_eq!(beam_outliers(&points, &rings, &BeamOutlierConfig::default())?, vec![20]);
/// # Ok::<(), rotating_scan::ScanError>(())
/// ```
///
/// # Errors
/// [`BeamOutlierConfig::validate`]'s, and [`ScanError::MemberOutOfRange`] when a ring
/// refers past `points`.
pub fn beam_outliers(
    points: &[[f64; 3]],
    rings: &Rings,
    config: &BeamOutlierConfig,
) -> Result<Vec<u32>, ScanError> {
    config.validate()?;
    rings.check_members(points.len())?;
    let rings: Vec<&[u32]> = rings.iter().collect();
    // Beams in parallel, each with a reused buffer; the order of the result is the rings'.
    let per_ring: Vec<Vec<u32>> = rings
        .par_iter()
        .map_init(Vec::new, |close, ring| {
            ring_outliers(points, ring, config, close)
        })
        .collect();
    Ok(per_ring.concat())
}

/// The outliers of one beam; `close` is scratch space.
fn ring_outliers(
    points: &[[f64; 3]],
    ring: &[u32],
    config: &BeamOutlierConfig,
    close: &mut Vec<bool>,
) -> Vec<u32> {
    let k = config.neighbours;
    let gap2 = config.max_gap * config.max_gap;
    let flat2 = config.flat_tolerance * config.flat_tolerance;
    let dev2 = config.min_deviation * config.min_deviation;
    let mut out = Vec::new();
    if ring.len() < 2 * k + 1 {
        return out;
    }
    let at = |j: usize| points[ring[j] as usize];
    // Whether consecutive samples j and j + 1 are close enough to be one surface.
    close.clear();
    close.extend((0..ring.len() - 1).map(|j| dist2(&at(j), &at(j + 1)) <= gap2));
    for j in k..ring.len() - k {
        // Neighbours j-k..j-1 and j+1..j+k, consecutive gaps small; the gap across the
        // point is judged between its two neighbours.
        let left_close = close[j - k..j - 1].iter().all(|&c| c);
        let right_close = close[j + 1..j + k].iter().all(|&c| c);
        if !(left_close && right_close) {
            continue;
        }
        let a = at(j - 1);
        let b = at(j + 1);
        let ab2 = dist2(&a, &b);
        if ab2 > 4.0 * gap2 || ab2 == 0.0 {
            continue;
        }
        let flat = (2..=k).all(|d| {
            line_dist2(&at(j - d), &a, &b) <= flat2 && line_dist2(&at(j + d), &a, &b) <= flat2
        });
        if flat && line_dist2(&at(j), &a, &b) > dev2 {
            out.push(ring[j]);
        }
    }
    out
}

#[inline]
fn dist2(a: &[f64; 3], b: &[f64; 3]) -> f64 {
    let d = [a[0] - b[0], a[1] - b[1], a[2] - b[2]];
    d[0] * d[0] + d[1] * d[1] + d[2] * d[2]
}

/// Squared distance from `p` to the line through `a` and `b` (`a ≠ b`).
#[inline]
fn line_dist2(p: &[f64; 3], a: &[f64; 3], b: &[f64; 3]) -> f64 {
    let u = [b[0] - a[0], b[1] - a[1], b[2] - a[2]];
    let v = [p[0] - a[0], p[1] - a[1], p[2] - a[2]];
    let c = [
        u[1] * v[2] - u[2] * v[1],
        u[2] * v[0] - u[0] * v[2],
        u[0] * v[1] - u[1] * v[0],
    ];
    (c[0] * c[0] + c[1] * c[1] + c[2] * c[2]) / (u[0] * u[0] + u[1] * u[1] + u[2] * u[2])
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn line_distance() {
        let d = line_dist2(&[0.0, 1.0, 0.0], &[0.0, 0.0, 0.0], &[2.0, 0.0, 0.0]);
        assert!((d - 1.0).abs() < 1e-12);
        let d = line_dist2(&[5.0, 0.0, 3.0], &[0.0, 0.0, 0.0], &[1.0, 0.0, 0.0]);
        assert!((d - 9.0).abs() < 1e-12);
    }

    #[test]
    fn validation_names_the_field() {
        let bad = BeamOutlierConfig::default().with_neighbours(0);
        assert!(matches!(
            bad.validate(),
            Err(ScanError::Parameter {
                field: "neighbours",
                ..
            })
        ));
        let bad = BeamOutlierConfig::default().with_max_gap(f64::NAN);
        assert!(matches!(
            bad.validate(),
            Err(ScanError::Parameter {
                field: "max_gap",
                ..
            })
        ));
    }

    #[test]
    fn a_corner_is_not_an_outlier() {
        // A beam sweeping along a wall then turning onto another wall: the corner's
        // neighbours are not on one line, so nothing is removed.
        let points: Vec<[f64; 3]> = (0..20)
            .map(|k| {
                let k = k as f64 * 0.1;
                if k <= 1.0 {
                    [5.0, k, 0.0]
                } else {
                    [5.0 - (k - 1.0), 1.0, 0.0]
                }
            })
            .collect();
        let rings = Rings::from_members(&[(0..20).collect()], 20).unwrap_or_default();
        let out = beam_outliers(&points, &rings, &BeamOutlierConfig::default());
        assert_eq!(out, Ok(vec![]));
    }
}

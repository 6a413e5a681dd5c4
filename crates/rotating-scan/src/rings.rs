//! Beams (rings) of a rotating scan: which points one laser fired, in sweep order.

use std::f64::consts::{FRAC_PI_2, PI, TAU};

use rayon::prelude::*;

use crate::ScanError;

/// Most beams [`Rings::from_firing_order`] accepts before it calls the order broken (the
/// largest spinning LiDARs have 128 beams).
pub const MAX_BEAMS: usize = 256;

/// A negative azimuth step up to this (radians, 10°) is jitter within a sweep; a larger
/// one means the sweep went on past a stretch without returns, round to the next beam.
const JITTER: f64 = 10.0 * PI / 180.0;

/// Points per parallel task where points are mapped one by one.
pub(crate) const PARALLEL_CHUNK: usize = 4096;

/// The points of each beam, in sweep order (increasing azimuth, as the sensor turns).
///
/// Stored compactly: ring `r` is `members[starts[r]..starts[r + 1]]`, point indices into
/// the cloud the rings were recovered from. Ring 0 is the beam the scan starts with (the
/// top beam for KITTI's HDL-64E frames).
///
/// ```
/// use rotating_scan::Rings;
/// // Two beams of four points each, firing order: beam 0 sweeps round, then beam 1.
/// let points: Vec<[f64; 3]> = (0..8)
///     .map(|i| {
///         let a = (i % 4) as f64 * std::f64::consts::FRAC_PI_2 + 0.1;
///         let z = if i < 4 { 0.5 } else { -0.5 };
///         [10.0 * a.cos(), 10.0 * a.sin(), z]
///     })
///     .collect();
/// let rings = Rings::from_firing_order(&points)?;
/// assert_eq!(rings.len(), 2);
/// assert_eq!(rings.ring(1), &[4, 5, 6, 7]);
/// # Ok::<(), rotating_scan::ScanError>(())
/// ```
#[derive(Debug, Clone, PartialEq, Eq, Default)]
pub struct Rings {
    members: Vec<u32>,
    starts: Vec<usize>,
}

/// How elevation is cut into beams by [`Rings::from_elevation`]: each point goes to the beam
/// whose elevation angle is nearest its own.
#[derive(Debug, Clone, PartialEq)]
pub struct ElevationBins {
    /// Beam elevations in radians, highest first (ring 0 is the highest beam).
    angles: Vec<f64>,
}

impl ElevationBins {
    /// `beams` beams evenly spaced from `highest_deg` down to `lowest_deg` (degrees).
    ///
    /// # Errors
    /// [`ScanError::Parameter`] unless `beams ≥ 2` and `lowest_deg < highest_deg`, both
    /// finite.
    pub fn uniform(beams: usize, lowest_deg: f64, highest_deg: f64) -> Result<Self, ScanError> {
        if !(2..=MAX_BEAMS).contains(&beams) {
            return Err(ScanError::Parameter {
                field: "beams",
                value: beams.to_string(),
                reason: "must be 2 to 256",
            });
        }
        if !(lowest_deg.is_finite() && highest_deg.is_finite() && lowest_deg < highest_deg) {
            return Err(ScanError::Parameter {
                field: "elevation range",
                value: format!("{lowest_deg}..{highest_deg}"),
                reason: "must be finite with lowest < highest",
            });
        }
        let step = (highest_deg - lowest_deg) / (beams - 1) as f64;
        Ok(Self {
            angles: (0..beams)
                .map(|k| (highest_deg - step * k as f64).to_radians())
                .collect(),
        })
    }

    /// Beams at the given elevations (radians, any order; sorted highest first here), e.g.
    /// [`Rings::elevations`] of a frame whose firing order is known, or a sensor's table.
    ///
    /// # Errors
    /// [`ScanError::Parameter`] for fewer than 2 or more than [`MAX_BEAMS`] angles, or a
    /// non-finite one.
    pub fn from_angles(mut angles: Vec<f64>) -> Result<Self, ScanError> {
        if angles.len() < 2 || angles.len() > MAX_BEAMS || angles.iter().any(|a| !a.is_finite()) {
            return Err(ScanError::Parameter {
                field: "beam elevations",
                value: format!("{} angles", angles.len()),
                reason: "need 2 to 256 finite angles",
            });
        }
        angles.sort_by(|a, b| b.total_cmp(a));
        Ok(Self { angles })
    }

    /// The beam elevations, highest first (radians).
    pub fn angles(&self) -> &[f64] {
        &self.angles
    }

    /// The beam nearest elevation `e` (radians).
    fn beam_of(&self, e: f64) -> usize {
        // Angles descend: the first angle not above e, or the last.
        let k = self.angles.partition_point(|&a| a > e);
        match k {
            0 => 0,
            k if k == self.angles.len() => k - 1,
            k if self.angles[k - 1] - e < e - self.angles[k] => k - 1,
            k => k,
        }
    }
}

/// Azimuth of `p` about the vertical axis, in (−π, π].
#[inline]
pub(crate) fn azimuth(p: &[f64; 3]) -> f64 {
    p[1].atan2(p[0])
}

/// [`azimuth`] within 1.2 · 10⁻⁵ radians, at a fraction of the cost of `atan2`
/// (branch-free, so a loop over points vectorizes): arctan on [0, 1] by the degree-9 odd
/// polynomial of Abramowitz & Stegun 4.4.49, then the octant. Splitting a scan into beams
/// compares azimuth steps of about a milliradian and turns of 2π, far above the error.
/// `p` must be off the vertical axis.
#[inline]
fn fast_azimuth(p: &[f64; 3]) -> f64 {
    let (x, y) = (p[0], p[1]);
    let (ax, ay) = (x.abs(), y.abs());
    let t = ax.min(ay) / ax.max(ay);
    let t2 = t * t;
    let atan = t
        * (0.999_866_0
            + t2 * (-0.330_299_5 + t2 * (0.180_141_0 + t2 * (-0.085_133_0 + t2 * 0.020_835_1))));
    let octant = if ay > ax { FRAC_PI_2 - atan } else { atan };
    let half = if x < 0.0 { PI - octant } else { octant };
    half.copysign(y)
}

/// Elevation of `p` seen from the origin, radians.
#[inline]
pub(crate) fn elevation(p: &[f64; 3]) -> f64 {
    p[2].atan2(p[0].hypot(p[1]))
}

fn check_finite(points: &[[f64; 3]]) -> Result<(), ScanError> {
    match points.iter().position(|p| !p.iter().all(|v| v.is_finite())) {
        Some(index) => Err(ScanError::NonFinite {
            index,
            point: points[index],
        }),
        None => Ok(()),
    }
}

impl Rings {
    /// The beams of a scan whose points are in firing order: each beam sweeps once round
    /// the vertical axis (azimuth increasing, counter-clockwise seen from above, as KITTI's
    /// Velodyne frames are stored), then the next beam starts where the scan started.
    ///
    /// The scan must start at its seam, with the first beam's first return, as a
    /// sensor's frame does. A beam ends where the azimuth, unwrapped along the points,
    /// passes a whole turn beyond that first point (less half the median step, to absorb
    /// the jitter of the seam), so a beam missing its first or last returns still ends
    /// at the seam — unless the next beam also misses its first returns and starts less
    /// than 10° before where this one ended, which azimuth alone cannot tell from jitter;
    /// a backward step of more than 10° counts as the sweep going on round
    /// a stretch without returns, and a step past more than one turn leaves an empty beam
    /// for each turn skipped, so beams keep their numbers. Points at the sensor's axis
    /// (x = y = 0) stay in the beam being swept.
    ///
    /// # Errors
    /// [`ScanError::NonFinite`] for a NaN or infinite coordinate,
    /// [`ScanError::NotFiringOrder`] when more than [`MAX_BEAMS`] beams come out.
    pub fn from_firing_order(points: &[[f64; 3]]) -> Result<Self, ScanError> {
        Self::from_firing_order_every(points, 1)
    }

    /// As [`Self::from_firing_order`], on every `n`-th point only (indices `0, n, 2n, …`;
    /// `n ≤ 1`: all): the beams of a scan thinned as §9.2.2 thins it, at a fraction of the
    /// cost.
    ///
    /// ```
    /// use rotating_scan::Rings;
    /// let points: Vec<[f64; 3]> = (0..720)
    ///     .map(|k| { let a = ((k % 360) as f64 + 0.5).to_radians(); [a.cos(), a.sin(), if k < 360 { 0.1 } else { -0.1 }] })
    ///     .collect();
    /// let rings = Rings::from_firing_order_every(&points, 2)?;
    /// assert_eq!(rings.len(), 2);
    /// assert_eq!(rings.ring(1)[..2], [360, 362]);
    /// # Ok::<(), rotating_scan::ScanError>(())
    /// ```
    ///
    /// # Errors
    /// As [`Self::from_firing_order`] (only the points taken are checked).
    pub fn from_firing_order_every(points: &[[f64; 3]], n: usize) -> Result<Self, ScanError> {
        let n = n.max(1);
        if let Some(index) = (0..points.len())
            .step_by(n)
            .find(|&i| !points[i].iter().all(|v| v.is_finite()))
        {
            return Err(ScanError::NonFinite {
                index,
                point: points[index],
            });
        }
        let taken: Vec<u32> = (0..points.len() as u32).step_by(n).collect();
        if taken.is_empty() {
            return Ok(Self::default());
        }
        // The azimuths, the costly part, in parallel (the current rayon pool).
        let azimuths: Vec<Option<f64>> = taken
            .par_iter()
            .with_min_len(PARALLEL_CHUNK)
            .map(|&i| {
                let p = &points[i as usize];
                (p[0] != 0.0 || p[1] != 0.0).then(|| fast_azimuth(p))
            })
            .collect();
        let steps = forward_steps(&azimuths);
        let mut positive: Vec<f64> = steps.iter().copied().filter(|&s| s > 0.0).collect();
        let half_step = if positive.is_empty() {
            0.0
        } else {
            let mid = positive.len() / 2;
            *positive.select_nth_unstable_by(mid, f64::total_cmp).1 / 2.0
        };
        let mut starts = vec![0];
        // Sweep since the first point, plus the seam allowance.
        let mut sweep = half_step;
        let mut turns = 0.0f64;
        for (i, step) in steps.iter().enumerate() {
            sweep += step;
            // A step over more than one turn leaves an empty beam between.
            while sweep >= (turns + 1.0) * TAU {
                turns += 1.0;
                starts.push(i + 1);
                if starts.len() > MAX_BEAMS + 1 {
                    return Err(ScanError::NotFiringOrder {
                        found: starts.len(),
                        max: MAX_BEAMS,
                    });
                }
            }
        }
        starts.push(taken.len());
        Ok(Self {
            members: taken,
            starts,
        })
    }

    /// The beams of a scan in any order, by elevation: each point goes to the beam of
    /// `bins` nearest its elevation seen from the origin, and each beam is sorted by
    /// azimuth (from −π; firing order kept among equal azimuths).
    ///
    /// Elevation seen from the origin is only approximate for a real sensor, whose lasers
    /// sit a few centimetres off the axis: near points stray into the next beams. Prefer
    /// [`Self::from_firing_order`] when the order is known.
    ///
    /// # Errors
    /// [`ScanError::NonFinite`] for a NaN or infinite coordinate.
    pub fn from_elevation(points: &[[f64; 3]], bins: &ElevationBins) -> Result<Self, ScanError> {
        check_finite(points)?;
        let beams = bins.angles.len();
        let beam: Vec<usize> = points.iter().map(|p| bins.beam_of(elevation(p))).collect();
        let mut starts = vec![0usize; beams + 1];
        for &b in &beam {
            starts[b + 1] += 1;
        }
        for k in 0..beams {
            starts[k + 1] += starts[k];
        }
        let mut fill = starts.clone();
        let mut members = vec![0u32; points.len()];
        for (i, &b) in beam.iter().enumerate() {
            members[fill[b]] = i as u32;
            fill[b] += 1;
        }
        for r in 0..beams {
            members[starts[r]..starts[r + 1]].sort_by(|&a, &b| {
                azimuth(&points[a as usize]).total_cmp(&azimuth(&points[b as usize]))
            });
        }
        Ok(Self { members, starts })
    }

    /// Rings from explicit member lists (point indices in sweep order), checked against a
    /// cloud of `points` points.
    ///
    /// # Errors
    /// [`ScanError::MemberOutOfRange`] for an index `≥ points`.
    pub fn from_members(rings: &[Vec<u32>], points: usize) -> Result<Self, ScanError> {
        let mut out = Self {
            members: Vec::with_capacity(rings.iter().map(Vec::len).sum()),
            starts: vec![0],
        };
        for ring in rings {
            if let Some(&index) = ring.iter().find(|&&i| i as usize >= points) {
                return Err(ScanError::MemberOutOfRange { index, points });
            }
            out.members.extend_from_slice(ring);
            out.starts.push(out.members.len());
        }
        Ok(out)
    }

    /// Number of beams.
    pub fn len(&self) -> usize {
        self.starts.len().saturating_sub(1)
    }

    /// Whether there is no beam.
    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }

    /// The points of beam `r` in sweep order (empty for `r ≥ len()`).
    pub fn ring(&self, r: usize) -> &[u32] {
        match (self.starts.get(r), self.starts.get(r + 1)) {
            (Some(&a), Some(&b)) => &self.members[a..b],
            _ => &[],
        }
    }

    /// The beams in order.
    pub fn iter(&self) -> impl Iterator<Item = &[u32]> {
        (0..self.len()).map(|r| self.ring(r))
    }

    /// Number of points over all beams.
    pub fn num_points(&self) -> usize {
        self.members.len()
    }

    /// Checks that every member indexes one of `points` points.
    ///
    /// # Errors
    /// [`ScanError::MemberOutOfRange`] naming the first member that does not.
    pub fn check_members(&self, points: usize) -> Result<(), ScanError> {
        match self.members.iter().find(|&&i| i as usize >= points) {
            Some(&index) => Err(ScanError::MemberOutOfRange { index, points }),
            None => Ok(()),
        }
    }

    /// The same beams with only the points `keep` accepts, order kept.
    #[must_use]
    pub fn retain(&self, mut keep: impl FnMut(u32) -> bool) -> Self {
        let mut out = Self {
            members: Vec::with_capacity(self.members.len()),
            starts: Vec::with_capacity(self.starts.len()),
        };
        out.starts.push(0);
        for ring in self.iter() {
            out.members
                .extend(ring.iter().copied().filter(|&i| keep(i)));
            out.starts.push(out.members.len());
        }
        out
    }

    /// The beam of each of `points` points (`None` for a point in no beam).
    pub fn beam_of_points(&self, points: usize) -> Vec<Option<u16>> {
        let mut beam = vec![None; points];
        for (r, ring) in self.iter().enumerate() {
            for &i in ring {
                if let Some(slot) = beam.get_mut(i as usize) {
                    *slot = u16::try_from(r).ok();
                }
            }
        }
        beam
    }

    /// The median elevation of each beam's points seen from the origin (radians; NaN for
    /// an empty beam): the beam table of a sensor, to give [`ElevationBins::from_angles`]
    /// for frames whose firing order is lost.
    pub fn elevations(&self, points: &[[f64; 3]]) -> Vec<f64> {
        self.iter()
            .map(|ring| {
                let mut e: Vec<f64> = ring
                    .iter()
                    .filter_map(|&i| points.get(i as usize))
                    .map(elevation)
                    .collect();
                if e.is_empty() {
                    return f64::NAN;
                }
                let mid = e.len() / 2;
                *e.select_nth_unstable_by(mid, f64::total_cmp).1
            })
            .collect()
    }
}

/// Azimuth step from each point to the next, as the sensor turns, from the points'
/// azimuths (`None` on the axis): a backward step of more than [`JITTER`] is taken the
/// long way round. Points on the axis step by 0.
fn forward_steps(azimuths: &[Option<f64>]) -> Vec<f64> {
    let mut steps = Vec::with_capacity(azimuths.len().saturating_sub(1));
    let mut last: Option<f64> = None;
    for &a in azimuths {
        let Some(a) = a else {
            if last.is_some() {
                steps.push(0.0);
            }
            continue;
        };
        if let Some(prev) = last {
            let mut d = a - prev;
            // Into (−π, π], then backward steps beyond the jitter go forward round.
            if d > PI {
                d -= TAU;
            } else if d <= -PI {
                d += TAU;
            }
            if d < -JITTER {
                d += TAU;
            }
            steps.push(d);
        }
        last = Some(a);
    }
    // Leading points on the axis step by nothing (they join beam 0).
    let missing = azimuths.len().saturating_sub(1) - steps.len();
    let mut out = vec![0.0; missing];
    out.extend(steps);
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    fn ring_points(beams: usize, per: usize, start_deg: f64) -> Vec<[f64; 3]> {
        let mut points = Vec::new();
        for b in 0..beams {
            let e = (2.0 - 0.4 * b as f64).to_radians();
            for k in 0..per {
                let a = (start_deg + 360.0 * k as f64 / per as f64).to_radians();
                let r = 20.0;
                points.push([r * e.cos() * a.cos(), r * e.cos() * a.sin(), r * e.sin()]);
            }
        }
        points
    }

    #[test]
    fn firing_order_splits_each_turn() {
        for start in [0.05, -179.9, 90.0] {
            let points = ring_points(5, 100, start);
            let rings = Rings::from_firing_order(&points).unwrap_or_default();
            assert_eq!(rings.len(), 5, "start {start}");
            for r in 0..5 {
                assert_eq!(rings.ring(r).first().copied(), Some(100 * r as u32));
                assert_eq!(rings.ring(r).len(), 100);
            }
        }
    }

    /// A&S give 10⁻⁵ for the polynomial; with the coefficients rounded as they print them
    /// the test measures 1.15 · 10⁻⁵.
    const FAST_AZIMUTH_ERROR: f64 = 1.2e-5;

    #[test]
    fn fast_azimuth_is_atan2_within_its_error() {
        // Every direction on a fine circle, at ranges from 1 mm to 1 km, and the axes.
        let mut worst = 0.0f64;
        for k in 0..100_000 {
            let a = f64::from(k) * TAU / 100_000.0 - PI;
            for r in [1e-3, 1.0, 37.5, 1e3] {
                let p = [r * a.cos(), r * a.sin(), 0.5];
                worst = worst.max((fast_azimuth(&p) - azimuth(&p)).abs());
            }
        }
        assert!(worst <= FAST_AZIMUTH_ERROR, "{worst}");
        assert!(worst > 1e-7, "{worst}: not the approximation");
        for p in [
            [1.0, 0.0, 0.0],
            [0.0, 2.0, 0.0],
            [-3.0, 0.0, 0.0],
            [0.0, -4.0, 0.0],
            [5.0, 5.0, 0.0],
        ] {
            assert!(
                (fast_azimuth(&p) - azimuth(&p)).abs() <= FAST_AZIMUTH_ERROR,
                "{p:?}"
            );
        }
    }

    #[test]
    fn elevation_bins_pick_the_nearest() {
        let bins = ElevationBins::uniform(5, -2.0, 2.0).unwrap_or_else(|_| unreachable!());
        let deg = |d: f64| d.to_radians();
        assert_eq!(bins.beam_of(deg(2.5)), 0);
        assert_eq!(bins.beam_of(deg(1.4)), 1);
        assert_eq!(bins.beam_of(deg(0.4)), 2);
        assert_eq!(bins.beam_of(deg(-3.0)), 4);
        assert!(ElevationBins::uniform(1, -2.0, 2.0).is_err());
        assert!(ElevationBins::uniform(4, 2.0, 2.0).is_err());
        assert!(ElevationBins::from_angles(vec![0.1]).is_err());
    }

    #[test]
    fn bad_points_are_named() {
        let mut points = ring_points(1, 10, 0.0);
        points[3][2] = f64::NAN;
        assert!(matches!(
            Rings::from_firing_order(&points),
            Err(ScanError::NonFinite { index: 3, .. })
        ));
        assert!(Rings::from_members(&[vec![0, 9]], 5).is_err());
    }
}

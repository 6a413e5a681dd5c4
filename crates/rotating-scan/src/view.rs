//! Thinning a scan: every n-th point, and the part of it a camera sees.

use crate::ScanError;

/// An azimuth and elevation window seen from the sensor, in degrees: azimuth about the
/// vertical axis from +x (forward) counter-clockwise (+y, left, is +90°), elevation above the
/// horizontal plane. KITTI keeps only the points its front camera sees (§9.2.2), which this
/// approximates in the sensor frame.
///
/// ```
/// use rotating_scan::FieldOfView;
/// let front = FieldOfView::new([-40.0, 40.0], [-15.0, 13.0])?;
/// assert!(front.contains(&[10.0, 1.0, -1.7]));
/// assert!(!front.contains(&[-10.0, 1.0, -1.7])); // behind
/// assert!(!front.contains(&[3.0, 0.0, -1.7]));   // below the window, near the car
/// # Ok::<(), rotating_scan::ScanError>(())
/// ```
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct FieldOfView {
    /// Unit directions of the azimuth window's edges, and whether it spans more than
    /// half a turn (then a point is inside unless it is in the complement).
    from: [f64; 2],
    to: [f64; 2],
    wide: bool,
    /// Tangents of the elevation bounds.
    tan_elevation: [f64; 2],
}

impl FieldOfView {
    /// The window `azimuth_deg[0]..=azimuth_deg[1]` (within −180–180°; the first may exceed
    /// the second for a window across the back, e.g. `[150, -150]`) by
    /// `elevation_deg[0]..=elevation_deg[1]` (within −90–90°).
    ///
    /// # Errors
    /// [`ScanError::Parameter`] for angles out of those ranges, or an elevation window whose
    /// bounds are reversed.
    pub fn new(azimuth_deg: [f64; 2], elevation_deg: [f64; 2]) -> Result<Self, ScanError> {
        let ok_az = azimuth_deg.iter().all(|a| (-180.0..=180.0).contains(a));
        if !ok_az {
            return Err(ScanError::Parameter {
                field: "azimuth window",
                value: format!("{azimuth_deg:?}"),
                reason: "angles must be within -180..180 degrees",
            });
        }
        let ok_el = elevation_deg.iter().all(|a| (-90.0..=90.0).contains(a))
            && elevation_deg[0] <= elevation_deg[1];
        if !ok_el {
            return Err(ScanError::Parameter {
                field: "elevation window",
                value: format!("{elevation_deg:?}"),
                reason: "must be lowest..highest within -90..90 degrees",
            });
        }
        let [lo, hi] = azimuth_deg.map(f64::to_radians);
        let width = (hi - lo).rem_euclid(std::f64::consts::TAU);
        let dir = |a: f64| [a.cos(), a.sin()];
        Ok(Self {
            from: dir(lo),
            to: dir(hi),
            wide: width > std::f64::consts::PI,
            tan_elevation: elevation_deg.map(|e| e.to_radians().tan()),
        })
    }

    /// Whether the sensor sees `p` through the window (edges included). Trigonometry-free:
    /// half-plane tests against the window's edges and the elevation tangents.
    ///
    /// The azimuth test comes first: it is cheaper, and for a camera's window it turns
    /// most of a turn away before the elevation is looked at.
    pub fn contains(&self, p: &[f64; 3]) -> bool {
        // Counter-clockwise of `from`, and clockwise of `to`.
        let after_from = self.from[0] * p[1] - self.from[1] * p[0] >= 0.0;
        let before_to = p[0] * self.to[1] - p[1] * self.to[0] >= 0.0;
        let in_azimuth = if self.wide {
            after_from || before_to
        } else {
            after_from && before_to
        };
        if !in_azimuth {
            return false;
        }
        let r = p[0].hypot(p[1]);
        if p[2] < self.tan_elevation[0] * r || p[2] > self.tan_elevation[1] * r {
            return false;
        }
        true
    }
}

/// Whether point `index` survives keeping every `n`-th point (`n = 2`: the even indices,
/// §9.2.2's halving; `n ≤ 1` keeps all).
///
/// ```
/// assert!(rotating_scan::keep_every(2, 4));
/// assert!(!rotating_scan::keep_every(2, 5));
/// assert!(rotating_scan::keep_every(1, 5));
/// ```
#[inline]
pub fn keep_every(n: usize, index: usize) -> bool {
    n <= 1 || index.is_multiple_of(n)
}

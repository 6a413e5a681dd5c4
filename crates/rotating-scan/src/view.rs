//! Thinning a scan: every n-th point, and the part of it a camera sees.

use crate::ScanError;
use crate::rings::{azimuth, elevation};

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
    azimuth: [f64; 2],
    elevation: [f64; 2],
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
        Ok(Self {
            azimuth: azimuth_deg.map(f64::to_radians),
            elevation: elevation_deg.map(f64::to_radians),
        })
    }

    /// Whether the sensor sees `p` through the window.
    pub fn contains(&self, p: &[f64; 3]) -> bool {
        let a = azimuth(p);
        let e = elevation(p);
        let [lo, hi] = self.azimuth;
        let in_azimuth = if lo <= hi {
            lo <= a && a <= hi
        } else {
            a >= lo || a <= hi
        };
        in_azimuth && self.elevation[0] <= e && e <= self.elevation[1]
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

//! Sensor poses and ray models: a pinhole depth camera and a spherical range sensor.

use crate::error::{SceneError, finite, positive};
use crate::vec3::{V3, cross, dot, normalize, sub};

/// A rigid sensor-to-world transform: `p_world = R · p_sensor + t`.
///
/// Both sensors use the camera convention for their own frame: `+z` forward (the optical
/// axis, or azimuth 0 / elevation 0), `+x` right, `+y` down.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Pose {
    rotation: [[f64; 3]; 3],
    translation: [f64; 3],
}

impl Default for Pose {
    fn default() -> Self {
        Self::identity()
    }
}

impl Pose {
    /// Sensor frame = world frame.
    pub fn identity() -> Self {
        Self {
            rotation: [[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]],
            translation: [0.0; 3],
        }
    }

    /// A pose from a row-major rotation matrix `R` (columns = sensor axes in world
    /// coordinates) and the sensor position `t` in metres.
    ///
    /// # Errors
    /// Non-finite entries, or `R` not orthonormal with determinant +1 (tolerance `1e-9`).
    pub fn new(rotation: [[f64; 3]; 3], translation: [f64; 3]) -> Result<Self, SceneError> {
        for (i, row) in rotation.iter().enumerate() {
            for &x in row {
                finite(["rotation row 0", "rotation row 1", "rotation row 2"][i], x)?;
            }
        }
        for &x in &translation {
            finite("translation", x)?;
        }
        let col = |j: usize| [rotation[0][j], rotation[1][j], rotation[2][j]];
        let mut deviation: f64 = 0.0;
        for i in 0..3 {
            for j in 0..3 {
                let want = if i == j { 1.0 } else { 0.0 };
                deviation = deviation.max((dot(col(i), col(j)) - want).abs());
            }
        }
        deviation = deviation.max((dot(cross(col(0), col(1)), col(2)) - 1.0).abs());
        if deviation > 1e-9 {
            return Err(SceneError::InvalidPose { deviation });
        }
        Ok(Self {
            rotation,
            translation,
        })
    }

    /// A sensor at `eye` whose forward axis (`+z`) points at `target`, with `+y` (down)
    /// opposite to the world direction `up` as far as possible. Metres, world frame.
    ///
    /// # Errors
    /// Non-finite input, `target == eye`, or `up` parallel to the viewing direction.
    pub fn look_at(eye: [f64; 3], target: [f64; 3], up: [f64; 3]) -> Result<Self, SceneError> {
        let forward = normalize(sub(target, eye)).ok_or(SceneError::InvalidView)?;
        let right = normalize(cross(forward, up)).ok_or(SceneError::InvalidView)?;
        let down = cross(forward, right);
        let rotation = [
            [right[0], down[0], forward[0]],
            [right[1], down[1], forward[1]],
            [right[2], down[2], forward[2]],
        ];
        Self::new(rotation, eye)
    }

    /// Row-major rotation matrix (columns = sensor axes in world coordinates).
    pub fn rotation(&self) -> [[f64; 3]; 3] {
        self.rotation
    }

    /// Sensor position in world coordinates (metres).
    pub fn translation(&self) -> [f64; 3] {
        self.translation
    }

    /// Maps a direction from the sensor frame to the world frame.
    #[inline]
    pub fn rotate(&self, d: [f64; 3]) -> [f64; 3] {
        let r = &self.rotation;
        [dot(r[0], d), dot(r[1], d), dot(r[2], d)]
    }
}

/// A sensor that shoots one ray per pixel of a `rows × cols` grid (row-major; row 0 at the
/// top, column 0 at the left). Implement it to scan with your own ray pattern.
pub trait Sensor: Sync {
    /// Image rows.
    fn rows(&self) -> usize;
    /// Image columns.
    fn cols(&self) -> usize;
    /// Sensor-to-world pose; rays start at its translation.
    fn pose(&self) -> &Pose;
    /// Direction of the ray through pixel `(row, col)` in the sensor frame; it should be a
    /// unit vector ([`Scene::scan`](crate::Scene::scan) normalises it, and leaves pixels
    /// with a zero or non-finite direction empty).
    fn direction(&self, row: usize, col: usize) -> [f64; 3];
}

/// Largest `rows × cols` a built-in sensor accepts (64 Mi pixels, 1.5 GiB of points).
pub const MAX_PIXELS: usize = 1 << 26;

fn check_size(rows: usize, cols: usize) -> Result<(), SceneError> {
    for (name, v) in [("rows", rows), ("cols", cols)] {
        if v == 0 {
            return Err(SceneError::InvalidParameter {
                name,
                value: 0.0,
                reason: "must be >= 1",
            });
        }
    }
    if rows.saturating_mul(cols) > MAX_PIXELS {
        return Err(SceneError::InvalidParameter {
            name: "rows × cols",
            value: rows as f64 * cols as f64,
            reason: "must be at most MAX_PIXELS (2^26)",
        });
    }
    Ok(())
}

/// A pinhole depth camera like a RealSense: focal lengths `fx`, `fy` and principal point
/// `(ppx, ppy)` in pixels, integer pixel coordinates (`u = col`, `v = row`).
///
/// The ray through pixel `(row, col)` has sensor-frame direction
/// `normalize(((col − ppx) / fx, (row − ppy) / fy, 1))`.
#[derive(Debug, Clone, PartialEq)]
pub struct PinholeCamera {
    rows: usize,
    cols: usize,
    fx: f64,
    fy: f64,
    ppx: f64,
    ppy: f64,
    pose: Pose,
}

impl PinholeCamera {
    /// A camera with the principal point at the image centre
    /// (`ppx = (cols − 1) / 2`, `ppy = (rows − 1) / 2`) and the identity pose.
    ///
    /// # Errors
    /// An empty image or more than [`MAX_PIXELS`] pixels, or focal lengths that are not finite and `> 0`.
    pub fn new(rows: usize, cols: usize, fx: f64, fy: f64) -> Result<Self, SceneError> {
        check_size(rows, cols)?;
        Ok(Self {
            rows,
            cols,
            fx: positive("fx", fx)?,
            fy: positive("fy", fy)?,
            ppx: (cols as f64 - 1.0) / 2.0,
            ppy: (rows as f64 - 1.0) / 2.0,
            pose: Pose::identity(),
        })
    }

    /// Sets the principal point (pixels).
    ///
    /// # Errors
    /// Non-finite values.
    pub fn with_principal_point(mut self, ppx: f64, ppy: f64) -> Result<Self, SceneError> {
        self.ppx = finite("ppx", ppx)?;
        self.ppy = finite("ppy", ppy)?;
        Ok(self)
    }

    /// Sets the pose.
    pub fn with_pose(mut self, pose: Pose) -> Self {
        self.pose = pose;
        self
    }

    /// Intrinsics `[fx, fy, ppx, ppy]` in pixels.
    pub fn intrinsics(&self) -> [f64; 4] {
        [self.fx, self.fy, self.ppx, self.ppy]
    }
}

impl Sensor for PinholeCamera {
    fn rows(&self) -> usize {
        self.rows
    }
    fn cols(&self) -> usize {
        self.cols
    }
    fn pose(&self) -> &Pose {
        &self.pose
    }
    #[inline]
    fn direction(&self, row: usize, col: usize) -> [f64; 3] {
        let d: V3 = [
            (col as f64 - self.ppx) / self.fx,
            (row as f64 - self.ppy) / self.fy,
            1.0,
        ];
        normalize(d).unwrap_or([0.0, 0.0, 1.0])
    }
}

/// A spherical range sensor like a LiDAR: `rows × cols` rays on a regular grid of azimuth
/// and elevation, one ray through the centre of each cell of the field of view.
///
/// Azimuth is measured from `+z` (forward), positive to the right (`+x`); elevation from the
/// `x–z` plane, positive up (`−y`). Column `c` has azimuth
/// `−fov_az/2 + (c + ½) · fov_az / cols`, row `r` elevation `fov_el/2 − (r + ½) · fov_el / rows`,
/// and the direction is `(cos el · sin az, −sin el, cos el · cos az)`.
#[derive(Debug, Clone, PartialEq)]
pub struct SphericalSensor {
    rows: usize,
    cols: usize,
    azimuth_fov_deg: f64,
    elevation_fov_deg: f64,
    pose: Pose,
    sin_cos_az: Vec<(f64, f64)>,
    sin_cos_el: Vec<(f64, f64)>,
}

impl SphericalSensor {
    /// A sensor with the given image size and fields of view in degrees (azimuth in
    /// `(0, 360]`, elevation in `(0, 180)`), and the identity pose.
    ///
    /// # Errors
    /// An empty image or more than [`MAX_PIXELS`] pixels, or a field of view out of range.
    pub fn new(
        rows: usize,
        cols: usize,
        azimuth_fov_deg: f64,
        elevation_fov_deg: f64,
    ) -> Result<Self, SceneError> {
        check_size(rows, cols)?;
        if !(azimuth_fov_deg > 0.0 && azimuth_fov_deg <= 360.0) {
            return Err(SceneError::InvalidParameter {
                name: "azimuth_fov_deg",
                value: azimuth_fov_deg,
                reason: "must be in (0, 360]",
            });
        }
        if !(elevation_fov_deg > 0.0 && elevation_fov_deg < 180.0) {
            return Err(SceneError::InvalidParameter {
                name: "elevation_fov_deg",
                value: elevation_fov_deg,
                reason: "must be in (0, 180)",
            });
        }
        let az = azimuth_fov_deg.to_radians();
        let el = elevation_fov_deg.to_radians();
        let sin_cos_az = (0..cols)
            .map(|c| (-az / 2.0 + (c as f64 + 0.5) * az / cols as f64).sin_cos())
            .collect();
        let sin_cos_el = (0..rows)
            .map(|r| (el / 2.0 - (r as f64 + 0.5) * el / rows as f64).sin_cos())
            .collect();
        Ok(Self {
            rows,
            cols,
            azimuth_fov_deg,
            elevation_fov_deg,
            pose: Pose::identity(),
            sin_cos_az,
            sin_cos_el,
        })
    }

    /// Sets the pose.
    pub fn with_pose(mut self, pose: Pose) -> Self {
        self.pose = pose;
        self
    }

    /// Fields of view `(azimuth, elevation)` in degrees.
    pub fn fov_deg(&self) -> (f64, f64) {
        (self.azimuth_fov_deg, self.elevation_fov_deg)
    }
}

impl Sensor for SphericalSensor {
    fn rows(&self) -> usize {
        self.rows
    }
    fn cols(&self) -> usize {
        self.cols
    }
    fn pose(&self) -> &Pose {
        &self.pose
    }
    #[inline]
    fn direction(&self, row: usize, col: usize) -> [f64; 3] {
        let (sa, ca) = self.sin_cos_az[col];
        let (se, ce) = self.sin_cos_el[row];
        [ce * sa, -se, ce * ca]
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn look_at_axes() -> Result<(), SceneError> {
        let p = Pose::look_at([0.0, 0.0, 1.0], [5.0, 0.0, 1.0], [0.0, 0.0, 1.0])?;
        let f = p.rotate([0.0, 0.0, 1.0]);
        let r = p.rotate([1.0, 0.0, 0.0]);
        let d = p.rotate([0.0, 1.0, 0.0]);
        assert!((f[0] - 1.0).abs() < 1e-15);
        assert!((r[1] + 1.0).abs() < 1e-15);
        assert!((d[2] + 1.0).abs() < 1e-15);
        assert!(Pose::look_at([0.0; 3], [0.0, 0.0, 1.0], [0.0, 0.0, 1.0]).is_err());
        assert!(
            Pose::new(
                [[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, -1.0]],
                [0.0; 3]
            )
            .is_err()
        );
        Ok(())
    }

    #[test]
    fn spherical_centre_and_corners() -> Result<(), SceneError> {
        let s = SphericalSensor::new(3, 3, 90.0, 60.0)?;
        let c = s.direction(1, 1);
        assert!((c[2] - 1.0).abs() < 1e-15);
        // Top-left pixel: left (−x) and up (−y).
        let tl = s.direction(0, 0);
        assert!(tl[0] < 0.0 && tl[1] < 0.0);
        assert!(SphericalSensor::new(3, 3, 0.0, 60.0).is_err());
        assert!(SphericalSensor::new(3, 3, 90.0, 180.0).is_err());
        assert!(SphericalSensor::new(0, 3, 90.0, 60.0).is_err());
        Ok(())
    }

    #[test]
    fn pinhole_principal_ray() -> Result<(), SceneError> {
        let cam = PinholeCamera::new(5, 7, 100.0, 100.0)?;
        assert_eq!(cam.direction(2, 3), [0.0, 0.0, 1.0]);
        let d = cam.direction(2, 6);
        assert!((d[0] / d[2] - 0.03).abs() < 1e-15);
        assert!(PinholeCamera::new(5, 7, -1.0, 100.0).is_err());
        Ok(())
    }
}

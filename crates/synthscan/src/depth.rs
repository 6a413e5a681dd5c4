//! RGB-D depth cameras: a pinhole camera with the depth errors of structured-light and
//! active-stereo sensors (Kinect v1, RealSense D435).
//!
//! Both kinds of sensor triangulate: a pixel's depth comes from its disparity `d` against a
//! second view (the Kinect's infrared projector, the D435's right imager) `B` metres away,
//! `z = f · B / d`. That fixes the shape of their errors, which [`DepthModel`] reproduces:
//!
//! * **Random depth noise** grows with the square of the depth, because a constant
//!   disparity error `σ_d` maps to `σ_z = z² · σ_d / (f · B)`. Khoshelham & Elberink
//!   (Sensors 12(2), 2012) measured the Kinect v1 at `σ_z ≈ 1.425e-3 · z²` (metres; about
//!   1.4 mm at 1 m and 3.6 cm at 5 m); Intel's depth-RMS rule for the D400 cameras
//!   (Grunnet-Jepsen et al., *Tuning depth cameras for best performance*) is
//!   `z² · subpixel / (f · B)` with a typical sub-pixel RMS of 0.08 px.
//! * **Quantisation**: disparity is a fixed-point number, so depth takes the discrete values
//!   `f · B / (k · step)`, spaced `z² · step / (f · B)` apart. The Kinect v1 reports
//!   disparity in 1/8 pixel with `f ≈ 580` px (its infrared camera) and `B = 7.5` cm, which
//!   gives the 7 cm depth resolution at 5 m that Khoshelham & Elberink report; the D400's
//!   disparity has 5 fractional bits (1/32 pixel, librealsense's disparity unit).
//! * **Missing returns**: at grazing incidence (too little light or texture comes back),
//!   next to depth discontinuities (matching windows straddle two surfaces), in the
//!   *shadow* of near objects (background the second view cannot see: a band left of each
//!   foreground edge as wide as the disparity difference), and outside the working range.

use rand::RngExt;
use rayon::prelude::*;

use crate::bvh::Bvh;
use crate::error::{SceneError, non_negative, positive, within};
use crate::scan::{ScanResult, normal_pair};
use crate::scene::Scene;
use crate::sensor::{PinholeCamera, Pose, Sensor};
use crate::vec3::{add, dot, normalize, scale};

/// Largest [`DepthModel::edge_band`] (pixels).
pub const MAX_EDGE_BAND: u32 = 64;

/// The depth errors of a triangulating RGB-D sensor (the physics and sources are set out at
/// the top of `src/depth.rs`). Lengths in metres, angles in degrees, pixels of the disparity
/// image.
///
/// Per pixel, in this order: the ray hits the nearest face at depth `z` (along the optical
/// axis); the pixel is dropped if it lies in a baseline shadow ([`DepthModel::shadows`]),
/// at grazing incidence ([`DepthModel::grazing_start_deg`]) or near a depth discontinuity
/// ([`DepthModel::edge_drop`]); then `z` gets normal noise of standard deviation
/// [`DepthModel::sigma`]`(z)`, is quantised in disparity and rounded to
/// [`DepthModel::depth_unit`], and the pixel is dropped if the result lies outside
/// `[min_depth, max_depth]`. The point is placed at the measured depth on the pixel's ray,
/// and keeps the label of the face the ray hit.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct DepthModel {
    /// Distance `B` between the camera and the second view (projector or second imager),
    /// metres; the second view sits along the camera's `+x` (to the right).
    pub baseline: f64,
    /// Focal length `f` of the disparity image, pixels: `z = f · B / d`. It belongs to the
    /// sensor's stereo matcher, not to the output image, so a camera that outputs a
    /// downsampled image keeps its full-resolution value.
    pub disparity_focal: f64,
    /// Disparity quantisation step, pixels (`0`: no quantisation).
    pub disparity_step: f64,
    /// Constant part `a` of the depth noise `σ_z(z) = a + b · z²`, metres.
    pub sigma_floor: f64,
    /// Quadratic part `b` of the depth noise `σ_z(z) = a + b · z²`, 1/metre.
    pub sigma_quadratic: f64,
    /// Depth is rounded to a multiple of this, metres (`0`: no rounding); 16-bit depth
    /// images usually store millimetres (`0.001`).
    pub depth_unit: f64,
    /// Nearest measurable depth, metres.
    pub min_depth: f64,
    /// Farthest measurable depth, metres (may be infinite).
    pub max_depth: f64,
    /// Incidence angle (between the ray and the surface normal) where returns start to go
    /// missing, degrees.
    pub grazing_start_deg: f64,
    /// Incidence angle beyond which no return comes back, degrees; between the two the
    /// probability of a missing return rises smoothly (smoothstep) from 0 to 1. Equal to
    /// `grazing_start_deg`: a hard cut; both 90: only surfaces seen edge-on vanish.
    pub grazing_end_deg: f64,
    /// Whether background pixels the second view cannot see (the shadow of near objects,
    /// left of their edges) are dropped.
    pub shadows: bool,
    /// A depth jump between 4-neighbours larger than this fraction of the nearer depth is a
    /// discontinuity (and so is a neighbour whose ray hits nothing).
    pub edge_jump: f64,
    /// Pixels within this many pixels (Chebyshev distance) of a discontinuity are at risk
    /// of being dropped; `0`: the pixels on either side of the jump only. At most
    /// [`MAX_EDGE_BAND`].
    pub edge_band: u32,
    /// Probability that a pixel at risk near a discontinuity is dropped, in `[0, 1]`.
    pub edge_drop: f64,
}

impl Default for DepthModel {
    fn default() -> Self {
        Self::kinect_v1()
    }
}

impl DepthModel {
    /// A Kinect v1 (structured light, PrimeSense): `B = 0.075` m and disparity in 1/8 px
    /// at `f = 580` px (Khoshelham & Elberink 2012; together they give the reported 7 cm
    /// depth resolution at 5 m); depth noise `a = 0`, `b = 1.16e-3` per metre, which with the
    /// quantisation's own RMS (`≈ 0.83e-3 · z²`) makes the measured `1.425e-3 · z²`; 1 mm
    /// depth unit; range 0.5–5 m (the range Khoshelham & Elberink evaluate); returns fade
    /// from 70° to 85° incidence; shadows on; pixels within 1 px of a jump of more than 5 %
    /// are dropped with probability 0.5.
    pub fn kinect_v1() -> Self {
        Self {
            baseline: 0.075,
            disparity_focal: 580.0,
            disparity_step: 0.125,
            sigma_floor: 0.0,
            sigma_quadratic: 1.16e-3,
            depth_unit: 0.001,
            min_depth: 0.5,
            max_depth: 5.0,
            grazing_start_deg: 70.0,
            grazing_end_deg: 85.0,
            shadows: true,
            edge_jump: 0.05,
            edge_band: 1,
            edge_drop: 0.5,
        }
    }

    /// A RealSense D435 (active stereo) at 848 × 480: `B = 0.050` m, `f = 425` px, disparity
    /// in 1/32 px; depth noise `a = 0`, `b = 3.7e-3` per metre: Intel's RMS rule
    /// `z² · 0.08 / (f · B) = 3.76e-3 · z²` less the quantisation's own RMS
    /// (`≈ 0.42e-3 · z²`), about 15 mm at 2 m (the Polylidar3D paper quotes "as much as"
    /// 4 cm at 2 m, Intel's ≤ 2 % specification); 1 mm depth unit; range 0.2–10 m (the
    /// datasheet's minimum depth at this resolution and its maximum range); returns fade
    /// from 75° to 88°; shadows on; pixels within 1 px of a jump of more than 5 % are
    /// dropped with probability 0.5.
    pub fn d435() -> Self {
        Self {
            baseline: 0.050,
            disparity_focal: 425.0,
            disparity_step: 1.0 / 32.0,
            sigma_floor: 0.0,
            sigma_quadratic: 3.7e-3,
            depth_unit: 0.001,
            min_depth: 0.2,
            max_depth: 10.0,
            grazing_start_deg: 75.0,
            grazing_end_deg: 88.0,
            shadows: true,
            edge_jump: 0.05,
            edge_band: 1,
            edge_drop: 0.5,
        }
    }

    /// No errors at all: the Kinect v1's geometry with zero noise, no quantisation, no
    /// rounding, no missing returns and an unlimited range. Points lie on their planes.
    pub fn ideal() -> Self {
        Self {
            disparity_step: 0.0,
            sigma_floor: 0.0,
            sigma_quadratic: 0.0,
            depth_unit: 0.0,
            min_depth: 0.0,
            max_depth: f64::INFINITY,
            grazing_start_deg: 90.0,
            grazing_end_deg: 90.0,
            shadows: false,
            edge_drop: 0.0,
            ..Self::kinect_v1()
        }
    }

    /// This model without missing returns (no shadows, grazing or edge drop-outs, range
    /// `[0, ∞)`); noise and quantisation kept.
    pub fn without_dropouts(self) -> Self {
        Self {
            min_depth: 0.0,
            max_depth: f64::INFINITY,
            grazing_start_deg: 90.0,
            grazing_end_deg: 90.0,
            shadows: false,
            edge_drop: 0.0,
            ..self
        }
    }

    /// Standard deviation of the random depth noise at depth `z`: `a + b · z²` (metres).
    pub fn sigma(&self, z: f64) -> f64 {
        self.sigma_floor + self.sigma_quadratic * z * z
    }

    /// Spacing of the quantised depths near depth `z`: `z² · step / (f · B)` (metres; 0
    /// without quantisation).
    pub fn depth_step(&self, z: f64) -> f64 {
        z * z * self.disparity_step / (self.disparity_focal * self.baseline)
    }

    /// Probability that a return at incidence angle `deg` (degrees) goes missing.
    pub fn grazing_drop_probability(&self, deg: f64) -> f64 {
        let (s, e) = (self.grazing_start_deg, self.grazing_end_deg);
        if deg >= e {
            1.0
        } else if deg <= s {
            0.0
        } else {
            let t = (deg - s) / (e - s);
            t * t * (3.0 - 2.0 * t)
        }
    }

    /// Checks every field's range.
    ///
    /// # Errors
    /// [`SceneError::InvalidParameter`] naming the first bad field.
    pub fn validate(&self) -> Result<(), SceneError> {
        positive("baseline", self.baseline)?;
        positive("disparity_focal", self.disparity_focal)?;
        non_negative("disparity_step", self.disparity_step)?;
        non_negative("sigma_floor", self.sigma_floor)?;
        non_negative("sigma_quadratic", self.sigma_quadratic)?;
        non_negative("depth_unit", self.depth_unit)?;
        non_negative("min_depth", self.min_depth)?;
        if self.max_depth.is_nan() || self.max_depth <= self.min_depth {
            return Err(SceneError::InvalidParameter {
                name: "max_depth",
                value: self.max_depth,
                reason: "must be > min_depth",
            });
        }
        within(
            "grazing_start_deg",
            self.grazing_start_deg,
            0.0..=90.0,
            "must be in [0, 90]",
        )?;
        within(
            "grazing_end_deg",
            self.grazing_end_deg,
            self.grazing_start_deg..=90.0,
            "must be in [grazing_start_deg, 90]",
        )?;
        positive("edge_jump", self.edge_jump)?;
        if self.edge_band > MAX_EDGE_BAND {
            return Err(SceneError::InvalidParameter {
                name: "edge_band",
                value: f64::from(self.edge_band),
                reason: "must be at most MAX_EDGE_BAND (64)",
            });
        }
        within("edge_drop", self.edge_drop, 0.0..=1.0, "must be in [0, 1]")?;
        Ok(())
    }
}

/// The RGB-D cameras of the accuracy suite: two sensors, each at its native resolution and
/// at half of it (every other row and column, like the RealSense decimation filter of
/// magnitude 2 that the Polylidar3D paper uses, Table 6).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum DepthCameraKind {
    /// Kinect v1 depth registered to its colour camera, 640 × 480, `fx = fy = 525` px (the
    /// intrinsics of the TUM RGB-D and ICL-NUIM data sets), [`DepthModel::kinect_v1`].
    Kinect,
    /// The Kinect at 320 × 240, `fx = fy = 262.5` px.
    KinectHalf,
    /// RealSense D435 depth at 848 × 480, `fx = fy = 425` px (≈ 90° horizontal field of
    /// view, as D435 units report; the datasheet gives 87° ± 3°), [`DepthModel::d435`].
    D435,
    /// The D435 at 424 × 240, `fx = fy = 212.5` px (the resolution the Polylidar3D paper
    /// runs at).
    D435Half,
}

impl DepthCameraKind {
    /// All four, full resolution before half for each sensor.
    pub const ALL: [Self; 4] = [Self::Kinect, Self::KinectHalf, Self::D435, Self::D435Half];

    /// A short name: `"Kinect 640×480"`, …
    pub fn name(self) -> &'static str {
        match self {
            Self::Kinect => "Kinect 640×480",
            Self::KinectHalf => "Kinect 320×240",
            Self::D435 => "D435 848×480",
            Self::D435Half => "D435 424×240",
        }
    }

    /// Image size `(rows, cols)`.
    pub fn size(self) -> (usize, usize) {
        match self {
            Self::Kinect => (480, 640),
            Self::KinectHalf => (240, 320),
            Self::D435 => (480, 848),
            Self::D435Half => (240, 424),
        }
    }

    /// Focal length `fx = fy` in pixels.
    pub fn focal(self) -> f64 {
        match self {
            Self::Kinect => 525.0,
            Self::KinectHalf => 262.5,
            Self::D435 => 425.0,
            Self::D435Half => 212.5,
        }
    }

    /// The sensor's depth model (the same at both resolutions).
    pub fn model(self) -> DepthModel {
        match self {
            Self::Kinect | Self::KinectHalf => DepthModel::kinect_v1(),
            Self::D435 | Self::D435Half => DepthModel::d435(),
        }
    }
}

/// A pinhole RGB-D depth camera: a [`PinholeCamera`] and the [`DepthModel`] of its errors.
/// Scan with [`Scene::scan_depth`]; as a plain [`Sensor`] ([`Scene::scan`]) it is the
/// error-free pinhole camera.
#[derive(Debug, Clone, PartialEq)]
pub struct SimulatedDepthCamera {
    camera: PinholeCamera,
    model: DepthModel,
}

impl SimulatedDepthCamera {
    /// A depth camera from its pinhole geometry and error model.
    ///
    /// # Errors
    /// A field of `model` out of range ([`DepthModel::validate`]).
    pub fn new(camera: PinholeCamera, model: DepthModel) -> Result<Self, SceneError> {
        model.validate()?;
        Ok(Self { camera, model })
    }

    /// One of the suite's cameras, principal point at the image centre, identity pose.
    ///
    /// # Errors
    /// None in practice (the presets are valid); kept for the constructors it calls.
    pub fn preset(kind: DepthCameraKind) -> Result<Self, SceneError> {
        let (rows, cols) = kind.size();
        let f = kind.focal();
        Self::new(PinholeCamera::new(rows, cols, f, f)?, kind.model())
    }

    /// Sets the pose.
    pub fn with_pose(mut self, pose: Pose) -> Self {
        self.camera = self.camera.with_pose(pose);
        self
    }

    /// Replaces the error model.
    ///
    /// # Errors
    /// A field of `model` out of range.
    pub fn with_model(mut self, model: DepthModel) -> Result<Self, SceneError> {
        model.validate()?;
        self.model = model;
        Ok(self)
    }

    /// The pinhole geometry.
    pub fn camera(&self) -> &PinholeCamera {
        &self.camera
    }

    /// The error model.
    pub fn model(&self) -> &DepthModel {
        &self.model
    }
}

impl Sensor for SimulatedDepthCamera {
    fn rows(&self) -> usize {
        self.camera.rows()
    }
    fn cols(&self) -> usize {
        self.camera.cols()
    }
    fn pose(&self) -> &Pose {
        self.camera.pose()
    }
    #[inline]
    fn direction(&self, row: usize, col: usize) -> [f64; 3] {
        self.camera.direction(row, col)
    }
}

/// Salt of the per-row random streams of [`Scene::scan_depth`].
const DEPTH_STREAM: u64 = 0xD1B5_4A32_D192_ED03;

impl Scene {
    /// Scans the scene with an RGB-D camera: the error-free depth of every pixel, then the
    /// camera's [`DepthModel`] (missing returns, noise, quantisation, range), random draws
    /// seeded by `seed`.
    ///
    /// Points are in the world frame, NaN with label `-1` where there is no depth; a pixel
    /// with depth keeps the label of the face its ray hit. Rows run in parallel; each row
    /// draws from its own stream (seed and row), the same number of draws per pixel, so the
    /// result is the same at any thread count.
    ///
    /// # Errors
    /// None for a camera built by [`SimulatedDepthCamera::new`] (its model is checked there).
    pub fn scan_depth(
        &self,
        camera: &SimulatedDepthCamera,
        seed: u64,
    ) -> Result<ScanResult, SceneError> {
        let model = camera.model();
        model.validate()?;
        let (rows, cols) = (camera.rows(), camera.cols());
        let pose = camera.pose();
        let origin = pose.translation();
        let faces = self.faces();
        let bvh = Bvh::new(faces);

        // Error-free depth along the optical axis, label and |cos incidence| per pixel.
        let mut depth = vec![f64::NAN; rows * cols];
        let mut labels = vec![-1i32; rows * cols];
        let mut cosine = vec![0.0f64; rows * cols];
        depth
            .par_chunks_mut(cols)
            .zip(labels.par_chunks_mut(cols))
            .zip(cosine.par_chunks_mut(cols))
            .enumerate()
            .for_each(|(row, ((z, l), c))| {
                for col in 0..cols {
                    let local = camera.direction(row, col);
                    let Some(dir) = normalize(pose.rotate(local)) else {
                        continue;
                    };
                    if let Some((t, fi)) = bvh.cast(faces, origin, dir) {
                        z[col] = t * local[2];
                        l[col] = faces[fi].label();
                        c[col] = dot(dir, faces[fi].normal()).abs();
                    }
                }
            });

        let fx = camera.camera().intrinsics()[0];
        let shadowed = if model.shadows {
            shadow_mask(&depth, cols, fx * model.baseline)
        } else {
            vec![false; rows * cols]
        };
        let near_edge = if model.edge_drop > 0.0 {
            edge_mask(
                &depth,
                rows,
                cols,
                model.edge_jump,
                model.edge_band as usize,
            )
        } else {
            vec![false; rows * cols]
        };

        let fb = model.disparity_focal * model.baseline;
        let mut points = vec![[f64::NAN; 3]; rows * cols];
        points
            .par_chunks_mut(cols)
            .zip(labels.par_chunks_mut(cols))
            .enumerate()
            .for_each(|(row, (pts, lbs))| {
                let mut rng = crate::scan::row_rng(seed ^ DEPTH_STREAM, row);
                for col in 0..cols {
                    let i = row * cols + col;
                    // The same four draws for every pixel.
                    let (gauss, _) = normal_pair(&mut rng);
                    let u_grazing = rng.random::<f64>();
                    let u_edge = rng.random::<f64>();
                    let z = depth[i];
                    if lbs[col] < 0 {
                        continue;
                    }
                    let incidence = cosine[i].clamp(0.0, 1.0).acos().to_degrees();
                    let dropped = shadowed[i]
                        || u_grazing < model.grazing_drop_probability(incidence)
                        || (near_edge[i] && u_edge < model.edge_drop);
                    let measured = if dropped {
                        None
                    } else {
                        measure(model, fb, z + model.sigma(z) * gauss)
                    };
                    match measured {
                        Some(zm) => {
                            let local = camera.direction(row, col);
                            pts[col] = add(origin, pose.rotate(scale(local, zm / local[2])));
                        }
                        None => lbs[col] = -1,
                    }
                }
            });
        Ok(ScanResult {
            rows,
            cols,
            points,
            labels,
            planes: self.ground_truth(),
        })
    }
}

/// The reported depth of a noisy depth `z`: quantised in disparity, rounded to the depth
/// unit, inside the range; `None` if the sensor reports nothing.
fn measure(model: &DepthModel, fb: f64, z: f64) -> Option<f64> {
    if z.is_nan() || z <= 0.0 {
        return None;
    }
    let mut z = z;
    if model.disparity_step > 0.0 {
        let steps = (fb / z / model.disparity_step).round();
        if steps < 1.0 {
            return None;
        }
        z = fb / (steps * model.disparity_step);
    }
    if model.depth_unit > 0.0 {
        z = (z / model.depth_unit).round() * model.depth_unit;
    }
    (z.is_finite() && z >= model.min_depth && z <= model.max_depth).then_some(z)
}

/// Pixels the second view, `B` to the camera's right, cannot see: in each row, pixel `c`
/// appears in the second view at column `c − f·B / z(c)`; it is hidden if a pixel to its
/// right appears at or left of that column (a nearer surface covers it there).
fn shadow_mask(depth: &[f64], cols: usize, fb: f64) -> Vec<bool> {
    let mut mask = vec![false; depth.len()];
    mask.par_chunks_mut(cols)
        .zip(depth.par_chunks(cols))
        .for_each(|(m, z)| {
            let mut min_right = f64::INFINITY;
            for c in (0..cols).rev() {
                if !z[c].is_finite() {
                    continue;
                }
                let p = c as f64 - fb / z[c];
                m[c] = p >= min_right;
                min_right = min_right.min(p);
            }
        });
    mask
}

/// Pixels within `band` (Chebyshev distance) of a depth discontinuity: a pixel with depth
/// whose 4-neighbour has no depth or differs by more than `jump` times the nearer depth.
fn edge_mask(depth: &[f64], rows: usize, cols: usize, jump: f64, band: usize) -> Vec<bool> {
    let is_jump = |a: f64, b: f64| !b.is_finite() || (a - b).abs() > jump * a.min(b);
    let mut edge = vec![false; depth.len()];
    edge.par_chunks_mut(cols).enumerate().for_each(|(r, e)| {
        for c in 0..cols {
            let z = depth[r * cols + c];
            if !z.is_finite() {
                continue;
            }
            let mut neighbours = [f64::NAN; 4];
            let mut n = 0;
            if c > 0 {
                neighbours[n] = depth[r * cols + c - 1];
                n += 1;
            }
            if c + 1 < cols {
                neighbours[n] = depth[r * cols + c + 1];
                n += 1;
            }
            if r > 0 {
                neighbours[n] = depth[(r - 1) * cols + c];
                n += 1;
            }
            if r + 1 < rows {
                neighbours[n] = depth[(r + 1) * cols + c];
                n += 1;
            }
            e[c] = neighbours[..n].iter().any(|&b| is_jump(z, b));
        }
    });
    if band == 0 {
        return edge;
    }
    // Separable dilation: along rows, then along columns.
    let mut wide = vec![false; edge.len()];
    wide.par_chunks_mut(cols)
        .zip(edge.par_chunks(cols))
        .for_each(|(w, e)| {
            for (c, v) in w.iter_mut().enumerate() {
                let (lo, hi) = (c.saturating_sub(band), (c + band).min(cols - 1));
                *v = e[lo..=hi].iter().any(|&x| x);
            }
        });
    let mut out = vec![false; edge.len()];
    out.par_chunks_mut(cols).enumerate().for_each(|(r, o)| {
        let (lo, hi) = (r.saturating_sub(band), (r + band).min(rows - 1));
        for (c, v) in o.iter_mut().enumerate() {
            *v = (lo..=hi).any(|rr| wide[rr * cols + c]);
        }
    });
    out
}

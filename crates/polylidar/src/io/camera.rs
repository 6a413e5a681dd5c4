//! Depth cameras: where a depth image's intrinsics come from and how many of its units
//! make a metre, turned into the back-projection of [`OrganizedPointCloud::from_depth_image`].

use std::path::{Path, PathBuf};

use polylidar_io::{ErrorKind, Format, IoError, Limits, ReadNotes};

use crate::{DepthOptions, Intrinsics, OrganizedPointCloud, PolylidarError};

/// Depth units per metre when nothing says otherwise: millimetres (RealSense, Kinect v1
/// through OpenNI, ICL-NUIM; Open3D's default).
pub const DEFAULT_UNITS_PER_METRE: f64 = 1000.0;

/// Where the intrinsics of a depth image come from.
#[derive(Debug, Clone, PartialEq)]
pub enum CameraSource {
    /// Focal lengths and principal point given by the caller, in pixels of the image read.
    Pinhole(Intrinsics),
    /// A camera file, read by its extension ([`polylidar_io::read_camera_file`]): an
    /// Open3D camera JSON (`.json`) or a RealSense metadata CSV; its image size must be
    /// the depth image's.
    File(PathBuf),
    /// The RealSense `_metadata.csv` beside the depth image
    /// ([`polylidar_io::metadata_path_for`]); what [`super::Input::read`] uses.
    Beside,
}

/// A depth camera: its intrinsics' source and its depth scale.
///
/// Precedence: the intrinsics are the [`CameraSource`] given (the CLI's `--intrinsics`,
/// numbers or a file) or else the RealSense CSV beside the image; the depth scale is
/// [`Self::units_per_metre`] when set, else the one the camera file states (RealSense
/// `Depth Units`), else [`DEFAULT_UNITS_PER_METRE`].
///
/// ```
/// use polylidar::Intrinsics;
/// use polylidar::io::{CameraSource, DepthCamera};
///
/// // A TUM RGB-D frame: PrimeSense intrinsics, 5000 units per metre.
/// let tum = DepthCamera::new(CameraSource::Pinhole(Intrinsics::new(525.0, 525.0, 319.5, 239.5)))
///     .with_units_per_metre(5000.0);
/// let cloud = tum.cloud(&[5000, 0, 10000, 5000], 2, 2, None)?;
/// assert_eq!(cloud.point(0, 0)[2], 1.0);
/// assert_eq!(cloud.point(1, 0)[2], 2.0);
/// # Ok::<(), polylidar::PolylidarError>(())
/// ```
#[derive(Debug, Clone, PartialEq)]
pub struct DepthCamera {
    /// Where the intrinsics come from.
    pub source: CameraSource,
    /// Depth units per metre (1000 for millimetres, 5000 for the TUM RGB-D benchmark);
    /// `None`: the camera file's own, else [`DEFAULT_UNITS_PER_METRE`].
    pub units_per_metre: Option<f64>,
}

impl Default for DepthCamera {
    /// The RealSense CSV beside the image, with its depth scale.
    fn default() -> Self {
        Self::new(CameraSource::Beside)
    }
}

impl DepthCamera {
    /// A camera with intrinsics from `source` and the depth scale of the file (or 1000).
    pub fn new(source: CameraSource) -> Self {
        Self {
            source,
            units_per_metre: None,
        }
    }

    /// Sets the depth units per metre.
    pub fn with_units_per_metre(mut self, units_per_metre: f64) -> Self {
        self.units_per_metre = Some(units_per_metre);
        self
    }

    /// The back-projection of a `width × height` depth image read from `depth_png` (the
    /// path locates a [`CameraSource::Beside`] CSV and names the image in errors).
    ///
    /// # Errors
    /// [`PolylidarError::Io`]: an unreadable camera file, a camera file for another
    /// image size, no CSV beside the image ([`ErrorKind::MissingMetadata`]);
    /// [`PolylidarError::Config`]: units per metre that are not finite and > 0.
    pub fn depth_options(
        &self,
        depth_png: &Path,
        width: usize,
        height: usize,
    ) -> Result<DepthOptions, PolylidarError> {
        let mut options = match &self.source {
            CameraSource::Pinhole(k) => {
                DepthOptions::new(*k).with_depth_scale(1.0 / DEFAULT_UNITS_PER_METRE)
            }
            CameraSource::File(path) => from_file(path, width, height)?,
            CameraSource::Beside => {
                from_file(&polylidar_io::metadata_path_for(depth_png)?, width, height)?
            }
        };
        if let Some(units) = self.units_per_metre {
            if !(units.is_finite() && units > 0.0) {
                return Err(PolylidarError::Config {
                    field: "depth_scale",
                    value: units.to_string(),
                    reason: "depth units per metre, finite and > 0",
                });
            }
            options = options.with_depth_scale(1.0 / units);
        }
        Ok(options)
    }

    /// Back-projects a depth image of `rows × cols` units (row-major, 0 for no return)
    /// taken by this camera; `depth_png` is where it came from (for
    /// [`CameraSource::Beside`] and errors), `None` for an image made in memory.
    ///
    /// # Errors
    /// Those of [`Self::depth_options`] (a [`CameraSource::Beside`] camera without a path
    /// has no CSV to read) and of [`OrganizedPointCloud::from_depth_image`].
    pub fn cloud(
        &self,
        depth: &[u16],
        rows: usize,
        cols: usize,
        depth_png: Option<&Path>,
    ) -> Result<OrganizedPointCloud, PolylidarError> {
        let path = depth_png.unwrap_or(Path::new("<memory>"));
        let options = self.depth_options(path, cols, rows)?;
        Ok(OrganizedPointCloud::from_depth_image(
            depth, rows, cols, &options,
        )?)
    }

    /// Reads a 16-bit depth PNG and back-projects it ([`Self::cloud`]).
    ///
    /// # Errors
    /// An unreadable PNG, one past the default budget of its size ([`Limits::for_path`]),
    /// and those of [`Self::cloud`].
    pub fn read(&self, depth_png: impl AsRef<Path>) -> Result<OrganizedPointCloud, PolylidarError> {
        let depth_png = depth_png.as_ref();
        self.read_with(depth_png, &Limits::for_path(depth_png))
    }

    /// [`Self::read`] within `limits`.
    ///
    /// # Errors
    /// As [`Self::read`].
    pub fn read_with(
        &self,
        depth_png: impl AsRef<Path>,
        limits: &Limits,
    ) -> Result<OrganizedPointCloud, PolylidarError> {
        let path = depth_png.as_ref();
        let image = polylidar_io::read_depth_png_with(path, limits)?;
        self.cloud(&image.data, image.height, image.width, Some(path))
    }
}

/// Whether `error` says that no intrinsics were found for a depth image (no source given
/// and no RealSense CSV beside it), for fronts that name their own options in the message.
pub fn is_missing_intrinsics(error: &PolylidarError) -> bool {
    matches!(
        error,
        PolylidarError::Io(IoError {
            kind: ErrorKind::MissingMetadata { .. },
            ..
        })
    )
}

/// The back-projection a camera file describes, checked against the image size.
fn from_file(path: &Path, width: usize, height: usize) -> Result<DepthOptions, PolylidarError> {
    let k = polylidar_io::read_camera_file(path)?;
    let json = path
        .extension()
        .is_some_and(|e| e.eq_ignore_ascii_case("json"));
    let format = if json {
        Format::CameraJson
    } else {
        Format::RealSenseMetadata
    };
    k.check_size(width, height)
        .map_err(|kind| IoError::new(format, kind).at(path))?;
    let options = DepthOptions::from(&k);
    Ok(match k.depth_scale {
        Some(_) => options,
        None => options.with_depth_scale(1.0 / DEFAULT_UNITS_PER_METRE),
    })
}

impl super::Input {
    /// Reads a file as [`super::Input::read_with`] does, but a depth PNG with `camera`'s
    /// intrinsics and depth scale instead of only a RealSense CSV beside it.
    ///
    /// # Errors
    /// As [`super::Input::read_with`] and [`DepthCamera::read_with`].
    pub fn read_with_camera(
        path: impl AsRef<Path>,
        camera: &DepthCamera,
        limits: &Limits,
    ) -> Result<(Self, ReadNotes), PolylidarError> {
        let path = path.as_ref();
        if polylidar_io::format_of(path) == Some(Format::DepthPng) {
            let cloud = camera.read_with(path, limits)?;
            Ok((Self::Organized(cloud), ReadNotes::default()))
        } else {
            Self::read_with(path, limits)
        }
    }
}

impl crate::Polylidar {
    /// [`Self::stream`] over 16-bit depth PNGs taken by `camera`, in the order given
    /// (each named by its path); the PNGs are read, decoded and back-projected on the
    /// loader thread.
    ///
    /// ```no_run
    /// use polylidar::{Config, Polylidar};
    /// use polylidar::io::{CameraSource, DepthCamera};
    /// use polylidar::stream::StreamOptions;
    ///
    /// let camera = DepthCamera::new(CameraSource::File("camera_primesense.json".into()));
    /// let frames = vec!["depth_00000.png".into(), "depth_00001.png".into()];
    /// let polylidar = Polylidar::new(Config::preset("rgbd-auto").unwrap_or_default())?;
    /// for frame in polylidar.stream_depth_pngs(frames, camera, StreamOptions::default()) {
    ///     println!("{}: {} polygons", frame.name, frame.extraction?.polygons.len());
    /// }
    /// # Ok::<(), polylidar::PolylidarError>(())
    /// ```
    pub fn stream_depth_pngs(
        &self,
        paths: Vec<PathBuf>,
        camera: DepthCamera,
        options: crate::stream::StreamOptions,
    ) -> crate::stream::FrameStream<'_> {
        let sources = paths
            .into_iter()
            .map(|p| (p.display().to_string(), p))
            .collect();
        self.stream(sources, move |path: PathBuf| camera.read(&path), options)
    }
}

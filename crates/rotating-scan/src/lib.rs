//! Rotating LiDAR scans — Velodyne-like sensors whose lasers (beams) each sweep once round
//! the vertical axis per frame, as in KITTI's frames — prepared for Polylidar:
//!
//! * [`Rings`]: which points each beam fired, in sweep order, recovered from the points'
//!   firing order ([`Rings::from_firing_order`]) or, when that is lost, from their
//!   elevation ([`Rings::from_elevation`] with [`ElevationBins`]);
//! * [`keep_every`] and [`FieldOfView`]: the thinning of Polylidar3D §9.2.2 (every second
//!   point, the part the front camera sees);
//! * [`beam_outliers`]: §9.2.2's outlier removal — a point whose neighbours on its beam
//!   lie on one flat surface and which deviates strongly from it;
//! * [`RangeImage`]: the organized `beams × azimuth steps` image rebuilt from the points
//!   (NaN where no return came back), so that the organized 3D path (O(n) meshing,
//!   smoothing, every plane direction) runs on a rotating scan.
//!
//! The crate works on plain `[f64; 3]` points and depends on nothing else of the workspace.
//!
//! ```
//! use rotating_scan::{BeamOutlierConfig, RangeImage, Rings, beam_outliers};
//!
//! // Four beams over flat ground 1.7 m below the sensor, 360 samples each, in firing order.
//! let mut points = Vec::new();
//! for beam in 0..4 {
//!     let elevation = (-8.0 - 2.0 * beam as f64).to_radians();
//!     let range = 1.7 / -elevation.tan();
//!     for k in 0..360 {
//!         let a = (k as f64 + 0.5).to_radians();
//!         points.push([range * a.cos(), range * a.sin(), -1.7]);
//!     }
//! }
//! points[400][2] = -1.0; // a spurious return 0.7 m above the road
//!
//! let rings = Rings::from_firing_order(&points)?;
//! assert_eq!(rings.len(), 4);
//! assert_eq!(beam_outliers(&points, &rings, &BeamOutlierConfig::default())?, vec![400]);
//! let image = RangeImage::build(&points, &rings, 360)?;
//! assert_eq!((image.rows, image.cols, image.valid()), (4, 360, 4 * 360));
//! # Ok::<(), rotating_scan::ScanError>(())
//! ```

#![forbid(unsafe_code)]
#![deny(rustdoc::broken_intra_doc_links)]

mod error;
mod outliers;
mod range_image;
mod rings;
mod view;

pub use error::ScanError;
pub use outliers::{BeamOutlierConfig, beam_outliers};
pub use range_image::{NO_POINT, RangeImage};
pub use rings::{ElevationBins, MAX_BEAMS, Rings};
pub use view::{FieldOfView, keep_every};

#[cfg(doctest)]
#[doc = include_str!("../README.md")]
struct ReadmeDoctests;

//! Synthetic scenes with known planes, scanned into organized point clouds with
//! ground-truth plane labels, exported as labelled triangle meshes, or sampled.
//!
//! * A [`Scene`] is a set of planar [`Face`]s (convex or not, with holes), each carrying the
//!   label of its ground-truth plane. Builders: [`Scene::room`] (floor, walls, optional
//!   ceiling, a table and an obstacle that cuts a hole in the floor), [`Scene::stairs`],
//!   [`Scene::ramps`] (tilted planes) and [`Scene::random_polyhedra`] (a room with random
//!   boxes, wedges and prisms, some tilted — SynPEB-like); or add your own polygons and
//!   [`Solid`]s.
//! * [`Scene::scan`] ray-casts it with a [`Sensor`]: a [`PinholeCamera`] (depth camera) or a
//!   [`SphericalSensor`] (LiDAR), with radial and tangential [`Noise`], into a
//!   [`ScanResult`]: row-major points (NaN where nothing was hit) and labels (`-1` there),
//!   plus the [`GroundTruthPlane`]s.
//! * [`Scene::to_mesh`] exports a labelled triangle mesh; [`Scene::sample_uniform`] draws
//!   unorganized points on chosen faces.
//! * [`synpeb_like`] gives a SynPEB-like benchmark frame: a random room and a 500 × 500
//!   spherical sensor.
//! * RGB-D: a [`SimulatedDepthCamera`] is a pinhole camera with the [`DepthModel`] of a Kinect v1 or
//!   RealSense D435 (depth noise `a + b·z²`, disparity quantisation, missing returns at
//!   grazing incidence, depth edges, baseline shadows and outside the range), scanned by
//!   [`Scene::scan_depth`]; [`rgbd_like`] gives a furnished room ([`Scene::indoor`]) and
//!   one of the four [`DepthCameraKind`]s.
//! * Airborne LiDAR: a [`City`] of flat, gabled and hipped roofs (courtyards as holes),
//!   trees and streets, scanned in zig-zag strips, generated square by square
//!   ([`City::tile`]) with ground-truth roof-plane labels, from 10⁵ to 10⁹ points.
//! * 2D shapes ([`shapes`]): uniform samples inside polygons with holes, GeoJSON shapes,
//!   the 2D paper's α and L² shape error, and the demo shape of `polylidar extract --demo`.
//!
//! Units: metres for lengths, degrees for angles, millidegrees for tangential noise. The
//! world frame is right-handed; builders put z up and the floor on `z = 0`. Sensor frames
//! follow the camera convention (`+z` forward, `+x` right, `+y` down); scan points are in
//! the world frame. Everything random is deterministic by seed and independent of the
//! rayon thread count.
//!
//! ```
//! use synthscan::{Noise, PinholeCamera, Pose, RoomConfig, Scene, Sensor, FLOOR_LABEL};
//!
//! let scene = Scene::room(&RoomConfig::default())?;
//! // A 48 × 64 depth camera 2 m above the floor, looking down at the obstacle.
//! let pose = Pose::look_at([4.5, 1.0, 2.0], [4.5, 1.5, 0.0], [0.0, 1.0, 0.0])?;
//! let camera = PinholeCamera::new(48, 64, 50.0, 50.0)?.with_pose(pose);
//! let scan = scene.scan(&camera, &Noise::none())?;
//! assert_eq!(scan.points.len(), camera.rows() * camera.cols());
//! // Every point lies on the plane of its label.
//! for (p, &l) in scan.points.iter().zip(&scan.labels) {
//!     let plane = &scan.planes[l as usize];
//!     let d: f64 = (0..3).map(|k| plane.normal[k] * p[k]).sum::<f64>() - plane.offset;
//!     assert!(d.abs() < 1e-9);
//! }
//! // The floor is seen around the obstacle, and the obstacle hides part of it.
//! assert!(scan.labels.contains(&FLOOR_LABEL));
//!
//! // The same scene as a labelled mesh with edges of at most 0.25 m.
//! let (vertices, triangles, labels) = scene.to_mesh(0.25)?;
//! assert_eq!(triangles.len(), labels.len());
//! # let _ = vertices;
//! # Ok::<(), synthscan::SceneError>(())
//! ```

#![deny(rustdoc::broken_intra_doc_links)]

mod builders;
mod bvh;
mod city;
mod depth;
mod error;
mod face;
mod indoor;
mod mesh;
mod scan;
mod scene;
mod sensor;
pub mod shapes;
mod solid;
mod triangulate;
mod unorganized;
mod vec3;

pub use builders::{
    FLOOR_LABEL, FloorBox, RampsConfig, RandomPolyhedraConfig, RoomConfig, StairsConfig,
    TableConfig,
};
pub use city::{Building, City, CityConfig, CityError, CityTile, RoofKind, RoofPlane};
pub use depth::{DepthCameraKind, DepthModel, MAX_EDGE_BAND, SimulatedDepthCamera};
pub use error::SceneError;
pub use face::Face;
pub use indoor::{IndoorConfig, rgbd_like};
pub use mesh::{LabelledMesh, MAX_MESH_TRIANGLES, PointSample};
/// The scenes' polygons are the workspace's 3D polygon with holes.
pub use plane_geom::Polygon3;
pub use scan::{Noise, ScanResult};
pub use scene::{GroundTruthPlane, Scene};
pub use sensor::{MAX_PIXELS, PinholeCamera, Pose, Sensor, SphericalSensor};
pub use solid::Solid;
pub use unorganized::{UnorganizedCloud, VIEWS, synpeb_like_views};

/// A SynPEB-like benchmark frame: [`Scene::random_polyhedra`] with
/// [`RandomPolyhedraConfig::default`] and `seed`, and the sensor to scan it with.
///
/// The sensor mimics the SynPEB scans (3D paper §9.3.2): a 500 × 500 [`SphericalSensor`]
/// with a 70° azimuth and 60° elevation field of view, 1 m above the floor at
/// `(0.5, 2.5)`, looking horizontally along `+x` into the 6 × 5 × 3 m room. Scan it with
/// [`Scene::scan`] and the [`Noise`] of the level you want (SynPEB: tangential 0.5, 1, 2 or
/// 4 mdeg).
///
/// # Errors
/// [`SceneError::PlacementFailed`] if the seed's objects do not fit (not seen with the
/// default configuration).
pub fn synpeb_like(seed: u64) -> Result<(Scene, SphericalSensor), SceneError> {
    let scene = Scene::random_polyhedra(&RandomPolyhedraConfig::default().with_seed(seed))?;
    let pose = Pose::look_at([0.5, 2.5, 1.0], [6.0, 2.5, 1.0], [0.0, 0.0, 1.0])?;
    let sensor = SphericalSensor::new(500, 500, 70.0, 60.0)?.with_pose(pose);
    Ok((scene, sensor))
}

/// The README's example, compiled and run as a doctest.
#[cfg(doctest)]
#[doc = include_str!("../README.md")]
struct ReadmeDoctests;

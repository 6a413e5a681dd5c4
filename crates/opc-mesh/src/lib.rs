//! Organized point clouds (range images, RGBD frames) and their O(n) right-cut half-edge
//! meshing (Polylidar3D §4.2, Alg. 1–2).
//!
//! ```
//! use opc_mesh::OrganizedPointCloud;
//! let points: Vec<[f64; 3]> = (0..12).map(|i| [(i % 4) as f64, (i / 4) as f64, 1.0]).collect();
//! let cloud = OrganizedPointCloud::new(3, 4, points)?;
//! assert_eq!(cloud.num_valid(), 12);
//! # Ok::<(), opc_mesh::OpcError>(())
//! ```

#![deny(rustdoc::broken_intra_doc_links)]

mod cloud;
mod error;

pub use cloud::{OrganizedPointCloud, is_valid};
pub use error::OpcError;

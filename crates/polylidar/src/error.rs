//! The facade's error type.

use halfedge_mesh::MeshError;
use polyextract::ExtractError;

/// Why the pipeline could not run.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum PolylidarError {
    /// A configuration value is out of range.
    #[error("invalid configuration: {field} = {value} ({reason})")]
    Config {
        /// The config field, as named in TOML.
        field: &'static str,
        /// The value given.
        value: String,
        /// What it must be.
        reason: &'static str,
    },
    /// The input could not be meshed.
    #[error(transparent)]
    Mesh(#[from] MeshError),
    /// A region's boundary could not be followed (a bug or a corrupt mesh; please report).
    #[error("polygon extraction of region {region} failed: {source}")]
    Extract {
        /// Index of the region among those kept.
        region: usize,
        /// The extraction error.
        source: ExtractError,
    },
    /// The organized cloud could not be built or meshed.
    #[error(transparent)]
    Organized(#[from] opc_mesh::OpcError),
    /// A rotating scan that cannot be prepared (bad parameter, points not in firing order).
    #[error(transparent)]
    Scan(#[from] rotating_scan::ScanError),
    /// A smoothing filter failed (bad options, no GPU adapter, …).
    #[error(transparent)]
    Smooth(#[from] mesh_smooth_gpu::SmoothError),
    /// Point normals or neighbourhoods of an unorganized cloud could not be computed
    /// (empty cloud, non-finite point, bad voxel size).
    #[error(transparent)]
    Normals(#[from] cloud_normals::NormalsError),
    /// Dominant-normal detection failed.
    #[error(transparent)]
    FastGa(#[from] fastga::FastGaError),
    /// Planar segmentation failed.
    #[error(transparent)]
    Segment(#[from] planeseg::SegmentError),
    /// Post-processing failed.
    #[error(transparent)]
    Postprocess(#[from] polypost::PostError),
    /// A file could not be read (feature `io`).
    #[cfg(feature = "io")]
    #[error(transparent)]
    Io(#[from] polylidar_io::IoError),
    /// An output file could not be written (feature `io`).
    #[cfg(feature = "io")]
    #[error("cannot write {}: {message}", path.display())]
    Write {
        /// The output path.
        path: std::path::PathBuf,
        /// The system's message.
        message: String,
    },
    /// The rayon thread pool could not be created.
    #[error("could not start {threads} worker threads: {message}")]
    ThreadPool {
        /// Threads requested.
        threads: usize,
        /// The system's message.
        message: String,
    },
}

impl PolylidarError {
    /// `Err(PolylidarError::Config { .. })` for the TOML `field` holding `value`, with
    /// what it must be.
    pub(crate) fn config<T>(
        field: &'static str,
        value: impl ToString,
        reason: &'static str,
    ) -> Result<T, Self> {
        Err(Self::Config {
            field,
            value: value.to_string(),
            reason,
        })
    }
}

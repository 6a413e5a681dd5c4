//! The crate's error type: which file, which format, what went wrong.

use std::fmt;
use std::path::{Path, PathBuf};

/// A file format handled by this crate, named in every [`IoError`].
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum Format {
    /// Point Cloud Library `.pcd`.
    Pcd,
    /// NumPy `.npy`.
    Npy,
    /// 16-bit greyscale depth `.png`.
    DepthPng,
    /// RealSense `_metadata.csv` (camera intrinsics).
    RealSenseMetadata,
    /// Open3D camera JSON (`width`, `height`, `intrinsic_matrix`).
    CameraJson,
    /// Text table of 2D or 3D points (`.csv`, `.txt`, `.xyz`).
    CsvPoints,
    /// Stanford `.ply`.
    Ply,
    /// Wavefront `.obj`.
    Obj,
    /// ASPRS `.las` / `.laz`.
    Las,
    /// An RGB picture (8-bit PNG or JPEG), the colour of an RGB-D frame.
    ColorImage,
    /// KITTI Velodyne `.bin` (float32 records `x y z reflectance`).
    KittiBin,
    /// Not known yet (dispatch by extension failed).
    Unknown,
}

impl fmt::Display for Format {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(match self {
            Format::Pcd => "PCD",
            Format::Npy => "NPY",
            Format::DepthPng => "depth PNG",
            Format::RealSenseMetadata => "RealSense metadata CSV",
            Format::CameraJson => "Open3D camera JSON",
            Format::CsvPoints => "point CSV",
            Format::Ply => "PLY",
            Format::Obj => "OBJ",
            Format::Las => "LAS/LAZ",
            Format::ColorImage => "colour picture",
            Format::KittiBin => "KITTI .bin",
            Format::Unknown => "input",
        })
    }
}

/// What went wrong, independent of the file it happened in.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum ErrorKind {
    /// The operating system refused to read or write the file.
    #[error("{0}")]
    Os(#[from] std::io::Error),
    /// The data ends before a needed part.
    #[error("truncated data: {what} needs {needed} bytes at byte {offset}, only {available} left")]
    Truncated {
        /// What was being read.
        what: &'static str,
        /// Byte offset where it starts.
        offset: usize,
        /// Bytes needed.
        needed: usize,
        /// Bytes available from `offset` on.
        available: usize,
    },
    /// A header line (1-based) cannot be understood.
    #[error("header line {line} malformed: {reason}")]
    Header {
        /// 1-based line number in the header.
        line: usize,
        /// What is wrong with it.
        reason: String,
    },
    /// The header is incomplete or inconsistent as a whole.
    #[error("bad header: {0}")]
    BadHeader(String),
    /// A data line (1-based) of a text format cannot be understood.
    #[error("line {line}: {reason}")]
    Line {
        /// 1-based line number in the file.
        line: usize,
        /// What is wrong with it.
        reason: String,
    },
    /// A feature of the format that this crate does not read.
    #[error("unsupported {what}: {value}")]
    Unsupported {
        /// Which feature (e.g. "DATA kind", "dtype").
        what: &'static str,
        /// The value found in the file.
        value: String,
    },
    /// A required field (e.g. `x`) is absent.
    #[error("missing field `{0}`")]
    MissingField(String),
    /// Array shape or element count does not match what is needed.
    #[error("shape mismatch: {0}")]
    Shape(String),
    /// A face refers to a vertex that does not exist.
    #[error("face {face}: vertex index {index} out of range ({vertices} vertices)")]
    FaceIndex {
        /// 0-based face number.
        face: usize,
        /// The offending index as written in the file (OBJ: 1-based or negative).
        index: i64,
        /// Number of vertices available.
        vertices: usize,
    },
    /// A value of a binary record cannot be what the format says it is.
    #[error("byte {offset}: {reason}")]
    Value {
        /// Byte offset of the value in the file.
        offset: usize,
        /// What is wrong with it.
        reason: String,
    },
    /// Compressed data is corrupt.
    #[error("corrupt compressed data: {0}")]
    Corrupt(String),
    /// The image is not a 16-bit greyscale depth image.
    #[error("not a 16-bit greyscale depth image: {0}")]
    NotDepth(String),
    /// An error reported by a third-party decoder (png, las).
    #[error("{0}")]
    Decoder(String),
    /// No camera intrinsics were given for a depth image and no metadata file was found
    /// beside it.
    #[error("no camera intrinsics: none given and no RealSense metadata CSV beside the image; tried {}", tried.iter().map(|p| p.display().to_string()).collect::<Vec<_>>().join(", "))]
    MissingMetadata {
        /// Paths looked at, in order.
        tried: Vec<PathBuf>,
    },
    /// A value that must be a finite number is NaN or infinite.
    #[error("record {record}: field `{field}` is {value}, not a finite number")]
    NonFinite {
        /// 0-based record (point) number.
        record: usize,
        /// The field's name.
        field: &'static str,
        /// The value found, as text (`NaN`, `inf`, `-inf`).
        value: String,
    },
    /// The file extension does not name a supported input.
    #[error(
        "unknown extension {0:?} (expected .csv .txt .xyz .npy .pcd .ply .obj .las .laz .png .bin)"
    )]
    UnknownExtension(String),
    /// The data is valid for its format but not usable as the requested input.
    #[error("{0}")]
    Unusable(String),
    /// Reading the input (and running the pipeline on it) would need more memory than the
    /// budget of [`crate::Limits`] allows; nothing of that size was allocated.
    #[error(
        "needs about {} for {what}, more than the memory budget of {}; if the file is \
         genuine, raise the budget (polylidar --max-memory, or Limits::with_max_memory)",
        crate::limits::format_bytes(*.estimate),
        crate::limits::format_bytes(*.limit)
    )]
    OverBudget {
        /// What the estimate is made of (sizes from the header).
        what: String,
        /// Bytes estimated.
        estimate: u64,
        /// The budget, [`crate::Limits::max_memory`].
        limit: u64,
    },
}

/// An error from any reader or writer of this crate: the file (if any), the format and the
/// problem.
///
/// Displayed as `path: FORMAT file: problem`, e.g.
/// `pc_01.pcd: PCD file: truncated data: LZF block needs 8 bytes at byte 210, only 3 left`.
#[derive(Debug, thiserror::Error)]
#[error("{}: {format} file: {kind}", location(.path.as_deref()))]
pub struct IoError {
    /// The file, or `None` for in-memory parsing.
    pub path: Option<PathBuf>,
    /// The format being read or written.
    pub format: Format,
    /// What went wrong.
    #[source]
    pub kind: ErrorKind,
}

fn location(path: Option<&Path>) -> String {
    path.map_or_else(|| "<memory>".to_owned(), |p| p.display().to_string())
}

impl IoError {
    /// An error for in-memory data of `format`.
    pub fn new(format: Format, kind: ErrorKind) -> Self {
        IoError {
            path: None,
            format,
            kind,
        }
    }

    /// The same error, attributed to `path`.
    #[must_use]
    pub fn at(mut self, path: &Path) -> Self {
        self.path = Some(path.to_path_buf());
        self
    }
}

/// Result of the format-internal parsers before the file and format are attached.
pub(crate) type KindResult<T> = Result<T, ErrorKind>;

/// Reads the whole file at `path` within the default [`crate::Limits`], attributing a
/// failure to `format`.
pub(crate) fn read_file(path: &Path, format: Format) -> Result<Vec<u8>, IoError> {
    crate::Limits::for_path(path).read_file(path, format)
}

/// Writes `bytes` to `path` atomically ([`crate::atomic::write_atomic`]: a failed write
/// leaves the old file as it was), attributing a failure to `format`.
pub(crate) fn write_file(path: &Path, format: Format, bytes: &[u8]) -> Result<(), IoError> {
    crate::atomic::write_atomic(path, bytes)
        .map_err(|e| IoError::new(format, ErrorKind::Os(e)).at(path))
}

/// Little helper for truncation checks: `bytes[offset..offset + needed]` or an error.
pub(crate) fn take<'a>(
    bytes: &'a [u8],
    offset: usize,
    needed: usize,
    what: &'static str,
) -> KindResult<&'a [u8]> {
    let available = bytes.len().saturating_sub(offset);
    if needed > available {
        return Err(ErrorKind::Truncated {
            what,
            offset,
            needed,
            available,
        });
    }
    Ok(&bytes[offset..offset + needed])
}

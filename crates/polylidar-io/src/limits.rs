//! The memory budget of the readers: what an input will cost, estimated from its header
//! before anything is allocated, and refused past a limit.
//!
//! A few kilobytes of PNG or LZF can claim gigabytes of pixels or points, and a text header
//! can claim any number of fields. Every reader of this crate therefore computes, from the
//! header alone, the bytes it will allocate and the bytes the polylidar pipeline will need
//! for the cloud and mesh built from the points ([`Limits::pipeline_bytes_per_point`]), and
//! returns [`crate::ErrorKind::OverBudget`] when the sum exceeds
//! [`Limits::max_memory`]. Files are read with a bound too: a FIFO or `/dev/zero` is read
//! up to the budget and refused past it, never until memory runs out.
//!
//! ```
//! use polylidar_io::{ErrorKind, Limits, PcdEncoding, PcdWriteOptions, PointCloud, encode_pcd,
//!     parse_pcd_with};
//!
//! let cloud = PointCloud::unorganized(vec![[0.0, 0.0, 1.0]; 1000]);
//! let bytes = encode_pcd(&cloud, &PcdWriteOptions::new(PcdEncoding::Binary))?;
//! // 1000 points fit the default budget, not one of 100 kB.
//! assert!(parse_pcd_with(&bytes, &Limits::default()).is_ok());
//! let tight = Limits::default().with_max_memory(100_000);
//! let e = parse_pcd_with(&bytes, &tight).unwrap_err();
//! assert!(matches!(e.kind, ErrorKind::OverBudget { .. }));
//! # Ok::<(), polylidar_io::IoError>(())
//! ```

use std::io::Read;
use std::path::Path;

use crate::error::{ErrorKind, Format, IoError, KindResult};

/// The cap of the default budget: 2 GiB.
pub const DEFAULT_MAX_MEMORY: u64 = 2 << 30;

/// The budget of an input of no size (a stream, a FIFO, bytes of length 0) under
/// [`Limits::for_input_size`]: 384 MiB, enough for every shared fixture of at most 1 MB
/// and for depth images up to 848 × 480 pixels however well they compress (275 MiB).
pub const BUDGET_FLOOR: u64 = 384 << 20;

/// Budget bytes granted per byte of input on top of [`BUDGET_FLOOR`] under
/// [`Limits::for_input_size`]. Of the shared fixtures, only compressed files claim more
/// than this per byte of the file (depth PNGs 1,300–2,300, the LAZ 130), and those stay
/// within the floor; uncompressed PCD, NPY, LAS and KITTI files claim 21–59. A file of 1 MiB
/// gets at most 448 MiB, so peak RSS on any input of at most 1 MB stays under 512 MB
/// (`docs/bench/hardening.md`).
pub const BUDGET_PER_INPUT_BYTE: u64 = 64;

/// What the polylidar pipeline needs per input point, beyond the reader's own arrays: the
/// point (or organized pixel) as `f64` and `f32` copies, its share of the half-edge mesh
/// (about two triangles of three half-edges), normals, smoothing buffers, labels and the
/// Delaunay or right-cut working memory, the 3D path's normals and neighbour lists. Peak
/// RSS of `polylidar extract` on the shared fixtures, less the 16 MiB of a run on a
/// thousand points, is 530–700 bytes per point for organized clouds and depth images,
/// 260–570 for KITTI and LAZ scans and 810 for the unorganized 3D path
/// (`docs/bench/hardening.md`); the big inputs that a budget decides on are organized.
pub const PIPELINE_BYTES_PER_POINT: u64 = 700;

/// The memory budget of a read.
///
/// [`Limits::default`] allows [`DEFAULT_MAX_MEMORY`] (2 GiB) or half of the machine's
/// physical memory, whichever is smaller, and counts [`PIPELINE_BYTES_PER_POINT`] for the
/// pipeline's use of each point; [`Limits::for_input_size`] (what the readers without a
/// `_with` use, and the command line without `--max-memory`) scales that budget down to
/// the input's size; [`Limits::reading_only`] counts the reader's own allocations alone.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Limits {
    /// Most bytes a read may plan for: the file's bytes, the decoded arrays, and the
    /// pipeline's share for every point.
    pub max_memory: u64,
    /// Bytes the caller will spend per point after reading (0 when the points are only
    /// read); a mesh face counts half of it.
    pub pipeline_bytes_per_point: u64,
}

impl Default for Limits {
    fn default() -> Self {
        Limits {
            max_memory: default_max_memory(),
            pipeline_bytes_per_point: PIPELINE_BYTES_PER_POINT,
        }
    }
}

impl Limits {
    /// No limit at all (for trusted data only).
    pub const fn unlimited() -> Self {
        Limits {
            max_memory: u64::MAX,
            pipeline_bytes_per_point: 0,
        }
    }

    /// The default budget for an input of `bytes` bytes: [`BUDGET_FLOOR`] plus
    /// [`BUDGET_PER_INPUT_BYTE`] per byte, capped at the default budget ([`Limits::default`]:
    /// 2 GiB or half the physical memory). Small inputs thus get a small budget — a
    /// kilobyte-sized decompression bomb is refused at 384 MiB, not at 2 GiB — and big files
    /// the room their points need.
    ///
    /// ```
    /// use polylidar_io::{BUDGET_FLOOR, Limits};
    ///
    /// assert_eq!(Limits::for_input_size(0).max_memory, BUDGET_FLOOR.min(Limits::default().max_memory));
    /// assert!(Limits::for_input_size(1 << 20).max_memory <= 448 << 20);
    /// assert_eq!(Limits::for_input_size(u64::MAX), Limits::default());
    /// ```
    pub fn for_input_size(bytes: u64) -> Self {
        let cap = default_max_memory();
        let scaled = BUDGET_FLOOR.saturating_add(bytes.saturating_mul(BUDGET_PER_INPUT_BYTE));
        Limits::default().with_max_memory(scaled.min(cap))
    }

    /// [`Limits::for_input_size`] of the file at `path`: its size when it is a regular
    /// file, else 0 (a FIFO, a device, a path that cannot be read: the floor).
    pub fn for_path(path: impl AsRef<Path>) -> Self {
        let bytes = std::fs::metadata(path)
            .ok()
            .filter(std::fs::Metadata::is_file)
            .map_or(0, |m| m.len());
        Self::for_input_size(bytes)
    }

    /// The same limits with a budget of `bytes`.
    #[must_use]
    pub const fn with_max_memory(mut self, bytes: u64) -> Self {
        self.max_memory = bytes;
        self
    }

    /// The same budget, counting only what the reader itself allocates (no pipeline share).
    #[must_use]
    pub const fn reading_only(mut self) -> Self {
        self.pipeline_bytes_per_point = 0;
        self
    }

    /// The pipeline's bytes for `points` points (saturating).
    pub(crate) fn pipeline(&self, points: u64) -> u64 {
        points.saturating_mul(self.pipeline_bytes_per_point)
    }

    /// `Ok` when `estimate` fits the budget, else [`ErrorKind::OverBudget`] explaining
    /// `what` the estimate is made of.
    pub(crate) fn check(&self, estimate: u64, what: impl FnOnce() -> String) -> KindResult<()> {
        if estimate > self.max_memory {
            return Err(ErrorKind::OverBudget {
                what: what(),
                estimate,
                limit: self.max_memory,
            });
        }
        Ok(())
    }

    /// Most bytes of a file a read holds: half the budget, since whatever the format, its
    /// decoded arrays take at least as much again.
    pub(crate) fn max_file_bytes(&self) -> u64 {
        self.max_memory / 2
    }

    /// Reads the file at `path` whole, refusing a regular file larger than
    /// [`Self::max_file_bytes`] before reading it, and any stream (FIFO, device) as soon as
    /// it passes that size.
    pub(crate) fn read_file(&self, path: &Path, format: Format) -> Result<Vec<u8>, IoError> {
        let fail = |k: ErrorKind| IoError::new(format, k).at(path);
        let file = std::fs::File::open(path).map_err(|e| fail(ErrorKind::Os(e)))?;
        let meta = file.metadata().map_err(|e| fail(ErrorKind::Os(e)))?;
        let max = self.max_file_bytes();
        let too_big = |what: String, estimate: u64| {
            fail(ErrorKind::OverBudget {
                what,
                estimate,
                limit: self.max_memory,
            })
        };
        if meta.is_file() && meta.len() > max {
            return Err(too_big(
                format!(
                    "holding a file of {} bytes and decoding it (twice its size at least)",
                    meta.len()
                ),
                meta.len().saturating_mul(2),
            ));
        }
        let expected = if meta.is_file() { meta.len() } else { 0 };
        match read_bounded(file, max, expected).map_err(|e| fail(ErrorKind::Os(e)))? {
            Some(bytes) => Ok(bytes),
            None => Err(too_big(
                format!(
                    "a stream that does not end within {} bytes (half the budget: its bytes \
                     and their decoding)",
                    max
                ),
                max.saturating_mul(2).saturating_add(2),
            )),
        }
    }
}

/// Reads `r` to its end, or `None` as soon as it passes `max` bytes; the buffer never
/// holds more than `max` bytes of capacity, so a stream without end costs at most that.
///
/// A stream of unknown length (`expected == 0`) gets the whole `max` reserved up front:
/// address space only, its pages are used as they are written, where growing the buffer
/// would copy it and hold both copies at once.
fn read_bounded(mut r: impl Read, max: u64, expected: u64) -> std::io::Result<Option<Vec<u8>>> {
    let max = usize::try_from(max).unwrap_or(usize::MAX);
    let first = usize::try_from(expected).unwrap_or(max).min(max);
    let mut bytes: Vec<u8> = Vec::new();
    if expected > 0 || bytes.try_reserve_exact(max).is_err() {
        bytes.reserve_exact(first.max(1));
    }
    let mut chunk = vec![0u8; 1 << 16];
    loop {
        let n = match r.read(&mut chunk) {
            Ok(0) => return Ok(Some(bytes)),
            Ok(n) => n,
            Err(e) if e.kind() == std::io::ErrorKind::Interrupted => continue,
            Err(e) => return Err(e),
        };
        let len = bytes.len() + n;
        if len > max {
            return Ok(None);
        }
        if len > bytes.capacity() {
            // Doubling, but never past `max`.
            let target = bytes.capacity().saturating_mul(2).max(len).min(max);
            bytes.reserve_exact(target - bytes.len());
        }
        bytes.extend_from_slice(&chunk[..n]);
    }
}

/// The default budget: [`DEFAULT_MAX_MEMORY`] or half of [`physical_memory`], whichever is
/// smaller (read once per process).
pub fn default_max_memory() -> u64 {
    static DEFAULT: std::sync::OnceLock<u64> = std::sync::OnceLock::new();
    *DEFAULT.get_or_init(|| {
        physical_memory().map_or(DEFAULT_MAX_MEMORY, |total| {
            DEFAULT_MAX_MEMORY.min(total / 2)
        })
    })
}

/// The machine's physical memory in bytes (`MemTotal` of `/proc/meminfo`), or `None`
/// where that is not available.
pub fn physical_memory() -> Option<u64> {
    let text = std::fs::read_to_string("/proc/meminfo").ok()?;
    let line = text.lines().find(|l| l.starts_with("MemTotal:"))?;
    let kib: u64 = line.split_ascii_whitespace().nth(1)?.parse().ok()?;
    kib.checked_mul(1024)
}

/// Parses a memory size: a number of bytes with an optional unit `K`, `M`, `G`, `T`
/// (powers of 1024; `KiB`, `MB`, `GB`… read the same, case-insensitive), e.g. `512M`,
/// `1.5G`, `2GiB`, `1000000`.
///
/// ```
/// assert_eq!(polylidar_io::parse_memory_size("512M"), Ok(512 << 20));
/// assert_eq!(polylidar_io::parse_memory_size("1.5 GiB"), Ok(3 << 29));
/// assert!(polylidar_io::parse_memory_size("lots").is_err());
/// ```
///
/// # Errors
/// A message naming the text when it is no size.
pub fn parse_memory_size(text: &str) -> Result<u64, String> {
    let t = text.trim();
    let split = t
        .find(|c: char| !(c.is_ascii_digit() || c == '.'))
        .unwrap_or(t.len());
    let (number, unit) = t.split_at(split);
    let bad = || format!("{text:?} is not a memory size (e.g. 512M, 2G, 1000000)");
    let value: f64 = number.parse().map_err(|_| bad())?;
    let shift = match unit.trim().to_ascii_lowercase().as_str() {
        "" | "b" => 0,
        "k" | "kb" | "kib" => 10,
        "m" | "mb" | "mib" => 20,
        "g" | "gb" | "gib" => 30,
        "t" | "tb" | "tib" => 40,
        _ => return Err(bad()),
    };
    let bytes = value * (1u64 << shift) as f64;
    if !bytes.is_finite() || bytes < 1.0 || bytes >= u64::MAX as f64 {
        return Err(format!("{text:?} is out of range: at least 1 byte"));
    }
    Ok(bytes as u64)
}

/// `bytes` in the largest binary unit that keeps one digit before the point: `1.6 GiB`.
pub fn format_bytes(bytes: u64) -> String {
    const UNITS: [&str; 5] = ["B", "KiB", "MiB", "GiB", "TiB"];
    let mut value = bytes as f64;
    let mut unit = 0;
    while value >= 1024.0 && unit + 1 < UNITS.len() {
        value /= 1024.0;
        unit += 1;
    }
    if unit == 0 {
        format!("{bytes} B")
    } else {
        format!("{value:.1} {}", UNITS[unit])
    }
}

/// `a × b` bytes, saturating.
pub(crate) fn times(a: usize, b: u64) -> u64 {
    (a as u64).saturating_mul(b)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn sizes_parse_and_print() {
        assert_eq!(parse_memory_size("1000"), Ok(1000));
        assert_eq!(parse_memory_size("2g"), Ok(2 << 30));
        assert_eq!(parse_memory_size("64 MiB"), Ok(64 << 20));
        assert_eq!(parse_memory_size("4k"), Ok(4096));
        assert!(parse_memory_size("0").is_err());
        assert!(parse_memory_size("-5M").is_err());
        assert!(parse_memory_size("5X").is_err());
        assert!(parse_memory_size("").is_err());
        assert_eq!(format_bytes(512), "512 B");
        assert_eq!(format_bytes(3 << 29), "1.5 GiB");
    }

    #[test]
    fn scaled_budget_grows_with_the_input_and_stops_at_the_cap() {
        let cap = Limits::default().max_memory;
        let floor = BUDGET_FLOOR.min(cap);
        assert_eq!(Limits::for_input_size(0).max_memory, floor);
        let mib = Limits::for_input_size(1 << 20).max_memory;
        assert_eq!(mib, (BUDGET_FLOOR + (64 << 20)).min(cap));
        assert!(mib <= 448 << 20);
        assert!(Limits::for_input_size(10 << 20).max_memory >= mib);
        assert_eq!(Limits::for_input_size(1 << 40), Limits::default());
        let dir = test_fixtures::scratch_dir("polylidar-io-limits", "for-path");
        let file = dir.join("two_mib.bin");
        std::fs::write(&file, vec![0u8; 2 << 20]).unwrap();
        assert_eq!(Limits::for_path(&file), Limits::for_input_size(2 << 20));
        assert_eq!(Limits::for_path(&dir), Limits::for_input_size(0));
        assert_eq!(
            Limits::for_path(dir.join("missing")),
            Limits::for_input_size(0)
        );
    }

    #[test]
    fn default_is_capped() {
        let d = Limits::default();
        assert!(d.max_memory <= DEFAULT_MAX_MEMORY);
        assert!(d.max_memory > 0);
        assert_eq!(d.pipeline_bytes_per_point, PIPELINE_BYTES_PER_POINT);
        assert!(d.check(d.max_memory, String::new).is_ok());
        assert!(matches!(
            d.check(d.max_memory + 1, || "x".to_owned()),
            Err(ErrorKind::OverBudget { .. })
        ));
    }
}

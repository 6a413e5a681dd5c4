//! Locates the real data in `../shared/fixtures` (beside the workspace root) for tests and
//! benchmarks, and applies the project's rule for missing data: under CI (`CI=true`) a
//! missing fixture is a failure; elsewhere the caller skips with a printed reason.
//!
//! Every skip is also logged ([`record_skip`]) to `target/test-skips.log`, which
//! `.ci/test.sh` empties before `cargo test` and summarises after it ("7 tests skipped:
//! fixtures not found at ../shared/fixtures"), so skipped tests do not pass unseen.
//!
//! ```no_run
//! let Some(path) = test_fixtures::fixture("synpeb/pc_01.pcd") else {
//!     return; // not in CI and the data is absent: skipped, reason printed
//! };
//! assert!(path.is_file());
//! ```

use std::path::{Path, PathBuf};

use rand::{RngExt, SeedableRng};
use rand_chacha::ChaCha8Rng;

/// The folder named by the `POLYLIDAR_FIXTURES` environment variable; else the first
/// `shared/fixtures` found beside the current directory or one of its ancestors (cargo runs
/// tests and benchmarks in their package's folder, inside the workspace); else the one
/// beside the workspace this crate was compiled in.
pub fn fixtures_dir() -> PathBuf {
    if let Some(dir) = std::env::var_os("POLYLIDAR_FIXTURES") {
        return PathBuf::from(dir);
    }
    let found = std::env::current_dir().ok().and_then(|cwd| {
        cwd.ancestors()
            .map(|dir| dir.join("shared/fixtures"))
            .find(|dir| dir.is_dir())
    });
    found.unwrap_or_else(|| {
        PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../../../shared/fixtures")
    })
}

/// Whether this process runs under CI (`CI` set to anything but `false` or `0`).
pub fn in_ci() -> bool {
    std::env::var("CI").is_ok_and(|v| !v.is_empty() && v != "false" && v != "0")
}

/// The path of fixture `relative` (e.g. `"synpeb/pc_01.pcd"`) if it exists.
///
/// # Panics
/// Under CI when the file is missing: tests that need real data must not pass silently
/// there. Elsewhere a missing file prints the reason to stderr and returns `None`.
pub fn fixture(relative: &str) -> Option<PathBuf> {
    let path = fixtures_dir().join(relative);
    if path.is_file() {
        return Some(path);
    }
    let message = format!(
        "fixture {relative} not found at {} (expected ../shared/fixtures beside the workspace)",
        path.display()
    );
    #[allow(clippy::panic)]
    if in_ci() {
        panic!("{message}; CI=true, so this is a failure");
    }
    record_skip(&message);
    None
}

/// The skip log: `POLYLIDAR_SKIP_LOG` if set, else `test-skips.log` in the cargo target
/// folder of the running test binary (`target/debug/deps/<test>` → `target/`).
pub fn skip_log() -> Option<PathBuf> {
    if let Some(path) = std::env::var_os("POLYLIDAR_SKIP_LOG") {
        return Some(PathBuf::from(path));
    }
    let exe = std::env::current_exe().ok()?;
    let profile = exe
        .ancestors()
        .find(|d| d.file_name().is_some_and(|n| n == "deps"))?;
    Some(profile.parent()?.parent()?.join("test-skips.log"))
}

/// Prints `skipping: <reason>` and appends a line `<test>\t<reason>` to [`skip_log`]
/// (the test is the running thread's name, which the test harness sets to the test's
/// path). Call it where a test returns early for want of data or hardware.
pub fn record_skip(reason: &str) {
    eprintln!("skipping: {reason}");
    let test = std::thread::current()
        .name()
        .unwrap_or("unnamed test")
        .to_owned();
    let Some(path) = skip_log() else { return };
    let line = format!("{test}\t{}\n", reason.replace(['\n', '\t'], " "));
    // A log that cannot be written loses only the summary line; the skip was printed.
    let _ = std::fs::OpenOptions::new()
        .create(true)
        .append(true)
        .open(path)
        .and_then(|mut f| std::io::Write::write_all(&mut f, line.as_bytes()));
}

/// `count` unit normals uniform on the sphere, reproducibly from `seed` (the random input
/// of the FastGA benchmarks, Polylidar3D Table 2).
///
/// ```
/// let normals = test_fixtures::random_unit_normals(100, 7);
/// assert_eq!(normals, test_fixtures::random_unit_normals(100, 7));
/// assert!(normals.iter().all(|n| (n[0] * n[0] + n[1] * n[1] + n[2] * n[2] - 1.0).abs() < 1e-12));
/// ```
pub fn random_unit_normals(count: usize, seed: u64) -> Vec<[f64; 3]> {
    let mut rng = ChaCha8Rng::seed_from_u64(seed);
    (0..count)
        .map(|_| {
            let z: f64 = rng.random_range(-1.0..=1.0);
            let phi: f64 = rng.random_range(0.0..std::f64::consts::TAU);
            let r = (1.0 - z * z).sqrt();
            [r * phi.cos(), r * phi.sin(), z]
        })
        .collect()
}

/// The triangles of an `n × n` grid of cells over `(n + 1)²` vertices numbered row by row
/// (`y · (n + 1) + x`), two counter-clockwise triangles a cell (seen from `+z` when `x`
/// and `y` grow along the first two axes): the mesh of a height field or a flat patch.
///
/// ```
/// let triangles = test_fixtures::grid_triangles(2);
/// assert_eq!(triangles.len(), 8);
/// assert_eq!(triangles[0], [0, 1, 4]);
/// assert!(triangles.iter().flatten().all(|&v| v < 9));
/// ```
pub fn grid_triangles(n: usize) -> Vec<[u32; 3]> {
    let id = |x: usize, y: usize| (y * (n + 1) + x) as u32;
    (0..n * n)
        .flat_map(|cell| {
            let (x, y) = (cell % n, cell / n);
            [
                [id(x, y), id(x + 1, y), id(x + 1, y + 1)],
                [id(x, y), id(x + 1, y + 1), id(x, y + 1)],
            ]
        })
        .collect()
}

/// A fresh, empty directory `<temp>/<prefix>-<process id>-<name>` for a test's files
/// (emptied first if an earlier run left it), removed with everything in it when the
/// returned guard is dropped: keep it bound (`let dir = scratch_dir(…)`) while the test
/// uses the directory. A test that fails keeps nothing either: the guard is dropped while
/// the panic unwinds.
///
/// ```
/// let path = {
///     let dir = test_fixtures::scratch_dir("test-fixtures-doc", "guard");
///     std::fs::write(dir.join("a.txt"), "a").unwrap();
///     assert!(dir.join("a.txt").is_file());
///     dir.to_path_buf()
/// };
/// assert!(!path.exists());
/// ```
///
/// # Panics
/// When the directory cannot be created.
#[expect(
    clippy::expect_used,
    reason = "a test helper: a test fails loudly here"
)]
pub fn scratch_dir(prefix: &str, name: &str) -> ScratchDir {
    let dir = std::env::temp_dir().join(format!("{prefix}-{}-{name}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).expect("a scratch directory under the temporary directory");
    ScratchDir(dir)
}

/// A test's scratch directory from [`scratch_dir`]; dropping it removes the directory.
#[derive(Debug)]
pub struct ScratchDir(PathBuf);

impl std::ops::Deref for ScratchDir {
    type Target = Path;

    fn deref(&self) -> &Path {
        &self.0
    }
}

impl AsRef<Path> for ScratchDir {
    fn as_ref(&self) -> &Path {
        &self.0
    }
}

impl Drop for ScratchDir {
    fn drop(&mut self) {
        // Best effort: a file still open elsewhere must not turn a passing test into a
        // failing one.
        let _ = std::fs::remove_dir_all(&self.0);
    }
}

/// The names of the entries of `dir`, sorted (to check that a write left no temporary
/// file behind).
///
/// # Panics
/// When `dir` cannot be read.
#[expect(
    clippy::expect_used,
    reason = "a test helper: a test fails loudly here"
)]
pub fn dir_entries(dir: &Path) -> Vec<String> {
    let mut names: Vec<String> = std::fs::read_dir(dir)
        .expect("a readable directory")
        .map(|e| {
            e.expect("a directory entry")
                .file_name()
                .to_string_lossy()
                .into_owned()
        })
        .collect();
    names.sort();
    names
}

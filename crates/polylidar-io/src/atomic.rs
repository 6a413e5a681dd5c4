//! Atomic file writes: the bytes go to a temporary file in the target's directory, are
//! flushed to disk (`fsync`), and the temporary file is then renamed over the target. A
//! reader sees the old file or the new one, never a mix; a write that fails (disk full,
//! file size limit, a writer that errors midway) leaves the old file byte for byte as it
//! was and removes the temporary file.
//!
//! [`write_atomic`] does all of it for one file. A command that writes several files
//! stages each with [`StagedFile::write`] and renames them all with [`commit_all`] once
//! every one is written, so that a later output's failure leaves none of the earlier ones
//! half done.
//!
//! ```
//! use polylidar_io::atomic::{StagedFile, commit_all, write_atomic};
//!
//! let dir = std::env::temp_dir().join(format!("polylidar-io-atomic-doc-{}", std::process::id()));
//! std::fs::create_dir_all(&dir)?;
//! let a = dir.join("a.txt");
//! write_atomic(&a, b"first")?;
//! write_atomic(&a, b"second")?;
//! assert_eq!(std::fs::read(&a)?, b"second");
//!
//! let b = dir.join("b.txt");
//! let staged = vec![StagedFile::write(&a, b"third")?, StagedFile::write(&b, b"fourth")?];
//! assert_eq!(std::fs::read(&a)?, b"second"); // nothing renamed yet
//! commit_all(staged).map_err(|(_, e)| e)?;
//! assert_eq!(std::fs::read(&b)?, b"fourth");
//! # std::fs::remove_dir_all(&dir)?;
//! # Ok::<(), std::io::Error>(())
//! ```
//!
//! The target keeps its name; a symbolic link is followed and the file it points to is
//! replaced. A read-only target is refused (as a plain write would), and so is a directory.
//! The temporary file is named `.<name>.<process id>.<n>.tmp`. A process killed outright
//! during a write (`SIGKILL`, an unhandled signal) cannot remove its temporary file; on
//! Linux the next write to the same target removes those of processes that no longer
//! exist.

use std::fs::{File, OpenOptions};
use std::io::{self, BufWriter, Write};
use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicU64, Ordering};

/// Temporary names tried before giving up (each exists only if another writer left it).
const NAME_ATTEMPTS: u32 = 64;

/// Counter that makes the temporary names of one process distinct.
static NEXT_TEMP: AtomicU64 = AtomicU64::new(0);

/// Writes `bytes` to `path` atomically (see the [module docs](self)).
///
/// # Errors
/// The system's error when the directory, the temporary file or the rename fails; the
/// old file is then unchanged and no temporary file is left.
pub fn write_atomic(path: impl AsRef<Path>, bytes: &[u8]) -> io::Result<()> {
    StagedFile::write(path, bytes)?.commit()
}

/// Writes to `path` atomically through `write`, which gets a buffered writer on the
/// temporary file; an error from `write` leaves the old file as it was.
///
/// ```
/// use std::io::Write;
/// let path = std::env::temp_dir().join(format!("polylidar-io-atomic-with-{}.txt", std::process::id()));
/// polylidar_io::atomic::write_atomic_with(&path, |w| writeln!(w, "hello"))?;
/// assert_eq!(std::fs::read_to_string(&path)?, "hello\n");
/// # std::fs::remove_file(&path)?;
/// # Ok::<(), std::io::Error>(())
/// ```
///
/// # Errors
/// As [`write_atomic`], and `write`'s own error.
pub fn write_atomic_with<F>(path: impl AsRef<Path>, write: F) -> io::Result<()>
where
    F: FnOnce(&mut BufWriter<File>) -> io::Result<()>,
{
    StagedFile::write_with(path, write)?.commit()
}

/// A file written in full to its temporary beside the target and flushed to disk, not yet
/// renamed into place. Dropping it without [`StagedFile::commit`] removes the temporary
/// file and leaves the target as it was.
#[derive(Debug)]
#[must_use = "a staged file is removed when dropped; call commit"]
pub struct StagedFile {
    /// The temporary file, in the target's directory.
    temp: PathBuf,
    /// Where it goes (symbolic links resolved).
    target: PathBuf,
    /// The path the caller gave.
    requested: PathBuf,
    /// Whether the rename happened (nothing to remove then).
    committed: bool,
    /// Whether the caller wrote through its own handle ([`StagedFile::create`]), so the
    /// file is flushed to disk at [`StagedFile::commit`].
    sync_on_commit: bool,
}

impl StagedFile {
    /// Writes `bytes` to a temporary file beside `path` and flushes it to disk.
    ///
    /// # Errors
    /// As [`write_atomic`].
    pub fn write(path: impl AsRef<Path>, bytes: &[u8]) -> io::Result<Self> {
        Self::write_with(path, |w| w.write_all(bytes))
    }

    /// Writes through `write` to a temporary file beside `path` and flushes it to disk.
    ///
    /// # Errors
    /// As [`write_atomic_with`].
    pub fn write_with<F>(path: impl AsRef<Path>, write: F) -> io::Result<Self>
    where
        F: FnOnce(&mut BufWriter<File>) -> io::Result<()>,
    {
        let requested = path.as_ref().to_path_buf();
        let target = resolve_target(&requested)?;
        let (file, temp) = create_temp(&target)?;
        // From here on, dropping `staged` removes the temporary file.
        let staged = Self {
            temp,
            target,
            requested,
            committed: false,
            sync_on_commit: false,
        };
        let mut writer = BufWriter::new(file);
        write(&mut writer)?;
        let file = writer
            .into_inner()
            .map_err(io::IntoInnerError::into_error)?;
        file.sync_all()?;
        Ok(staged)
    }

    /// Creates the empty temporary file beside `path` and returns it with its handle, for
    /// writers that must own their file (one that seeks back to patch a header, say).
    /// Write through the handle, close it, then [`StagedFile::commit`] flushes the file to
    /// disk and renames it; dropping the staged file instead removes it.
    ///
    /// ```
    /// use std::io::Write;
    /// use polylidar_io::atomic::StagedFile;
    /// let path = std::env::temp_dir().join(format!("polylidar-io-atomic-create-{}.txt", std::process::id()));
    /// let (staged, mut file) = StagedFile::create(&path)?;
    /// file.write_all(b"owned")?;
    /// drop(file);
    /// staged.commit()?;
    /// assert_eq!(std::fs::read(&path)?, b"owned");
    /// # std::fs::remove_file(&path)?;
    /// # Ok::<(), std::io::Error>(())
    /// ```
    ///
    /// # Errors
    /// As [`write_atomic`].
    pub fn create(path: impl AsRef<Path>) -> io::Result<(Self, File)> {
        let requested = path.as_ref().to_path_buf();
        let target = resolve_target(&requested)?;
        let (file, temp) = create_temp(&target)?;
        let staged = Self {
            temp,
            target,
            requested,
            committed: false,
            sync_on_commit: true,
        };
        Ok((staged, file))
    }

    /// The path the file will have (as given, before links are resolved).
    pub fn path(&self) -> &Path {
        &self.requested
    }

    /// Renames the temporary file over the target and flushes the directory entry.
    ///
    /// # Errors
    /// The system's error when the rename fails; the temporary file is then removed and
    /// the target unchanged.
    pub fn commit(mut self) -> io::Result<()> {
        if self.sync_on_commit {
            File::open(&self.temp)?.sync_all()?;
        }
        std::fs::rename(&self.temp, &self.target)?;
        self.committed = true;
        sync_directory(&self.target);
        Ok(())
    }
}

impl Drop for StagedFile {
    fn drop(&mut self) {
        if !self.committed {
            // Best effort: the file is ours and nobody else knows its name.
            let _ = std::fs::remove_file(&self.temp);
        }
    }
}

/// Renames every staged file into place, in order. The renames run after every file has
/// been written in full, so a failed write never leaves a set of outputs half replaced;
/// a failed rename (rare: the temporary file sits in the target's directory) stops
/// there and removes the remaining temporary files.
///
/// # Errors
/// The path that could not be renamed into place and the system's error.
pub fn commit_all(staged: Vec<StagedFile>) -> Result<(), (PathBuf, io::Error)> {
    for file in staged {
        let path = file.path().to_path_buf();
        file.commit().map_err(|e| (path, e))?;
    }
    Ok(())
}

/// Where the bytes for `path` go: the file a symbolic link points to, or `path` itself;
/// a directory or a read-only file is refused.
fn resolve_target(path: &Path) -> io::Result<PathBuf> {
    if path.file_name().is_none() {
        return Err(io::Error::new(
            io::ErrorKind::InvalidInput,
            "the path names no file",
        ));
    }
    let target = match std::fs::symlink_metadata(path) {
        Ok(meta) if meta.file_type().is_symlink() => match std::fs::canonicalize(path) {
            Ok(resolved) => resolved,
            // A dangling link: create the file it names.
            Err(_) => {
                let link = std::fs::read_link(path)?;
                match path.parent() {
                    Some(dir) if link.is_relative() => dir.join(link),
                    _ => link,
                }
            }
        },
        _ => path.to_path_buf(),
    };
    match std::fs::metadata(&target) {
        Ok(meta) if meta.is_dir() => Err(io::Error::new(
            io::ErrorKind::IsADirectory,
            "is a directory",
        )),
        Ok(meta) if meta.permissions().readonly() => Err(io::Error::new(
            io::ErrorKind::PermissionDenied,
            "the file is read-only",
        )),
        _ => Ok(target),
    }
}

/// Creates a new temporary file beside `target`, with the target's permissions when it
/// exists.
fn create_temp(target: &Path) -> io::Result<(File, PathBuf)> {
    let dir = match target.parent() {
        Some(d) if !d.as_os_str().is_empty() => d,
        _ => Path::new("."),
    };
    let name = target
        .file_name()
        .map(|n| n.to_string_lossy().into_owned())
        .unwrap_or_default();
    remove_stale(dir, &name);
    let permissions = std::fs::metadata(target).ok().map(|m| m.permissions());
    let mut last = None;
    for _ in 0..NAME_ATTEMPTS {
        let n = NEXT_TEMP.fetch_add(1, Ordering::Relaxed);
        let temp = dir.join(format!(".{name}.{}.{n}.tmp", std::process::id()));
        match OpenOptions::new().write(true).create_new(true).open(&temp) {
            Ok(file) => {
                if let Some(p) = &permissions
                    && let Err(e) = file.set_permissions(p.clone())
                {
                    drop(file);
                    let _ = std::fs::remove_file(&temp);
                    return Err(e);
                }
                return Ok((file, temp));
            }
            Err(e) if e.kind() == io::ErrorKind::AlreadyExists => last = Some(e),
            Err(e) => return Err(e),
        }
    }
    Err(last.unwrap_or_else(|| io::Error::other("no free temporary file name")))
}

/// Removes the temporary files `.<name>.<pid>.<n>.tmp` in `dir` whose process no longer
/// exists (Linux, where `/proc/<pid>` tells; elsewhere nothing is removed). A process
/// that still runs keeps its files, whatever they are for.
fn remove_stale(dir: &Path, name: &str) {
    let proc = Path::new("/proc");
    if !proc.join("self").exists() {
        return;
    }
    let prefix = format!(".{name}.");
    let Ok(entries) = std::fs::read_dir(dir) else {
        return;
    };
    for entry in entries.flatten() {
        let file = entry.file_name();
        let Some(middle) = file
            .to_str()
            .and_then(|f| f.strip_prefix(&prefix))
            .and_then(|f| f.strip_suffix(".tmp"))
        else {
            continue;
        };
        let Some((pid, n)) = middle.split_once('.') else {
            continue;
        };
        let ours = pid.parse::<u32>().is_ok() && n.parse::<u64>().is_ok();
        if ours && !proc.join(pid).exists() {
            let _ = std::fs::remove_file(entry.path());
        }
    }
}

/// Flushes the directory entry of a renamed file (Unix; elsewhere the rename stands as
/// the system keeps it). Failures are ignored: the file itself is already on disk.
fn sync_directory(target: &Path) {
    #[cfg(unix)]
    {
        let dir = match target.parent() {
            Some(d) if !d.as_os_str().is_empty() => d,
            _ => Path::new("."),
        };
        if let Ok(d) = File::open(dir) {
            let _ = d.sync_all();
        }
    }
    #[cfg(not(unix))]
    let _ = target;
}

#[cfg(test)]
mod tests {
    use super::*;

    fn scratch(name: &str) -> test_fixtures::ScratchDir {
        test_fixtures::scratch_dir("polylidar-io-atomic", name)
    }

    #[test]
    fn replaces_the_file() {
        let dir = scratch("replace");
        let path = dir.join("out.json");
        write_atomic(&path, b"old").unwrap();
        write_atomic(&path, b"new contents").unwrap();
        assert_eq!(std::fs::read(&path).unwrap(), b"new contents");
        assert_eq!(test_fixtures::dir_entries(&dir), ["out.json"]);
    }

    #[test]
    fn a_writer_failing_midway_leaves_the_old_file_and_no_temporary() {
        let dir = scratch("midway");
        let path = dir.join("out.json");
        let old: Vec<u8> = (0..10_000u32).flat_map(|i| i.to_le_bytes()).collect();
        std::fs::write(&path, &old).unwrap();
        let err = write_atomic_with(&path, |w| {
            w.write_all(&[7; 100_000])?;
            Err(io::Error::other("disk full"))
        })
        .unwrap_err();
        assert_eq!(err.to_string(), "disk full");
        assert_eq!(std::fs::read(&path).unwrap(), old);
        assert_eq!(test_fixtures::dir_entries(&dir), ["out.json"]);
    }

    #[test]
    fn staged_files_are_renamed_only_on_commit_and_removed_when_dropped() {
        let dir = scratch("staged");
        let (a, b) = (dir.join("a"), dir.join("b"));
        std::fs::write(&a, b"old a").unwrap();
        let first = StagedFile::write(&a, b"new a").unwrap();
        assert_eq!(std::fs::read(&a).unwrap(), b"old a");
        assert_eq!(test_fixtures::dir_entries(&dir).len(), 2);
        // A later output fails: the earlier one is dropped, not committed.
        let second = StagedFile::write_with(&b, |_| Err(io::Error::other("no")));
        assert!(second.is_err());
        drop(first);
        assert_eq!(std::fs::read(&a).unwrap(), b"old a");
        assert_eq!(test_fixtures::dir_entries(&dir), ["a"]);
        let all = vec![
            StagedFile::write(&a, b"A").unwrap(),
            StagedFile::write(&b, b"B").unwrap(),
        ];
        commit_all(all).unwrap();
        assert_eq!(std::fs::read(&a).unwrap(), b"A");
        assert_eq!(std::fs::read(&b).unwrap(), b"B");
        assert_eq!(test_fixtures::dir_entries(&dir), ["a", "b"]);
    }

    #[test]
    fn a_created_file_replaces_the_target_only_on_commit() {
        let dir = scratch("create");
        let path = dir.join("cloud.las");
        std::fs::write(&path, b"old").unwrap();
        let (staged, mut file) = StagedFile::create(&path).unwrap();
        file.write_all(b"half a file").unwrap();
        drop(file);
        drop(staged);
        assert_eq!(std::fs::read(&path).unwrap(), b"old");
        assert_eq!(test_fixtures::dir_entries(&dir), ["cloud.las"]);
        let (staged, mut file) = StagedFile::create(&path).unwrap();
        file.write_all(b"new").unwrap();
        drop(file);
        staged.commit().unwrap();
        assert_eq!(std::fs::read(&path).unwrap(), b"new");
        assert_eq!(test_fixtures::dir_entries(&dir), ["cloud.las"]);
    }

    #[test]
    fn a_directory_or_read_only_target_is_refused() {
        let dir = scratch("refused");
        let sub = dir.join("sub");
        std::fs::create_dir(&sub).unwrap();
        assert_eq!(
            write_atomic(&sub, b"x").unwrap_err().kind(),
            io::ErrorKind::IsADirectory
        );
        let locked = dir.join("locked");
        std::fs::write(&locked, b"keep").unwrap();
        let mut p = std::fs::metadata(&locked).unwrap().permissions();
        p.set_readonly(true);
        std::fs::set_permissions(&locked, p).unwrap();
        assert_eq!(
            write_atomic(&locked, b"x").unwrap_err().kind(),
            io::ErrorKind::PermissionDenied
        );
        assert_eq!(std::fs::read(&locked).unwrap(), b"keep");
        assert_eq!(test_fixtures::dir_entries(&dir), ["locked", "sub"]);
    }

    #[cfg(unix)]
    #[test]
    fn a_symbolic_link_keeps_pointing_at_the_new_file() {
        let dir = scratch("link");
        let real = dir.join("real.txt");
        std::fs::write(&real, b"old").unwrap();
        let link = dir.join("link.txt");
        std::os::unix::fs::symlink(&real, &link).unwrap();
        write_atomic(&link, b"new").unwrap();
        assert!(
            std::fs::symlink_metadata(&link)
                .unwrap()
                .file_type()
                .is_symlink()
        );
        assert_eq!(std::fs::read(&real).unwrap(), b"new");
    }

    #[cfg(target_os = "linux")]
    #[test]
    fn temporaries_of_dead_processes_are_removed_by_the_next_write() {
        let dir = scratch("stale");
        let path = dir.join("out.json");
        // Above Linux's largest process id (2^22): no such process.
        let dead = dir.join(".out.json.4294967295.7.tmp");
        let alive = dir.join(format!(".out.json.{}.999999.tmp", std::process::id()));
        let other = dir.join(".other.json.4294967295.7.tmp");
        for p in [&dead, &alive, &other] {
            std::fs::write(p, b"partial").unwrap();
        }
        write_atomic(&path, b"new").unwrap();
        let mut expected = vec![
            format!(".out.json.{}.999999.tmp", std::process::id()),
            ".other.json.4294967295.7.tmp".to_owned(),
            "out.json".to_owned(),
        ];
        expected.sort();
        assert_eq!(test_fixtures::dir_entries(&dir), expected);
    }

    #[cfg(unix)]
    #[test]
    fn keeps_the_permissions_of_the_file_it_replaces() {
        use std::os::unix::fs::PermissionsExt;
        let dir = scratch("mode");
        let path = dir.join("script.sh");
        std::fs::write(&path, b"old").unwrap();
        std::fs::set_permissions(&path, std::fs::Permissions::from_mode(0o640)).unwrap();
        write_atomic(&path, b"new").unwrap();
        let mode = std::fs::metadata(&path).unwrap().permissions().mode() & 0o777;
        assert_eq!(mode, 0o640);
    }
}

//! The files a command writes.
//!
//! Every output path is checked before any work is done ([`Outputs::plan`]): its directory
//! exists or can be created and is writable, the path is not a directory or a read-only
//! file, and no two outputs, and no output and input, are the same file (compared after
//! resolving links and `..`, and by inode on Unix). Once the results are ready each output
//! is written in full to a temporary file beside its target ([`Outputs::stage`]); only when
//! all are written are they renamed into place ([`Outputs::commit`]). A failure anywhere
//! before the renames leaves every previous file as it was and removes the temporary
//! files.

use std::path::{Component, Path, PathBuf};

use polylidar_io::atomic::{StagedFile, commit_all};

use crate::run::CliError;

/// A file as compared with others: its absolute path with links resolved as far as the
/// file system has them, and on Unix the device and inode of an existing file.
#[derive(Debug, Clone, PartialEq, Eq)]
struct Identity {
    path: PathBuf,
    inode: Option<(u64, u64)>,
}

impl Identity {
    fn same_file(&self, other: &Identity) -> bool {
        self.path == other.path || (self.inode.is_some() && self.inode == other.inode)
    }
}

/// The inputs and outputs of one command (see the [module docs](self)).
#[derive(Debug, Default)]
pub struct Outputs {
    /// What each input is (`the input`, `--config`) and its identity.
    inputs: Vec<(String, PathBuf, Identity)>,
    /// The flag of each checked output, its path and identity.
    planned: Vec<(String, PathBuf, Identity)>,
    /// Outputs written to their temporary files, in the order they are renamed.
    staged: Vec<StagedFile>,
}

impl Outputs {
    /// No inputs, no outputs.
    pub fn new() -> Self {
        Self::default()
    }

    /// Records an input file (`what` names it in errors: `the input`, `--config`) that no
    /// output may overwrite. Paths that do not exist are ignored (reading them fails
    /// later with its own error).
    pub fn input(&mut self, what: &str, path: &Path) {
        if let Ok(identity) = identity(path)
            && std::fs::metadata(path).is_ok()
        {
            self.inputs
                .push((what.to_owned(), path.to_path_buf(), identity));
        }
    }

    /// Checks the output `path` of `flag` before any work: see the [module docs](self).
    ///
    /// # Errors
    /// [`CliError::Write`] naming the path and what is wrong.
    pub fn plan(&mut self, flag: &str, path: &Path) -> Result<(), CliError> {
        let fail = |message: String| CliError::Write {
            path: path.to_path_buf(),
            message,
        };
        if path.file_name().is_none() {
            return Err(fail(format!("{flag} needs a file name")));
        }
        match std::fs::metadata(path) {
            Ok(meta) if meta.is_dir() => {
                return Err(fail(format!(
                    "{flag} is a directory; give a file name inside it"
                )));
            }
            Ok(meta) if meta.permissions().readonly() => {
                return Err(fail(format!(
                    "{flag} is a read-only file; make it writable or write elsewhere"
                )));
            }
            _ => {}
        }
        check_directory(path).map_err(fail)?;
        let me = identity(path).map_err(|e| fail(e.to_string()))?;
        if let Some((what, input, _)) = self.inputs.iter().find(|(_, _, i)| i.same_file(&me)) {
            return Err(fail(format!(
                "{flag} is {what} ({}); it would be overwritten; write to another file",
                input.display()
            )));
        }
        if let Some((other, _, _)) = self
            .planned
            .iter()
            .find(|(f, _, i)| i.same_file(&me) && f != flag)
        {
            return Err(fail(format!(
                "{flag} and {other} name the same file; give each output its own"
            )));
        }
        if !self.planned.iter().any(|(f, _, i)| f == flag && *i == me) {
            self.planned.push((flag.to_owned(), path.to_path_buf(), me));
        }
        Ok(())
    }

    /// Writes `bytes` for the output `path` of `flag` to a temporary file beside it
    /// (checking it first if [`Self::plan`] has not), creating its directory. Nothing is
    /// renamed into place before [`Self::commit`].
    ///
    /// # Errors
    /// [`CliError::Write`] naming the path; the temporary file is then removed.
    pub fn stage(&mut self, flag: &str, path: &Path, bytes: &[u8]) -> Result<(), CliError> {
        self.plan(flag, path)?;
        let fail = |e: std::io::Error| CliError::Write {
            path: path.to_path_buf(),
            message: e.to_string(),
        };
        if let Some(dir) = path.parent().filter(|d| !d.as_os_str().is_empty()) {
            std::fs::create_dir_all(dir).map_err(fail)?;
        }
        self.staged
            .push(StagedFile::write(path, bytes).map_err(fail)?);
        Ok(())
    }

    /// Renames every staged output into place, in the order staged; returns their paths.
    ///
    /// # Errors
    /// [`CliError::Write`] naming the output that could not be renamed (the remaining
    /// temporary files are removed).
    pub fn commit(self) -> Result<Vec<PathBuf>, CliError> {
        let paths = self.staged.iter().map(|s| s.path().to_path_buf()).collect();
        commit_all(self.staged).map_err(|(path, e)| CliError::Write {
            path,
            message: e.to_string(),
        })?;
        Ok(paths)
    }
}

/// The nearest existing directory above `path` is a directory and accepts a new file.
fn check_directory(path: &Path) -> Result<(), String> {
    let absolute = absolute(path).map_err(|e| e.to_string())?;
    let mut dir = absolute.parent();
    while let Some(d) = dir {
        match std::fs::metadata(d) {
            Ok(meta) if meta.is_dir() => return probe(d),
            Ok(_) => return Err(format!("{} is not a directory", d.display())),
            Err(_) => dir = d.parent(),
        }
    }
    Err("no existing directory above it".to_owned())
}

/// Creates and removes an empty file in `dir`: the one check of writability that holds
/// for every user and file system (read-only mounts included).
fn probe(dir: &Path) -> Result<(), String> {
    let probe = dir.join(format!(".polylidar-write-check.{}", std::process::id()));
    match std::fs::OpenOptions::new()
        .write(true)
        .create_new(true)
        .open(&probe)
    {
        Ok(file) => {
            drop(file);
            let _ = std::fs::remove_file(&probe);
            Ok(())
        }
        Err(e) if e.kind() == std::io::ErrorKind::AlreadyExists => Ok(()),
        Err(e) => Err(format!("cannot create files in {}: {e}", dir.display())),
    }
}

/// `path` made absolute against the current directory, `.` and `..` folded lexically.
fn absolute(path: &Path) -> std::io::Result<PathBuf> {
    let joined = if path.is_absolute() {
        path.to_path_buf()
    } else {
        std::env::current_dir()?.join(path)
    };
    let mut out = PathBuf::new();
    for component in joined.components() {
        match component {
            Component::CurDir => {}
            Component::ParentDir => {
                out.pop();
            }
            other => out.push(other.as_os_str()),
        }
    }
    Ok(out)
}

/// The identity of `path`, existing or not: the canonical path of its nearest existing
/// ancestor (links resolved) followed by the rest.
fn identity(path: &Path) -> std::io::Result<Identity> {
    let absolute = absolute(path)?;
    let mut rest = Vec::new();
    let mut base = absolute.as_path();
    let resolved = loop {
        if let Ok(canonical) = std::fs::canonicalize(base) {
            break canonical;
        }
        match (base.file_name(), base.parent()) {
            (Some(name), Some(parent)) => {
                rest.push(name.to_os_string());
                base = parent;
            }
            _ => break base.to_path_buf(),
        }
    };
    let full = rest.iter().rev().fold(resolved, |p, name| p.join(name));
    Ok(Identity {
        inode: inode(&full),
        path: full,
    })
}

#[cfg(unix)]
fn inode(path: &Path) -> Option<(u64, u64)> {
    use std::os::unix::fs::MetadataExt;
    std::fs::metadata(path).ok().map(|m| (m.dev(), m.ino()))
}

#[cfg(not(unix))]
fn inode(_: &Path) -> Option<(u64, u64)> {
    None
}

#[cfg(test)]
mod tests {
    use super::*;

    fn scratch(name: &str) -> test_fixtures::ScratchDir {
        test_fixtures::scratch_dir("polylidar-cli-outputs", name)
    }

    #[test]
    fn an_output_may_not_be_an_input_under_another_spelling() {
        let dir = scratch("input");
        let input = dir.join("scan.pcd");
        std::fs::write(&input, b"cloud").unwrap();
        std::fs::create_dir(dir.join("sub")).unwrap();
        let mut outputs = Outputs::new();
        outputs.input("the input", &input);
        let spelled = dir.join("sub").join("..").join(".").join("scan.pcd");
        let err = outputs.plan("-o", &spelled).unwrap_err().to_string();
        assert!(err.contains("-o is the input"), "{err}");
        #[cfg(unix)]
        {
            let link = dir.join("link.pcd");
            std::os::unix::fs::symlink(&input, &link).unwrap();
            assert!(outputs.plan("--plot", &link).is_err());
            let hard = dir.join("hard.pcd");
            std::fs::hard_link(&input, &hard).unwrap();
            assert!(outputs.plan("--plot", &hard).is_err());
        }
        assert_eq!(std::fs::read(&input).unwrap(), b"cloud");
    }

    #[test]
    fn two_outputs_may_not_share_a_file() {
        let dir = scratch("twice");
        let mut outputs = Outputs::new();
        outputs.plan("-o", &dir.join("a.geojson")).unwrap();
        let err = outputs
            .plan("--plot", &dir.join("new").join("..").join("a.geojson"))
            .unwrap_err()
            .to_string();
        assert!(err.contains("--plot and -o name the same file"), "{err}");
    }

    #[test]
    fn directories_and_missing_parents_are_checked_first() {
        let dir = scratch("dirs");
        let mut outputs = Outputs::new();
        assert!(outputs.plan("-o", &dir).is_err());
        let file = dir.join("file");
        std::fs::write(&file, b"x").unwrap();
        let err = outputs
            .plan("-o", &file.join("out.geojson"))
            .unwrap_err()
            .to_string();
        assert!(err.contains("is not a directory"), "{err}");
        // A directory that does not exist yet is fine; nothing is created by the check.
        outputs
            .plan("-o", &dir.join("new").join("deeper").join("out.geojson"))
            .unwrap();
        assert_eq!(test_fixtures::dir_entries(&dir), ["file"]);
    }

    #[test]
    fn nothing_is_replaced_until_every_output_is_written() {
        let dir = scratch("commit");
        let (a, b) = (dir.join("a.geojson"), dir.join("b.png"));
        std::fs::write(&a, b"old a").unwrap();
        std::fs::write(&b, b"old b").unwrap();
        let mut outputs = Outputs::new();
        outputs.stage("-o", &a, b"new a").unwrap();
        // The second output fails (its target became a directory): the first is dropped.
        std::fs::remove_file(&b).unwrap();
        std::fs::create_dir(&b).unwrap();
        assert!(outputs.stage("--plot", &b, b"new b").is_err());
        drop(outputs);
        assert_eq!(std::fs::read(&a).unwrap(), b"old a");
        assert_eq!(test_fixtures::dir_entries(&dir), ["a.geojson", "b.png"]);
        std::fs::remove_dir(&b).unwrap();
        let mut outputs = Outputs::new();
        outputs.stage("-o", &a, b"new a").unwrap();
        outputs.stage("--plot", &b, b"new b").unwrap();
        assert_eq!(std::fs::read(&a).unwrap(), b"old a");
        let written = outputs.commit().unwrap();
        assert_eq!(written, [a.clone(), b.clone()]);
        assert_eq!(std::fs::read(&a).unwrap(), b"new a");
        assert_eq!(test_fixtures::dir_entries(&dir), ["a.geojson", "b.png"]);
    }
}

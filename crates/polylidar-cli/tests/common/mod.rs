//! What the tests of the `polylidar` binary share: running it, a scratch folder, reading
//! its `--json` output.
#![allow(clippy::expect_used, clippy::unwrap_used, clippy::panic)]
// Each test file uses some of these helpers, none all of them.
#![allow(dead_code)]

use std::path::Path;
use std::process::{Command, Output};

use test_fixtures::ScratchDir;

/// Runs the binary with `args`.
pub fn polylidar(args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_polylidar"))
        .args(args)
        .output()
        .expect("the binary runs")
}

/// Runs the binary with `args` in the folder `dir` (relative paths start there).
pub fn polylidar_in(dir: &Path, args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_polylidar"))
        .current_dir(dir)
        .args(args)
        .output()
        .expect("the binary runs")
}

/// Asserts that the run succeeded, showing its stderr when it did not; its stderr.
pub fn succeeded(output: &Output) -> String {
    let stderr = String::from_utf8_lossy(&output.stderr).into_owned();
    assert!(output.status.success(), "{stderr}");
    stderr
}

/// A fresh, empty folder for one test's files (`tag` names the test file, `name` the
/// test), removed when the returned guard is dropped.
pub fn scratch(tag: &str, name: &str) -> ScratchDir {
    test_fixtures::scratch_dir(&format!("polylidar-{tag}"), name)
}

/// The one JSON object a successful run printed on stdout.
pub fn json(output: &Output) -> serde_json::Value {
    succeeded(output);
    serde_json::from_slice(&output.stdout).expect("stdout is one JSON object")
}

//! Helpers shared by the CLI's integration tests.

use std::path::PathBuf;
use std::process::Command;

/// Runs the CLI with `args`: whether it succeeded, its standard output and
/// its standard error.
#[allow(dead_code)] // not every test binary asks for success alone
pub fn dalembert(args: &[&str]) -> (bool, String, String) {
    let (code, stdout, stderr) = dalembert_exit(args);
    (code == Some(0), stdout, stderr)
}

/// Runs the CLI with `args`: its exit code (`None` if a signal ended it),
/// standard output and standard error.
pub fn dalembert_exit(args: &[&str]) -> (Option<i32>, String, String) {
    let out = Command::new(env!("CARGO_BIN_EXE_dalembert"))
        .args(args)
        .output()
        .expect("the CLI runs");
    (
        out.status.code(),
        String::from_utf8_lossy(&out.stdout).into_owned(),
        String::from_utf8_lossy(&out.stderr).into_owned(),
    )
}

/// An empty scratch folder `name` under the tests' temporary directory.
#[allow(dead_code)] // not every test binary writes files
pub fn scratch(name: &str) -> PathBuf {
    let dir = PathBuf::from(env!("CARGO_TARGET_TMPDIR")).join(name);
    let _ = std::fs::remove_dir_all(&dir);
    dir
}

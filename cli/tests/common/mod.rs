//! Helpers shared by the CLI's integration tests.

use std::process::Command;

/// Runs the CLI with `args`: whether it succeeded, its standard output and
/// its standard error.
pub fn dalembert(args: &[&str]) -> (bool, String, String) {
    let out = Command::new(env!("CARGO_BIN_EXE_dalembert"))
        .args(args)
        .output()
        .expect("the CLI runs");
    (
        out.status.success(),
        String::from_utf8_lossy(&out.stdout).into_owned(),
        String::from_utf8_lossy(&out.stderr).into_owned(),
    )
}

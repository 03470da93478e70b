//! `dalembert generate` and `derive` write only their own text to standard
//! output, so that a redirected output is Rust code or a derivation. Uses
//! the symbolic engine: run one test at a time (`RUST_TEST_THREADS=1`).

use std::path::PathBuf;
use std::process::Command;

/// `dalembert ARGS…` on the pendulum at the wall: standard output and
/// standard error.
fn dalembert(command: &str) -> (String, String) {
    let model = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../models/pendulum_wall.toml");
    let out = Command::new(env!("CARGO_BIN_EXE_dalembert"))
        .arg(command)
        .arg(model)
        .output()
        .expect("the CLI runs");
    assert!(out.status.success(), "{out:?}");
    (
        String::from_utf8(out.stdout).unwrap(),
        String::from_utf8_lossy(&out.stderr).into_owned(),
    )
}

/// symbolica shows a licence notice on its first use; it once went to
/// standard output, ahead of the code, so that `generate FILE > model.rs`
/// wrote a file that does not compile.
#[test]
fn generated_code_alone_reaches_standard_output() {
    let (code, _) = dalembert("generate");
    assert!(code.starts_with("// @generated"), "{}", &code[..200]);
    syn::parse_file(&code).expect("standard output is one Rust file");
    let (derivation, _) = dalembert("derive");
    assert!(
        derivation.starts_with("model `pendulum_wall`"),
        "{}",
        &derivation[..200]
    );
}

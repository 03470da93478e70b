//! The corpus of bad model files in `tests/bad_models/`: each gets its own
//! clear errors with file:line:col (snapshots in `tests/snapshots/`), never a
//! panic. Files whose errors are found only in the symbolic stage use the
//! symbolic engine: run one test at a time (`RUST_TEST_THREADS=1`).

use std::path::Path;

mod common;

#[test]
fn every_bad_model_gets_its_diagnostics() {
    let files = common::toml_files(Path::new("tests/bad_models"));
    assert!(files.len() >= 20, "the corpus has {} files", files.len());
    for file in files {
        let name = file.file_stem().unwrap().to_string_lossy().into_owned();
        let errors = match dalembert_codegen::derive(&file) {
            Ok(_) => panic!("{} was accepted", file.display()),
            Err(e) => e,
        };
        assert!(!errors.errors.is_empty());
        // Plain form (what tools parse) and the rendered form (what people read).
        let text = format!("{errors}\n\n{}", errors.render());
        insta::assert_snapshot!(name, text);
    }
}

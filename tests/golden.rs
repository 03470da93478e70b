//! Golden generated files: the emitted Rust for every built-in model, as
//! snapshots in `tests/snapshots/`. A change to the generator that changes
//! emitted code shows up here for review. Uses the symbolic engine: run one
//! test at a time (`RUST_TEST_THREADS=1`).

mod common;

#[test]
fn generated_files_match_their_snapshots() {
    let files = common::model_files();
    assert!(!files.is_empty());
    for file in files {
        let name = format!("generated_{}", file.file_stem().unwrap().to_string_lossy());
        let code = dalembert_codegen::generate(&file).unwrap_or_else(|e| panic!("{}", e.render()));
        assert!(code.starts_with("// @generated"));
        insta::assert_snapshot!(name, code);
    }
}

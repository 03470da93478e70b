//! Golden generated files: the emitted Rust for every built-in model, as
//! snapshots in `tests/snapshots/`. A change to the generator that changes
//! emitted code shows up here for review. Uses the symbolic engine: run one
//! test at a time (`RUST_TEST_THREADS=1`).

use std::path::Path;

#[test]
fn generated_files_match_their_snapshots() {
    let mut files: Vec<_> = std::fs::read_dir(Path::new(env!("CARGO_MANIFEST_DIR")).join("models"))
        .unwrap()
        .map(|e| e.unwrap().path())
        .filter(|p| p.extension().is_some_and(|e| e == "toml"))
        .collect();
    files.sort();
    assert!(!files.is_empty());
    for file in files {
        let name = format!("generated_{}", file.file_stem().unwrap().to_string_lossy());
        let code = dalembert_codegen::generate(&file).unwrap_or_else(|e| panic!("{}", e.render()));
        assert!(code.starts_with("// @generated"));
        insta::assert_snapshot!(name, code);
    }
}

//! Golden generated files: the emitted Rust for every built-in model, as
//! snapshots in `tests/snapshots/`. A change to the generator that changes
//! emitted code shows up here for review. The files compared are the build
//! script's (`OUT_DIR`), which `tests/reproducible.rs` checks against each
//! model generated alone.

use std::path::Path;

mod common;

#[test]
fn generated_files_match_their_snapshots() {
    let files = common::model_files();
    assert!(!files.is_empty());
    for file in files {
        let stem = file.file_stem().unwrap().to_string_lossy().into_owned();
        let built = Path::new(env!("OUT_DIR")).join(format!("{stem}.rs"));
        let code =
            std::fs::read_to_string(&built).unwrap_or_else(|e| panic!("{}: {e}", built.display()));
        assert!(code.starts_with("// @generated"));
        insta::assert_snapshot!(format!("generated_{stem}"), code);
    }
}

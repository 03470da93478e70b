//! Golden generated files: the emitted Rust for every built-in model, as
//! snapshots in `tests/snapshots/`. A change to the generator that changes
//! emitted code shows up here for review. The files compared are the build
//! script's (`OUT_DIR`), each derived in a process of its own, which
//! `tests/reproducible.rs` checks against the model generated alone: a
//! process that derives several models in turn may group a later model's
//! sums and products otherwise (symbolica keeps the symbols it has seen),
//! so snapshots taken that way changed whenever a model was added before
//! another in file order.

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

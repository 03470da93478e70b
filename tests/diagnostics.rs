//! The corpus of bad model files in `tests/bad_models/`: each gets its own
//! clear errors with file:line:col (snapshots in `tests/snapshots/`), never a
//! panic. Files whose errors are found only in the symbolic stage use the
//! symbolic engine: run one test at a time (`RUST_TEST_THREADS=1`).

use std::path::Path;
use std::time::{Duration, Instant};

mod common;

/// How long the derivation may take to refuse a bad model: a third of the
/// 60 s every model file is held to, with room for a loaded machine. (The
/// slowest here takes about a second; `rank_of_b_too_large` took 50 s
/// before the elimination's steps were bounded.)
const REFUSED_WITHIN: Duration = Duration::from_secs(20);

/// Each is refused within [`REFUSED_WITHIN`] too: a model past a limit is
/// stopped by the budget before the work it bounds, not after.
#[test]
fn every_bad_model_gets_its_diagnostics() {
    let files = common::toml_files(Path::new("tests/bad_models"));
    assert!(files.len() >= 20, "the corpus has {} files", files.len());
    for file in files {
        let name = file.file_stem().unwrap().to_string_lossy().into_owned();
        let start = Instant::now();
        let errors = match dalembert_codegen::derive(&file) {
            Ok(_) => panic!("{} was accepted", file.display()),
            Err(e) => e,
        };
        let took = start.elapsed();
        assert!(took < REFUSED_WITHIN, "{name} was refused after {took:?}");
        assert!(!errors.errors.is_empty());
        // Plain form (what tools parse) and the rendered form (what people read).
        let text = format!("{errors}\n\n{}", errors.render());
        insta::assert_snapshot!(name, text);
    }
}

/// What is not a model file's text is refused before it is read whole: a
/// FIFO (which would block the reader) and a device (/dev/zero, which would
/// never end) as not regular files, a file over the size limit as too
/// large, and bytes that are not UTF-8 at their own line and column.
#[test]
fn files_that_are_not_model_text_are_refused() {
    use dalembert_codegen::ErrorKind;
    let dir = std::path::PathBuf::from(env!("CARGO_TARGET_TMPDIR")).join("not-model-text");
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    let kind = |path: &Path| match dalembert_codegen::derive(path) {
        Ok(_) => panic!("{} was accepted", path.display()),
        Err(e) => {
            assert_eq!(e.errors.len(), 1, "{e}");
            (e.errors[0].kind.clone(), e.errors[0].line, e.errors[0].col)
        }
    };
    let fifo = dir.join("fifo.toml");
    let made = std::process::Command::new("mkfifo").arg(&fifo).status();
    assert!(made.is_ok_and(|s| s.success()), "mkfifo");
    assert!(matches!(kind(&fifo).0, ErrorKind::NotAFile(_)));
    assert!(matches!(
        kind(Path::new("/dev/zero")).0,
        ErrorKind::NotAFile(_)
    ));
    assert!(matches!(kind(&dir).0, ErrorKind::NotAFile(_)));
    let large = dir.join("large.toml");
    let limit = dalembert_codegen::ir::MAX_FILE_BYTES;
    std::fs::write(&large, "#".repeat(limit as usize + 1)).unwrap();
    assert_eq!(kind(&large).0, ErrorKind::TooLarge { limit });
    let latin1 = dir.join("latin1.toml");
    std::fs::write(&latin1, b"[model]\nname = \"m\"\ndoc = \"caf\xe9\"\n").unwrap();
    assert_eq!(kind(&latin1), (ErrorKind::NotUtf8, 3, 11));
    // A reference file for `check` goes through the same reader.
    let refused = dalembert_codegen::reference::Reference::load(&fifo).unwrap_err();
    assert!(refused.contains("not a regular file"), "{refused}");
}

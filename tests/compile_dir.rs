//! `compile_dir` in a build script derives each model in a process of its
//! own (the build script run again). When that process fails although the
//! model derives, the model's code is not written from a derivation in the
//! calling process (whose code may differ from the model's alone): the
//! failure is the model's error, with the process's exit status.
//!
//! The process started is this test binary, which then exits at once with
//! status 3, as a build script that crashed would; so this file holds this
//! one test.

use std::path::Path;

/// What `compile_dir` sets in the process it starts for one model.
const ONE_MODEL: &str = "DALEMBERT_COMPILE_ONE_MODEL";

#[test]
fn a_failed_model_process_is_an_error_not_a_silent_rederivation() {
    if std::env::var_os(ONE_MODEL).is_some() {
        std::process::exit(3);
    }
    let dir = Path::new(env!("CARGO_TARGET_TMPDIR")).join("compile-dir-failed-child");
    let _ = std::fs::remove_dir_all(&dir);
    let (models, out) = (dir.join("models"), dir.join("out"));
    std::fs::create_dir_all(&models).unwrap();
    std::fs::create_dir_all(&out).unwrap();
    let source = Path::new(env!("CARGO_MANIFEST_DIR")).join("models/puck.toml");
    std::fs::copy(source, models.join("puck.toml")).unwrap();
    // As cargo sets them for a build script. SAFETY: this binary runs this
    // one test, and nothing else reads the environment meanwhile.
    unsafe {
        std::env::set_var("TARGET", "x86_64-unknown-linux-gnu");
        std::env::set_var("HOST", "x86_64-unknown-linux-gnu");
        std::env::set_var("OUT_DIR", &out);
    }
    let errors = dalembert_codegen::compile_dir(&models, &out)
        .expect_err("a model whose process failed must not be generated silently");
    let text: Vec<String> = errors.iter().map(|e| e.render()).collect();
    assert_eq!(errors.len(), 1, "{text:?}");
    assert!(
        text[0].contains("puck.toml")
            && text[0].contains("the process started to generate it alone failed")
            && text[0].contains("exit status: 3"),
        "{}",
        text[0]
    );
    assert!(
        !out.join("puck.rs").exists(),
        "the model's code was written"
    );
}

//! Generates Rust for every model in `models/` into OUT_DIR (see
//! `src/lib.rs`, which includes it). Reruns only when a model file or the
//! generator changes.
use std::path::{Path, PathBuf};

fn main() {
    let models = Path::new(env!("CARGO_MANIFEST_DIR")).join("models");
    println!("cargo::rerun-if-changed=models");
    let Some(out) = std::env::var_os("OUT_DIR").map(PathBuf::from) else {
        eprintln!("OUT_DIR is not set: run this build script through cargo");
        std::process::exit(1);
    };
    if let Err(errors) = dalembert_codegen::compile_dir(&models, &out) {
        for e in errors {
            eprintln!("{}", e.render());
        }
        std::process::exit(1);
    }
}

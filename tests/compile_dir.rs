//! `compile_dir`, what a user's build script calls: every model of a
//! directory generated in this process, each file byte for byte what
//! `generate` writes for the model alone, and the errors of every broken
//! model collected with its file named. Uses the symbolic engine: run one
//! test at a time (`RUST_TEST_THREADS=1`).

use std::path::{Path, PathBuf};

/// A directory of this test's with `models` (file names) copied from the
/// built-in models and `extra` (file name, text) written beside them.
fn models_dir(tag: &str, models: &[&str], extra: &[(&str, &str)]) -> (PathBuf, PathBuf) {
    let dir = Path::new(env!("CARGO_TARGET_TMPDIR")).join(format!("compile-dir-{tag}"));
    let _ = std::fs::remove_dir_all(&dir);
    let (models_dir, out) = (dir.join("models"), dir.join("out"));
    std::fs::create_dir_all(&models_dir).unwrap();
    std::fs::create_dir_all(&out).unwrap();
    let builtin = Path::new(env!("CARGO_MANIFEST_DIR")).join("models");
    for m in models {
        std::fs::copy(builtin.join(m), models_dir.join(m)).unwrap();
    }
    for (name, text) in extra {
        std::fs::write(models_dir.join(name), text).unwrap();
    }
    (models_dir, out)
}

/// Three models, the largest first in name order after two others: each
/// file as `generate` writes it, and the index including each.
#[test]
fn every_model_is_generated_as_alone() {
    let models = ["chain_3.toml", "chain_7.toml", "puck.toml"];
    let (dir, out) = models_dir("good", &models, &[]);
    let done = dalembert_codegen::compile_dir(&dir, &out)
        .unwrap_or_else(|e| panic!("{:?}", e.iter().map(|e| e.render()).collect::<Vec<_>>()));
    assert_eq!(done.len(), 3);
    let index = std::fs::read_to_string(out.join("models.rs")).unwrap();
    for (g, m) in done.iter().zip(models) {
        assert_eq!(g.model_file, dir.join(m));
        let written = std::fs::read_to_string(&g.rust_file).unwrap();
        let alone = dalembert_codegen::generate(&g.model_file).unwrap();
        assert!(written == alone, "{m}: not the file generated alone");
        let name = g.rust_file.file_name().unwrap().to_string_lossy();
        assert!(index.contains(&*name), "{m}: not in the index:\n{index}");
    }
}

/// Two broken models among good ones: both reported, each at its file;
/// no index is written.
#[test]
fn errors_of_every_model_are_collected() {
    let broken = [
        ("a_bad.toml", "[model]\nname = \"a_bad\"\n"),
        (
            "z_bad.toml",
            "[model]\nname = \"z_bad\"\n[coordinates]\nnames = [\"x\"]\n[dynamics]\nkinetic_energy = \"x_dot^2/2 + y\"\n",
        ),
    ];
    let (dir, out) = models_dir("bad", &["puck.toml"], &broken);
    let errors = dalembert_codegen::compile_dir(&dir, &out).expect_err("two models are broken");
    let text: Vec<String> = errors.iter().map(|e| e.render()).collect();
    assert_eq!(errors.len(), 2, "{text:?}");
    assert!(text[0].contains("a_bad.toml"), "{}", text[0]);
    assert!(text[1].contains("z_bad.toml"), "{}", text[1]);
    assert!(!out.join("models.rs").exists(), "an index was written");
}

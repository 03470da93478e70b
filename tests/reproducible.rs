//! The generated code of a model does not depend on what else the process
//! derived before it: a build script derives every model in one process,
//! `dalembert generate` and `dalembert simulate FILE` derive one. Each case
//! runs in a child process of its own (symbolica keeps its symbols for the
//! life of a process), so this file holds only these tests.

use std::path::Path;

mod common;

const CHILD: &str = "DALEMBERT_REPRODUCIBLE_CHILD";

/// A model that makes chain_3's names in another order (q3 before q1, the
/// parameters reversed) and uses them in sums and products.
const PRELUDE: &str = r#"
[model]
name = "prelude"
[parameters]
h = "1"
g = "1"
l3 = "1"
m3 = "1"
l2 = "1"
m2 = "1"
l1 = "1"
m1 = "1"
[coordinates]
names = ["q3", "q2", "q1"]
[dynamics]
kinetic_energy = "(q3_dot^2 + q2_dot^2 + q1_dot^2)/2"
potential = "h*g*l3*m3*l2*m2*l1*m1*(cos(q3) + sin(q2) + cos(q1))"
[[wall]]
name = "floor"
surface = "q3 + q2 + q1 + 10"
"#;

fn chain_3() -> std::path::PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("models/chain_3.toml")
}

/// In a child: derives the prelude first when asked, then writes chain_3's
/// generated code (or that of the model file `DALEMBERT_MODEL` names) to
/// the file the parent names.
#[test]
#[ignore = "runs only in the child process the other tests start"]
fn generate_in_child() {
    let Ok(out) = std::env::var(CHILD) else {
        return; // not a child: nothing to do
    };
    if std::env::var("DALEMBERT_PRELUDE").is_ok() {
        let dir = std::env::temp_dir().join(format!("dalembert-prelude-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let file = dir.join("prelude.toml");
        std::fs::write(&file, PRELUDE).unwrap();
        dalembert_codegen::derive(&file).unwrap_or_else(|e| panic!("prelude: {e}"));
        std::fs::remove_dir_all(&dir).unwrap();
    }
    let model = std::env::var_os("DALEMBERT_MODEL").map_or_else(chain_3, Into::into);
    let code = dalembert_codegen::generate(&model).unwrap_or_else(|e| panic!("{e}"));
    std::fs::write(out, code).unwrap();
}

/// What a child process generates for `model` (chain_3 by default).
fn generated(model: Option<&Path>, prelude: bool, tag: &str) -> String {
    let out = std::env::temp_dir().join(format!(
        "dalembert-reproducible-{}-{tag}.rs",
        std::process::id()
    ));
    let mut env = vec![(CHILD, out.as_os_str())];
    if prelude {
        env.push(("DALEMBERT_PRELUDE", "1".as_ref()));
    }
    if let Some(m) = model {
        env.push(("DALEMBERT_MODEL", m.as_os_str()));
    }
    common::in_child("generate_in_child", true, &env);
    let code = std::fs::read_to_string(&out).unwrap();
    std::fs::remove_file(&out).unwrap();
    code
}

/// chain_3 generated alone and generated after a model that made its names
/// in the opposite order: the same file.
#[test]
fn generated_code_does_not_depend_on_earlier_derivations() {
    let alone = generated(None, false, "alone");
    let after = generated(None, true, "after");
    assert!(alone.contains("pub fn floor_collide"));
    assert!(
        alone == after,
        "chain_3's code changed after deriving another model first"
    );
}

/// Every built-in model as the build script wrote it against the same
/// model generated alone in a process of its own: the same file. (Derived
/// in one process after the models before it, chain_7's `forcing` came out
/// with other groupings of its sums and products; the build script now
/// derives each model in a process of its own.)
#[test]
fn build_script_output_matches_each_model_generated_alone() {
    let files = common::model_files();
    assert!(files.len() > 10, "the built-in models are missing");
    let mut differ = Vec::new();
    for file in &files {
        let name = file.file_stem().unwrap().to_string_lossy().into_owned();
        let built = std::fs::read_to_string(Path::new(env!("OUT_DIR")).join(format!("{name}.rs")))
            .unwrap_or_else(|e| panic!("{name}: the build script's file: {e}"));
        if generated(Some(file), false, &name) != built {
            differ.push(name);
        }
    }
    assert!(
        differ.is_empty(),
        "generated alone, these differ from the build script's files: {differ:?}"
    );
}

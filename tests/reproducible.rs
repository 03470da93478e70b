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

/// Every built-in model as the build script wrote it (all of them in one
/// process, in name order) against the same model generated alone in a
/// process of its own: the same file.
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

const ORDER: &str = "DALEMBERT_REPRODUCIBLE_ORDER";

/// In a child: every built-in model generated in one process, in the order
/// `DALEMBERT_REPRODUCIBLE_ORDER` names (`name`, `reverse` or `shuffled`),
/// each file against the build script's.
#[test]
#[ignore = "runs only in the child process the other tests start"]
fn generate_all_in_child() {
    let Ok(order) = std::env::var(ORDER) else {
        return;
    };
    let mut files = common::model_files();
    match order.as_str() {
        "name" => {}
        "reverse" => files.reverse(),
        "shuffled" => {
            let mut seed = 7;
            for i in (1..files.len()).rev() {
                let j = (common::lcg(&mut seed) * (i + 1) as f64) as usize;
                files.swap(i, j.min(i));
            }
        }
        other => panic!("unknown order {other}"),
    }
    let mut differ = Vec::new();
    for file in &files {
        let name = file.file_stem().unwrap().to_string_lossy().into_owned();
        let built = std::fs::read_to_string(Path::new(env!("OUT_DIR")).join(format!("{name}.rs")))
            .unwrap_or_else(|e| panic!("{name}: the build script's file: {e}"));
        let code = dalembert_codegen::generate(file).unwrap_or_else(|e| panic!("{e}"));
        if code != built {
            differ.push(name);
        }
    }
    let names: Vec<_> = files
        .iter()
        .map(|f| f.file_stem().unwrap().to_owned())
        .collect();
    assert!(
        differ.is_empty(),
        "in order {names:?}, these differ: {differ:?}"
    );
}

/// Every built-in model generated in one process, in name order, in
/// reverse and in a shuffled order: each file is the one generated alone.
#[test]
fn one_process_in_any_order_gives_each_model_alone() {
    for order in ["name", "reverse", "shuffled"] {
        common::in_child("generate_all_in_child", true, &[(ORDER, order.as_ref())]);
    }
}

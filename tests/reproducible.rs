//! The generated code of a model does not depend on what else the process
//! derived before it: a build script derives every model in one process,
//! `dalembert generate` and `dalembert simulate FILE` derive one. Each case
//! runs in a child process of its own (symbolica keeps its symbols for the
//! life of a process), so this file holds only these tests.

use std::path::Path;
use std::process::Command;

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
/// generated code to the file the parent names.
#[test]
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
    }
    let code = dalembert_codegen::generate(&chain_3()).unwrap_or_else(|e| panic!("{e}"));
    std::fs::write(out, code).unwrap();
}

fn generated(prelude: bool, tag: &str) -> String {
    let out = std::env::temp_dir().join(format!(
        "dalembert-reproducible-{}-{tag}.rs",
        std::process::id()
    ));
    let mut child = Command::new(std::env::current_exe().unwrap());
    child
        .args(["--exact", "generate_in_child", "--test-threads=1"])
        .env(CHILD, &out);
    if prelude {
        child.env("DALEMBERT_PRELUDE", "1");
    }
    let status = child.status().unwrap();
    assert!(status.success(), "the child process failed");
    std::fs::read_to_string(out).unwrap()
}

/// chain_3 generated alone and generated after a model that made its names
/// in the opposite order: the same file.
#[test]
fn generated_code_does_not_depend_on_earlier_derivations() {
    if std::env::var(CHILD).is_ok() {
        return;
    }
    let alone = generated(false, "alone");
    let after = generated(true, "after");
    assert!(alone.contains("pub fn floor_collide"));
    assert!(
        alone == after,
        "chain_3's code changed after deriving another model first"
    );
}

//! If `generate` succeeds, the file compiles: model files with random names
//! (Rust keywords, the generated code's own names, names that differ only in
//! case or underscores, ordinary ones) are generated, and every file that
//! generates is compiled against the runtime by rustc in one crate. Uses the
//! symbolic engine: run one test at a time (`RUST_TEST_THREADS=1`).

mod common;

use std::path::{Path, PathBuf};

use proptest::prelude::*;
use proptest::test_runner::{Config, TestRunner};

/// Names that mean something to Rust, to the generated file or to the
/// runtime, and near-collisions of each other.
const TRICKY: &[&str] = &[
    "type",
    "fn",
    "match",
    "self",
    "Self",
    "crate",
    "super",
    "async",
    "dyn",
    "union",
    "mod",
    "r#x",
    "Params",
    "params",
    "Wall",
    "wall",
    "Walls",
    "Option",
    "Some",
    "None",
    "Ok",
    "Err",
    "Default",
    "default",
    "Result",
    "Vec",
    "String",
    "f64",
    "f32",
    "usize",
    "core",
    "std",
    "Rows",
    "Values",
    "Model",
    "Dynamics",
    "Surfaces",
    "FromParams",
    "libm",
    "sin",
    "cos",
    "sqrt",
    "o0",
    "t0",
    "i0",
    "sc0_sin",
    "q",
    "v",
    "new",
    "with_params",
    "NAME",
    "WALLS",
    "Q",
    "N",
    "a1",
    "a_1",
    "A1",
    "floor",
    "Floor",
    "x_dot",
    "x",
    "e",
    "pi",
    "euler_e",
    "coeff",
    "der",
    "abs",
    "Rational",
    "main",
    "_",
    "_x",
    "x_",
    "__",
    "mass_matrix",
    "collide",
];

/// Mostly ordinary names (`first` gives their first character), one in
/// six from [`TRICKY`].
fn name(first: &'static str) -> impl Strategy<Value = String> {
    prop_oneof![
        1 => (0..TRICKY.len()).prop_map(|i| TRICKY[i].to_string()),
        5 => proptest::string::string_regex(&format!("{first}[a-z0-9]{{0,3}}(_[a-z0-9]{{1,2}})?"))
            .unwrap(),
    ]
}

/// A small model file with the given names (duplicates and bad names are
/// the validator's to refuse).
fn model(
    model: &str,
    params: &[String],
    coords: &[String],
    walls: &[String],
    definition: &str,
) -> String {
    let params_toml: String = params.iter().map(|p| format!("{p} = \"2\"\n")).collect();
    let mass = params.first().cloned().unwrap_or_else(|| "1".into());
    let t: Vec<String> = coords
        .iter()
        .map(|c| format!("{mass}*{c}_dot^2/2"))
        .collect();
    let coord_list: Vec<String> = coords.iter().map(|c| format!("\"{c}\"")).collect();
    let walls_toml: String = walls
        .iter()
        .map(|w| {
            format!(
                "[[wall]]\nname = \"{w}\"\nsurface = \"{} + {definition}\"\n",
                coords[0]
            )
        })
        .collect();
    format!(
        "[model]\nname = \"{model}\"\n[parameters]\n{params_toml}[definitions]\n{definition} = \"3\"\n[coordinates]\nnames = [{}]\n[dynamics]\nkinetic_energy = \"{}\"\npotential = \"{mass}*{}\"\n{walls_toml}",
        coord_list.join(", "),
        t.join(" + "),
        coords[0],
    )
}

#[test]
fn every_generated_file_compiles() {
    let dir = PathBuf::from(env!("CARGO_TARGET_TMPDIR")).join("generated-names");
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    let mut runner = TestRunner::new(Config {
        cases: 400,
        failure_persistence: None,
        ..Config::default()
    });
    let strategy = (
        name("[a-z]"),
        proptest::collection::vec(name("[a-zA-Z]"), 1..3),
        proptest::collection::vec(name("[a-zA-Z]"), 1..3),
        proptest::collection::vec(name("[a-z]"), 1..3),
        name("[a-zA-Z]"),
    );
    let generated = std::cell::RefCell::new(Vec::<(String, String)>::new());
    let refused = std::cell::Cell::new(0);
    runner
        .run(&strategy, |(m, params, coords, walls, definition)| {
            let text = model(&m, &params, &coords, &walls, &definition);
            let k = generated.borrow().len() + refused.get();
            let file = dir.join(format!("case{k}.toml"));
            std::fs::write(&file, &text).unwrap();
            match dalembert_codegen::generate(&file) {
                Ok(code) => generated.borrow_mut().push((text, code)),
                Err(_) => refused.set(refused.get() + 1),
            }
            Ok(())
        })
        .unwrap();
    let generated = generated.into_inner();
    assert!(
        generated.len() >= 30 && refused.get() >= 30,
        "{} generated, {} refused: the names should give both",
        generated.len(),
        refused.get()
    );
    // One crate, a module per generated file.
    let mut lib = String::from("#![allow(dead_code)]\n");
    for (k, (_, code)) in generated.iter().enumerate() {
        std::fs::write(dir.join(format!("m{k}.rs")), code).unwrap();
        lib.push_str(&format!("#[path = \"m{k}.rs\"]\npub mod m{k};\n"));
    }
    std::fs::write(dir.join("lib.rs"), lib).unwrap();
    let out = compile(&dir, "generated_names");
    let stderr = String::from_utf8_lossy(&out.stderr);
    if !out.status.success() {
        // Name the first model file whose module has an error.
        let first = (0..generated.len())
            .find(|k| stderr.contains(&format!("m{k}.rs")))
            .map(|k| generated[k].0.clone())
            .unwrap_or_default();
        panic!("a generated file does not compile:\n{first}\n\n{stderr}");
    }
}

/// rustc on `dir/lib.rs` as a library crate against the runtime.
fn compile(dir: &Path, crate_name: &str) -> std::process::Output {
    common::rustc(
        dir,
        "lib.rs",
        &["--crate-type", "lib", "--crate-name", crate_name],
    )
}

/// Text from the model file reaches generated code only as inert comment
/// text: a file name with line breaks and code in it, and docs with CR,
/// `*/`, control characters, a line separator and bidirectional overrides
/// and isolates (which rustc denies in comments), generate a file that
/// compiles and defines nothing of theirs.
#[test]
fn text_from_the_model_file_stays_inert() {
    let dir = PathBuf::from(env!("CARGO_TARGET_TMPDIR")).join("generated-text");
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    let hostile =
        r#"a\rb */ c /* d \u0007 e \u2028 f \u202E g \u2066 h \u2069 \r\npub fn injected_doc() {}"#;
    let text = format!(
        r#"[model]
name = "inert"
doc = "{hostile}"

[parameters]
m = {{ value = "1", doc = "{hostile}" }}

[coordinates]
names = ["x"]

[dynamics]
kinetic_energy = "m/2*x_dot^2"

[[wall]]
name = "wall"
doc = "{hostile}"
surface = "x"
"#
    );
    let file = dir.join("inj\r\npub fn injected() {}\n\u{202e}.toml");
    std::fs::write(&file, text).unwrap();
    let code = dalembert_codegen::generate(&file).unwrap();
    for line in code.lines() {
        let code_part = line.trim_start();
        assert!(
            !code_part.starts_with("pub fn injected"),
            "a line of the model file's became code:\n{code}"
        );
        assert!(
            !line.contains('\r') && !line.contains('\u{202e}'),
            "{line:?}"
        );
    }
    std::fs::write(dir.join("m.rs"), &code).unwrap();
    std::fs::write(
        dir.join("lib.rs"),
        "#![allow(dead_code)]\n#[path = \"m.rs\"]\npub mod m;\n",
    )
    .unwrap();
    let out = compile(&dir, "generated_text");
    assert!(
        out.status.success(),
        "{}\n\n{code}",
        String::from_utf8_lossy(&out.stderr)
    );
}

//! `dalembert check`: the misprint rule is exactly the paper's pattern.
//! Uses the symbolic engine: run one test at a time (`RUST_TEST_THREADS=1`).

use std::path::PathBuf;
use std::process::Command;

/// `dalembert check MODEL REFERENCE-TEXT` for a built-in model: exit code
/// and output.
fn check(model: &str, name: &str, reference: &str) -> (Option<i32>, String) {
    let root = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("..");
    check_file(
        &root.join("models").join(format!("{model}.toml")),
        name,
        reference,
    )
}

/// The scratch directory of these tests.
fn scratch() -> PathBuf {
    let dir = PathBuf::from(env!("CARGO_TARGET_TMPDIR")).join("check");
    std::fs::create_dir_all(&dir).unwrap();
    dir
}

/// `dalembert check MODEL-FILE REFERENCE-TEXT`: exit code and output.
fn check_file(model: &std::path::Path, name: &str, reference: &str) -> (Option<i32>, String) {
    let file = scratch().join(format!("{name}.toml"));
    std::fs::write(&file, reference).unwrap();
    let out = Command::new(env!("CARGO_BIN_EXE_dalembert"))
        .arg("check")
        .arg(model)
        .arg(&file)
        .output()
        .expect("the CLI runs");
    let stdout = String::from_utf8_lossy(&out.stdout).into_owned();
    let stderr = String::from_utf8_lossy(&out.stderr);
    (out.status.code(), format!("{stdout}\n{stderr}"))
}

/// The pendulum at the wall has P = I. Printed as the identity inside a
/// prefactor of 0 (so that every diagonal entry differs), or of 1/2, it
/// disagrees: a prefactor of 0 explains nothing, and a misprint is one
/// entry of a matrix the prefactor otherwise makes right, not every
/// diagonal "1". Printed as 2·I inside 1/2 it agrees exactly.
#[test]
fn a_prefactor_is_no_free_pass() {
    let reference = |prefactor: &str, diagonal: &str| {
        format!(
            "model = \"pendulum_wall\"\nwall = \"wall\"\nsource = \"a test\"\nprefactor = \"{prefactor}\"\nprojector = [[\"{diagonal}\", \"0\"], [\"0\", \"{diagonal}\"]]\n"
        )
    };
    let (code, out) = check("pendulum_wall", "zero", &reference("0", "1"));
    assert_eq!(code, Some(1), "{out}");
    assert!(
        out.contains("DISAGREES") && !out.contains("misprint"),
        "{out}"
    );
    let (code, out) = check("pendulum_wall", "half", &reference("1/2", "1"));
    assert_eq!(code, Some(1), "{out}");
    assert!(
        out.contains("DISAGREES") && !out.contains("misprint"),
        "{out}"
    );
    let (code, out) = check("pendulum_wall", "one", &reference("1", "1"));
    assert_eq!(code, Some(0), "{out}");
    assert!(
        out.contains("verdict: agrees with the reference\n"),
        "{out}"
    );
    let (code, out) = check("pendulum_wall", "two", &reference("1/2", "2"));
    assert_eq!(code, Some(0), "{out}");
    // The paper's own pattern still counts: §3.2's (3,3) entry.
    let paper = std::fs::read_to_string(
        PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../models/reference/ball_floor.toml"),
    )
    .unwrap();
    let (code, out) = check("ball_floor", "paper", &paper);
    assert_eq!(code, Some(0), "{out}");
    assert!(out.contains("except 1 misprinted diagonal entry"), "{out}");
}

/// A point of unit mass meeting the line cos(a)·x + sin(a)·y = 0: P is the
/// projector onto the normal, entries cos²a, sin a·cos a, sin²a. Written
/// with double angles (as sympy prints them), the entries are shown equal
/// (the reduction writes sin 2a and cos 2a in sin a and cos a). An entry
/// equal only by an identity the reduction does not know (tanh² = 1 −
/// 1/cosh²) is equal at random points, not proven, and agrees; a wrong
/// double-angle entry still disagrees.
#[test]
fn double_angles_are_proven_equal_and_other_identities_tested_at_points() {
    let model = scratch().join("slanted.toml");
    std::fs::write(
        &model,
        r#"[model]
name = "slanted"

[parameters]
a = "1/3"

[coordinates]
names = ["x", "y"]

[dynamics]
kinetic_energy = "(x_dot^2 + y_dot^2)/2"

[[wall]]
name = "line"
surface = "cos(a)*x + sin(a)*y"
"#,
    )
    .unwrap();
    let reference = |entry: &str| {
        format!(
            "model = \"slanted\"\nwall = \"line\"\nsource = \"a test\"\nprojector = [[\"(1 + cos(2*a))/2\", \"{entry}\"], [\"sin(a)*cos(a)\", \"sin(a)^2\"]]\n"
        )
    };
    let (code, out) = check_file(&model, "double", &reference("sin(2*a)/2"));
    assert_eq!(code, Some(0), "{out}");
    assert!(
        !out.contains("not proven") && out.contains("verdict: agrees with the reference"),
        "{out}"
    );
    let tanh = "sin(a)*cos(a)*cosh(a)^2*(1 - tanh(a)^2)";
    let (code, out) = check_file(&model, "tanh", &reference(tanh));
    assert_eq!(code, Some(0), "{out}");
    assert!(
        out.contains("entry (1,2): equal at 32 random points, not proven")
            && out.contains("verdict: agrees with the reference (1 entry equal only at random points, not proven)"),
        "{out}"
    );
    let (code, out) = check_file(&model, "wrong", &reference("sin(2*a)"));
    assert_eq!(code, Some(1), "{out}");
    assert!(
        out.contains("entry (1,2) DIFFERS (")
            && out.contains("wrong.toml:4:35): reference")
            && out.contains("DISAGREES"),
        "{out}"
    );
}

/// Mistakes in a reference are reported at their place in its file, as a
/// model file's are: an entry that does not parse, one that is undefined
/// as written, a row of the wrong length, and a file that is not TOML.
/// Before, they named only "P entry (2, 2)", or nothing.
#[test]
fn reference_mistakes_are_located() {
    let head = "model = \"pendulum_wall\"\nwall = \"wall\"\nsource = \"a test\"\n";
    let cases = [
        (
            "unclosed",
            "projector = [\n  [\"1\", \"0\"],\n  [\"0\", \"(1\"],\n]\n",
            "unclosed.toml:6:9: the reference's P entry (2, 2), `(1`",
        ),
        (
            "zero_power",
            "projector = [[\"0^0\", \"0\"], [\"0\", \"1\"]]\n",
            "zero_power.toml:4:15: the reference's P entry (1, 1), `0^0`: `0^0` is 0 to the power 0",
        ),
        (
            "short_row",
            "projector = [\n  [\"1\", \"0\"],\n  [\"0\"],\n]\n",
            "short_row.toml:6:4: the reference P must be 2×2: its row 2 has 1 entries",
        ),
        (
            "not_toml",
            "projector = [[\"1\", \"0\"], [\"0\", \"1\"]\n",
            "not_toml.toml:5:1:",
        ),
    ];
    for (name, body, expected) in cases {
        let (code, out) = check("pendulum_wall", name, &format!("{head}{body}"));
        assert_eq!(code, Some(2), "{name}: {out}");
        assert!(out.contains(expected), "{name}: {out}");
    }
}

/// A reference entry that is undefined as written (0^0, which once
/// panicked the comparison) is refused with its place, not compared.
#[test]
fn undefined_reference_entries_are_refused() {
    let reference = "model = \"pendulum_wall\"\nwall = \"wall\"\nsource = \"a test\"\nprojector = [[\"0^0\", \"0\"], [\"0\", \"1\"]]\n";
    let (code, out) = check("pendulum_wall", "zero_to_zero", reference);
    assert_eq!(code, Some(2), "{out}");
    assert!(
        out.contains("`0^0` is 0 to the power 0, which is undefined"),
        "{out}"
    );
}

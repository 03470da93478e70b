//! `dalembert generate` and `derive` write only their own text to standard
//! output, so that a redirected output is Rust code or a derivation. Uses
//! the symbolic engine: run one test at a time (`RUST_TEST_THREADS=1`).

use std::path::PathBuf;
use std::process::Command;

/// `dalembert ARGS…` on the pendulum at the wall: standard output and
/// standard error.
fn dalembert(command: &str) -> (String, String) {
    let model = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../models/pendulum_wall.toml");
    let out = Command::new(env!("CARGO_BIN_EXE_dalembert"))
        .arg(command)
        .arg(model)
        .output()
        .expect("the CLI runs");
    assert!(out.status.success(), "{out:?}");
    (
        String::from_utf8(out.stdout).unwrap(),
        String::from_utf8_lossy(&out.stderr).into_owned(),
    )
}

/// symbolica shows a licence notice on its first use; it once went to
/// standard output, ahead of the code, so that `generate FILE > model.rs`
/// wrote a file that does not compile.
#[test]
fn generated_code_alone_reaches_standard_output() {
    let (code, _) = dalembert("generate");
    assert!(code.starts_with("// @generated"), "{}", &code[..200]);
    syn::parse_file(&code).expect("standard output is one Rust file");
    let (derivation, _) = dalembert("derive");
    assert!(
        derivation.starts_with("model `pendulum_wall`"),
        "{}",
        &derivation[..200]
    );
}

/// A model file whose T couples every velocity with every other through
/// the coordinates: T = ½m|q̇|² + ½k(Σ cos qᵢ q̇ᵢ)², n coordinates.
fn dense(n: usize) -> String {
    let q: Vec<String> = (0..n).map(|i| format!("q{i}")).collect();
    let squares: Vec<String> = q.iter().map(|q| format!("{q}_dot^2")).collect();
    let coupled: Vec<String> = q.iter().map(|q| format!("cos({q})*{q}_dot")).collect();
    let potential: Vec<String> = q.iter().map(|q| format!("{q}^2")).collect();
    format!(
        "[model]\nname = \"dense\"\n\n[parameters]\nm = {{ value = \"1\" }}\nk = {{ value = \"1/2\" }}\n\n\
         [coordinates]\nnames = [{}]\n\n[dynamics]\nkinetic_energy = \"m/2*({}) + k/2*({})^2\"\npotential = \"{}\"\n\n\
         [[wall]]\nname = \"floor\"\nsurface = \"q0 + 1\"\n",
        q.iter()
            .map(|q| format!("\"{q}\""))
            .collect::<Vec<_>>()
            .join(", "),
        squares.join(" + "),
        coupled.join(" + "),
        potential.join(" + "),
    )
}

/// Generated code has a bounded size: a dense model of 50 coordinates
/// (about 66 000 instructions, its q̈ and collision map each an
/// elimination over a full G) is refused at its kinetic energy, naming the
/// bound. Before, 60 such coordinates wrote 7.1 MB of Rust that a debug
/// build took 214 s and 1.7 GB to compile.
#[test]
fn generated_code_has_a_bounded_size() {
    let dir = PathBuf::from(env!("CARGO_TARGET_TMPDIR")).join("generate");
    std::fs::create_dir_all(&dir).unwrap();
    let file = dir.join("dense_50.toml");
    std::fs::write(&file, dense(50)).unwrap();
    let out = Command::new(env!("CARGO_BIN_EXE_dalembert"))
        .arg("generate")
        .arg(&file)
        .output()
        .expect("the CLI runs");
    let stdout = String::from_utf8_lossy(&out.stdout);
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(2), "{stdout}\n{stderr}");
    assert!(stdout.is_empty(), "{}", &stdout[..stdout.len().min(200)]);
    // The message as one line (miette wraps it to the terminal's width).
    let stderr = stderr.split_whitespace().collect::<Vec<_>>().join(" ");
    assert!(
        stderr.contains("dense_50.toml:12:18: too large")
            && stderr.contains("more than the 60000 a model's generated Rust may have")
            && stderr.contains("the largest function, `accelerations`"),
        "{stderr}"
    );
}

/// The code `generate` writes for `dense(n)`, which must succeed.
fn generated_dense(n: usize) -> String {
    let dir = PathBuf::from(env!("CARGO_TARGET_TMPDIR")).join("generate");
    std::fs::create_dir_all(&dir).unwrap();
    let file = dir.join(format!("dense_{n}.toml"));
    std::fs::write(&file, dense(n)).unwrap();
    let out = Command::new(env!("CARGO_BIN_EXE_dalembert"))
        .arg("generate")
        .arg(&file)
        .output()
        .expect("the CLI runs");
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    String::from_utf8_lossy(&out.stdout).into_owned()
}

/// A dense model of 30 coordinates is within the bound, but not with its
/// tangents (about three times q̈'s and the map's code): it generates
/// without them, and its header says so.
#[test]
fn tangents_past_the_bound_are_left_out() {
    let code = generated_dense(30);
    assert!(
        code.contains("//   tangents                     left out: they would add "),
        "{}",
        &code[..code.len().min(2000)]
    );
    assert!(code.contains("pub fn accelerations("));
    assert!(!code.contains("accelerations_tangent"));
}

/// A dense model of 24 coordinates has room for its tangents along the
/// phase but not for those by the parameters as well: it keeps the first
/// and its header says the second were left out. (With both counted as
/// one, it lost both.)
#[test]
fn tangents_by_the_parameters_past_the_bound_are_left_out_alone() {
    let code = generated_dense(24);
    let header = &code[..code.len().min(3000)];
    assert!(
        code.contains("//   tangents by the parameters   left out: they would add "),
        "{header}"
    );
    assert!(
        !code.contains("//   tangents                     left out"),
        "{header}"
    );
    assert!(code.contains("pub fn accelerations_tangent("));
    assert!(code.contains("pub fn floor_collide_tangent("));
    for f in [
        "accelerations_parameter_tangent(",
        "floor_collide_parameter_tangent(",
        "floor_surface_parameter_tangent(",
    ] {
        assert!(!code.contains(&format!("pub fn {f}")), "{f}");
    }
}

/// `derive` of a model written with bodies shows what the bodies layer
/// derived, each with the line of its declaration, before G: the
/// coordinates too, which this file leaves to the body.
#[test]
fn derive_shows_what_the_bodies_derive() {
    let model =
        PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../tests/bodies/ball_wall_euler.toml");
    let out = Command::new(env!("CARGO_BIN_EXE_dalembert"))
        .arg("derive")
        .arg(model)
        .output()
        .expect("the CLI runs");
    assert!(out.status.success(), "{out:?}");
    let text = String::from_utf8(out.stdout).unwrap();
    let shown = text.find("derived from the bodies").expect(&text);
    assert!(shown < text.find("G =").unwrap(), "{text}");
    for line in [
        "  coordinates = x, y, phi, theta, psi   (line 14)",
        "  ball_wy = theta_dot*sin(phi) - psi_dot*cos(phi)*sin(theta)   (line 15)",
        "  T = J*(ball_wx^2 + ball_wy^2 + ball_wz^2)/2   (line 14)",
        "  V = m*(a*x + g*r)   (line 14)",
        "  row of A = x_dot - ball_wy*r   (line 25)",
        "  wall `wall` surface = x - r   (line 28)",
        "  wall `wall` contact row = y_dot - ball_wz*r   (line 28)",
    ] {
        assert!(
            text.lines().any(|l| l == line),
            "no line `{line}` in\n{text}"
        );
    }
}

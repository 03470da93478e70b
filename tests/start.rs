//! The start's velocity from what a user gives (`simulate::starting_velocity`):
//! velocities, and rates that are definitions linear in them, met together
//! with the constraints; what happens when they cannot all hold. Bodies
//! started by their angular velocity are in `tests/bodies_motion.rs`.
//!
//! Uses the symbolic engine: run one test at a time (`RUST_TEST_THREADS=1`).

use dalembert::runtime::linalg::ProjectorError;
use dalembert::runtime::prelude::*;
use dalembert::runtime::simulate::{StartRule, starting_velocity, starting_velocity_with};
use dalembert_codegen::interpret::Interpreted;

/// A point in the plane held on the diagonal direction (ẋ = ẏ), with two
/// rates: `along = x_dot + y_dot` and `across = x_dot - y_dot`, which is
/// the constraint's own row.
const DIAGONAL: &str = r#"
[model]
name = "diagonal"
[coordinates]
names = ["x", "y"]
[definitions]
along = "x_dot + y_dot"
across = "x_dot - y_dot"
[dynamics]
kinetic_energy = "(x_dot^2 + y_dot^2)/2"
constraints = ["x_dot - y_dot"]
[initial]
along = 2
across = 0
"#;

fn diagonal() -> Interpreted<2> {
    // One file per call: tests may run side by side.
    static CALLS: std::sync::atomic::AtomicUsize = std::sync::atomic::AtomicUsize::new(0);
    let k = CALLS.fetch_add(1, std::sync::atomic::Ordering::Relaxed);
    let file = std::env::temp_dir().join(format!(
        "dalembert_diagonal_{}_{k}.toml",
        std::process::id()
    ));
    std::fs::write(&file, DIAGONAL).unwrap();
    let d = dalembert_codegen::derive(&file).unwrap_or_else(|e| panic!("{e}"));
    std::fs::remove_file(&file).unwrap();
    Interpreted::new(&d).unwrap()
}

/// The rates alone fix the velocity: ẋ + ẏ = 2 on ẋ = ẏ is (1, 1); the
/// second rate repeats the constraint with a value it allows.
#[test]
fn rates_and_constraints_together_fix_the_velocity() {
    let m = diagonal();
    assert_eq!(m.start_rate_names(), ["along", "across"]);
    assert_eq!(m.start_values().as_slice(), [2.0, 0.0]);
    let q = [0.0; 2];
    let (v, rule) = starting_velocity(&m, &q, &[0.0; 2], &[false; 2]).unwrap();
    assert_eq!(rule, StartRule::Completed);
    assert!(
        (v[0] - 1.0).abs() < 1e-15 && (v[1] - 1.0).abs() < 1e-15,
        "{v:?}"
    );
}

/// A velocity given against the constraint and the rates: ẋ = 3 cannot be
/// completed, so the velocity nearest (3, 0) in the metric of G with
/// ẋ = ẏ and ẋ + ẏ = 2 is taken, (1, 1), the rates kept.
#[test]
fn a_velocity_that_conflicts_gives_way_to_the_rates() {
    let m = diagonal();
    let (v, rule) =
        starting_velocity_with(&m, &[0.0; 2], &[3.0, 0.0], &[true, false], &[2.0, 0.0]).unwrap();
    assert_eq!(rule, StartRule::Projected);
    assert!(
        (v[0] - 1.0).abs() < 1e-15 && (v[1] - 1.0).abs() < 1e-15,
        "{v:?}"
    );
}

/// Rates that no admissible velocity has are an error, not a start that
/// quietly drops one: `across = 1` contradicts ẋ = ẏ.
#[test]
fn rates_against_the_constraints_are_refused() {
    let m = diagonal();
    let got = starting_velocity_with(&m, &[0.0; 2], &[0.0; 2], &[false; 2], &[2.0, 1.0]);
    assert_eq!(got, Err(ProjectorError::Inconsistent));
}

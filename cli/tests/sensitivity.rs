//! `dalembert simulate --sensitivity`: the growth of a perturbation of the
//! start, from Φ followed through the run. In a free flight Φ(t) =
//! [[I, tI], [0, I]], so the perturbation (1, 1, 1, 1) grows by
//! √(((1 + t)² + 1)/2); through collisions the figure is finite and the run
//! otherwise unchanged.

use std::path::PathBuf;
mod common;
use common::dalembert;

/// The growth |Φ δx₀|/|δx₀| the summary reports.
fn growth(stdout: &str) -> f64 {
    let line = stdout
        .lines()
        .find(|l| l.contains("sensitivity: |Φ δx₀|/|δx₀| = "))
        .unwrap_or_else(|| panic!("no sensitivity line in:\n{stdout}"));
    let value = line.split(" = ").nth(1).unwrap().split(' ').next().unwrap();
    value.parse().unwrap()
}

fn out_dir(name: &str) -> String {
    let dir = PathBuf::from(env!("CARGO_TARGET_TMPDIR")).join(name);
    dir.to_string_lossy().into_owned()
}

#[test]
fn a_free_flight_grows_as_its_closed_form() {
    let file = concat!(env!("CARGO_MANIFEST_DIR"), "/../tests/walls/disk_sqrt.toml");
    let dir = out_dir("sensitivity_flight");
    for method in ["dormand-prince", "taylor", "rk4"] {
        let args = [
            "simulate",
            file,
            "--t-end",
            "0.2",
            "--sensitivity",
            "--integrator",
            method,
            "--out",
            &dir,
        ];
        let (ok, stdout, _) = dalembert(&args);
        assert!(ok, "{stdout}");
        assert!(stdout.contains("0 collisions"), "{stdout}");
        let expected = ((1.2f64 * 1.2 + 1.0) / 2.0).sqrt();
        let got = growth(&stdout);
        assert!(
            (got - expected).abs() <= 1e-6 * expected,
            "{method}: {got} against {expected}"
        );
    }
}

#[test]
fn through_collisions_the_run_is_the_same_with_and_without() {
    let dir = out_dir("sensitivity_pendulum");
    let args = ["simulate", "pendulum_wall", "--t-end", "10", "--out", &dir];
    let (ok, plain, _) = dalembert(&args);
    assert!(ok, "{plain}");
    let mut with = args.to_vec();
    with.push("--sensitivity");
    let (ok, followed, _) = dalembert(&with);
    assert!(ok, "{followed}");
    let g = growth(&followed);
    assert!(g.is_finite() && g > 1.0, "{followed}");
    let collisions = |s: &str| {
        s.lines()
            .find(|l| l.contains(" collisions,"))
            .map(|l| l.split(" steps").next().unwrap().to_string())
    };
    assert_eq!(collisions(&plain), collisions(&followed));
}

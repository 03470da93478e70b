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

/// A point dropped from height y₀ onto the floor under gravity g:
/// y(t) = v τ − g τ²/2, τ = t − (2m − 1) v/g after m bounces, v = √(2 g y₀).
/// So ∂y/∂y₀ = (τ − (2m − 1)(v − g τ)/g)·g/v and ∂ẏ/∂y₀ = 2m·g/v: at the
/// n-th bounce ∂y/∂y₀ is 2n − 1 just before and −(2n − 1) just after.
/// `--phi` writes both entries on every row (each a step's end), and each
/// method's columns agree with the closed form.
#[test]
fn phi_columns_of_a_bouncing_point_follow_its_closed_form() {
    let dir = out_dir("sensitivity_phi_columns");
    std::fs::create_dir_all(&dir).unwrap();
    let file = PathBuf::from(&dir).join("bounce_1d.toml");
    std::fs::write(
        &file,
        "[model]\nname = \"bounce_1d\"\n[parameters]\ng = { value = \"981/100\" }\n\
         [coordinates]\nnames = [\"y\"]\n[dynamics]\nkinetic_energy = \"y_dot^2/2\"\n\
         potential = \"g*y\"\n[[wall]]\nname = \"floor\"\nsurface = \"y\"\n[initial]\ny = \"1\"\n",
    )
    .unwrap();
    let (g, y0) = (9.81f64, 1.0f64);
    let v = (2.0 * g * y0).sqrt();
    for method in ["dormand-prince", "taylor", "rk4"] {
        let args = [
            "simulate",
            file.to_str().unwrap(),
            "--t-end",
            "3",
            "--integrator",
            method,
            "--phi",
            "y/y, y_dot/y",
            "--out",
            &dir,
        ];
        let (ok, stdout, stderr) = dalembert(&args);
        assert!(ok, "{stdout}{stderr}");
        let csv = std::fs::read_to_string(PathBuf::from(&dir).join("bounce_1d.csv")).unwrap();
        let mut lines = csv.lines();
        assert_eq!(
            lines.next().unwrap(),
            "t,y,y_dot,energy,residual_velocity,residual_position,collision,dy/dy(0),dy_dot/dy(0)"
        );
        let (mut bounces, mut rows) = (0, 0);
        for line in lines {
            let cells: Vec<&str> = line.split(',').collect();
            let at = |k: usize| cells[k].parse::<f64>().unwrap();
            let (t, dy, dv) = (at(0), at(7), at(8));
            // A bounce's first row is before it, the next after it.
            let before = cells[6] == "floor";
            let m = f64::from(bounces);
            let (want_dy, want_dv) = if before {
                (2.0 * m + 1.0, 2.0 * m * g / v)
            } else {
                let tau = t - (2.0 * m - 1.0) * v / g;
                let dy = (tau - (2.0 * m - 1.0) * (v - g * tau) / g) * g / v;
                (dy, 2.0 * m * g / v)
            };
            // RK4's fixed steps carry 1e-11 here; the bound has room.
            assert!(
                (dy - want_dy).abs() <= 1e-7 * want_dy.abs().max(1.0)
                    && (dv - want_dv).abs() <= 1e-7 * want_dv.abs().max(1.0),
                "{method}, t = {t} after {bounces} bounces (before one: {before}): ({dy}, {dv}) against ({want_dy}, {want_dv})"
            );
            bounces += u32::from(before);
            rows += 1;
        }
        assert_eq!(bounces, 3, "{method}");
        assert!(rows > 2000, "{method}: {rows} rows");
    }
}

#[test]
fn phi_entries_are_named_as_the_model_names_its_state() {
    let dir = out_dir("sensitivity_phi_names");
    let run = |phi: &str| {
        let args = [
            "simulate",
            "pendulum_wall",
            "--t-end",
            "0.1",
            "--phi",
            phi,
            "--out",
            &dir,
        ];
        dalembert(&args)
    };
    let (ok, stdout, stderr) = run("x/z");
    assert!(!ok, "{stdout}");
    assert!(
        stderr
            .contains("`z` is not a coordinate or velocity of pendulum_wall (x, y, x_dot, y_dot)"),
        "{stderr}"
    );
    let (ok, stdout, stderr) = run("all");
    assert!(ok, "{stdout}{stderr}");
    let csv = std::fs::read_to_string(PathBuf::from(&dir).join("pendulum_wall.csv")).unwrap();
    let header = csv.lines().next().unwrap();
    assert!(
        header.ends_with(",dy_dot/dx(0),dy_dot/dy(0),dy_dot/dx_dot(0),dy_dot/dy_dot(0)"),
        "{header}"
    );
    // Φ(0) = I.
    let first: Vec<f64> = csv
        .lines()
        .nth(1)
        .unwrap()
        .split(',')
        .skip(9)
        .map(|c| c.parse().unwrap())
        .collect();
    let identity: Vec<f64> = (0..16)
        .map(|k| f64::from(u8::from(k / 4 == k % 4)))
        .collect();
    assert_eq!(first, identity);
}

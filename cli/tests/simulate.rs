//! `dalembert simulate` end to end: files written, collisions recorded,
//! parameters overridable, clear refusals (the starting state is in
//! `start.rs`).

use std::path::PathBuf;
mod common;
use common::{dalembert, scratch};

#[test]
fn writes_the_trajectory_and_the_plot() {
    let dir = scratch("simulate-pendulum");
    let out = dir.to_str().unwrap();
    let (ok, stdout, stderr) =
        dalembert(&["simulate", "pendulum_wall", "--t-end", "3", "--out", out]);
    assert!(ok, "{stdout}\n{stderr}");
    assert!(stdout.contains("collisions"), "{stdout}");
    // The output's bound is said before the run.
    assert!(
        stdout.starts_with("pendulum_wall: writing ")
            && stdout.contains("a row every 0.0015 to t = 3 (2001 rows) and two per collision, at most 10000000 rows"),
        "{stdout}"
    );
    let csv = std::fs::read_to_string(dir.join("pendulum_wall.csv")).unwrap();
    let mut lines = csv.lines();
    assert_eq!(
        lines.next().unwrap(),
        "t,x,y,x_dot,y_dot,energy,residual_velocity,residual_position,collision"
    );
    let rows: Vec<Vec<&str>> = lines.map(|l| l.split(',').collect()).collect();
    assert!(rows.len() > 2000);
    // Every row on the rod's circle; the bob bounces off the wall x = 1/2.
    for r in &rows {
        let (x, y): (f64, f64) = (r[1].parse().unwrap(), r[2].parse().unwrap());
        assert!((x * x + y * y - 1.0).abs() < 1e-12);
        assert!(x <= 0.5 + 1e-12);
    }
    let hits: Vec<_> = rows.iter().filter(|r| r[8] == "wall").collect();
    assert!(!hits.is_empty());
    for h in hits {
        assert!((h[1].parse::<f64>().unwrap() - 0.5).abs() < 1e-12);
    }
    let svg = std::fs::read_to_string(dir.join("pendulum_wall.svg")).unwrap();
    assert!(svg.starts_with("<svg") && svg.contains("energy drift") && svg.contains("<circle"));
}

/// t, coordinates and velocities of the CSV's last row.
fn last_row(csv: &std::path::Path) -> Vec<f64> {
    let text = std::fs::read_to_string(csv).unwrap();
    let last = text.lines().last().unwrap();
    last.split(',')
        .take(5)
        .map(|x| x.parse().unwrap())
        .collect()
}

#[test]
fn parameters_and_initial_values_can_be_set() {
    let dir = scratch("simulate-masses");
    let out = dir.to_str().unwrap();
    // Equal masses exchange velocities.
    let (ok, stdout, stderr) = dalembert(&[
        "simulate",
        "masses_on_line",
        "--t-end",
        "0.3",
        "--set",
        "m2=1",
        "--set",
        "x2_dot=0",
        "--integrator",
        "rk4",
        "--step",
        "0.01",
        "--out",
        out,
    ]);
    assert!(ok, "{stdout}\n{stderr}");
    let last = last_row(&dir.join("masses_on_line.csv"));
    // x1 = 1/5 moving at 1 meets x2 = 3/5 (at rest) at t = 0.4: at t = 0.3
    // both are still in free flight.
    assert!((last[1] - 0.5).abs() < 1e-12 && (last[2] - 0.6).abs() < 1e-12);
    let (ok, stdout, _) = dalembert(&[
        "simulate",
        "masses_on_line",
        "--t-end",
        "0.5",
        "--set",
        "m2=1",
        "--set",
        "x2_dot=0",
        "--out",
        out,
    ]);
    assert!(ok);
    assert!(stdout.contains(" 1 collisions"), "{stdout}");
    // After the impact at t = 0.4 the velocities are exchanged.
    let last = last_row(&dir.join("masses_on_line.csv"));
    assert!(
        last[3].abs() < 1e-12 && (last[4] - 1.0).abs() < 1e-12,
        "{last:?}"
    );
}

#[test]
fn refuses_clearly() {
    let (ok, _, stderr) = dalembert(&["simulate", "ball_wall"]);
    assert!(!ok && stderr.contains("instantaneous model"), "{stderr}");
    let (ok, _, stderr) = dalembert(&["simulate", "no_such_model"]);
    assert!(
        !ok && stderr.contains("ball_bounce") && stderr.contains("pendulum_wall"),
        "{stderr}"
    );
    let (ok, _, stderr) = dalembert(&["simulate", "puck", "--set", "mass=2"]);
    assert!(
        !ok && stderr.contains("`mass` is not a parameter"),
        "{stderr}"
    );
    let (ok, _, stderr) = dalembert(&["simulate", "pendulum_wall", "--set", "x=0.9"]);
    assert!(!ok && stderr.contains("holonomic"), "{stderr}");
    // A singular G where the start is projected onto ker A: said in words,
    // not as the error's Rust name.
    let (ok, _, stderr) = dalembert(&["simulate", "ball_wall_quaternion", "--set", "J=0"]);
    assert!(
        !ok && stderr.contains("G(q) is not positive definite") && !stderr.contains("Definite"),
        "{stderr}"
    );
}

/// A setting out of range is named with its value as given: a negative
/// number is read as the flag's value (not as an unknown flag), and a
/// value far from 1 is written in exponent form.
#[test]
fn settings_out_of_range_are_named() {
    for (flag, value) in [("--t-end", "-1"), ("--atol", "-1e-12"), ("--every", "-0.5")] {
        let (ok, _, stderr) = dalembert(&["simulate", "puck", flag, value]);
        assert!(
            !ok && stderr.contains(&format!("{flag} must be a positive finite number (got -")),
            "{flag} {value}: {stderr}"
        );
    }
    let (ok, _, stderr) = dalembert(&["simulate", "puck", "--t-end", "0.01", "--every", "1e-300"]);
    assert!(
        !ok && stderr.contains("--every 1e-300 would write 1.0e298 rows") && stderr.len() < 200,
        "{stderr}"
    );
}

/// A model file of a user's, never compiled: a puck on a round table (its
/// rim `sqrt`, its radius a derived parameter) cut by a slanted edge (`tan`
/// of an angle given with `pi`).
const TABLE: &str = r#"
[model]
name = "table"
doc = "A puck on a round table of radius R cut by the edge y = 1 + x tan(alpha)."

[parameters]
m = "1"
a = "1"
R = { value = "2*a", doc = "the table's radius, derived from a" }
alpha = "pi/6"

[coordinates]
names = ["x", "y"]

[dynamics]
kinetic_energy = "m/2*(x_dot^2 + y_dot^2)"

[[wall]]
name = "rim"
surface = "R - sqrt(x^2 + y^2)"

[[wall]]
name = "edge"
surface = "1 + tan(alpha)*x - y"

[initial]
x = "-R/2"
y = "-a/2"
x_dot = "pi/4"
y_dot = "-1/3"
"#;

/// Every row of the table's CSV as numbers (the collision column as text).
fn table_rows(csv: &std::path::Path) -> Vec<(Vec<f64>, String)> {
    let text = std::fs::read_to_string(csv).unwrap();
    let mut lines = text.lines();
    assert_eq!(
        lines.next().unwrap(),
        "t,x,y,x_dot,y_dot,energy,residual_velocity,residual_position,collision"
    );
    lines
        .map(|l| {
            let cells: Vec<&str> = l.split(',').collect();
            let numbers = cells[..8].iter().map(|x| x.parse().unwrap()).collect();
            (numbers, cells[8].to_string())
        })
        .collect()
}

#[test]
fn a_model_file_simulates_without_writing_rust() {
    let dir = scratch("simulate-table");
    std::fs::create_dir_all(&dir).unwrap();
    let file = dir.join("table.toml");
    std::fs::write(&file, TABLE).unwrap();
    let (file, out) = (file.to_str().unwrap(), dir.to_str().unwrap());
    let (ok, stdout, stderr) = dalembert(&["simulate", file, "--t-end", "20", "--out", out]);
    assert!(ok, "{stdout}\n{stderr}");
    let rows = table_rows(&dir.join("table.csv"));
    let tan = (std::f64::consts::PI / 6.0).tan();
    let speed2 = (std::f64::consts::PI / 4.0).powi(2) + 1.0 / 9.0;
    let (mut rim, mut edge) = (0, 0);
    for (r, hit) in &rows {
        let (x, y) = (r[1], r[2]);
        assert!(x.hypot(y) <= 2.0 + 1e-9, "off the table: {r:?}");
        assert!(y <= 1.0 + tan * x + 1e-9, "across the edge: {r:?}");
        assert!(
            (r[3] * r[3] + r[4] * r[4] - speed2).abs() < 1e-9,
            "speed changed: {r:?}"
        );
        match hit.as_str() {
            "rim" => {
                rim += 1;
                assert!((x.hypot(y) - 2.0).abs() < 1e-9);
            }
            "edge" => {
                edge += 1;
                assert!((1.0 + tan * x - y).abs() < 1e-9);
            }
            _ => {}
        }
    }
    assert!(rim > 0 && edge > 0, "rim {rim}, edge {edge}");
    assert_eq!(rows[0].0[1..3], [-1.0, -0.5], "the start (-R/2, -a/2)");
    // The derived radius follows its parameter: with a = 3/2 the rim is at
    // 3, and the start, written with R and a, follows too.
    let (ok, stdout, stderr) = dalembert(&[
        "simulate", file, "--t-end", "20", "--set", "a=1.5", "--out", out,
    ]);
    assert!(ok, "{stdout}\n{stderr}");
    let rows = table_rows(&dir.join("table.csv"));
    assert_eq!(rows[0].0[1..3], [-1.5, -0.75], "the start (-R/2, -a/2)");
    let rim: Vec<_> = rows.iter().filter(|(_, hit)| hit == "rim").collect();
    assert!(!rim.is_empty());
    for (r, _) in rim {
        assert!((r[1].hypot(r[2]) - 3.0).abs() < 1e-9, "{r:?}");
    }
    // A derived parameter is not set directly.
    let (ok, _, stderr) = dalembert(&["simulate", file, "--set", "R=5", "--out", out]);
    assert!(!ok && stderr.contains("derived parameter"), "{stderr}");
}

/// The rows of a CSV at the times k·`every` (collisions left out), by k:
/// their coordinates and velocities.
type Grid = std::collections::BTreeMap<u64, Vec<f64>>;

fn grid_rows(csv: &str, every: f64) -> Grid {
    let mut grid = Grid::new();
    for line in csv.lines().skip(1).filter(|l| l.ends_with(',')) {
        let x: Vec<f64> = line
            .split(',')
            .take_while(|c| !c.is_empty())
            .map(|c| c.parse().unwrap())
            .collect();
        let k = (x[0] / every).round();
        if x[0] == k * every || x[0] == 3.0 {
            grid.insert(k as u64, x[1..].to_vec());
        }
    }
    grid
}

/// `--integrator taylor` runs a built-in model and a model file (through
/// the interpreter's series) to the same collisions as the default method,
/// at the order picked from the model's series work and at a fixed one, and
/// names the order in its summary; a tolerance outside (0, 1),
/// an order beyond the series' capacity, or either with another method is
/// refused.
#[test]
fn taylor_integrator_from_the_command_line() {
    for (model, name) in [
        ("ball_bounce", "ball_bounce"),
        ("models/pendulum_wall.toml", "pendulum_wall"),
    ] {
        let model = if model.ends_with(".toml") {
            format!("{}/../{model}", env!("CARGO_MANIFEST_DIR"))
        } else {
            model.to_string()
        };
        let (mut collisions, mut rows) = (Vec::new(), Vec::new());
        for (run, method) in [
            ("dormand-prince", &["dormand-prince"][..]),
            ("taylor", &["taylor"]),
            ("taylor-28", &["taylor", "--order", "28"]),
        ] {
            let dir = scratch(&format!("simulate-{name}-{run}"));
            let out = dir.to_str().unwrap();
            let mut args = vec!["simulate", &model, "--t-end", "3", "--out", out];
            args.push("--integrator");
            args.extend(method);
            let (ok, stdout, stderr) = dalembert(&args);
            assert!(ok, "{stdout}\n{stderr}");
            // The summary names Taylor's order: picked from the model's
            // series work (above the tolerance's 20 for these small
            // models, built in or interpreted), or the one fixed.
            let order = stdout.split("at order ").nth(1).map(|rest| {
                let digits: String = rest.chars().take_while(char::is_ascii_digit).collect();
                digits.parse::<usize>().unwrap()
            });
            match run {
                "taylor" => assert!(order.is_some_and(|p| p > 20), "{stdout}"),
                "taylor-28" => assert_eq!(order, Some(28), "{stdout}"),
                _ => assert_eq!(order, None, "{stdout}"),
            }
            // And the mean order of the series computed, at most the full
            // one (the lower-order trials bring it down).
            let mean = stdout.split("mean order ").nth(1).map(|rest| {
                let number: String = rest
                    .chars()
                    .take_while(|c| c.is_ascii_digit() || *c == '.')
                    .collect();
                number.parse::<f64>().unwrap()
            });
            match (order, mean) {
                (Some(p), Some(m)) => assert!(m >= 2.0 && m <= p as f64, "{stdout}"),
                (None, None) => {}
                _ => panic!("{stdout}"),
            }
            let csv = std::fs::read_to_string(dir.join(format!("{name}.csv"))).unwrap();
            let hits = csv.lines().skip(1).filter(|l| !l.ends_with(',')).count();
            collisions.push(hits);
            // Taylor's rows come off each step's polynomial: its steps
            // are not cut at the 2 000 rows (a few per flight, against
            // one per row before; Dormand–Prince's still stop at rows).
            let steps: u64 = stdout
                .split(" steps")
                .next()
                .and_then(|head| head.split_whitespace().last())
                .and_then(|n| n.parse().ok())
                .unwrap();
            assert_eq!(run != "dormand-prince", steps < 200, "{run}: {steps} steps");
            rows.push(grid_rows(&csv, 3.0 / 2000.0));
        }
        assert!(collisions[0] > 0, "{name}: {collisions:?}");
        assert_eq!(collisions[0], collisions[1], "{name}");
        assert_eq!(collisions[0], collisions[2], "{name}");
        // The same grid of rows from all three; the rows read off Taylor's
        // polynomials agree with Dormand–Prince's step ends to its
        // tolerance, and with each other's to rounding.
        assert_eq!(rows[0].len(), 2001, "{name}: every grid time, 0 to 3");
        for run in &rows[1..] {
            assert_eq!(
                run.keys().collect::<Vec<_>>(),
                rows[0].keys().collect::<Vec<_>>()
            );
        }
        let gap = |a: &Grid, b: &Grid| {
            a.iter()
                .flat_map(|(t, x)| x.iter().zip(&b[t]).map(|(x, y)| (x - y).abs()))
                .fold(0.0, f64::max)
        };
        assert!(
            gap(&rows[0], &rows[1]) < 1e-6,
            "{name}: {}",
            gap(&rows[0], &rows[1])
        );
        assert!(
            gap(&rows[1], &rows[2]) < 1e-11,
            "{name}: {}",
            gap(&rows[1], &rows[2])
        );
    }
    // A tolerance below 1e-26 would ask for an order above 31: refused at
    // once (it ran on at steps of ρ·1e-10).
    for (flag, value) in [
        ("--tolerance", "2"),
        ("--tolerance", "1e-300"),
        ("--order", "32"),
        ("--order", "1"),
    ] {
        let (ok, _, stderr) = dalembert(&[
            "simulate",
            "ball_bounce",
            "--integrator",
            "taylor",
            flag,
            value,
        ]);
        assert!(!ok && stderr.contains(flag), "{flag} {value}: {stderr}");
    }
    // A fixed order below the tolerance's is run, with a note saying what
    // it costs; above it, no note.
    for (order, noted) in [("10", true), ("28", false)] {
        let (ok, _, stderr) = dalembert(&[
            "simulate",
            "ball_bounce",
            "--integrator",
            "taylor",
            "--order",
            order,
            "--t-end",
            "0.5",
            "--out",
            scratch("simulate-order-note").to_str().unwrap(),
        ]);
        assert!(ok, "{stderr}");
        assert_eq!(
            stderr.contains("below the order the tolerance asks for (20)"),
            noted,
            "--order {order}: {stderr}"
        );
    }
    // Taylor's settings with another method: refused, not ignored.
    for (flag, value) in [("--tolerance", "1e-12"), ("--order", "28")] {
        let (ok, _, stderr) = dalembert(&["simulate", "ball_bounce", flag, value]);
        assert!(
            !ok && stderr.contains("applies to --integrator taylor only"),
            "{flag}: {stderr}"
        );
    }
}

/// A point in the unit disk whose wall is written through a square root
/// (`tests/walls/disk_sqrt.toml`), from the command line: with Taylor's
/// method, as with Dormand–Prince, every row is inside the disk and the
/// same collisions are met (6 in 10 s without gravity), with gravity too.
/// (The wall's series converges on a shorter interval than the motion's:
/// a step chosen from the motion's alone once left the disk after 2
/// collisions and ended at |q| = 7.5.)
#[test]
fn taylor_keeps_a_point_inside_a_square_root_wall() {
    let file = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../tests/walls/disk_sqrt.toml");
    let file = file.to_str().unwrap();
    for gravity in ["g=0", "g=9.81"] {
        let mut hits = Vec::new();
        for integrator in ["dormand-prince", "taylor"] {
            let dir = scratch(&format!("simulate-disk-{integrator}-{gravity}"));
            let out = dir.to_str().unwrap();
            let (ok, stdout, stderr) = dalembert(&[
                "simulate",
                file,
                "--t-end",
                "10",
                "--set",
                gravity,
                "--integrator",
                integrator,
                "--out",
                out,
            ]);
            assert!(ok, "{stdout}\n{stderr}");
            let rows = table_rows(&dir.join("disk_sqrt.csv"));
            for (r, _) in &rows {
                assert!(
                    r[1].hypot(r[2]) <= 1.0 + 1e-12,
                    "{integrator}: outside {r:?}"
                );
            }
            let rim: Vec<f64> = rows
                .iter()
                .filter(|(_, hit)| hit == "rim")
                .map(|(r, _)| r[0])
                .collect();
            hits.push(rim);
        }
        assert!(hits[0].len() >= 6, "{gravity}: {hits:?}");
        // One row per collision, v⁻'s, labelled with the wall.
        assert_eq!(hits[0].len(), hits[1].len(), "{gravity}: {hits:?}");
        for (a, b) in hits[0].iter().zip(&hits[1]) {
            assert!((a - b).abs() < 1e-8, "{gravity}: {a} vs {b}");
        }
    }
}

/// A model file's errors name its walls as the file does (not by an
/// index), and a run with E₀ = 0 states its energy drift without a
/// relative figure (which would divide by zero).
#[test]
fn messages_name_walls_and_drift_as_they_are() {
    let file = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../tests/walls/disk_sqrt.toml");
    let file = file.to_str().unwrap();
    let dir = scratch("simulate-disk-messages");
    let out = dir.to_str().unwrap();
    let (ok, stdout, stderr) = dalembert(&["simulate", file, "--set", "x=2", "--out", out]);
    assert!(!ok, "{stdout}");
    assert!(
        stderr.contains("wall \"rim\"") && !stderr.contains("WallIndex"),
        "{stderr}"
    );
    let (ok, stdout, stderr) = dalembert(&[
        "simulate", file, "--set", "x_dot=0", "--set", "y_dot=0", "--t-end", "1", "--out", out,
    ]);
    assert!(ok, "{stdout}\n{stderr}");
    assert!(
        stdout.contains("energy 0.000000000000 at the start"),
        "{stdout}"
    );
    assert!(!stdout.contains("relative"), "{stdout}");
}

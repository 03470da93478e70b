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

/// A point dropped from height h (its start, `[initial] y = "h"`) onto the
/// floor under gravity g, written to `dir`.
fn dropped_point(dir: &str) -> PathBuf {
    std::fs::create_dir_all(dir).unwrap();
    let file = PathBuf::from(dir).join("dropped.toml");
    std::fs::write(
        &file,
        "[model]\nname = \"dropped\"\n[parameters]\ng = { value = \"981/100\" }\nh = { value = \"1\" }\n\
         [coordinates]\nnames = [\"y\"]\n[dynamics]\nkinetic_energy = \"y_dot^2/2\"\n\
         potential = \"g*y\"\n[[wall]]\nname = \"floor\"\nsurface = \"y\"\n[initial]\ny = \"h\"\n",
    )
    .unwrap();
    file
}

/// `simulate` of `dropped_point` to t = 3 with `method` and `flags`: its
/// standard output, and the CSV's header and rows (cells split).
fn dropped_run(dir: &str, method: &str, flags: &[&str]) -> (String, String, Vec<Vec<String>>) {
    let file = dropped_point(dir);
    let mut args = vec!["simulate", file.to_str().unwrap(), "--t-end", "3"];
    args.extend(["--integrator", method, "--out", dir]);
    args.extend(flags);
    let (ok, stdout, stderr) = dalembert(&args);
    assert!(ok, "{stdout}{stderr}");
    let csv = std::fs::read_to_string(PathBuf::from(dir).join("dropped.csv")).unwrap();
    let mut lines = csv.lines();
    let header = lines.next().unwrap().to_string();
    let rows = lines
        .map(|l| l.split(',').map(str::to_string).collect())
        .collect();
    (stdout, header, rows)
}

/// A point dropped from height y₀ onto the floor under gravity g:
/// y(t) = v τ − g τ²/2, τ = t − (2m − 1) v/g after m bounces, v = √(2 g y₀).
/// So ∂y/∂y₀ = (τ − (2m − 1)(v − g τ)/g)·g/v and ∂ẏ/∂y₀ = 2m·g/v: at the
/// n-th bounce ∂y/∂y₀ is 2n − 1 just before and −(2n − 1) just after.
/// The n-th bounce comes at t*ₙ = (2n − 1) v/g, so ∂t*ₙ/∂y₀ = (2n − 1)/v;
/// started with a small speed ẏ₀ the first comes at (ẏ₀ + √(ẏ₀² + 2gy₀))/g
/// and the bounce speed √(ẏ₀² + 2gy₀) does not move at ẏ₀ = 0, so
/// ∂t*ₙ/∂ẏ₀ = 1/g for every n.
/// `--phi` writes the entries on every row (each a step's end) and the
/// instants' derivatives on the row before each bounce, and each
/// method's columns agree with the closed form.
#[test]
fn phi_columns_of_a_bouncing_point_follow_its_closed_form() {
    let dir = out_dir("sensitivity_phi_columns");
    let (g, y0) = (9.81f64, 1.0f64);
    let v = (2.0 * g * y0).sqrt();
    for method in ["dormand-prince", "taylor", "rk4"] {
        let (_, header, lines) = dropped_run(&dir, method, &["--phi", "y/y, y_dot/y, y/y_dot"]);
        assert_eq!(
            header,
            "t,y,y_dot,energy,residual_velocity,residual_position,collision,dy/dy(0),dy_dot/dy(0),dy/dy_dot(0),dt_collision/dy(0),dt_collision/dy_dot(0)"
        );
        let (mut bounces, mut rows) = (0, 0);
        for cells in &lines {
            let at = |k: usize| cells[k].parse::<f64>().unwrap();
            let (t, dy, dv) = (at(0), at(7), at(8));
            // A bounce's first row is before it, the next after it.
            let before = cells[6] == "floor";
            let m = f64::from(bounces);
            if before {
                let (by_y, by_v) = (at(10), at(11));
                let (want_y, want_v) = ((2.0 * m + 1.0) / v, 1.0 / g);
                assert!(
                    (by_y - want_y).abs() <= 1e-7 * want_y
                        && (by_v - want_v).abs() <= 1e-7 * want_v,
                    "{method}, bounce {}: ∂t*/∂(y₀, ẏ₀) = ({by_y}, {by_v}) against ({want_y}, {want_v})",
                    bounces + 1
                );
            } else {
                assert_eq!(
                    (cells[10].as_str(), cells[11].as_str()),
                    ("", ""),
                    "{method}, t = {t}"
                );
            }
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
        header.ends_with(
            ",dy_dot/dx(0),dy_dot/dy(0),dy_dot/dx_dot(0),dy_dot/dy_dot(0),\
             dt_collision/dx(0),dt_collision/dy(0),dt_collision/dx_dot(0),dt_collision/dy_dot(0)"
        ),
        "{header}"
    );
    // Φ(0) = I.
    let first: Vec<f64> = csv
        .lines()
        .nth(1)
        .unwrap()
        .split(',')
        .skip(9)
        .take(16)
        .map(|c| c.parse().unwrap())
        .collect();
    let identity: Vec<f64> = (0..16)
        .map(|k| f64::from(u8::from(k / 4 == k % 4)))
        .collect();
    assert_eq!(first, identity);
}

/// The height and speed of the point of
/// [`phi_columns_of_a_bouncing_point_follow_its_closed_form`] dropped from
/// height `h`, at `t` after `m` bounces.
fn bounce_closed_form(t: f64, m: u32, g: f64, h: f64) -> [f64; 2] {
    let v = (2.0 * g * h).sqrt();
    let tau = t - (2.0 * f64::from(m) - 1.0) * v / g;
    [v * tau - g * tau * tau / 2.0, v - g * tau]
}

/// `--by h,g` on the bouncing point dropped from height h (`[initial] y =
/// "h"`, so the start moves with h and not with g): on every row, with each
/// method, the columns dy/dp and dy_dot/dp against the closed form's own
/// derivatives by p at the same t and number of bounces (Richardson
/// differences of the formula). The row before a bounce has the derivative
/// of the flight before it, the row after it that of the flight after it.
/// The row before the n-th bounce, at t = (2n − 1)v/g, v = √(2gh), also has
/// the instant's derivatives, (2n − 1)/v by h and −(2n − 1)v/(2g²) by g;
/// that cell is empty on every other row.
#[test]
fn by_parameters_of_a_bouncing_point_follow_its_closed_form() {
    let dir = out_dir("sensitivity_by_parameters");
    let (g, h) = (9.81f64, 1.0f64);
    let derivative = |f: &dyn Fn(f64) -> [f64; 2], x: f64| -> [f64; 2] {
        let central = |d: f64| {
            let (a, b) = (f(x + d), f(x - d));
            [(a[0] - b[0]) / (2.0 * d), (a[1] - b[1]) / (2.0 * d)]
        };
        let (coarse, fine) = (central(1e-4), central(5e-5));
        [0, 1].map(|i| (4.0 * fine[i] - coarse[i]) / 3.0)
    };
    for method in ["dormand-prince", "taylor", "rk4"] {
        let (stdout, header, lines) = dropped_run(&dir, method, &["--by", "h, g"]);
        assert!(stdout.contains("  ∂/∂h at t = 3: y "), "{stdout}");
        assert_eq!(
            header,
            "t,y,y_dot,energy,residual_velocity,residual_position,collision,dy/dh,dy_dot/dh,dt_collision/dh,dy/dg,dy_dot/dg,dt_collision/dg"
        );
        let v = (2.0 * g * h).sqrt();
        let (mut bounces, mut rows) = (0, 0);
        for cells in &lines {
            let at = |k: usize| cells[k].parse::<f64>().unwrap();
            let t = at(0);
            let by_h = derivative(&|h| bounce_closed_form(t, bounces, g, h), h);
            let by_g = derivative(&|g| bounce_closed_form(t, bounces, g, h), g);
            for (got, want, what) in [([at(7), at(8)], by_h, "h"), ([at(10), at(11)], by_g, "g")] {
                for i in 0..2 {
                    assert!(
                        (got[i] - want[i]).abs() <= 1e-7 * want[i].abs().max(1.0),
                        "{method}, t = {t} after {bounces} bounces, ∂/∂{what}: {got:?} against {want:?}"
                    );
                }
            }
            if cells[6] == "floor" {
                let n = f64::from(2 * bounces + 1);
                for (got, want, what) in
                    [(at(9), n / v, "h"), (at(12), -n * v / (2.0 * g * g), "g")]
                {
                    assert!(
                        (got - want).abs() <= 1e-9 * want.abs(),
                        "{method}, bounce {}: ∂t*/∂{what} {got}, not {want}",
                        bounces + 1
                    );
                }
                bounces += 1;
            } else {
                assert!(
                    cells[9].is_empty() && cells[12].is_empty(),
                    "{method}: {cells:?}"
                );
            }
            rows += 1;
        }
        assert_eq!(bounces, 3, "{method}");
        assert!(rows > 2000, "{method}: {rows} rows");
    }
}

/// Richardson-extrapolated central differences of `end` (the end state of
/// a run with a parameter moved by its argument) at steps 2e-5 and 1e-5.
fn differences_of_runs(end: impl Fn(f64) -> Vec<f64>) -> Vec<f64> {
    let central = |d: f64| -> Vec<f64> {
        let (a, b) = (end(d), end(-d));
        a.iter().zip(&b).map(|(a, b)| (a - b) / (2.0 * d)).collect()
    };
    let (coarse, fine) = (central(2e-5), central(1e-5));
    fine.iter()
        .zip(&coarse)
        .map(|(f, c)| (4.0 * f - c) / 3.0)
        .collect()
}

/// `--by` on the hardest kind of model the CLI takes: a Chaplygin sleigh
/// (a constraint that moves with c, which the start's completed velocity
/// follows) in an elliptic rink written through a square root (whose edge
/// moves with a). The end row's columns, and each collision row's
/// `dt_collision/dp`, against Richardson differences of the end states and
/// the collision instants of whole runs with `--set c=…` or `--set a=…`,
/// through the same collisions.
#[test]
fn by_parameters_on_a_square_root_rink_match_differences_of_whole_runs() {
    let file = concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/../tests/walls/sleigh_oval.toml"
    );
    let dir = out_dir("sensitivity_by_sleigh");
    let tight = [
        "--rtol", "1e-12", "--atol", "1e-14", "--t-end", "6", "--every", "0.5",
    ];
    // The last row's numbers, the number of collisions, and each collision
    // row's cells, of a run with `extra`.
    let run = |extra: &[&str]| -> (Vec<f64>, usize, Vec<Vec<String>>) {
        let mut args = vec!["simulate", file, "--out", &dir];
        args.extend(tight);
        args.extend(extra);
        let (ok, stdout, stderr) = dalembert(&args);
        assert!(ok, "{args:?}: {stdout}{stderr}");
        let collisions = stdout
            .lines()
            .find_map(|l| {
                l.split(" collisions,")
                    .next()
                    .filter(|_| l.contains(" collisions,"))
            })
            .and_then(|l| l.rsplit(' ').next())
            .and_then(|n| n.parse().ok())
            .unwrap_or_else(|| panic!("no collision count in {stdout}"));
        let csv = std::fs::read_to_string(PathBuf::from(&dir).join("sleigh_oval.csv")).unwrap();
        let last = csv.lines().last().unwrap();
        let cells: Vec<f64> = last
            .split(',')
            .filter(|c| !c.is_empty())
            .filter_map(|c| c.parse().ok())
            .collect();
        // (t, 3 coordinates, 3 velocities, energy, 2 residuals, then the
        // wall met at 10.)
        let met = (csv.lines().skip(1))
            .map(|l| l.split(',').map(str::to_string).collect::<Vec<_>>())
            .filter(|c| !c[10].is_empty())
            .collect();
        (cells, collisions, met)
    };
    let (followed, collisions, met) = run(&["--by", "c,a"]);
    assert!(collisions >= 3, "{collisions} collisions");
    assert_eq!(met.len(), collisions);
    // t, 3 coordinates, 3 velocities, energy, 2 residuals, then 6 columns
    // by c and 6 by a (the instants' columns are empty here).
    assert_eq!(followed.len(), 10 + 12);
    for (k, (p, p0)) in [("c", 0.1f64), ("a", 1.2)].into_iter().enumerate() {
        // The end state, then every collision instant.
        let end = |d: f64| -> Vec<f64> {
            let set = format!("{p}={}", p0 + d);
            let (row, c, met) = run(&["--set", &set]);
            assert_eq!(c, collisions, "{p} moved by {d}: other collisions");
            let instants = met.iter().map(|cells| cells[0].parse::<f64>().unwrap());
            row[1..7].iter().copied().chain(instants).collect()
        };
        let want = differences_of_runs(end);
        let got = &followed[10 + 6 * k..16 + 6 * k];
        let size = want[..6].iter().fold(1.0f64, |a, x| a.max(x.abs()));
        for (g, w) in got.iter().zip(&want) {
            assert!(
                (g - w).abs() <= 1e-6 * size,
                "∂/∂{p}: followed {got:?}, differences {want:?}"
            );
        }
        // dt_collision/dp, after the 6 columns by p.
        for (n, (cells, w)) in met.iter().zip(&want[6..]).enumerate() {
            let g: f64 = cells[17 + 7 * k].parse().unwrap();
            assert!(
                (g - w).abs() <= 1e-6 * w.abs().max(1.0),
                "∂t*/∂{p} of collision {n}: followed {g}, differences {w}"
            );
        }
    }
}

#[test]
fn by_names_only_parameters_of_the_model() {
    let dir = out_dir("sensitivity_by_names");
    let run = |by: &str| {
        let args = [
            "simulate",
            "pendulum_wall",
            "--t-end",
            "0.1",
            "--by",
            by,
            "--out",
            &dir,
        ];
        dalembert(&args)
    };
    let (ok, stdout, stderr) = run("x");
    assert!(!ok, "{stdout}");
    assert!(
        stderr.contains("--by: `x` is not a parameter of pendulum_wall (parameters: "),
        "{stderr}"
    );
    let (ok, stdout, stderr) = run("l,l");
    assert!(!ok, "{stdout}");
    assert!(stderr.contains("--by: `l` is named twice"), "{stderr}");
    // A derived parameter (the coin's A = m R²/4) is not a direction of
    // its own.
    let coin = concat!(env!("CARGO_MANIFEST_DIR"), "/../tests/bodies/coin.toml");
    let args = [
        "simulate", coin, "--t-end", "0.1", "--by", "A", "--out", &dir,
    ];
    let (ok, stdout, stderr) = dalembert(&args);
    assert!(!ok, "{stdout}");
    assert!(
        stderr.contains(
            "--by: `A` is a derived parameter of coin (computed from others): differentiate by those it is computed from (parameters: m, R, g)"
        ),
        "{stderr}"
    );
    // A model without parameters says it has none.
    let file = PathBuf::from(&dir).join("no_parameters.toml");
    std::fs::create_dir_all(&dir).unwrap();
    let text = "[coordinates]\nnames = [\"x\"]\n[dynamics]\nkinetic_energy = \"x_dot^2/2\"\npotential = \"x\"\n[[wall]]\nsurface = \"x\"\n[initial]\nx = 1\n";
    std::fs::write(&file, text).unwrap();
    let file = file.to_str().unwrap();
    let args = [
        "simulate", file, "--t-end", "0.1", "--by", "g", "--out", &dir,
    ];
    let (ok, stdout, stderr) = dalembert(&args);
    assert!(!ok, "{stdout}");
    assert!(
        stderr.contains("--by: `g` is not a parameter of no_parameters (parameters: it has none)"),
        "{stderr}"
    );
}

/// `--by l` on the built-in pendulum, whose rod length l moves its
/// holonomic constraint x² + y² = l² away from the file's start: the start
/// is taken to its nearest point on the circle, l·(−4/5, −3/5), and a note
/// says so. The end row's columns against differences of whole runs of
/// the same model with that start written as a function of l in its file
/// (`--set l=…`), through the same collisions.
#[test]
fn by_a_parameter_of_a_holonomic_constraint_moves_the_start_onto_it() {
    let dir = out_dir("sensitivity_by_rod");
    std::fs::create_dir_all(&dir).unwrap();
    let file = PathBuf::from(&dir).join("pendulum_wall.toml");
    let text = include_str!("../../models/pendulum_wall.toml")
        .replace("x = \"-4/5\"", "x = \"-4/5*l\"")
        .replace("y = \"-3/5\"", "y = \"-3/5*l\"");
    assert!(text.contains("-4/5*l") && text.contains("-3/5*l"));
    std::fs::write(&file, text).unwrap();
    let tight = [
        "--rtol", "1e-12", "--atol", "1e-14", "--t-end", "4", "--every", "0.5",
    ];
    let run = |model: &str, extra: &[&str]| -> (Vec<f64>, String, String) {
        let mut args = vec!["simulate", model, "--out", &dir];
        args.extend(tight);
        args.extend(extra);
        let (ok, stdout, stderr) = dalembert(&args);
        assert!(ok, "{args:?}: {stdout}{stderr}");
        let csv = std::fs::read_to_string(PathBuf::from(&dir).join("pendulum_wall.csv")).unwrap();
        let last: Vec<f64> = (csv.lines().last().unwrap().split(','))
            .filter_map(|c| c.parse().ok())
            .collect();
        let collisions = stdout
            .lines()
            .find(|l| l.contains(" collisions,"))
            .unwrap()
            .split(" steps")
            .next()
            .unwrap()
            .to_string();
        (last, collisions, stderr)
    };
    let (followed, collisions, stderr) = run("pendulum_wall", &["--by", "l"]);
    assert!(
        stderr.contains("note: --by l: the start's coordinates leave the holonomic constraints"),
        "{stderr}"
    );
    let end = |d: f64| -> Vec<f64> {
        let set = format!("l={}", 1.0 + d);
        let (row, c, _) = run(file.to_str().unwrap(), &["--set", &set]);
        assert_eq!(c, collisions, "l moved by {d}: other collisions");
        row[1..5].to_vec()
    };
    let want = differences_of_runs(end);
    // t, 2 coordinates, 2 velocities, energy, 2 residuals, then 4 columns.
    let got = &followed[8..12];
    let size = want.iter().fold(1.0f64, |a, x| a.max(x.abs()));
    for (g, w) in got.iter().zip(&want) {
        assert!(
            (g - w).abs() <= 1e-6 * size,
            "∂/∂l: followed {got:?}, differences {want:?}"
        );
    }
}

/// The start's derivative is taken with steps relative to the parameter:
/// a point thrown down from height h at speed √h (`[initial] y = "h"`,
/// `y_dot = "-sqrt(h)"`), run with h = 10⁻⁴ and `--by h`, starts with
/// ∂y/∂h = 1 and ∂ẏ/∂h = −1/(2√h) = −50. (A step of 10⁻³ would take h below
/// zero and the start's speed to NaN.)
#[test]
fn by_a_small_parameter_differentiates_its_start_in_its_own_scale() {
    let dir = out_dir("sensitivity_by_small");
    std::fs::create_dir_all(&dir).unwrap();
    let file = PathBuf::from(&dir).join("thrown.toml");
    std::fs::write(
        &file,
        "[model]\nname = \"thrown\"\n[parameters]\ng = { value = \"981/100\" }\nh = { value = \"1\" }\n\
         [coordinates]\nnames = [\"y\"]\n[dynamics]\nkinetic_energy = \"y_dot^2/2\"\n\
         potential = \"g*y\"\n[[wall]]\nname = \"floor\"\nsurface = \"y\"\n\
         [initial]\ny = \"h\"\ny_dot = \"-sqrt(h)\"\n",
    )
    .unwrap();
    let file = file.to_str().unwrap();
    let args = [
        "simulate", file, "--set", "h=1e-4", "--by", "h", "--t-end", "1e-3", "--out", &dir,
    ];
    let (ok, stdout, stderr) = dalembert(&args);
    assert!(ok, "{stdout}{stderr}");
    let csv = std::fs::read_to_string(PathBuf::from(&dir).join("thrown.csv")).unwrap();
    let first: Vec<f64> = (csv.lines().nth(1).unwrap().split(','))
        .skip(7)
        .take(2)
        .map(|c| c.parse().unwrap())
        .collect();
    assert!(
        (first[0] - 1.0).abs() <= 1e-9 && (first[1] + 50.0).abs() <= 1e-6,
        "{first:?}"
    );
}

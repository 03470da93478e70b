//! `dalembert simulate`'s starting state: `[initial]` values that follow
//! the parameters, coordinates and velocities `--set`, the velocities left
//! out that follow from the constraints, and rates that are not velocities
//! (a body's angular velocity) given in the file and by `--set`.

mod common;
use common::{dalembert, scratch};

/// `[initial]` values written with parameters follow `--set`: the §3.2.1
/// ball starts on the floor (`z = "r"`) whatever its radius. With the
/// file's value fixed it would start inside the floor of a larger ball.
#[test]
fn initial_values_follow_the_parameters_set() {
    let dir = scratch("simulate-initial");
    let out = dir.to_str().unwrap();
    for r in ["1", "0.25"] {
        let set = format!("r={r}");
        let (ok, stdout, stderr) = dalembert(&[
            "simulate",
            "ball_bounce",
            "--t-end",
            "0.6",
            "--set",
            &set,
            "--out",
            out,
        ]);
        assert!(ok, "r = {r}: {stdout}\n{stderr}");
        let text = std::fs::read_to_string(dir.join("ball_bounce.csv")).unwrap();
        let first: Vec<f64> = text
            .lines()
            .nth(1)
            .unwrap()
            .split(',')
            .take(4)
            .map(|x| x.parse().unwrap())
            .collect();
        assert_eq!(
            first[3],
            r.parse::<f64>().unwrap(),
            "z at the start, r = {r}"
        );
        // Back on the floor after 2·ż/g ≈ 0.41 s.
        assert!(stdout.contains(" 1 collisions"), "r = {r}: {stdout}");
    }
    // A coordinate set by name still wins over the file's expression.
    let (ok, stdout, stderr) = dalembert(&[
        "simulate",
        "ball_bounce",
        "--t-end",
        "0.1",
        "--set",
        "r=1",
        "--set",
        "z=2",
        "--out",
        out,
    ]);
    assert!(ok, "{stdout}\n{stderr}");
    let text = std::fs::read_to_string(dir.join("ball_bounce.csv")).unwrap();
    let z: f64 = text
        .lines()
        .nth(1)
        .unwrap()
        .split(',')
        .nth(3)
        .unwrap()
        .parse()
        .unwrap();
    assert_eq!(z, 2.0);
}

/// `simulate MODEL --set theta=0.5` for 0.1 s into a scratch folder of its
/// own: (stdout, stderr, the CSV's first row as a lookup by column name).
fn started_at_tilt(model: &str) -> (String, String, impl Fn(&str) -> f64) {
    let dir = scratch(&format!("simulate-start-{model}"));
    let out = dir.to_str().unwrap();
    let (ok, stdout, stderr) = dalembert(&[
        "simulate",
        model,
        "--set",
        "theta=0.5",
        "--t-end",
        "0.1",
        "--out",
        out,
    ]);
    assert!(ok, "{stdout}\n{stderr}");
    let csv = std::fs::read_to_string(dir.join(format!("{model}.csv"))).unwrap();
    let header: Vec<String> = csv
        .lines()
        .next()
        .unwrap()
        .split(',')
        .map(String::from)
        .collect();
    let first: Vec<String> = csv
        .lines()
        .nth(1)
        .unwrap()
        .split(',')
        .map(String::from)
        .collect();
    let value = move |name: &str| {
        let column = header.iter().position(|h| h == name).unwrap();
        first[column].parse().unwrap()
    };
    (stdout, stderr, value)
}

/// A velocity `--set` off the constraints is projected onto ker A, and the
/// first row is that projected state with its own residual: at θ = 0.5 the
/// rolling ball's file velocity has A q̇ = −0.26, its projection none.
#[test]
fn the_first_row_is_the_projected_start() {
    let (stdout, stderr, value) = started_at_tilt("ball_wall_euler");
    assert!(stderr.contains("not admissible"), "{stderr}");
    // x' = r ω_y with ω_y = −ψ' sin θ at φ = 0 (r = 1/2), and y' = −r ω_x = 0.
    let (x_dot, psi_dot) = (value("x_dot"), value("psi_dot"));
    assert!(
        (x_dot + 0.5 * psi_dot * 0.5f64.sin()).abs() < 1e-12,
        "{x_dot} {psi_dot}"
    );
    assert!(value("residual_velocity") < 1e-12);
    assert!(stdout.contains("|A q̇| = "), "{stdout}");
    let worst: f64 = stdout
        .split("|A q̇| = ")
        .nth(1)
        .and_then(|s| s.split(',').next())
        .unwrap()
        .parse()
        .unwrap();
    assert!(worst < 1e-10, "{stdout}");
}

/// Velocities the start does not give follow from the constraints: the
/// Chaplygin ball's file gives its three angular rates only, and at the
/// attitude `--set` chooses the centre's velocity is the rolling one
/// (ẋ = −r ψ̇ sin θ, ẏ = −r θ̇ at φ = ψ = 0, r = 1/2), the rates unchanged.
#[test]
fn velocities_left_out_follow_from_the_constraints() {
    let (_, stderr, value) = started_at_tilt("chaplygin_ball");
    assert!(!stderr.contains("not admissible"), "{stderr}");
    assert!(
        stderr.contains("follow from the constraints: x_dot = "),
        "{stderr}"
    );
    assert_eq!(
        (value("phi_dot"), value("theta_dot"), value("psi_dot")),
        (1.0, 0.5, 2.0)
    );
    assert!((value("x_dot") + 0.5 * 2.0 * 0.5f64.sin()).abs() < 1e-12);
    assert!((value("y_dot") + 0.25).abs() < 1e-12);
}

/// A ball (its attitude a unit quaternion) at a general attitude, started by
/// its angular velocity: the file gives `ball_wx = 1` and `ball_wz = 5`,
/// `--set ball_wz=7` changes the latter, and nothing else about the
/// velocities is said. The first row's ω, computed here from (e, ė) by
/// ω = 2(e₀ė⃗ − ė₀e⃗ − ė⃗ × e⃗), is (1, 0, 7) (ω_y, free, takes the least
/// kinetic energy: 0), the centre rolls (ẋ = r ω_y, ẏ = −r ω_x), and e·ė = 0.
#[test]
fn a_ball_is_started_by_its_angular_velocity() {
    let dir = scratch("simulate-start-rates");
    std::fs::create_dir_all(&dir).unwrap();
    let root = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("..");
    let text = std::fs::read_to_string(root.join("tests/bodies/ball_wall_quaternion.toml"))
        .unwrap()
        .split("[initial]")
        .next()
        .unwrap()
        .to_string()
        + "[initial]\nx = \"3/2\"\ne0 = \"cos(1/2)\"\ne1 = \"sin(1/2)/3\"\n\
           e2 = \"2*sin(1/2)/3\"\ne3 = \"-2*sin(1/2)/3\"\nball_wx = 1\nball_wz = 5\n";
    let file = dir.join("spun.toml");
    std::fs::write(&file, text).unwrap();
    let out = dir.to_str().unwrap();
    let (ok, stdout, stderr) = dalembert(&[
        "simulate",
        file.to_str().unwrap(),
        "--set",
        "ball_wz=7",
        "--t-end",
        "0.1",
        "--out",
        out,
    ]);
    assert!(ok, "{stdout}\n{stderr}");
    assert!(
        stderr.contains("follow from the constraints and ball_wx = 1e0, ball_wz = 7e0: "),
        "{stderr}"
    );
    let csv = std::fs::read_to_string(dir.join("ball_wall_quaternion.csv")).unwrap();
    let header: Vec<&str> = csv.lines().next().unwrap().split(',').collect();
    let first: Vec<f64> = (csv.lines().nth(1).unwrap().split(','))
        .map(|x| x.parse().unwrap_or(f64::NAN))
        .collect();
    let value = |name: &str| first[header.iter().position(|h| *h == name).unwrap()];
    let e = ["e0", "e1", "e2", "e3"].map(value);
    let de = ["e0_dot", "e1_dot", "e2_dot", "e3_dot"].map(value);
    let cross = [
        de[2] * e[3] - de[3] * e[2],
        de[3] * e[1] - de[1] * e[3],
        de[1] * e[2] - de[2] * e[1],
    ];
    let w: Vec<f64> = (0..3)
        .map(|i| 2.0 * (e[0] * de[i + 1] - de[0] * e[i + 1] - cross[i]))
        .collect();
    for (got, want) in w.iter().zip([1.0, 0.0, 7.0]) {
        assert!((got - want).abs() < 1e-12, "ω = {w:?}");
    }
    let r = 0.5;
    assert!((value("x_dot") - r * w[1]).abs() < 1e-12);
    assert!((value("y_dot") + r * w[0]).abs() < 1e-12);
    let norm_rate: f64 = e.iter().zip(&de).map(|(a, b)| a * b).sum();
    assert!(norm_rate.abs() < 1e-12, "e·ė = {norm_rate}");
    // A name that is none of the model's lists the rates too.
    let (ok, _, stderr) = dalembert(&[
        "simulate",
        file.to_str().unwrap(),
        "--set",
        "ball_wy2=1",
        "--out",
        out,
    ]);
    assert!(!ok);
    assert!(
        stderr.contains("or rate given at the start (ball_wx, ball_wz)"),
        "{stderr}"
    );
}

//! `dalembert periodic`: every built-in model with walls gets an orbit or
//! a reason (exit 1, never a crash or a usage error), §3.2.1's two-bounce
//! orbit through the JSON output, Garwin's superball as a model file
//! (derived and interpreted now) with its multipliers in closed form
//! (tests/periodic.rs derives them), and mistakes in the arguments.

mod common;
use common::dalembert_exit as run;

/// A number after `"key": ` in one-line JSON.
fn field(json: &str, key: &str) -> f64 {
    let start = json
        .find(&format!("\"{key}\": "))
        .unwrap_or_else(|| panic!("no {key} in {json}"))
        + key.len()
        + 4;
    let rest = &json[start..];
    let end = rest.find([',', '}']).unwrap();
    rest[..end].trim().parse().unwrap()
}

/// The multipliers of the JSON output.
fn multipliers(json: &str) -> Vec<[f64; 2]> {
    let start = json.find("\"multipliers\": [").unwrap() + "\"multipliers\": [".len();
    let end = start + json[start..].find("]]").unwrap() + 1;
    json[start..end]
        .split("], [")
        .map(|pair| {
            let pair = pair.trim_matches(['[', ']']);
            let (re, im) = pair.split_once(", ").unwrap();
            [re.parse().unwrap(), im.parse().unwrap()]
        })
        .collect()
}

#[test]
fn every_built_in_model_with_walls_gets_an_orbit_or_a_reason() {
    let dir = concat!(env!("CARGO_MANIFEST_DIR"), "/../models");
    let mut models: Vec<String> = std::fs::read_dir(dir)
        .unwrap()
        .filter_map(|e| {
            let path = e.unwrap().path();
            let text = std::fs::read_to_string(&path).ok()?;
            let moving = text.contains("[coordinates]") && text.contains("[[wall]]");
            (path.extension()? == "toml" && moving)
                .then(|| path.file_stem().unwrap().to_string_lossy().into_owned())
        })
        .collect();
    models.sort();
    assert!(models.len() >= 10, "{models:?}");
    let mut found = 0;
    for model in &models {
        let (code, stdout, stderr) = run(&["periodic", model]);
        match code {
            Some(0) => {
                assert!(
                    stdout.contains("periodic orbit through"),
                    "{model}: {stdout}"
                );
                assert!(stdout.contains("stability: "), "{model}: {stdout}");
                found += 1;
            }
            Some(1) => assert!(
                stderr.starts_with(&format!("no periodic orbit of {model} through `")),
                "{model}: {stderr}"
            ),
            other => panic!("{model}: exit {other:?}\n{stdout}\n{stderr}"),
        }
    }
    // The balls on the floor, the pendulum, the superball at least.
    assert!(found >= 5, "orbits found for {found} of {models:?}");
}

#[test]
fn section_3_2_1_through_the_json_output() {
    let (code, stdout, stderr) = run(&[
        "periodic",
        "ball_bounce",
        "--collisions",
        "2",
        "--set",
        "x_dot=1.001",
        "--residual",
        "1e-12",
        "--json",
    ]);
    assert_eq!(code, Some(0), "{stderr}");
    let json = stdout.trim();
    assert!(field(json, "residual") <= 1e-12, "{json}");
    assert!(field(json, "iterations") <= 8.0, "{json}");
    // Two flights of 2ż/g each.
    assert!(
        (field(json, "period") - 4.0 * field(json, "z_dot") / 9.81).abs() <= 1e-12,
        "{json}"
    );
    let found = multipliers(json);
    assert_eq!(found.len(), 11, "{json}");
    assert!(
        found.iter().all(|z| (z[0] - 1.0).hypot(z[1]) <= 1e-5),
        "{json}"
    );
    assert!(json.contains("\"stability\": \"neutral\""), "{json}");
}

#[test]
fn the_superball_as_a_model_file() {
    let file = concat!(env!("CARGO_MANIFEST_DIR"), "/../models/superball.toml");
    let (code, stdout, stderr) = run(&["periodic", file, "--rtol", "1e-12", "--json"]);
    assert_eq!(code, Some(0), "{stderr}");
    let json = stdout.trim();
    assert!(
        field(json, "x_dot").abs() <= 1e-12 && field(json, "a_dot").abs() <= 1e-12,
        "{json}"
    );
    let (re, im) = (-31.0 / 49.0, 1440f64.sqrt() / 49.0);
    let found = multipliers(json);
    for target in [[re, im], [re, -im]] {
        assert!(
            found
                .iter()
                .any(|z| (z[0] - target[0]).hypot(z[1] - target[1]) <= 1e-9),
            "{target:?} in {json}"
        );
    }
    assert_eq!(
        found
            .iter()
            .filter(|z| (z[0] - 1.0).hypot(z[1]) <= 1e-9)
            .count(),
        3,
        "{json}"
    );
}

/// ball_bounce spinning about the vertical while it bounces straight up
/// (tests/periodic.rs has the same orbit through the library): with
/// `--angles phi` the orbit's φ makes one whole turn per flight, and the
/// JSON says so; without, the search heads for a ball at rest.
#[test]
fn an_angle_that_makes_a_whole_turn() {
    let omega = 1.02 * std::f64::consts::TAU / (2.0 * 5.0 / 9.81);
    let spin = format!("phi_dot={omega}");
    let mut args = vec!["periodic", "ball_bounce", "--rtol", "1e-12", "--json"];
    for set in ["x_dot=0", "psi_dot=0", "z_dot=5", &spin] {
        args.extend(["--set", set]);
    }
    let (code, stdout, stderr) = run(&[&args[..], &["--angles", "phi"]].concat());
    assert_eq!(code, Some(0), "{stderr}");
    let json = stdout.trim();
    assert!(json.contains("\"turns\": {\"phi\": 1}"), "{json}");
    let turn = field(json, "phi_dot") * field(json, "period");
    assert!((turn - std::f64::consts::TAU).abs() <= 1e-8, "{json}");
    // Without --angles φ must come back to its own value, ω·2ż/g = 0:
    // Newton's method shrinks the flight (ż → 0) towards a ball resting
    // on the floor, and says so.
    let (code, stdout, stderr) = run(&args);
    assert_eq!(code, Some(1), "{stdout}{stderr}");
    assert!(stderr.contains("slide along `floor`"), "{stderr}");
}

/// The puck's search heads for motions along its wall (tests/periodic.rs):
/// the reason says so and that more steps will not help.
#[test]
fn a_search_towards_grazing_is_named() {
    let (code, _, stderr) = run(&["periodic", "puck"]);
    assert_eq!(code, Some(1), "{stderr}");
    assert!(
        stderr.contains("heads for motions that slide along `wall`")
            && stderr.contains("more --iterations will not help"),
        "{stderr}"
    );
}

#[test]
fn mistakes_in_the_arguments() {
    for (args, says) in [
        (
            &["periodic", "superball", "--wall", "ceiling"][..],
            "`ceiling` is not a wall of superball (floor, table)",
        ),
        (
            &["periodic", "superball", "--collisions", "0"][..],
            "--collisions must be at least 1",
        ),
        (
            &["periodic", "superball", "--t-max", "-1"][..],
            "--t-max must be a positive finite number",
        ),
        (&["periodic", "ball_floor"][..], "instantaneous model"),
        (
            &["periodic", "superball", "--angles", "a,phi"][..],
            "--angles: `phi` is not a coordinate of superball (x, z, a)",
        ),
    ] {
        let (code, _, stderr) = run(args);
        assert_eq!(code, Some(2), "{args:?}: {stderr}");
        assert!(stderr.contains(says), "{args:?}: {stderr}");
    }
}

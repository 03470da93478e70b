//! The model language: every documented function and constant, in every
//! part of a model, reaches the emitted programs with the value it means.
//! Each emitted function is checked against the model's formulas written
//! out in Rust (T, V, h, f) and their numeric derivatives. Uses the
//! symbolic engine: run one test at a time (`RUST_TEST_THREADS=1`).

mod common;

use std::f64::consts::{E, PI};
use std::path::Path;

use dalembert_codegen::derive::Derivation;
use dalembert_codegen::quantity::Quantity;

/// Writes `text` as a model file `name.toml` in a temporary directory of
/// its own, runs `f` on its path and removes the directory.
fn with_model_file<T>(name: &str, text: &str, f: impl FnOnce(&Path) -> T) -> T {
    let dir =
        std::env::temp_dir().join(format!("dalembert-language-{}-{name}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let path = dir.join(format!("{name}.toml"));
    std::fs::write(&path, text).unwrap();
    let out = f(&path);
    std::fs::remove_dir_all(&dir).unwrap();
    out
}

fn derive(name: &str, text: &str) -> Derivation {
    with_model_file(name, text, |path| {
        dalembert_codegen::derive(path).unwrap_or_else(|e| panic!("{name}: {e}"))
    })
}

/// The model's function `q` at `inputs` (parameters, coordinates, velocities).
fn eval(d: &Derivation, q: Quantity, inputs: &[f64]) -> Vec<f64> {
    d.function(q)
        .unwrap_or_else(|| panic!("no {q:?}"))
        .program
        .eval(inputs)
}

fn wall_eval(d: &Derivation, wall: usize, q: Quantity, inputs: &[f64]) -> Vec<f64> {
    d.walls[wall].function(q).unwrap().program.eval(inputs)
}

/// Every function in every part: T, V, a holonomic constraint, a velocity
/// constraint, definitions and two walls.
const EVERYTHING: &str = r#"
[model]
name = "everything"

[parameters]
m = 2
k = "3/2"
R = 5

[coordinates]
names = ["x", "y", "z", "th"]

[definitions]
r = "sqrt(x^2 + y^2)"
lift = "1 + tan(th/4)^2"

[dynamics]
kinetic_energy = "m/2*(x_dot^2 + y_dot^2 + z_dot^2) + lift/2*th_dot^2 + exp(1)/10*x_dot*th_dot"
potential = "k*r^2/2 + log(2 + sin(th)) + e*z - pi*x/10 + 0.25*y"
holonomic = ["z - tan(x/7)"]
constraints = ["sqrt(1 + th^2)*x_dot - exp(th/3)*y_dot + 1e-1*th_dot"]

[[wall]]
name = "rim"
surface = "R - r"

[[wall]]
name = "floor"
surface = "z + 2 + sqrt(1 + th^2)/10"
"#;

const PARAMS: [f64; 3] = [2.0, 1.5, 5.0];

fn t(q: &[f64], v: &[f64]) -> f64 {
    let lift = 1.0 + (q[3] / 4.0).tan().powi(2);
    1.0 * (v[0] * v[0] + v[1] * v[1] + v[2] * v[2])
        + lift / 2.0 * v[3] * v[3]
        + E / 10.0 * v[0] * v[3]
}

fn potential(q: &[f64]) -> f64 {
    let r2 = q[0] * q[0] + q[1] * q[1];
    1.5 * r2 / 2.0 + (2.0 + q[3].sin()).ln() + E * q[2] - PI * q[0] / 10.0 + 0.25 * q[1]
}

fn holonomic(q: &[f64]) -> f64 {
    q[2] - (q[0] / 7.0).tan()
}

fn constraint_row(q: &[f64]) -> [f64; 4] {
    [(1.0 + q[3] * q[3]).sqrt(), -(q[3] / 3.0).exp(), 0.0, 0.1]
}

fn rim(q: &[f64]) -> f64 {
    5.0 - (q[0] * q[0] + q[1] * q[1]).sqrt()
}

fn floor(q: &[f64]) -> f64 {
    q[2] + 2.0 + (1.0 + q[3] * q[3]).sqrt() / 10.0
}

const H: f64 = 1e-4;

/// ∂f/∂x_k by central differences.
fn partial(f: &dyn Fn(&[f64]) -> f64, x: &[f64], k: usize) -> f64 {
    let (mut a, mut b) = (x.to_vec(), x.to_vec());
    a[k] += H;
    b[k] -= H;
    (f(&a) - f(&b)) / (2.0 * H)
}

/// vᵀ∇²f v as the second derivative of f(x + s v) at s = 0.
fn second_along(f: &dyn Fn(&[f64]) -> f64, x: &[f64], v: &[f64]) -> f64 {
    let at = |s: f64| f(&x.iter().zip(v).map(|(a, b)| a + s * b).collect::<Vec<_>>());
    (at(H) - 2.0 * at(0.0) + at(-H)) / (H * H)
}

fn close(what: &str, got: f64, want: f64, tol: f64) {
    assert!(
        (got - want).abs() <= tol * (1.0 + want.abs()),
        "{what}: emitted {got}, expected {want}"
    );
}

/// T, V, G and the forcing h of G q̈ + h = Aᵀλ (∂²T/∂v∂q · q̇ − ∂T/∂q +
/// ∂V/∂q) emitted for `d` at `inputs` (parameters, q, v) against the
/// formulas `t` and `potential` and their numeric derivatives.
fn check_energies(
    d: &Derivation,
    inputs: &[f64],
    q: &[f64],
    v: &[f64],
    t: &dyn Fn(&[f64], &[f64]) -> f64,
    potential: &dyn Fn(&[f64]) -> f64,
) {
    let n = q.len();
    close(
        "T",
        eval(d, Quantity::KineticEnergy, inputs)[0],
        t(q, v),
        1e-12,
    );
    close(
        "V",
        eval(d, Quantity::Potential, inputs)[0],
        potential(q),
        1e-12,
    );
    let g = eval(d, Quantity::MassMatrix, inputs);
    for i in 0..n {
        for j in 0..n {
            let tv = |w: &[f64]| t(q, w);
            let dj = |w: &[f64]| partial(&tv, w, j);
            close(
                &format!("G[{i}][{j}]"),
                g[n * i + j],
                partial(&dj, v, i),
                1e-5,
            );
        }
    }
    let forcing = eval(d, Quantity::Forcing, inputs);
    for (i, &got) in forcing.iter().enumerate().take(n) {
        let dt_dvi = |x: &[f64], w: &[f64]| partial(&|u: &[f64]| t(x, u), w, i);
        let mixed: f64 = (0..n)
            .map(|j| partial(&|x: &[f64]| dt_dvi(x, v), q, j) * v[j])
            .sum();
        let want = mixed - partial(&|x: &[f64]| t(x, v), q, i) + partial(potential, q, i);
        close(&format!("forcing[{i}]"), got, want, 1e-5);
    }
}

/// Wall `w`'s f, df and vᵀ∇²f v emitted for `d` against its formula `f`.
fn check_wall(
    d: &Derivation,
    w: usize,
    inputs: &[f64],
    q: &[f64],
    v: &[f64],
    f: &dyn Fn(&[f64]) -> f64,
) {
    close(
        "f",
        wall_eval(d, w, Quantity::Surface, inputs)[0],
        f(q),
        1e-12,
    );
    let normal = wall_eval(d, w, Quantity::Normal, inputs);
    for (k, &df) in normal.iter().enumerate().take(q.len()) {
        close(&format!("df[{k}]"), df, partial(f, q, k), 1e-7);
    }
    let hess = wall_eval(d, w, Quantity::SurfaceHessian, inputs)[0];
    close("vᵀ∇²f v", hess, second_along(f, q, v), 1e-4);
}

#[test]
fn every_function_and_constant_reaches_the_emitted_programs() {
    let d = derive("everything", EVERYTHING);
    let mut seed = 7u64;
    for _ in 0..20 {
        let q: Vec<f64> = (0..4).map(|_| 0.2 + common::lcg(&mut seed)).collect();
        let v: Vec<f64> = (0..4).map(|_| 2.0 * common::lcg(&mut seed) - 1.0).collect();
        let inputs: Vec<f64> = PARAMS.iter().chain(&q).chain(&v).copied().collect();

        check_energies(&d, &inputs, &q, &v, &t, &potential);
        close(
            "h",
            eval(&d, Quantity::Holonomic, &inputs)[0],
            holonomic(&q),
            1e-12,
        );

        // Rows of A: dh first, then the velocity constraint.
        let a = eval(&d, Quantity::Constraints, &inputs);
        let row = constraint_row(&q);
        for k in 0..4 {
            close(&format!("dh[{k}]"), a[k], partial(&holonomic, &q, k), 1e-7);
            close(&format!("A[{k}]"), a[4 + k], row[k], 1e-12);
        }
        let drift = eval(&d, Quantity::ConstraintDrift, &inputs);
        close(
            "drift of dh",
            drift[0],
            second_along(&holonomic, &q, &v),
            1e-4,
        );
        let av = |x: &[f64]| {
            constraint_row(x)
                .iter()
                .zip(&v)
                .map(|(r, w)| r * w)
                .sum::<f64>()
        };
        let along: f64 = (0..4).map(|j| partial(&av, &q, j) * v[j]).sum();
        close("drift of A v", drift[1], along, 1e-6);

        for (w, f) in [(0, rim as fn(&[f64]) -> f64), (1, floor)] {
            check_wall(&d, w, &inputs, &q, &v, &f);
        }
    }
    // The same programs in f32.
    let f32_code = with_model_file("everything", EVERYTHING, |path| {
        dalembert_codegen::generate_f32(path).unwrap()
    });
    assert!(f32_code.contains("sqrtf") && f32_code.contains("expf"));
}

#[test]
fn exp_of_one_is_e_not_zero() {
    let d = derive(
        "exp_one",
        r#"
[model]
name = "exp_one"
[coordinates]
names = ["x"]
[dynamics]
kinetic_energy = "exp(1)*x_dot^2/2"
potential = "exp(1)*x"
[[wall]]
name = "floor"
surface = "x"
"#,
    );
    close(
        "V",
        eval(&d, Quantity::Potential, &[2.0, 0.0])[0],
        2.0 * E,
        1e-15,
    );
    close(
        "G",
        eval(&d, Quantity::MassMatrix, &[2.0, 0.0])[0],
        E,
        1e-15,
    );
}

/// exp(k·x) in every part of a model: the symbolic engine's exact
/// arithmetic takes it for exp(x)^k, so k counts towards the degree limit
/// (with k = 10⁵ or 10⁹ its exponents overflowed and the derivation
/// panicked); within the limit the programs have the value it means.
#[test]
fn exp_of_a_multiple_is_bounded_as_a_power() {
    let model = |k: &str| {
        format!(
            r#"
[model]
name = "exp_multiple"
[coordinates]
names = ["x", "z"]
[dynamics]
kinetic_energy = "(x_dot^2 + z_dot^2)/2"
potential = "exp(-{k}*z) + z"
[[wall]]
name = "floor"
surface = "z - exp(300*x)/2"
contact = ["x_dot*exp(2*z) - z_dot"]
"#
        )
    };
    for k in ["100000", "999999999", "1/0.00001"] {
        let text = model(k);
        let errors = with_model_file("exp_multiple", &text, |path| {
            dalembert_codegen::derive(path).expect_err(k)
        });
        let message = errors.to_string();
        assert!(
            message.contains("polynomial degree") && message.contains(":8:"),
            "{k}: {message}"
        );
    }
    let d = derive("exp_multiple", &model("40"));
    let (x, z) = (1e-3, 0.25);
    let inputs = [x, z, 0.0, 0.0];
    close(
        "V",
        eval(&d, Quantity::Potential, &inputs)[0],
        (-40.0f64 * z).exp() + z,
        1e-15,
    );
    close(
        "f",
        wall_eval(&d, 0, Quantity::Surface, &inputs)[0],
        z - (300.0 * x).exp() / 2.0,
        1e-15,
    );
}

/// Names symbolica gives meanings of its own are plain names in a model.
#[test]
fn the_symbolic_engines_own_names_are_plain_names() {
    let d = derive(
        "engine_names",
        r#"
[model]
name = "engine_names"
[parameters]
euler_e = 5
[coordinates]
names = ["coeff", "der", "abs", "conj", "arg"]
[dynamics]
kinetic_energy = "log(euler_e)/2*(coeff_dot^2 + der_dot^2 + abs_dot^2 + conj_dot^2 + arg_dot^2)"
potential = "coeff^2 + der + abs + conj + arg"
[[wall]]
name = "floor"
surface = "coeff"
"#,
    );
    let mut inputs = vec![5.0, 3.0, 1.0, 1.0, 1.0, 1.0];
    inputs.extend([0.0; 5]);
    close(
        "G[0][0]",
        eval(&d, Quantity::MassMatrix, &inputs)[0],
        5f64.ln(),
        1e-15,
    );
    close("V", eval(&d, Quantity::Potential, &inputs)[0], 13.0, 1e-15);
    inputs[0] = 7.0;
    close(
        "G[0][0] at euler_e = 7",
        eval(&d, Quantity::MassMatrix, &inputs)[0],
        7f64.ln(),
        1e-15,
    );
}

/// Decimals in expressions are exact.
#[test]
fn decimals_are_exact() {
    let d = derive(
        "decimals",
        r#"
[model]
name = "decimals"
[coordinates]
names = ["x"]
[dynamics]
kinetic_energy = "0.5*x_dot^2"
potential = "0.1*x + 2.5e-1*x^2"
[[wall]]
name = "floor"
surface = "x"
"#,
    );
    assert_eq!(d.mass_matrix[0][0], "1");
    close(
        "V",
        eval(&d, Quantity::Potential, &[2.0, 0.0])[0],
        0.2 + 1.0,
        1e-15,
    );
}

/// A parameter's value may be an expression: of other parameters (a derived
/// parameter, computed wherever it is used, so it follows them), or a
/// constant such as pi/12. `[initial]` values are expressions of parameters.
#[test]
fn derived_parameters_constants_and_initial_expressions() {
    let d = derive(
        "derived",
        r#"
[model]
name = "derived"
[parameters]
m = 2
r = "1/10"
J = "2/5*m*r^2"
alpha = "pi/12"
[coordinates]
names = ["x", "th"]
[dynamics]
kinetic_energy = "m/2*x_dot^2 + J/2*th_dot^2"
potential = "m*tan(alpha)*x"
[[wall]]
name = "floor"
surface = "x - r"
[initial]
x = "r + 1"
th = "pi/2"
th_dot = "sqrt(2)"
"#,
    );
    let names: Vec<&str> = d.model.params.iter().map(|p| p.name.as_str()).collect();
    assert_eq!(names, ["m", "r", "alpha"]);
    assert_eq!(d.model.derived, ["J"]);
    close("alpha", d.model.params[2].value, PI / 12.0, 1e-15);
    // G follows m and r: J = 2/5·m·r² at m = 3, r = 2.
    let g = eval(
        &d,
        Quantity::MassMatrix,
        &[3.0, 2.0, PI / 12.0, 0.0, 0.0, 0.0, 0.0],
    );
    close("G[1][1]", g[3], 0.4 * 3.0 * 4.0, 1e-15);
    let v = eval(
        &d,
        Quantity::Potential,
        &[3.0, 2.0, 0.5, 2.0, 0.0, 0.0, 0.0],
    )[0];
    close("V", v, 3.0 * 0.5f64.tan() * 2.0, 1e-14);
    let init = &d.model.initial;
    close("x(0)", init[0], 1.1, 1e-15);
    close("th(0)", init[1], PI / 2.0, 1e-15);
    close("th_dot(0)", init[3], 2f64.sqrt(), 1e-15);
}

/// What the generated code could not compile is refused before generation:
/// a model type that is a name the file already uses, walls whose enum
/// variants would collide, `self` as a wall.
#[test]
fn names_the_generated_code_cannot_hold_are_refused() {
    let model = |name: &str, walls: &[&str]| {
        let mut text = format!(
            "[model]\nname = \"{name}\"\n[coordinates]\nnames = [\"x\"]\n[dynamics]\nkinetic_energy = \"x_dot^2/2\"\n"
        );
        for w in walls {
            text.push_str(&format!("[[wall]]\nname = \"{w}\"\nsurface = \"x\"\n"));
        }
        dalembert_codegen::ir::parse(std::path::Path::new("names.toml"), &text)
    };
    for name in [
        "default",
        "option",
        "params",
        "wall",
        "self",
        "some",
        "result",
        "series_scratch",
    ] {
        let e = model(name, &["floor"]).expect_err(name);
        assert!(e.to_string().contains(name), "{e}");
    }
    for walls in [
        &["a1", "a_1"][..],
        &["floor", "Floor"],
        &["self"],
        &["Self"],
    ] {
        assert!(model("fine", walls).is_err(), "{walls:?} accepted");
    }
    assert!(model("fine", &["a1", "a2"]).is_ok());
}

/// Hostile numbers: a literal that would wrap around i128 to a positive
/// value is refused instead of giving a negative mass a positive sign.
#[test]
fn numbers_never_wrap_around() {
    let text = "[model]\nname = \"wrap\"\n[parameters]\nm = \"1/-170141183460469231731687303715884105728\"\n[coordinates]\nnames = [\"x\"]\n[dynamics]\nkinetic_energy = \"m*x_dot^2/2\"\n[[wall]]\nname = \"floor\"\nsurface = \"x\"\n";
    let e = dalembert_codegen::ir::parse(std::path::Path::new("wrap.toml"), text).unwrap_err();
    assert!(e.to_string().contains("too large"), "{e}");
}

/// The arc and hyperbolic functions in T, V, a constraint and a wall.
const ARCS: &str = r#"
[model]
name = "arcs"

[parameters]
m = 2

[coordinates]
names = ["x", "y"]

[dynamics]
kinetic_energy = "m/2*cosh(y/2)*x_dot^2 + (1 + atan(x)^2)/2*y_dot^2"
potential = "sinh(x/3)*tanh(y) + asin(x/4) - acos(y/5) + asinh(x/2)*atanh(y/3)"
constraints = ["tanh(x)*x_dot + cosh(y)*y_dot"]

[[wall]]
name = "rim"
surface = "2 - atan(x)^2 - sinh(y)^2 + asin(x/5)*acos(y/5) + acosh(2 + x*y)/10"
"#;

/// [`ARCS`] without its constraint: q̈ in closed form, so the model has
/// Taylor series.
fn arcs_free() -> String {
    ARCS.replace("name = \"arcs\"", "name = \"arcs_free\"")
        .replace("constraints = [\"tanh(x)*x_dot + cosh(y)*y_dot\"]\n", "")
}

/// The arc and hyperbolic functions in every part: T, V, a constraint and a
/// wall, checked like [`EVERYTHING`] against the formulas and their
/// numeric derivatives, and present in the f32 programs as libm's f32
/// functions.
#[test]
fn arc_and_hyperbolic_functions_reach_the_emitted_programs() {
    let t = |q: &[f64], v: &[f64]| {
        (q[1] / 2.0).cosh() * v[0] * v[0] + (1.0 + q[0].atan().powi(2)) / 2.0 * v[1] * v[1]
    };
    let potential = |q: &[f64]| {
        (q[0] / 3.0).sinh() * q[1].tanh() + (q[0] / 4.0).asin() - (q[1] / 5.0).acos()
            + (q[0] / 2.0).asinh() * (q[1] / 3.0).atanh()
    };
    let rim = |q: &[f64]| {
        2.0 - q[0].atan().powi(2) - q[1].sinh().powi(2)
            + (q[0] / 5.0).asin() * (q[1] / 5.0).acos()
            + (2.0 + q[0] * q[1]).acosh() / 10.0
    };
    let d = derive("arcs", ARCS);
    let mut seed = 11u64;
    for _ in 0..20 {
        let q: Vec<f64> = (0..2).map(|_| 2.0 * common::lcg(&mut seed) - 1.0).collect();
        let v: Vec<f64> = (0..2).map(|_| 2.0 * common::lcg(&mut seed) - 1.0).collect();
        let inputs: Vec<f64> = [2.0].iter().chain(&q).chain(&v).copied().collect();
        check_energies(&d, &inputs, &q, &v, &t, &potential);
        let a = eval(&d, Quantity::Constraints, &inputs);
        close("A[0]", a[0], q[0].tanh(), 1e-12);
        close("A[1]", a[1], q[1].cosh(), 1e-12);
        check_wall(&d, 0, &inputs, &q, &v, &rim);
    }
    let f32_code = with_model_file("arcs", ARCS, |path| {
        dalembert_codegen::generate_f32(path).unwrap()
    });
    for f in [
        "atanf", "asinf", "acosf", "sinhf", "coshf", "tanhf", "asinhf", "acoshf", "atanhf",
    ] {
        assert!(f32_code.contains(f), "{f} in the f32 programs");
    }
}

/// The emitted Taylor series through the arc and hyperbolic functions (an
/// arc function's recurrence c′w = a′, a hyperbolic one's exponentials),
/// compiled by rustc and run, against the interpreter's: q, q̇ and a wall's
/// f to order 12, from a state inside the functions' domains.
#[test]
fn emitted_series_of_arc_and_hyperbolic_functions_match_the_interpreter() {
    use dalembert::runtime::taylor::{Coefficients, Series};
    use dalembert::runtime::{TaylorSeries, Walls};
    let text = arcs_free();
    assert!(!text.contains("constraints"));
    let d = derive("arcs_free", &text);
    let code = with_model_file("arcs_free", &text, |path| {
        dalembert_codegen::generate(path).unwrap()
    });
    let dir = std::path::PathBuf::from(env!("CARGO_TARGET_TMPDIR")).join("language-arcs");
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    std::fs::write(dir.join("m.rs"), code).unwrap();
    let (q, v) = ([0.3, -0.4], [0.7, 0.2]);
    std::fs::write(
        dir.join("main.rs"),
        format!(
            r#"
#[path = "m.rs"]
#[allow(dead_code)]
mod m;
use dalembert_runtime::taylor::Series;
use dalembert_runtime::{{FromParams, TaylorSeries, Walls}};
fn main() {{
    let model = m::ArcsFree::with_params(Default::default());
    let mut s = Series::at(&{q:?}, &{v:?});
    let mut scratch = Default::default();
    assert!(model.taylor_series(&mut s, &mut scratch, 12));
    let mut f = [0.0; dalembert_runtime::taylor::CAPACITY];
    assert!(model.surface_series(model.walls()[0], &s, &mut scratch, &mut f));
    for c in s.q.iter().chain(&s.v).chain([&f]) {{
        for x in &c[..=12] {{
            println!("{{x:e}}");
        }}
    }}
}}
"#
        ),
    )
    .unwrap();
    let out = common::rustc(
        &dir,
        "main.rs",
        &["--crate-type", "bin", "--crate-name", "arcs", "-O"],
    );
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let run = std::process::Command::new(dir.join("arcs"))
        .output()
        .unwrap();
    assert!(
        run.status.success(),
        "{}",
        String::from_utf8_lossy(&run.stderr)
    );
    let compiled: Vec<f64> = String::from_utf8(run.stdout)
        .unwrap()
        .lines()
        .map(|l| l.parse().unwrap())
        .collect();
    let m = dalembert_codegen::interpret::Interpreted::<2>::new(&d).unwrap();
    // (The interpreter's series keep no scratch of the caller's.)
    let mut s = Series::at(&q, &v);
    assert!(m.taylor_series(&mut s, &mut (), 12));
    let mut f: Coefficients = [0.0; dalembert::runtime::taylor::CAPACITY];
    assert!(m.surface_series(m.walls()[0], &s, &mut (), &mut f));
    let interpreted: Vec<f64> = (s.q.iter().chain(&s.v).chain([&f]))
        .flat_map(|c| c[..=12].to_vec())
        .collect();
    assert_eq!(compiled.len(), interpreted.len());
    for (i, (a, b)) in compiled.iter().zip(&interpreted).enumerate() {
        assert!(
            (a - b).abs() <= 1e-13 * (1.0 + b.abs()),
            "coefficient {i}: compiled {a:e}, interpreted {b:e}"
        );
    }
}

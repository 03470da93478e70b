//! Helpers shared by the integration tests.

#![allow(dead_code)] // each test binary uses some of these

use dalembert::runtime::linalg::correction;
use dalembert::runtime::simulate::{
    DormandPrince, Integrator, Rk4, Settings, State, Taylor, admissible, starting_velocity,
};
use dalembert::runtime::{Dynamics, FromParams, Model, Rows};
use nalgebra::DMatrix;
use proptest::test_runner::{Config, TestCaseError, TestRunner};

/// v projected onto ker A (Euclidean; membership in ker A does not depend on
/// the metric). A must have full row rank.
pub fn onto_kernel<const N: usize>(a: &Rows<N>, v: [f64; N]) -> [f64; N] {
    let k = a.len();
    if k == 0 {
        return v;
    }
    let am = DMatrix::from_fn(k, N, |i, j| a.as_slice()[i][j]);
    let vv = DMatrix::from_fn(N, 1, |i, _| v[i]);
    let lam = (&am * am.transpose())
        .lu()
        .solve(&(&am * &vv))
        .expect("A has full row rank");
    let w = vv - am.transpose() * lam;
    std::array::from_fn(|i| w[(i, 0)])
}

/// A small deterministic generator of numbers in [0, 1) (a linear
/// congruential generator: reproducible test inputs without a dependency).
pub fn lcg(state: &mut u64) -> f64 {
    *state = state
        .wrapping_mul(6364136223846793005)
        .wrapping_add(1442695040888963407);
    (*state >> 11) as f64 / (1u64 << 53) as f64
}

/// Runs `check` on `cases` random cases: the model with random parameters
/// (each the file's value times a factor in [1/2, 2]), a configuration in
/// [0.2, 1.4] per coordinate (clear of the Euler angles' singularity at
/// θ = 0) and velocities in [−3, 3].
pub fn for_random_cases<M: Model<Q, N> + FromParams, const Q: usize, const N: usize>(
    cases: u32,
    check: impl Fn(&M, &[f64; Q], [f64; N]) -> Result<(), TestCaseError>,
) {
    let parameters = M::with_params(Default::default()).parameter_names().len();
    let strategy = (
        proptest::collection::vec(0.5f64..2.0, parameters),
        proptest::array::uniform::<_, Q>(0.2f64..1.4),
        proptest::array::uniform::<_, N>(-3.0f64..3.0),
    );
    TestRunner::new(Config {
        cases,
        ..Config::default()
    })
    .run(&strategy, |(factors, q, v)| {
        check(&scaled::<M, Q, N>(&factors), &q, v)
    })
    .unwrap();
}

/// The model with each parameter the file's value times `factors[i]`.
pub fn scaled<M: Model<Q, N> + FromParams, const Q: usize, const N: usize>(factors: &[f64]) -> M {
    let mut model = M::with_params(Default::default());
    for (i, f) in factors.iter().enumerate() {
        let x = model.parameter(i).unwrap_or(1.0);
        model.set_parameter(i, x * f);
    }
    model
}

/// The built-in model files (`models/*.toml`), in name order: the order
/// the build script derives them in.
pub fn model_files() -> Vec<std::path::PathBuf> {
    toml_files(&std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("models"))
}

/// The `*.toml` files in `dir`, in name order.
pub fn toml_files(dir: &std::path::Path) -> Vec<std::path::PathBuf> {
    let mut files: Vec<_> = std::fs::read_dir(dir)
        .unwrap()
        .map(|e| e.unwrap().path())
        .filter(|p| p.extension().is_some_and(|e| e == "toml"))
        .collect();
    files.sort();
    files
}

/// The model file's initial state of `m`, at t = 0: the velocities the
/// file leaves out follow from the constraints, as `simulate` starts.
pub fn initial<M: Dynamics<N>, const N: usize>(m: &M) -> State<N> {
    let q = m.initial_coordinates();
    let given = m.initial_velocities_given();
    let (v, _) = starting_velocity(m, &q, &m.initial_velocities(), &given)
        .expect("the file's start can be put on the constraints");
    State { t: 0.0, q, v }
}

/// Dormand–Prince at `rtol`, with atol a hundredth of it.
pub fn dormand_prince(rtol: f64) -> Settings {
    Settings {
        integrator: Integrator::DormandPrince(DormandPrince {
            rtol,
            atol: rtol * 1e-2,
            max_step: f64::INFINITY,
        }),
        ..Settings::default()
    }
}

/// Runs `test` of this test binary in a process of its own (with `env`
/// set, and `--ignored` for a test that runs only there) and asserts that
/// it passed. Its output is shown only when it failed, so the suite's
/// report counts each test once.
pub fn in_child(test: &str, ignored: bool, env: &[(&str, &std::ffi::OsStr)]) {
    let mut child = std::process::Command::new(std::env::current_exe().unwrap());
    child.args(["--exact", test, "--test-threads=1"]);
    if ignored {
        child.arg("--ignored");
    }
    for (name, value) in env {
        child.env(name, value);
    }
    let out = child.output().unwrap();
    assert!(
        out.status.success(),
        "{test} failed in its own process:\n{}{}",
        String::from_utf8_lossy(&out.stdout),
        String::from_utf8_lossy(&out.stderr)
    );
}

/// A random direction (δq, δv) tangent to the constraint manifold at
/// (q, v) (`simulate::tangent_direction` of a random one). `None` where
/// the rows cannot be solved.
pub fn admissible_direction<M: Dynamics<N>, const N: usize>(
    m: &M,
    q: &[f64; N],
    v: &[f64; N],
    seed: &mut u64,
) -> Option<([f64; N], [f64; N])> {
    let dq: [f64; N] = std::array::from_fn(|_| lcg(seed) - 0.5);
    let dv: [f64; N] = std::array::from_fn(|_| lcg(seed) - 0.5);
    dalembert::runtime::simulate::tangent_direction(m, q, v, &dq, &dv).ok()
}

/// The derivative of `f` at 0 by central differences with steps h and h/2,
/// combined by one Richardson step (error O(h⁴)).
pub fn richardson(f: impl Fn(f64) -> Vec<f64>, h: f64) -> Vec<f64> {
    let central = |h: f64| -> Vec<f64> {
        let (plus, minus) = (f(h), f(-h));
        plus.iter()
            .zip(&minus)
            .map(|(a, b)| (a - b) / (2.0 * h))
            .collect()
    };
    let (coarse, fine) = (central(h), central(h / 2.0));
    fine.iter()
        .zip(&coarse)
        .map(|(f, c)| (4.0 * f - c) / 3.0)
        .collect()
}

/// Carlson's symmetric elliptic integral R_F(x, y, z) by duplication.
pub fn carlson_rf(mut x: f64, mut y: f64, mut z: f64) -> f64 {
    for _ in 0..60 {
        let l = (x * y).sqrt() + (y * z).sqrt() + (z * x).sqrt();
        x = (x + l) / 4.0;
        y = (y + l) / 4.0;
        z = (z + l) / 4.0;
    }
    1.0 / ((x + y + z) / 3.0).sqrt()
}

/// Incomplete elliptic integral of the first kind F(φ, k).
pub fn elliptic_f(phi: f64, k: f64) -> f64 {
    let (s, c) = phi.sin_cos();
    s * carlson_rf(c * c, 1.0 - k * k * s * s, 1.0)
}

/// Time for a pendulum of length l released from rest at angle θ₀ (from
/// the downward vertical) to swing through the bottom to angle θ on the
/// other side: √(l/g) [K(k) + F(φ, k)], k = sin(θ₀/2), sin φ = sin(θ/2)/k.
pub fn pendulum_time(l: f64, g: f64, theta0: f64, theta: f64) -> f64 {
    let k = (theta0 / 2.0).sin();
    let phi = ((theta / 2.0).sin() / k).asin();
    (l / g).sqrt() * (elliptic_f(std::f64::consts::FRAC_PI_2, k) + elliptic_f(phi, k))
}

/// The derivation of the model file `dir/name.toml` (`dir` from the crate's
/// root), or a panic saying why not.
pub fn derived(dir: &str, name: &str) -> dalembert_codegen::Derivation {
    let file = std::path::Path::new(env!("CARGO_MANIFEST_DIR"))
        .join(dir)
        .join(format!("{name}.toml"));
    dalembert_codegen::derive(&file).unwrap_or_else(|e| panic!("{dir}/{name}: {e}"))
}

/// The runtime's rlib these tests were built against, in `deps`.
fn runtime_rlib(deps: &std::path::Path) -> std::path::PathBuf {
    std::fs::read_dir(deps)
        .unwrap()
        .map(|e| e.unwrap().path())
        .filter(|p| {
            let name = p.file_name().unwrap().to_string_lossy().into_owned();
            name.starts_with("libdalembert_runtime-") && name.ends_with(".rlib")
        })
        .max_by_key(|p| p.metadata().unwrap().modified().unwrap())
        .expect("the runtime's rlib is built before the tests")
}

/// rustc (edition 2024) on `dir/source` against the runtime, with `args`
/// (crate type, name, options), writing into `dir`.
pub fn rustc(dir: &std::path::Path, source: &str, args: &[&str]) -> std::process::Output {
    let deps = std::env::current_exe()
        .unwrap()
        .parent()
        .unwrap()
        .to_path_buf();
    std::process::Command::new(std::env::var("RUSTC").unwrap_or_else(|_| "rustc".into()))
        .args(["--edition", "2024"])
        .args(args)
        .arg("-L")
        .arg(format!("dependency={}", deps.display()))
        .arg("--extern")
        .arg(format!(
            "dalembert_runtime={}",
            runtime_rlib(&deps).display()
        ))
        .arg("--out-dir")
        .arg(dir)
        .arg(dir.join(source))
        .output()
        .expect("rustc runs")
}

/// The model file `tests/walls/{name}.toml`, interpreted.
pub fn wall_model<const N: usize>(name: &str) -> dalembert_codegen::interpret::Interpreted<N> {
    let file = std::path::Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("tests/walls")
        .join(format!("{name}.toml"));
    let d = dalembert_codegen::derive(&file).unwrap_or_else(|e| panic!("{name}: {e}"));
    dalembert_codegen::interpret::Interpreted::new(&d).unwrap_or_else(|e| panic!("{name}: {e}"))
}

/// Each integrator with the step of the differences and the agreement
/// required. A fixed-step RK4 run's end moves with the start by more than
/// rounding (its last steps before each collision and before t_end are cut
/// where the collision falls): on the spinning ball the discrepancy grew as
/// 1/ε (1.8e-6 at ε = 1e-4, 8e-6 at 1e-5, 3.8e-5 at 1e-6) and did not move
/// when RK4's step was halved, so its differences take a larger ε.
pub fn integrators() -> [(&'static str, Settings, f64, f64); 3] {
    let with = |integrator| Settings {
        integrator,
        ..Settings::default()
    };
    [
        (
            "Dormand–Prince",
            with(Integrator::DormandPrince(DormandPrince {
                rtol: 1e-12,
                atol: 1e-14,
                max_step: f64::INFINITY,
            })),
            1e-5,
            1e-6,
        ),
        (
            "Taylor",
            with(Integrator::Taylor(Taylor {
                tolerance: 1e-15,
                ..Taylor::default()
            })),
            1e-5,
            1e-6,
        ),
        ("RK4", with(Integrator::Rk4(Rk4 { step: 2e-4 })), 1e-4, 1e-5),
    ]
}

/// (q, v) moved onto h(q) = 0 (Gauss–Newton) and v onto ker A(q).
pub fn onto_manifold<M: Dynamics<N>, const N: usize>(
    m: &M,
    q: [f64; N],
    v: [f64; N],
) -> ([f64; N], [f64; N]) {
    let mut q = q;
    let identity: [[f64; N]; N] =
        std::array::from_fn(|i| std::array::from_fn(|j| (i == j) as u8 as f64));
    for _ in 0..5 {
        let h = m.holonomic(&q);
        if h.as_slice().is_empty() {
            break;
        }
        let a = m.constraints(&q);
        let rows = &a.as_slice()[..h.as_slice().len()];
        let d = correction(&identity, rows, h.as_slice()).unwrap();
        q = std::array::from_fn(|i| q[i] - d[i]);
    }
    (q, admissible(m, &q, &v).unwrap())
}

/// The largest gap between `got` and `fd`, relative to fd's largest
/// entry (at least 1), and that size.
pub fn relative_gap(got: &[f64], fd: &[f64]) -> (f64, f64) {
    let size = fd.iter().fold(1.0_f64, |a, x| a.max(x.abs()));
    let gap = got
        .iter()
        .zip(fd)
        .fold(0.0_f64, |a, (g, f)| a.max((g - f).abs()));
    (gap / size, size)
}

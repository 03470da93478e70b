//! Derivatives through the generated functions: q̈'s tangent and each
//! collision map's, the generator's forward differentiation of their
//! programs, against central differences of the same functions with
//! Richardson extrapolation, on every generated model at random parameters
//! and states, and on the interpreted models of `tests/walls/` (walls
//! through square roots, quotients, logarithms, sines, tangents and
//! exponentials; sleighs' constraints, one with a blade offset and a rink
//! that move with the parameters; a pendulum's holonomic constraint).
//! And an exact identity: the map is linear in admissible v⁻, so its
//! derivative along an admissible δv⁻ is (I − 2P)δv⁻. The derivatives by
//! the parameters (of q̈, of each map and each wall's f) the same way,
//! with the parameters moved along a random direction.

mod common;

use std::path::Path;

use dalembert::for_each_model;
use dalembert::models::*;
use dalembert::runtime::dynamics::accelerations;
use dalembert::runtime::linalg::{correction, mat_vec};
use dalembert::runtime::prelude::*;
use dalembert_codegen::interpret::Interpreted;
use proptest::prelude::prop_assert;
use proptest::test_runner::TestCaseError;

use common::{admissible_direction, for_random_cases, onto_kernel};

/// The error allowed, relative to the size of the derivative and of the
/// function (a central difference's rounding grows with the latter).
const TOL: f64 = 1e-8;

/// The derivative of `f` at 0 by central differences with step `h`,
/// improved by one Richardson step (error O(h⁴)), and an estimate of that
/// result's error: its distance from the same at step h/4 (a wall's map
/// near its centre of curvature changes on a scale of |q|, where a fixed
/// step's error is no longer small).
fn differences(f: impl Fn(f64) -> Vec<f64>, h: f64) -> (Vec<f64>, Vec<f64>) {
    let (rough, fine) = (common::richardson(&f, h), common::richardson(&f, h / 4.0));
    let error = fine
        .iter()
        .zip(&rough)
        .map(|(a, b)| (a - b).abs())
        .collect();
    (fine, error)
}

fn max_abs(x: &[f64]) -> f64 {
    x.iter().fold(0.0_f64, |m, y| m.max(y.abs()))
}

/// The derivative against the differences: within [`TOL`] relative to the
/// size of both and of the function (a central difference's rounding grows
/// with the latter), plus the differences' own estimated error.
fn agree(
    what: &str,
    derivative: &[f64],
    (fd, error): &(Vec<f64>, Vec<f64>),
    value: &[f64],
) -> Result<(), String> {
    let scale = 1.0 + max_abs(fd) + max_abs(value);
    for (i, (d, x)) in derivative.iter().zip(fd).enumerate() {
        let within = (d - x).abs() <= TOL * scale + error[i]; // false for NaN
        if !within {
            return Err(format!(
                "{what}, entry {i}: derivative {d:e}, differences {x:e} (scale {scale:e}, their error {:e})",
                error[i]
            ));
        }
    }
    Ok(())
}

/// `x + s·e_j` for the j-th of the 2N phase directions.
fn moved<const N: usize>(q: &[f64; N], v: &[f64; N], j: usize, s: f64) -> ([f64; N], [f64; N]) {
    let (mut q, mut v) = (*q, *v);
    if j < N {
        q[j] += s
    } else {
        v[j - N] += s
    }
    (q, v)
}

/// ∂q̈/∂(q, v) column by column against differences of q̈ itself, where the
/// model writes q̈ out; and the tangent's value is q̈.
fn accelerations_by_differences<M: Dynamics<N>, const N: usize>(
    m: &M,
    q: &[f64; N],
    v: [f64; N],
) -> Result<(), TestCaseError> {
    let v = onto_kernel(&m.constraints(q), v);
    let Some(a) = m.closed_form_accelerations(q, &v) else {
        assert!(m.accelerations_tangent(q, &v, q, &v).is_none());
        return Ok(());
    };
    if !a.iter().all(|x| x.is_finite()) {
        return Ok(()); // a singular configuration: nothing to differentiate
    }
    let (by_q, by_v) = m
        .accelerations_jacobian(q, &v)
        .expect("a model that writes q̈ out has its tangent");
    let (value, _) = m
        .accelerations_tangent(q, &v, &[0.0; N], &[0.0; N])
        .unwrap();
    assert_eq!(value, a, "{}: the tangent's q̈ is q̈", m.name());
    for j in 0..2 * N {
        let column: Vec<f64> = (0..N)
            .map(|i| if j < N { by_q[i][j] } else { by_v[i][j - N] })
            .collect();
        let fd = differences(
            |s| {
                let (q, v) = moved(q, &v, j, s);
                m.closed_form_accelerations(&q, &v).unwrap().to_vec()
            },
            1e-3,
        );
        agree(&format!("{} ∂q̈/∂x{j}", m.name()), &column, &fd, &a).map_err(TestCaseError::fail)?;
    }
    Ok(())
}

/// Each wall's ∂v⁺/∂(q, v⁻) against differences of the map, at an
/// admissible v⁻; along an admissible δv⁻ it is (I − 2P)δv⁻. Walls whose
/// map is solved at run time have no tangent (`None`), the rest must.
fn collisions<M: Walls<Q, N>, const Q: usize, const N: usize>(
    m: &M,
    q: &[f64; Q],
    v: [f64; N],
) -> Result<(), TestCaseError> {
    let a = m.constraints(q);
    let v = onto_kernel(&a, v);
    for &wall in m.walls() {
        let name = format!("{} {}", m.name(), m.wall_name(wall));
        let Some((by_q, by_v)) = m.collide_jacobian(wall, q, &v) else {
            continue;
        };
        let after = m.collide(wall, q, &v);
        if !after.iter().all(|x| x.is_finite()) {
            continue;
        }
        for j in 0..Q + N {
            let column: Vec<f64> = (0..N)
                .map(|i| if j < Q { by_q[i][j] } else { by_v[i][j - Q] })
                .collect();
            let fd = differences(
                |s| {
                    let (mut q, mut v) = (*q, v);
                    if j < Q {
                        q[j] += s
                    } else {
                        v[j - Q] += s
                    }
                    m.collide(wall, &q, &v).to_vec()
                },
                1e-3,
            );
            agree(&format!("{name} ∂v⁺/∂x{j}"), &column, &fd, &after)
                .map_err(TestCaseError::fail)?;
        }
        // (I − 2P)δv along an admissible direction: δv = v itself.
        let p = m.projector(wall, q);
        let pv = mat_vec(&p, &v);
        let expected: Vec<f64> = (0..N).map(|i| v[i] - 2.0 * pv[i]).collect();
        let along: Vec<f64> = (0..N)
            .map(|i| (0..N).map(|k| by_v[i][k] * v[k]).sum())
            .collect();
        let exact = (expected, vec![0.0; N]);
        agree(&format!("{name} ∂v⁺/∂v⁻ v⁻"), &along, &exact, &v).map_err(TestCaseError::fail)?;
    }
    Ok(())
}

/// Along directions tangent to the constraint manifold every form of q̈
/// and of the map has the same derivative, so the generated tangents
/// (closed forms, elimination, maps shortened by A v = 0) must equal the
/// differences of the runtime's own numeric solves: q̈ from G, h, A and
/// Ȧq̇ (`dynamics::accelerations`), v⁺ = v − 2G⁻¹Bᵀ(BG⁻¹Bᵀ)⁻¹Bv.
fn against_numeric_solves<M: Surfaces<N>, const N: usize>(
    m: &M,
    q: &[f64; N],
    v: [f64; N],
) -> Result<(), TestCaseError> {
    let v = onto_kernel(&m.constraints(q), v);
    let mut seed = q[0].to_bits() ^ v[0].to_bits();
    let Some((dq, dv)) = admissible_direction(m, q, &v, &mut seed) else {
        return Ok(());
    };
    let at = |s: f64| -> ([f64; N], [f64; N]) {
        (
            std::array::from_fn(|i| q[i] + s * dq[i]),
            std::array::from_fn(|i| v[i] + s * dv[i]),
        )
    };
    if let Some((a, da)) = m.accelerations_tangent(q, &v, &dq, &dv) {
        let Ok(numeric) = accelerations(m, q, &v) else {
            return Ok(());
        };
        let fd = differences(
            |s| {
                let (q, v) = at(s);
                accelerations(m, &q, &v).map_or(vec![f64::NAN; N], |x| x.qdd.to_vec())
            },
            1e-3,
        );
        agree(
            &format!("{} q̈ along an admissible direction", m.name()),
            &da,
            &fd,
            &a,
        )
        .map_err(TestCaseError::fail)?;
        let close = a
            .iter()
            .zip(&numeric.qdd)
            .all(|(x, y)| (x - y).abs() <= 1e-9 * (1.0 + y.abs()));
        prop_assert!(
            close,
            "{}: q̈ {a:?} against the numeric {:?}",
            m.name(),
            numeric.qdd
        );
    }
    for &wall in m.walls() {
        let Some((after, dafter)) = m.collide_tangent(wall, q, &v, &dq, &dv) else {
            continue;
        };
        let solve = |q: &[f64; N], v: &[f64; N]| -> Vec<f64> {
            let b = m.wall_rows(wall, q);
            let r = b.apply(v);
            correction(&m.mass_matrix(q), b.as_slice(), r.as_slice())
                .map_or(vec![f64::NAN; N], |d| {
                    (0..N).map(|i| v[i] - 2.0 * d[i]).collect()
                })
        };
        let fd = differences(
            |s| {
                let (q, v) = at(s);
                solve(&q, &v)
            },
            1e-3,
        );
        let name = format!(
            "{} {} v⁺ along an admissible direction",
            m.name(),
            m.wall_name(wall)
        );
        agree(&name, &dafter, &fd, &after).map_err(TestCaseError::fail)?;
    }
    Ok(())
}

/// A random direction of the parameters, from the state's bits.
fn parameter_direction(count: usize, seed: u64) -> Vec<f64> {
    let mut state = seed | 1;
    (0..count)
        .map(|_| 2.0 * common::lcg(&mut state) - 1.0)
        .collect()
}

/// `m` with its parameters moved by `s·dp`.
fn moved_parameters<M: Model<Q, N> + Clone, const Q: usize, const N: usize>(
    m: &M,
    dp: &[f64],
    s: f64,
) -> M {
    let mut moved = m.clone();
    for (k, d) in dp.iter().enumerate() {
        let x = m.parameter(k).expect("a parameter for each entry");
        moved.set_parameter(k, x + s * d);
    }
    moved
}

/// The derivatives by the parameters (q̈'s, each wall's map and f) along a
/// random direction against differences of the functions with the
/// parameters moved, the state held; the tangents' values are the
/// functions'. A direction of the wrong length has none.
fn parameters_by_differences<M: Surfaces<N> + Clone, const N: usize>(
    m: &M,
    q: &[f64; N],
    v: [f64; N],
) -> Result<(), TestCaseError> {
    let v = onto_kernel(&m.constraints(q), v);
    let count = m.parameter_names().len();
    let dp = parameter_direction(count, q[0].to_bits() ^ v[0].to_bits());
    let wrong = vec![1.0; count + 1];
    let fd = |f: &dyn Fn(&M) -> Vec<f64>| differences(|s| f(&moved_parameters(m, &dp, s)), 1e-3);
    if let Some(a) = m.closed_form_accelerations(q, &v) {
        let (value, da) = m
            .accelerations_parameter_tangent(q, &v, &dp)
            .expect("a model that writes q̈ out has its derivative by the parameters");
        assert_eq!(value, a, "{}: the tangent's q̈ is q̈", m.name());
        assert!(m.accelerations_parameter_tangent(q, &v, &wrong).is_none());
        if a.iter().all(|x| x.is_finite()) {
            let fd = fd(&|m: &M| m.closed_form_accelerations(q, &v).unwrap().to_vec());
            agree(&format!("{} ∂q̈/∂p δp", m.name()), &da, &fd, &a).map_err(TestCaseError::fail)?;
        }
    }
    for &wall in m.walls() {
        let name = format!("{} {}", m.name(), m.wall_name(wall));
        let (f, df) = m
            .surface_parameter_tangent(wall, q, &dp)
            .expect("every generated wall has f's derivative by the parameters");
        assert_eq!(f, m.surface(wall, q), "{name}: the tangent's f is f");
        assert!(m.surface_parameter_tangent(wall, q, &wrong).is_none());
        let fd_f = fd(&|m: &M| vec![m.surface(wall, q)]);
        agree(&format!("{name} ∂f/∂p δp"), &[df], &fd_f, &[f]).map_err(TestCaseError::fail)?;
    }
    collisions_by_parameters(m, q, v)
}

/// Each wall's ∂v⁺/∂p along a random direction of the parameters against
/// differences of the map with the parameters moved, at an admissible v⁻.
fn collisions_by_parameters<M: Walls<Q, N> + Clone, const Q: usize, const N: usize>(
    m: &M,
    q: &[f64; Q],
    v: [f64; N],
) -> Result<(), TestCaseError> {
    let v = onto_kernel(&m.constraints(q), v);
    let count = m.parameter_names().len();
    let dp = parameter_direction(count, v[0].to_bits());
    for &wall in m.walls() {
        let name = format!("{} {}", m.name(), m.wall_name(wall));
        let Some((after, dafter)) = m.collide_parameter_tangent(wall, q, &v, &dp) else {
            assert!(m.collide_tangent(wall, q, &v, q, &v).is_none(), "{name}");
            continue;
        };
        assert_eq!(
            after,
            m.collide(wall, q, &v),
            "{name}: the tangent's v⁺ is v⁺"
        );
        if after.iter().all(|x| x.is_finite()) {
            let fd = differences(
                |s| moved_parameters(m, &dp, s).collide(wall, q, &v).to_vec(),
                1e-3,
            );
            agree(&format!("{name} ∂v⁺/∂p δp"), &dafter, &fd, &after)
                .map_err(TestCaseError::fail)?;
        }
    }
    Ok(())
}

/// The walls of a generated model whose collision map has no tangent.
fn tangent_walls<M: Walls<Q, N> + FromParams, const Q: usize, const N: usize>() -> Vec<String> {
    let m = M::with_params(Default::default());
    let (q, v) = ([0.5; Q], [0.0; N]);
    m.walls()
        .iter()
        .filter(|&&w| m.collide_tangent(w, &q, &v, &q, &v).is_none())
        .map(|&w| format!("{} {}", m.name(), m.wall_name(w)))
        .collect()
}

macro_rules! tangent_test {
    ($module:ident, $ty:ident, 0, $n:literal) => {
        #[test]
        fn $module() {
            for_random_cases::<$ty, 0, $n>(64, collisions);
            for_random_cases::<$ty, 0, $n>(64, collisions_by_parameters);
        }
    };
    ($module:ident, $ty:ident, $q:literal, $n:literal) => {
        #[test]
        fn $module() {
            for_random_cases::<$ty, $q, $n>(64, collisions);
            for_random_cases::<$ty, $n, $n>(64, accelerations_by_differences);
            for_random_cases::<$ty, $n, $n>(64, against_numeric_solves);
            for_random_cases::<$ty, $n, $n>(64, parameters_by_differences);
        }
    };
}

for_each_model!(tangent_test);

/// Every generated wall's collision map has a tangent (a map solved at run
/// time from G and B would have none; no built-in model has one).
#[test]
fn every_generated_wall_has_a_tangent() {
    let mut without = Vec::new();
    macro_rules! collect {
        ($module:ident, $ty:ident, $q:literal, $n:literal) => {
            without.extend(tangent_walls::<$ty, $q, $n>());
        };
    }
    for_each_model!(collect);
    assert_eq!(without, Vec::<String>::new());
}

/// The model file `tests/walls/{name}.toml`, interpreted.
fn interpreted<const N: usize>(name: &str) -> Interpreted<N> {
    let file = Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("tests/walls")
        .join(format!("{name}.toml"));
    let d = dalembert_codegen::derive(&file).unwrap_or_else(|e| panic!("{name}: {e}"));
    Interpreted::new(&d).unwrap_or_else(|e| panic!("{name}: {e}"))
}

/// The same checks on interpreted models with walls through functions
/// (uses the symbolic engine: run one test at a time).
#[test]
fn interpreted_models_with_nonpolynomial_walls() {
    fn both<const N: usize>(
        m: &Interpreted<N>,
        q: &[f64; N],
        v: [f64; N],
    ) -> Result<(), TestCaseError> {
        collisions(m, q, v)?;
        accelerations_by_differences(m, q, v)?;
        against_numeric_solves(m, q, v)?;
        parameters_by_differences(m, q, v)
    }
    fn run<const N: usize>(name: &str) {
        let m = interpreted::<N>(name);
        let mut state = 7_u64;
        for _ in 0..32 {
            // Inside the walls' domains (|q| < 0.6 for the disks).
            let q: [f64; N] = std::array::from_fn(|_| 0.6 * common::lcg(&mut state) - 0.3);
            let v: [f64; N] = std::array::from_fn(|_| 6.0 * common::lcg(&mut state) - 3.0);
            both(&m, &q, v).unwrap_or_else(|e| panic!("{name}: {e}"));
        }
    }
    for name in [
        "disk_log",
        "disk_power",
        "disk_quotient",
        "disk_sin",
        "disk_sqrt",
        "disk_tan",
        "disk_thin_ring",
        "oval_exp",
        "pendulum_peg",
        "disk_atan",
        "disk_asin",
        "disk_acos",
        "disk_sinh",
        "disk_cosh",
        "disk_tanh",
        "disk_asinh",
        "disk_acosh",
        "disk_atanh",
        "disk_functions",
    ] {
        run::<2>(name);
    }
    run::<3>("sleigh_rink");
    run::<3>("sleigh_oval");
}

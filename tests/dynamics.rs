//! The generated equations of motion G q̈ + h = Aᵀλ, A q̇ = 0, solved by the
//! runtime, checked against what they must satisfy independently of how
//! they were derived: the energy T + V is constant along the motion (the
//! reactions do no work on admissible velocities), A q̇ stays zero to second
//! order, both by finite differences of the generated T, V and A; and the
//! analytic motion of the Chaplygin sleigh (puck); the §3.2 ball's three
//! models meet the floor by one map. The generated closed forms of q̈ are
//! checked against the equations themselves, on every model, at random
//! parameters and states.

use dalembert::for_each_model;
use dalembert::models::*;
use dalembert::runtime::dynamics::{DynamicsError, accelerations, qdd};
use dalembert::runtime::linalg::mat_vec;
use dalembert::runtime::prelude::*;
use nalgebra::DMatrix;
use proptest::prelude::*;

mod common;
use common::{for_random_cases, lcg, onto_kernel};

/// v projected onto ker A(q).
fn admissible<M: Dynamics<N>, const N: usize>(m: &M, q: &[f64; N], v: [f64; N]) -> [f64; N] {
    onto_kernel(&m.constraints(q), v)
}

fn step<const N: usize>(x: &[f64; N], dx: &[f64; N], e: f64) -> [f64; N] {
    std::array::from_fn(|i| x[i] + e * dx[i])
}

/// dE/dt = 0 and d(A q̇)/dt = 0 along (q̇, q̈), by central differences.
fn check_motion<M: Dynamics<N>, const N: usize>(m: &M, seed: u64) {
    let mut s = seed;
    for _ in 0..50 {
        let q: [f64; N] = std::array::from_fn(|_| 0.2 + 1.2 * lcg(&mut s));
        let v = admissible(m, &q, std::array::from_fn(|_| -2.0 + 4.0 * lcg(&mut s)));
        let acc = accelerations(m, &q, &v).unwrap();
        let a = acc.qdd;
        let eps = 1e-5;
        let (qp, vp) = (step(&q, &v, eps), step(&v, &a, eps));
        let (qm, vm) = (step(&q, &v, -eps), step(&v, &a, -eps));
        let de = (m.energy(&qp, &vp) - m.energy(&qm, &vm)) / (2.0 * eps);
        let scale = 1.0 + m.kinetic_energy(&q, &v).abs();
        assert!(de.abs() < 1e-6 * scale, "{}: dE/dt = {de}", m.name());
        let ap = m.constraints(&qp).apply(&vp);
        let am = m.constraints(&qm).apply(&vm);
        for (x, y) in ap.as_slice().iter().zip(am.as_slice()) {
            let d = (x - y) / (2.0 * eps);
            assert!(d.abs() < 1e-6 * scale, "{}: d(Aq̇)/dt = {d}", m.name());
        }
    }
}

#[test]
fn energy_and_constraints_hold_along_the_motion() {
    check_motion(&Puck::default(), 1);
    check_motion(&BallWallEuler::default(), 2);
}

/// The sleigh with its blade at the centre of mass: the heading rate and the
/// speed along the blade are constant (φ̈ = 0, u̇ = ẍ cos φ + ÿ sin φ = 0).
#[test]
fn chaplygin_sleigh_moves_as_known() {
    let puck = Puck::default();
    let mut s = 3;
    for _ in 0..50 {
        let phi = -3.0 + 6.0 * lcg(&mut s);
        let (u, w) = (-2.0 + 4.0 * lcg(&mut s), -2.0 + 4.0 * lcg(&mut s));
        let q = [lcg(&mut s), lcg(&mut s), phi];
        let v = [u * phi.cos(), u * phi.sin(), w];
        let acc = accelerations(&puck, &q, &v).unwrap();
        let [xdd, ydd, phidd] = acc.qdd;
        assert!(phidd.abs() < 1e-12);
        assert!((xdd * phi.cos() + ydd * phi.sin()).abs() < 1e-12);
        // The blade's reaction holds the puck on its circle: m u φ̇ = |λ|.
        assert!((acc.lambda[0].abs() - puck.params().m * (u * w).abs()).abs() < 1e-9);
    }
}

#[test]
fn singular_and_non_finite_states_are_typed_errors() {
    let ball = BallWallEuler::default();
    // θ = 0: the Euler angles' singularity, G is singular.
    let q = [1.0, 0.0, 0.3, 0.0, 0.2];
    assert_eq!(
        accelerations(&ball, &q, &[0.0; 5]),
        Err(DynamicsError::SingularMassMatrix)
    );
    let q = [f64::NAN, 0.0, 0.3, 1.0, 0.2];
    assert_eq!(
        accelerations(&ball, &q, &[0.0; 5]),
        Err(DynamicsError::NonFinite)
    );
}

/// The closed form q̈ at (q, v) (v made admissible) solves the equations:
/// r = G q̈ + h lies in the row space of A (r = Aᵀλ for some λ) and
/// A q̈ + Ȧq̇ = 0. Both are checked with the generated G, h, A and Ȧq̇ only.
fn check_closed_form<M: Dynamics<N>, const N: usize>(
    m: &M,
    q: &[f64; N],
    v: [f64; N],
) -> Result<(), TestCaseError> {
    let a = m.constraints(q);
    let v = onto_kernel(&a, v);
    let Some(x) = m.closed_form_accelerations(q, &v) else {
        return Err(TestCaseError::fail(format!("{}: no closed form", m.name())));
    };
    let h = m.forcing(q, &v);
    let gx = mat_vec(&m.mass_matrix(q), &x);
    let r: [f64; N] = std::array::from_fn(|i| gx[i] + h[i]);
    let scale = 1.0 + h.iter().chain(&gx).fold(0.0_f64, |s, y| s.max(y.abs()));
    // r minus its Euclidean projection onto the row space of A.
    let k = a.len();
    let rv = DMatrix::from_fn(N, 1, |i, _| r[i]);
    let off = if k == 0 {
        rv
    } else {
        let am = DMatrix::from_fn(k, N, |i, j| a.as_slice()[i][j]);
        let lam = (&am * am.transpose()).lu().solve(&(&am * &rv)).unwrap();
        rv - am.transpose() * lam
    };
    prop_assert!(
        off.amax() <= 1e-9 * scale,
        "{}: G q̈ + h off the row space of A by {}",
        m.name(),
        off.amax()
    );
    let drift = m.constraint_drift(q, &v);
    for (row, c) in a.as_slice().iter().zip(drift) {
        let ax: f64 = row.iter().zip(&x).map(|(p, y)| p * y).sum();
        prop_assert!(
            (ax + c).abs() <= 1e-9 * scale,
            "{}: A q̈ + Ȧq̇ = {}",
            m.name(),
            ax + c
        );
    }
    Ok(())
}

/// 256 random cases (see `common::for_random_cases`), on every model with a
/// closed form.
fn closed_form<M: Dynamics<N> + FromParams, const N: usize>() {
    let defaults = M::with_params(Default::default());
    if defaults
        .closed_form_accelerations(&[0.5; N], &[0.0; N])
        .is_none()
    {
        // A model without one (`closed_forms_exist_where_expected` says
        // which have one) solves at run time.
        return;
    }
    for_random_cases::<M, N, N>(256, check_closed_form);
}

macro_rules! closed_form_test {
    // Instantaneous models have no motion.
    ($module:ident, $ty:ident, 0, $n:literal) => {};
    ($module:ident, $ty:ident, $q:literal, $n:literal) => {
        #[test]
        fn $module() {
            closed_form::<$ty, $n>();
        }
    };
}

mod closed_form_solves_the_equations {
    use super::*;
    for_each_model!(closed_form_test);
}

/// The generator derives q̈ in closed form wherever G⁻¹ is symbolic, and
/// writes the solve out by elimination for structured chains, so every
/// model with coordinates has it (instantaneous models have no `Dynamics`
/// at all).
#[test]
fn closed_forms_exist_where_expected() {
    fn has<M: Dynamics<N> + Default, const N: usize>() -> bool {
        M::default()
            .closed_form_accelerations(&[0.5; N], &[0.0; N])
            .is_some()
    }
    assert!(has::<BallBounce, 6>());
    assert!(has::<BallWallEuler, 5>());
    assert!(has::<PendulumWall, 2>());
    assert!(has::<Puck, 3>());
    assert!(has::<MassesOnLine, 2>());
    assert!(has::<Chain3, 3>());
    assert!(has::<Chain4Symbolic, 4>());
    assert!(has::<Chain4, 4>());
    assert!(has::<Chain8, 8>());
    assert!(has::<BallWallQuaternion, 6>());
}

/// Where the closed form is not finite (G singular), `qdd` falls back to the
/// numeric solve and reports why; elsewhere both agree.
#[test]
fn qdd_uses_the_closed_form_and_falls_back() {
    let ball = BallWallEuler::default();
    let q = [1.0, 0.0, 0.3, 0.0, 0.2];
    assert!(ball.closed_form_accelerations(&q, &[0.0; 5]).is_some());
    assert_eq!(
        qdd(&ball, &q, &[0.0; 5]),
        Err(DynamicsError::SingularMassMatrix)
    );
    let mut s = 11;
    for _ in 0..100 {
        let q: [f64; 5] = std::array::from_fn(|_| 0.2 + 1.2 * lcg(&mut s));
        let v = admissible(&ball, &q, std::array::from_fn(|_| -2.0 + 4.0 * lcg(&mut s)));
        let fast = qdd(&ball, &q, &v).unwrap();
        let slow = accelerations(&ball, &q, &v).unwrap().qdd;
        for (a, b) in fast.iter().zip(&slow) {
            assert!(
                (a - b).abs() < 1e-10 * (1.0 + b.abs()),
                "{fast:?} vs {slow:?}"
            );
        }
    }
}

/// The starting state of `[initial]` is a function of the parameters: the
/// §3.2.1 ball starts on the floor (`z = "r"`) at any radius; the inherent
/// constant keeps the file's values.
#[test]
fn the_initial_state_follows_the_parameters() {
    use dalembert::models::ball_bounce::Params;
    for r in [0.5, 1.0, 0.125] {
        let ball = BallBounce::with_params(Params {
            r,
            ..Params::default()
        });
        let q = ball.initial_coordinates();
        assert_eq!(q[2], r);
        assert_eq!(q[4], std::f64::consts::FRAC_PI_2);
        assert_eq!(ball.initial_velocities(), [1.0, 0.0, 2.0, 0.0, 0.0, 5.0]);
        assert_eq!(ball.surface(ball_bounce::Wall::Floor, &q), 0.0);
    }
    assert_eq!(BallBounce::INITIAL_COORDINATES[2], 0.5);
}

/// The §3.2 ball meets the floor by one map in all three of its models:
/// `ball_floor` (the paper's velocities v, ω), `ball_bounce_omega` (the
/// centre and ω as coordinates' rates) and `ball_bounce` (Euler angles, at
/// φ = ψ = 0, θ = π/2, where ω = (θ', −ψ', φ')), at random velocities and
/// parameters: the velocities after the collision agree to rounding.
#[test]
fn the_three_models_of_the_ball_meet_the_floor_alike() {
    let mut seed = 7u64;
    for _ in 0..200 {
        let mut draw = |lo: f64, hi: f64| lo + (hi - lo) * lcg(&mut seed);
        let (m, r, j) = (draw(0.5, 2.0), draw(0.2, 1.0), draw(0.05, 0.5));
        let floor = BallFloor::with_params(ball_floor::Params { m, r, J: j });
        let omega = BallBounceOmega::with_params(ball_bounce_omega::Params {
            m,
            r,
            J: j,
            ..Default::default()
        });
        let euler = BallBounce::with_params(ball_bounce::Params {
            m,
            r,
            J: j,
            ..Default::default()
        });
        // (v, ω), falling onto the floor.
        let mut v: [f64; 6] = core::array::from_fn(|_| draw(-3.0, 3.0));
        v[2] = -draw(0.1, 3.0);
        let paper = floor.floor_collide(&[], &v);
        let q_omega = [0.0, 0.0, r, 0.0, 0.0, 0.0];
        let by_omega = omega.collide(ball_bounce_omega::Wall::Floor, &q_omega, &v);
        // In Euler angles: (φ', θ', ψ') = (ω_z, ω_x, −ω_y).
        let q_euler = [0.0, 0.0, r, 0.0, std::f64::consts::FRAC_PI_2, 0.0];
        let v_euler = [v[0], v[1], v[2], v[5], v[3], -v[4]];
        let e = euler.collide(ball_bounce::Wall::Floor, &q_euler, &v_euler);
        let by_euler = [e[0], e[1], e[2], e[4], -e[5], e[3]];
        let scale = v.iter().fold(0.0f64, |a, x| a.max(x.abs()));
        for i in 0..6 {
            assert!(
                (by_omega[i] - paper[i]).abs() <= 1e-14 * scale,
                "centre and ω, component {i}: {by_omega:?} vs {paper:?}"
            );
            assert!(
                (by_euler[i] - paper[i]).abs() <= 1e-13 * scale,
                "Euler angles, component {i}: {by_euler:?} vs {paper:?}"
            );
        }
    }
}

/// A model whose q̈ is solved at run time, derived in `took`: within 10 s,
/// no closed form; at random states q̈ solves the equations, and each
/// collision keeps T and reverses B v; along q̈, T + V and A q̇ keep.
fn solved_at_run_time(d: &dalembert_codegen::Derivation, took: std::time::Duration) {
    use dalembert_codegen::interpret::Interpreted;
    assert!(took.as_secs_f64() < 10.0, "derived in {took:?}");
    assert!(d.accelerations.is_none(), "q̈ in closed form");
    let m = Interpreted::<6>::new(d).unwrap();
    let wall = m.walls()[0];
    let mut s = 11;
    for _ in 0..50 {
        let q: [f64; 6] = std::array::from_fn(|_| 0.2 + 1.2 * lcg(&mut s));
        let v: [f64; 6] = std::array::from_fn(|_| -2.0 + 4.0 * lcg(&mut s));
        check_closed_form(&m, &q, v).unwrap();
        let v = admissible(&m, &q, v);
        let after = m.collide(wall, &q, &v);
        let (t0, t1) = (m.kinetic_energy(&q, &v), m.kinetic_energy(&q, &after));
        assert!((t1 - t0).abs() <= 1e-9 * (1.0 + t0), "T {t0} → {t1}");
        let b = m.wall_rows(wall, &q);
        for (x, y) in b
            .apply(&v)
            .as_slice()
            .iter()
            .zip(b.apply(&after).as_slice())
        {
            assert!((x + y).abs() <= 1e-9 * (1.0 + t0), "B v {x} → {y}");
        }
    }
    check_motion(&m, 12);
}

/// `tests/bodies/shell_past_the_budget.toml` (a fuzz mutant of the
/// spherical robot, not a physical system): q̈ and the wall's P in closed
/// form are past the budget of one exact matrix step, so both are solved at
/// run time. Before that budget, the same model (with acosh for asinh) took
/// 30 s to generate and q̈ compiled to 15 032 operations; the elimination is
/// 490.
#[test]
fn past_the_budget_of_exact_products_the_motion_is_solved_at_run_time() {
    use dalembert_codegen::derive::Projection;
    let start = std::time::Instant::now();
    let d = common::derived("tests/bodies", "shell_past_the_budget");
    solved_at_run_time(&d, start.elapsed());
    assert!(matches!(d.walls[0].projection, Projection::Structured));
}

/// The Chaplygin ball as a quaternion (`tests/bodies/chaplygin_quaternion.toml`)
/// with its centre moved along x·f(x + i₂), fuzz mutants that are not
/// physical systems: within the budget of each matrix step, q̈ in closed
/// form is past the one of its size, in terms (asinh: 44 087 terms in an
/// entry, which ran past 100 s being simplified) or, exponentials
/// expanded, in nodes (exp: 8.9 million, 30 s to compile into 4 609
/// operations). Both are solved at run time instead.
#[test]
fn past_the_size_of_a_closed_form_the_motion_is_solved_at_run_time() {
    let root = std::path::Path::new(env!("CARGO_MANIFEST_DIR"));
    let text =
        std::fs::read_to_string(root.join("tests/bodies/chaplygin_quaternion.toml")).unwrap();
    let written = r#"position = ["x", "y", "r"]"#;
    assert!(text.contains(written));
    for f in ["asinh", "exp"] {
        let moved = format!(r#"position = ["x*{f}(x + i2)", "y", "r"]"#);
        let file = std::env::temp_dir().join(format!("dalembert_chaplygin_{f}.toml"));
        std::fs::write(&file, text.replace(written, &moved)).unwrap();
        let start = std::time::Instant::now();
        let d = dalembert_codegen::derive(&file).unwrap_or_else(|e| panic!("{f}: {e}"));
        solved_at_run_time(&d, start.elapsed());
    }
}

//! The generated equations of motion G q̈ + h = Aᵀλ, A q̇ = 0, solved by the
//! runtime, checked against what they must satisfy independently of how
//! they were derived: the energy T + V is constant along the motion (the
//! reactions do no work on admissible velocities), A q̇ stays zero to second
//! order, both by finite differences of the generated T, V and A; and the
//! analytic motion of the Chaplygin sleigh (puck).

use dalembert::models::{BallWallEuler, Puck};
use dalembert::runtime::Model;
use dalembert::runtime::dynamics::{DynamicsError, accelerations};

mod common;
use common::{lcg, onto_kernel};

/// v projected onto ker A(q).
fn admissible<M: Model<N, N>, const N: usize>(m: &M, q: &[f64; N], v: [f64; N]) -> [f64; N] {
    onto_kernel(&m.constraints(q), v)
}

fn step<const N: usize>(x: &[f64; N], dx: &[f64; N], e: f64) -> [f64; N] {
    std::array::from_fn(|i| x[i] + e * dx[i])
}

/// dE/dt = 0 and d(A q̇)/dt = 0 along (q̇, q̈), by central differences.
fn check_motion<M: Model<N, N>, const N: usize>(m: &M, seed: u64) {
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
        assert!(de.abs() < 1e-6 * scale, "{}: dE/dt = {de}", M::NAME);
        let ap = m.constraints(&qp).apply(&vp);
        let am = m.constraints(&qm).apply(&vm);
        for (x, y) in ap.as_slice().iter().zip(am.as_slice()) {
            let d = (x - y) / (2.0 * eps);
            assert!(d.abs() < 1e-6 * scale, "{}: d(Aq̇)/dt = {d}", M::NAME);
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
        assert!((acc.lambda[0].abs() - puck.params.m * (u * w).abs()).abs() < 1e-9);
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

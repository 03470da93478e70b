//! Chaplygin's ball (`models/chaplygin_ball.toml`, written as a body): a
//! ball with unequal principal moments and its centre of mass at its centre
//! rolls without slipping on a horizontal floor. The model has no wall, and
//! its file starts it from the three angular rates alone; the centre's
//! velocity follows from the rolling constraint.
//!
//! The independent answers are classical (Chaplygin, 1903): the energy and
//! the angular momentum about the contact point, K = Θω + m a × (ω × a)
//! with Θ the inertia in space and a the vector from the contact point to
//! the centre, are conserved, K as a vector fixed in space (gravity and the
//! reaction have no moment about the contact point). The rotation, ω and K
//! are computed here from the Euler angles by composing rotations, not
//! from the model's expressions.

use dalembert::models::{BallWallEuler, ChaplyginBall};
use dalembert::runtime::prelude::*;
use dalembert::runtime::simulate::{
    Integrator, Rk4, SeriesRoom, Settings, Simulator, StartRule, State, Taylor, starting_velocity,
};

mod common;
use common::dormand_prince;

type M3 = [[f64; 3]; 3];

fn rot_z(a: f64) -> M3 {
    let (s, c) = a.sin_cos();
    [[c, -s, 0.0], [s, c, 0.0], [0.0, 0.0, 1.0]]
}

fn rot_x(a: f64) -> M3 {
    let (s, c) = a.sin_cos();
    [[1.0, 0.0, 0.0], [0.0, c, -s], [0.0, s, c]]
}

fn mul(a: &M3, b: &M3) -> M3 {
    std::array::from_fn(|i| std::array::from_fn(|j| (0..3).map(|k| a[i][k] * b[k][j]).sum()))
}

fn apply(a: &M3, v: [f64; 3]) -> [f64; 3] {
    std::array::from_fn(|i| (0..3).map(|k| a[i][k] * v[k]).sum())
}

fn cross(a: [f64; 3], b: [f64; 3]) -> [f64; 3] {
    [
        a[1] * b[2] - a[2] * b[1],
        a[2] * b[0] - a[0] * b[2],
        a[0] * b[1] - a[1] * b[0],
    ]
}

const EX: [f64; 3] = [1.0, 0.0, 0.0];
const EZ: [f64; 3] = [0.0, 0.0, 1.0];

/// ω in space for R = Rz(φ) Rx(θ) Rz(ψ): each rate turns about its own axis
/// as the rotations before it carry that axis.
fn omega(q: &[f64; 5], v: &[f64; 5]) -> [f64; 3] {
    let (phi, theta) = (q[2], q[3]);
    let (dphi, dtheta, dpsi) = (v[2], v[3], v[4]);
    let node = apply(&rot_z(phi), EX);
    let axis = apply(&mul(&rot_z(phi), &rot_x(theta)), EZ);
    std::array::from_fn(|i| dphi * EZ[i] + dtheta * node[i] + dpsi * axis[i])
}

/// K = Θω + m a × (ω × a), a = r e_z, Θ = R diag(i1, i2, i3) Rᵀ.
fn contact_momentum(ball: &ChaplyginBall, q: &[f64; 5], v: &[f64; 5]) -> [f64; 3] {
    let p = ball.params();
    let r = mul(&mul(&rot_z(q[2]), &rot_x(q[3])), &rot_z(q[4]));
    let w = omega(q, v);
    // Θω = R I Rᵀ ω.
    let body: [f64; 3] = std::array::from_fn(|i| (0..3).map(|k| r[k][i] * w[k]).sum());
    let spun = apply(&r, [p.i1 * body[0], p.i2 * body[1], p.i3 * body[2]]);
    let a = [0.0, 0.0, p.r];
    let arm = cross(a, cross(w, a));
    std::array::from_fn(|i| spun[i] + p.m * arm[i])
}

/// The velocity of the material point at the contact: v_C + ω × (−a).
fn slip(ball: &ChaplyginBall, q: &[f64; 5], v: &[f64; 5]) -> [f64; 3] {
    let turn = cross(omega(q, v), [0.0, 0.0, -ball.params().r]);
    [v[0] + turn[0], v[1] + turn[1], turn[2]]
}

fn norm(x: &[f64]) -> f64 {
    x.iter().map(|a| a * a).sum::<f64>().sqrt()
}

/// The file gives φ̇, θ̇, ψ̇ and is silent on ẋ, ẏ: they follow, the rates
/// are kept, and the contact point is at rest, at the file's attitude and
/// at others. Rates that contradict a given centre velocity cannot be
/// completed, and the start is then the projection.
#[test]
fn the_start_follows_from_the_angular_rates() {
    let ball = ChaplyginBall::default();
    let given = ball.initial_velocities_given();
    assert_eq!(given, [false, false, true, true, true]);
    let rates = ball.initial_velocities();
    for (phi, theta, psi) in [(0.0, 1.0, 0.0), (1.1, 0.3, -2.0), (-2.5, 2.9, 0.7)] {
        let q = [0.4, -1.0, phi, theta, psi];
        let (v, rule) = starting_velocity(&ball, &q, &rates, &given).unwrap();
        assert_eq!(rule, StartRule::Completed);
        assert_eq!(&v[2..], &rates[2..]);
        let s = slip(&ball, &q, &v);
        assert!(norm(&s) < 1e-15, "slip {s:?} at {q:?}");
        assert!(norm(&v[..2]) > 0.1, "the centre moves: {v:?}");
    }
    // ẋ given as well, and not the one the rates need.
    let q = ball.initial_coordinates();
    let mut wrong = rates;
    wrong[0] = 1.0;
    let mut all = given;
    all[0] = true;
    let (v, rule) = starting_velocity(&ball, &q, &wrong, &all).unwrap();
    assert_eq!(rule, StartRule::Projected);
    assert!(norm(&slip(&ball, &q, &v)) < 1e-14);
}

/// Where the constraints leave a choice, the velocities not given take the
/// least kinetic energy: the homogeneous rolling ball (`ball_wall_euler`,
/// J scalar) given only ẋ must roll straight without spin, ω = (0, ẋ/r, 0)
/// and ẏ = 0, at a tilt where the Euler rates of that motion are all
/// non-zero (φ̇ = −ψ̇ cos θ cancels the spin about the vertical).
#[test]
fn a_start_with_a_choice_adds_nothing_to_what_the_constraints_force() {
    let ball = BallWallEuler::default();
    let r = ball.params().r;
    let q = [1.0, 0.0, 0.3, 1.0, 0.2];
    let mut v = [0.0; 5];
    v[0] = 0.7;
    let given = [true, false, false, false, false];
    let (v, rule) = starting_velocity(&ball, &q, &v, &given).unwrap();
    assert_eq!(rule, StartRule::Completed);
    let w = omega(&q, &v);
    let expected = [0.0, 0.7 / r, 0.0];
    for i in 0..3 {
        assert!((w[i] - expected[i]).abs() < 1e-13, "ω = {w:?}, v = {v:?}");
    }
    assert_eq!(v[0], 0.7);
    assert!(v[1].abs() < 1e-14, "{v:?}");
    assert!(v[2].abs() > 0.1 && v[4].abs() > 0.1, "{v:?}");
}

/// Along 20 s of rolling, energy and K stay at their starting values with
/// every integrator, and no collision is reported (there is no wall).
#[test]
fn energy_and_the_contact_momentum_are_conserved() {
    let ball = ChaplyginBall::default();
    let q = ball.initial_coordinates();
    let (v, _) = starting_velocity(
        &ball,
        &q,
        &ball.initial_velocities(),
        &ball.initial_velocities_given(),
    )
    .unwrap();
    let energy = |q: &[f64; 5], v: &[f64; 5]| ball.kinetic_energy(q, v) + ball.potential(q);
    let (e0, k0) = (energy(&q, &v), contact_momentum(&ball, &q, &v));
    // K is not along the vertical: its horizontal part is conserved too.
    assert!(norm(&k0[..2]) > 0.05, "{k0:?}");
    let taylor = Settings {
        integrator: Integrator::Taylor(Taylor::default()),
        ..Settings::default()
    };
    let rk4 = Settings {
        integrator: Integrator::Rk4(Rk4 { step: 1e-3 }),
        ..Settings::default()
    };
    for (name, settings, tol) in [
        ("dormand-prince", dormand_prince(1e-12), 1e-11),
        ("taylor", taylor, 1e-13),
        ("rk4", rk4, 1e-10),
    ] {
        let start = State { t: 0.0, q, v };
        let mut room = SeriesRoom::new(&ball);
        let mut sim = Simulator::with_series(&mut room, start, settings).unwrap();
        let (mut worst_e, mut worst_k) = (0.0f64, 0.0f64);
        let stats = sim
            .run(20.0, |step| {
                let (q, v) = (&step.state.q, &step.state.v);
                let k = contact_momentum(&ball, q, v);
                let dk: Vec<f64> = (0..3).map(|i| k[i] - k0[i]).collect();
                worst_e = worst_e.max((energy(q, v) - e0).abs() / e0.abs());
                worst_k = worst_k.max(norm(&dk) / norm(&k0));
                true
            })
            .unwrap();
        assert_eq!(stats.collisions, 0, "{name}");
        assert_eq!(sim.state().t, 20.0, "{name}");
        eprintln!(
            "{name}: energy {worst_e:e}, K {worst_k:e}, {} steps",
            stats.steps
        );
        assert!(worst_e < tol, "{name}: relative energy error {worst_e:e}");
        assert!(worst_k < tol, "{name}: relative error of K {worst_k:e}");
        // The ball has rolled somewhere, and turned.
        let end = sim.state();
        assert!(norm(&[end.q[0] - q[0], end.q[1] - q[1]]) > 0.1, "{name}");
    }
}

//! A spherical robot written as bodies (tests/bodies/spherical_robot.toml):
//! a ball shell rolling on the floor with a free rotor inside on its body z
//! axis, through impacts with a rough wall, against the conservation laws
//! of the mechanics, computed here from the attitude by formulas of this
//! file:
//!
//! - the energy, through flights and impacts (the rough law keeps it);
//! - the rotor's spin about its axis, k (ω_shell · e₃ + α̇): no torque
//!   acts on the rotor about its axis (a free bearing, the rotor symmetric),
//!   and no impulse either (the wall's and the floor's impulses act on the
//!   shell alone), so it is kept through flights and impacts;
//! - between impacts, the angular momentum about the contact point with the
//!   floor, K = J ω_s + I_r ω_r + M r e_z × Ṡ (fixed frame): the floor's
//!   force acts at that point and the point moves with the centre, so K
//!   changes only by the torque of gravity (−a, 0, −g) at the centre,
//!   r e_z × M(−a, 0, −g) = −M a r e_y: K(t) = K(t₀) − M a r e_y (t − t₀)
//!   (for a = 0, Chaplygin's integral, here for a ball and a gyrostat);
//! - the contact point with the floor is at rest: Ṡ = ω_s × r e_z.
//!
//! Uses the symbolic engine: run one test at a time (`RUST_TEST_THREADS=1`).

mod common;

use common::derived;
use dalembert::runtime::prelude::*;
use dalembert::runtime::simulate::Simulator;
use dalembert_codegen::interpret::Interpreted;

// The file's parameters.
const M_SHELL: f64 = 1.0;
const R: f64 = 0.5;
const J: f64 = 1.0 / 6.0;
const M_ROTOR: f64 = 0.5;
const I_ACROSS: f64 = 1.0 / 40.0;
const K_AXIAL: f64 = 1.0 / 20.0;
const A: f64 = 1.0;

type V3 = [f64; 3];

fn add(a: V3, b: V3) -> V3 {
    std::array::from_fn(|i| a[i] + b[i])
}

fn scale(s: f64, a: V3) -> V3 {
    a.map(|x| s * x)
}

fn dot(a: V3, b: V3) -> f64 {
    a.iter().zip(&b).map(|(x, y)| x * y).sum()
}

fn cross(a: V3, b: V3) -> V3 {
    [
        a[1] * b[2] - a[2] * b[1],
        a[2] * b[0] - a[0] * b[2],
        a[0] * b[1] - a[1] * b[0],
    ]
}

/// The shell's body z axis e₃ and angular velocity (fixed frame) for
/// z-x-z angles (φ, θ, ψ): ω = φ̇ e_z + θ̇ R_z(φ)e_x + ψ̇ e₃.
fn attitude(q: &[f64; 6], v: &[f64; 6]) -> (V3, V3) {
    let (phi, theta) = (q[2], q[3]);
    let e3 = [
        phi.sin() * theta.sin(),
        -phi.cos() * theta.sin(),
        theta.cos(),
    ];
    let node = [phi.cos(), phi.sin(), 0.0];
    let omega = add(add([0.0, 0.0, v[2]], scale(v[3], node)), scale(v[4], e3));
    (e3, omega)
}

/// The rotor's spin about its axis, k (ω_s · e₃ + α̇).
fn rotor_spin(q: &[f64; 6], v: &[f64; 6]) -> f64 {
    let (e3, omega) = attitude(q, v);
    K_AXIAL * (dot(omega, e3) + v[5])
}

/// The angular momentum about the floor's contact point (fixed frame).
fn momentum_about_contact(q: &[f64; 6], v: &[f64; 6]) -> V3 {
    let (e3, shell) = attitude(q, v);
    let rotor = add(shell, scale(v[5], e3));
    // The rotor's inertia I ω = i ω + (k − i)(e₃·ω) e₃ (symmetric about e₃).
    let rotor_momentum = add(
        scale(I_ACROSS, rotor),
        scale((K_AXIAL - I_ACROSS) * dot(e3, rotor), e3),
    );
    let centre_velocity = [v[0], v[1], 0.0];
    add(
        add(scale(J, shell), rotor_momentum),
        scale(
            (M_SHELL + M_ROTOR) * R,
            cross([0.0, 0.0, 1.0], centre_velocity),
        ),
    )
}

/// The velocity of the shell's point touching the floor: Ṡ − ω_s × r e_z.
fn slip(q: &[f64; 6], v: &[f64; 6]) -> V3 {
    let (_, omega) = attitude(q, v);
    add([v[0], v[1], 0.0], scale(-1.0, cross(omega, [0.0, 0.0, R])))
}

fn largest_difference(a: V3, b: V3) -> f64 {
    (0..3).map(|i| (a[i] - b[i]).abs()).fold(0.0, f64::max)
}

#[test]
fn a_spherical_robot_keeps_its_integrals_through_rough_impacts() {
    let d = derived("tests/bodies", "spherical_robot");
    let m = Interpreted::<6>::new(&d).unwrap();
    let start = common::initial(&m);
    let (q0, v0) = (start.q, start.v);
    // The file gives the angle rates; the centre's velocity followed from
    // the rolling rows, so the floor's contact point is at rest.
    let at_start = slip(&q0, &v0);
    assert!(
        at_start.iter().all(|x| x.abs() < 1e-12),
        "slip at the start {at_start:?}"
    );
    assert!(v0[0] < 0.0, "rolling towards the wall: {v0:?}");

    let e0 = m.energy(&q0, &v0);
    let spin0 = rotor_spin(&q0, &v0);
    // K at the start of the current flight, and when that was.
    let mut k_flight = (momentum_about_contact(&q0, &v0), 0.0);
    // K at time t of a flight from (k, t₀).
    let torque = [0.0, -(M_SHELL + M_ROTOR) * A * R, 0.0];
    let expected = |(k, t0): (V3, f64), t: f64| add(k, scale(t - t0, torque));
    let (mut impacts, mut jumps) = (0, 0.0_f64);
    let mut sim = Simulator::new(&m, start, common::dormand_prince(1e-12)).unwrap();
    while sim.state().t < 20.0 {
        let step = sim.step(20.0).unwrap();
        let s = step.state;
        let e = m.energy(&s.q, &s.v);
        assert!(
            (e - e0).abs() <= 1e-9 * e0,
            "t = {}: energy {e0} → {e}",
            s.t
        );
        let spin = rotor_spin(&s.q, &s.v);
        assert!(
            (spin - spin0).abs() <= 1e-9 * spin0.abs(),
            "t = {}: rotor spin {spin0} → {spin}",
            s.t
        );
        let moving = slip(&s.q, &s.v);
        assert!(
            moving.iter().all(|x| x.abs() < 1e-9),
            "t = {}: slip {moving:?}",
            s.t
        );
        assert!(
            s.q[0] >= R - 1e-12,
            "t = {}: beyond the wall, x = {}",
            s.t,
            s.q[0]
        );
        match &step.collision {
            None => {
                let k = momentum_about_contact(&s.q, &s.v);
                let want = expected(k_flight, s.t);
                let off = largest_difference(k, want);
                assert!(off <= 1e-9, "t = {}: K {k:?} against {want:?}", s.t);
            }
            Some(c) => {
                // Just before the impact K is the flight's; after it, a
                // new flight's.
                let before = momentum_about_contact(&c.q, &c.v_minus);
                let off = largest_difference(before, expected(k_flight, c.t));
                assert!(
                    off <= 1e-9,
                    "t = {}: K before the impact off by {off:e}",
                    c.t
                );
                let after = momentum_about_contact(&s.q, &s.v);
                jumps = jumps.max(largest_difference(after, before));
                k_flight = (after, c.t);
                impacts += 1;
            }
        }
    }
    eprintln!("{impacts} impacts; largest change of K at one: {jumps:.3}");
    assert!(impacts >= 3, "only {impacts} impacts with the wall");
    // The impacts do change K (the integral is the flight's, not the
    // motion's), so its constancy between them is not the trivial one.
    assert!(jumps > 1e-3, "{jumps}");
}

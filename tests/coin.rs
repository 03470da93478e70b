//! A coin (a disk, `body.disk`) written as a body, against independent
//! answers:
//! - rolling on the floor: straight rolling, pivoting and the steady circle
//!   in closed form, energy and no slip along a tilted run;
//! - between two smooth walls: a head-on impact in closed form, energy and
//!   A v = 0 through tilted impacts;
//! - into a rough wall: the rim point's velocity reversed, the floor's
//!   contact at rest and the energy kept through each impact, with
//!   Dormand–Prince and Taylor's method;
//! - inside a smooth spherical dome: the wall's f against a search over
//!   the rim, and each impact against the smooth law from G, the rows and
//!   that search's gradient.
//!
//! Uses the symbolic engine: run one test at a time (`RUST_TEST_THREADS=1`).

mod common;

use common::derived;
use dalembert::runtime::prelude::*;
use dalembert::runtime::simulate::{Integrator, SeriesRoom, Settings, Simulator, State, Taylor};
use dalembert_codegen::interpret::Interpreted;

/// The coin (tests/bodies/coin.toml) against closed forms: upright with
/// spin ψ̇ = w and no turning it rolls straight, x = −R w t, staying
/// upright; upright turning about its vertical diameter (φ̇ = Ω, ψ̇ = 0)
/// its centre stays put; tilted at θ₀ with the precession and spin of
/// the steady motion (derived below) it keeps θ₀, φ̇ and ψ̇. From a
/// tilted, turning start, along the run the energy is kept and the rim's
/// point nearest the floor, computed here as C = S − R u with
/// u = R_z(φ) R_x(θ) e_y, is at rest.
#[test]
fn a_rolling_coin_moves_as_theory_says() {
    let d = derived("tests/bodies", "coin");
    let m = Interpreted::<5>::new(&d).unwrap();
    let r = 0.5;
    let settings = common::dormand_prince(1e-12);
    let start = |theta: f64, rates: [f64; 3]| coin_start(&m, [0.0, 0.0, 0.3, theta, 0.0], rates);
    let upright = std::f64::consts::FRAC_PI_2;

    // Rolling straight along the heading φ = 0.3.
    let w = 3.0;
    let mut room = SeriesRoom::new(&m);
    let mut sim =
        Simulator::with_series(&mut room, start(upright, [0.0, 0.0, w]), settings).unwrap();
    sim.run(1.0, |_| true).unwrap();
    let x = sim.state();
    let along = [0.3f64.cos(), 0.3f64.sin()];
    for (i, a) in along.iter().enumerate() {
        assert!((x.q[i] + r * w * a).abs() < 1e-10, "straight: {x:?}");
    }
    assert!((x.q[3] - upright).abs() < 1e-10, "straight: {x:?}");

    // Turning about the vertical diameter.
    let mut room = SeriesRoom::new(&m);
    let mut sim =
        Simulator::with_series(&mut room, start(upright, [2.0, 0.0, 0.0]), settings).unwrap();
    sim.run(1.0, |_| true).unwrap();
    let x = sim.state();
    assert!(x.q[0].abs() < 1e-10 && x.q[1].abs() < 1e-10, "pivot: {x:?}");
    assert!((x.q[2] - 2.3).abs() < 1e-10, "pivot: {x:?}");

    // Steady rolling in a circle at the tilt θ₀ (Newton–Euler, derived
    // here: with ω = Ω k + ψ̇ e and ω₃ = ω·e = ψ̇ + Ω cos θ, the centre
    // moves at a ω₃ on a circle turning at Ω, and dH/dt = Ω k × H equals
    // the contact force's torque about the centre when
    // Ω sin θ ((C + m a²) ω₃ − A Ω cos θ) + m g a cos θ = 0).
    let (mass, g, (a_moment, c_moment)) = (1.0, 9.81, (r * r / 4.0, r * r / 2.0));
    let (theta0, precession) = (1.2f64, 1.5);
    let (c0, s0) = (theta0.cos(), theta0.sin());
    let omega3 = (a_moment * precession * c0 - mass * g * r * c0 / (precession * s0))
        / (c_moment + mass * r * r);
    let spin = omega3 - precession * c0;
    let mut room = SeriesRoom::new(&m);
    let mut sim =
        Simulator::with_series(&mut room, start(theta0, [precession, 0.0, spin]), settings)
            .unwrap();
    let mut drift = 0.0f64;
    sim.run(2.0, |step| {
        let (q, v) = (&step.state.q, &step.state.v);
        drift = drift
            .max((q[3] - theta0).abs())
            .max((v[2] - precession).abs())
            .max((v[4] - spin).abs());
        true
    })
    .unwrap();
    assert!(drift < 1e-8, "steady circle: θ, φ̇ or ψ̇ moved by {drift:e}");

    // Tilted and turning: energy and no slip.
    let energy = |q: &[f64; 5], v: &[f64; 5]| m.kinetic_energy(q, v) + m.potential(q);
    let slip = |q: &[f64; 5], v: &[f64; 5]| {
        let (phi, theta) = (q[2], q[3]);
        let (dphi, dtheta, dpsi) = (v[2], v[3], v[4]);
        let w = [
            dtheta * phi.cos() + dpsi * phi.sin() * theta.sin(),
            dtheta * phi.sin() - dpsi * phi.cos() * theta.sin(),
            dphi + dpsi * theta.cos(),
        ];
        let u = [
            -phi.sin() * theta.cos(),
            phi.cos() * theta.cos(),
            theta.sin(),
        ];
        let centre = [v[0], v[1], r * theta.cos() * dtheta];
        let turn = [
            w[1] * u[2] - w[2] * u[1],
            w[2] * u[0] - w[0] * u[2],
            w[0] * u[1] - w[1] * u[0],
        ];
        (0..3)
            .map(|i| (centre[i] - r * turn[i]).abs())
            .fold(0.0, f64::max)
    };
    let x0 = start(1.2, [1.5, 0.0, 6.0]);
    let e0 = energy(&x0.q, &x0.v);
    assert!(slip(&x0.q, &x0.v) < 1e-12, "start: {x0:?}");
    let mut room = SeriesRoom::new(&m);
    let mut sim = Simulator::with_series(&mut room, x0, settings).unwrap();
    let mut worst = (0.0f64, 0.0f64);
    sim.run(2.0, |step| {
        let (q, v) = (&step.state.q, &step.state.v);
        worst.0 = worst.0.max((energy(q, v) - e0).abs() / e0);
        worst.1 = worst.1.max(slip(q, v));
        true
    })
    .unwrap();
    assert!(
        sim.state().q[3] > 0.2,
        "the coin fell flat: {:?}",
        sim.state()
    );
    assert!(
        worst.0 < 1e-9 && worst.1 < 1e-9,
        "energy {:e}, slip {:e}",
        worst.0,
        worst.1
    );
}

/// A coin's start at `q` with the angle rates (φ̇, θ̇, ψ̇) given, the
/// centre's velocity following from the rolling rows.
fn coin_start<M: Dynamics<5>>(m: &M, q: [f64; 5], rates: [f64; 3]) -> State<5> {
    let v = [0.0, 0.0, rates[0], rates[1], rates[2]];
    let given = [false, false, true, true, true];
    let (v, _) = dalembert::runtime::simulate::starting_velocity(m, &q, &v, &given).unwrap();
    State { t: 0.0, q, v }
}

/// The coin lying flat (θ = 0), where its z-x-z angles φ and ψ both turn
/// it about its axis: G is singular there, and the start is refused as
/// such, not left to shrink Dormand–Prince's steps to nothing (its q̈ in
/// closed form divides by sin θ).
#[test]
fn a_coin_lying_flat_is_a_singular_start() {
    use dalembert::runtime::dynamics::DynamicsError;
    use dalembert::runtime::simulate::SimError;
    let m = Interpreted::<5>::new(&derived("tests/bodies", "coin")).unwrap();
    let flat = State {
        t: 0.0,
        q: [0.0, 0.0, 0.3, 0.0, 0.0],
        v: [0.0; 5],
    };
    let e = Simulator::new(&m, flat, Settings::default()).err();
    assert_eq!(
        e,
        Some(SimError::Dynamics {
            t: 0.0,
            error: DynamicsError::SingularMassMatrix
        })
    );
}

/// The coin between two smooth walls (tests/bodies/coin_walls.toml, the
/// walls' surfaces derived from the disk: f = n·S − offset − R√(1 − (n·e)²)).
/// Upright and rolling head-on into the wall x = 0 at speed R w from
/// x = 3/2, it meets it at t = (3/2 − R)/(R w), when the centre is R from
/// it, and leaves with every velocity reversed (by symmetry the smooth law
/// with the rolling rows gives v⁺ = −v⁻). Tilted, turning and bouncing
/// between the walls, the energy is kept and A v = 0 through each impact.
#[test]
fn a_coin_bounces_off_smooth_walls() {
    let d = derived("tests/bodies", "coin_walls");
    let m = Interpreted::<5>::new(&d).unwrap();
    let r = 0.5;
    let settings = common::dormand_prince(1e-12);
    let start = |x: f64, phi: f64, theta: f64, rates: [f64; 3]| {
        coin_start(&m, [x, 0.0, phi, theta, 0.0], rates)
    };
    let w = 2.0;
    let x0 = start(1.5, 0.0, std::f64::consts::FRAC_PI_2, [0.0, 0.0, w]);
    assert!((x0.v[0] + r * w).abs() < 1e-12, "{x0:?}");
    let mut room = SeriesRoom::new(&m);
    let mut sim = Simulator::with_series(&mut room, x0, settings).unwrap();
    let mut hits = Vec::new();
    sim.run(1.5, |step| {
        if let Some(c) = &step.collision {
            hits.push((c.t, c.q, c.v_minus, c.v_plus));
        }
        true
    })
    .unwrap();
    assert_eq!(hits.len(), 1, "{hits:?}");
    let (t, q, before, after) = hits[0];
    assert!((t - (1.5 - r) / (r * w)).abs() < 1e-10, "met at {t}");
    assert!((q[0] - r).abs() < 1e-10, "{q:?}");
    for i in 0..5 {
        assert!(
            (after[i] + before[i]).abs() < 1e-10,
            "{before:?} -> {after:?}"
        );
    }
    assert!(
        (sim.state().q[0] - (r + r * w * 0.5)).abs() < 1e-9,
        "{:?}",
        sim.state()
    );

    let x0 = start(1.5, 0.3, 1.3, [0.8, 0.0, 7.0]);
    let energy = |q: &[f64; 5], v: &[f64; 5]| m.kinetic_energy(q, v) + m.potential(q);
    let e0 = energy(&x0.q, &x0.v);
    let mut room = SeriesRoom::new(&m);
    let mut sim = Simulator::with_series(&mut room, x0, settings).unwrap();
    let (mut collisions, mut worst) = (0, 0.0f64);
    sim.run(6.0, |step| {
        let (q, v) = (&step.state.q, &step.state.v);
        worst = worst.max((energy(q, v) - e0).abs() / e0);
        worst = worst.max(
            m.constraints(q)
                .as_slice()
                .iter()
                .map(|row| row.iter().zip(v).map(|(a, b)| a * b).sum::<f64>().abs())
                .fold(0.0, f64::max),
        );
        collisions += usize::from(step.collision.is_some());
        true
    })
    .unwrap();
    assert!(collisions >= 2, "{collisions} collisions");
    assert!(worst < 1e-9, "energy or A v off by {worst:e}");
}

/// The coin rolling into a rough wall (tests/bodies/coin_rough.toml: the
/// wall's contact rows derived from the disk, |w| times the velocity of
/// the rim's point nearest the wall). Checked at each impact with the
/// kinematics written out here (ω from the z-x-z rates, the contact points
/// C = S − R w/|w|, w = n − (n·e)e): the impact is on the wall (the
/// centre R|w| from it), the contact point's velocity is reversed, all
/// three components (B v⁺ = −B v⁻: the normal and the sticking rows),
/// the floor's contact point stays at rest, and the energy is kept; the
/// motion is not merely reversed (the rotation about the line through
/// the two contact points keeps its rate). Together these fix v⁺: the
/// rows span all admissible velocities but that rotation. The same with
/// Taylor's method, whose first impact is Dormand–Prince's.
#[test]
fn a_coin_bounces_off_a_rough_wall() {
    let d = derived("tests/bodies", "coin_rough");
    let m = Interpreted::<5>::new(&d).unwrap();
    let r = 0.5;
    let settings = common::dormand_prince(1e-12);
    let energy = |q: &[f64; 5], v: &[f64; 5]| m.kinetic_energy(q, v) + m.potential(q);
    // The velocity of the rim's point nearest the plane of normal n.
    let rim_point = |q: &[f64; 5], v: &[f64; 5], n: [f64; 3]| -> [f64; 3] {
        let (phi, theta) = (q[2], q[3]);
        let (dphi, dtheta, dpsi) = (v[2], v[3], v[4]);
        let e = [
            phi.sin() * theta.sin(),
            -phi.cos() * theta.sin(),
            theta.cos(),
        ];
        let omega = [
            dtheta * phi.cos() + dpsi * phi.sin() * theta.sin(),
            dtheta * phi.sin() - dpsi * phi.cos() * theta.sin(),
            dphi + dpsi * theta.cos(),
        ];
        let ne: f64 = (0..3).map(|i| n[i] * e[i]).sum();
        let w: [f64; 3] = std::array::from_fn(|i| n[i] - ne * e[i]);
        let size = w.iter().map(|x| x * x).sum::<f64>().sqrt();
        let arm: [f64; 3] = std::array::from_fn(|i| -r * w[i] / size);
        let centre = [v[0], v[1], r * theta.cos() * dtheta];
        std::array::from_fn(|i| {
            let (j, k) = ((i + 1) % 3, (i + 2) % 3);
            centre[i] + omega[j] * arm[k] - omega[k] * arm[j]
        })
    };
    let x0 = coin_start(&m, [1.5, 0.0, 0.3, 1.3, 0.0], [0.8, 0.0, 7.0]);
    let e0 = energy(&x0.q, &x0.v);
    // Every impact on the rough wall: when, where, v⁻ and v⁺.
    let impacts = |settings| {
        let mut room = SeriesRoom::new(&m);
        let mut sim = Simulator::with_series(&mut room, x0, settings).unwrap();
        let mut rough = Vec::new();
        sim.run(20.0, |step| {
            if let Some(c) = &step.collision
                && c.wall.0 == 0
            {
                rough.push((c.t, c.q, c.v_minus, c.v_plus));
            }
            true
        })
        .unwrap();
        rough
    };
    let rough = impacts(settings);
    assert!(
        rough.len() >= 2,
        "{} impacts on the rough wall",
        rough.len()
    );
    // Taylor's method (the wall's f has a root, the motion a rolling
    // constraint): the same first impact. The motion after an impact on a
    // rough wall is sensitive: Dormand–Prince at rtol 1e-10, 1e-12 and
    // 1e-13 already disagree on the second impact's instant (17.8, 12.2
    // and 12.7), so later impacts are checked each for itself.
    let taylor = impacts(Settings {
        integrator: Integrator::Taylor(Taylor::default()),
        ..Settings::default()
    });
    assert!(
        taylor.len() >= 2,
        "{} impacts on the rough wall",
        taylor.len()
    );
    assert!(
        (rough[0].0 - taylor[0].0).abs() < 1e-12,
        "first met at {} and {}",
        rough[0].0,
        taylor[0].0
    );
    for (_, q, before, after) in rough.iter().chain(&taylor) {
        let (theta, phi) = (q[3], q[2]);
        let reach = r * (1.0 - (phi.sin() * theta.sin()).powi(2)).sqrt();
        assert!((q[0] - reach).abs() < 1e-9, "not on the wall: {q:?}");
        let (c0, c1) = (
            rim_point(q, before, [1.0, 0.0, 0.0]),
            rim_point(q, after, [1.0, 0.0, 0.0]),
        );
        let scale = c0.iter().map(|x| x.abs()).fold(1e-3, f64::max);
        for i in 0..3 {
            assert!(
                (c1[i] + c0[i]).abs() < 1e-9 * scale,
                "contact point {c0:?} -> {c1:?}"
            );
        }
        let floor = rim_point(q, after, [0.0, 0.0, 1.0]);
        assert!(
            floor.iter().all(|x| x.abs() < 1e-9),
            "the floor's contact slips: {floor:?}"
        );
        let (e_before, e_after) = (energy(q, before), energy(q, after));
        assert!(
            (e_after - e_before).abs() < 1e-10 * e0,
            "{e_before} -> {e_after}"
        );
        let reversed = (0..5).all(|i| (after[i] + before[i]).abs() < 1e-6);
        assert!(!reversed, "merely reversed: {before:?} -> {after:?}");
    }
}

/// The farthest distance² of the coin's rim from `c` at q = (x, y, φ, θ, ψ)
/// (centre (x, y, R sin θ), attitude R_z(φ) R_x(θ) R_z(ψ), rim in the
/// body's x-y plane), by search over the rim: samples, then a ternary
/// search about the best one.
fn rim_farthest(q: &[f64; 5], r: f64, c: [f64; 3]) -> f64 {
    let (phi, theta, psi) = (q[2], q[3], q[4]);
    let rz = |a: f64| {
        [
            [a.cos(), -a.sin(), 0.0],
            [a.sin(), a.cos(), 0.0],
            [0.0, 0.0, 1.0],
        ]
    };
    let rx = |a: f64| {
        [
            [1.0, 0.0, 0.0],
            [0.0, a.cos(), -a.sin()],
            [0.0, a.sin(), a.cos()],
        ]
    };
    let mul = |a: [[f64; 3]; 3], b: [[f64; 3]; 3]| {
        std::array::from_fn::<[f64; 3], 3, _>(|i| {
            std::array::from_fn(|j| (0..3).map(|k| a[i][k] * b[k][j]).sum())
        })
    };
    let rot = mul(mul(rz(phi), rx(theta)), rz(psi));
    let centre = [q[0], q[1], r * theta.sin()];
    let at = |t: f64| -> f64 {
        (0..3)
            .map(|i| {
                let p = centre[i] + r * (t.cos() * rot[i][0] + t.sin() * rot[i][1]) - c[i];
                p * p
            })
            .sum()
    };
    let samples = 720;
    let step = std::f64::consts::TAU / samples as f64;
    let best = (0..samples)
        .map(|k| k as f64 * step)
        .max_by(|a, b| at(*a).total_cmp(&at(*b)))
        .unwrap();
    let (mut lo, mut hi) = (best - step, best + step);
    for _ in 0..200 {
        let (m1, m2) = (lo + (hi - lo) / 3.0, hi - (hi - lo) / 3.0);
        if at(m1) < at(m2) {
            lo = m1;
        } else {
            hi = m2;
        }
    }
    at(0.5 * (lo + hi))
}

/// The coin rolling inside a smooth spherical dome (tests/bodies/
/// coin_in_sphere.toml: radius ρ = 2 about (0, 0, 1); the wall's f derived
/// from the disk, its rim's point farthest from the dome's centre, in
/// closed form). Against a search over the rim written here: f = (ρ² −
/// max |P − c|²)/(2ρ) at random configurations (1e-12), and through each
/// impact of a tilted, turning run: the impact is on that surface, and v⁺
/// is the smooth law (I − 2P)v⁻ with P from G, the rolling rows and the
/// normal by central differences of the search (the runtime's generic
/// `linalg::projector`, not the generated map), the energy kept. The file
/// leaves the projector to `auto`, which weighs B as well as G: the wall is
/// solved at run time (its closed form is large), q̈ stays in closed form.
#[test]
fn a_coin_meets_a_smooth_sphere_where_its_rim_is_farthest() {
    let d = derived("tests/bodies", "coin_in_sphere");
    assert!(d.walls[0].structured(), "the dome's P in closed form");
    assert!(d.accelerations.is_some(), "q̈ not in closed form");
    let m = Interpreted::<5>::new(&d).unwrap();
    let (r, rho, c) = (0.5, 2.0, [0.0, 0.0, 1.0]);
    let dome = m.walls()[0];
    let f = |q: &[f64; 5]| (rho * rho - rim_farthest(q, r, c)) / (2.0 * rho);
    let mut seed = 7u64;
    for _ in 0..200 {
        let mut u = || common::lcg(&mut seed);
        let q = [
            2.0 * u() - 1.0,
            2.0 * u() - 1.0,
            6.0 * u(),
            0.3 + 2.5 * u(),
            6.0 * u(),
        ];
        let (got, want) = (m.surface(dome, &q), f(&q));
        assert!(
            (got - want).abs() < 1e-12,
            "at {q:?}: f = {got}, the rim says {want}"
        );
    }
    let x0 = coin_start(&m, [0.2, 0.1, 0.3, 1.2, 0.0], [0.6, 0.0, 9.0]);
    let e0 = m.energy(&x0.q, &x0.v);
    let mut sim = Simulator::new(&m, x0, common::dormand_prince(1e-12)).unwrap();
    let mut impacts = 0;
    sim.run(8.0, |step| {
        if let Some(col) = &step.collision {
            impacts += 1;
            let q = col.q;
            assert!(
                f(&q).abs() < 1e-9,
                "impact off the rim's surface: f = {}",
                f(&q)
            );
            let h = 1e-6;
            let normal: [f64; 5] = std::array::from_fn(|j| {
                let (mut a, mut b) = (q, q);
                a[j] += h;
                b[j] -= h;
                (f(&a) - f(&b)) / (2.0 * h)
            });
            let mut rows = vec![normal];
            rows.extend_from_slice(m.constraints(&q).as_slice());
            let p = dalembert::runtime::linalg::projector(&m.mass_matrix(&q), &rows).unwrap();
            let v = col.v_minus;
            let want: Vec<f64> = (0..5)
                .map(|i| v[i] - 2.0 * (0..5).map(|j| p[i][j] * v[j]).sum::<f64>())
                .collect();
            let scale = v.iter().fold(1.0f64, |s, x| s.max(x.abs()));
            for i in 0..5 {
                assert!(
                    (col.v_plus[i] - want[i]).abs() < 1e-6 * scale,
                    "v⁺ {:?}, the law says {want:?}",
                    col.v_plus
                );
            }
            let e = m.energy(&q, &col.v_plus);
            assert!((e - e0).abs() < 1e-9 * e0, "energy {e0} -> {e}");
        }
        true
    })
    .unwrap();
    assert!(impacts >= 3, "{impacts} impacts with the dome");
}

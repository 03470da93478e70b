//! Return maps and periodic orbits through collisions
//! (`simulate::return_map`, `periodic`), against independent answers:
//! DΠ against Richardson differences of whole return maps along the
//! section; §3.2.1's orbit and its multipliers as the linear theory of
//! Theorem 3.2's map predicts; Garwin's superball's vertical bounce and its
//! multipliers in closed form.

mod common;

use dalembert::models::{BallBounce, BallWallEuler, Chain3, PendulumWall, Puck, Superball};
use dalembert::runtime::prelude::*;
use dalembert::runtime::simulate::{
    Integrator, ReturnError, Section, Settings, Simulator, State, Taylor, return_map,
};
use dalembert_periodic::{self as periodic, PeriodicError, Search, Stability};

use common::{admissible_direction, dormand_prince, initial, richardson};

/// A direction along the section at x (on the wall, leaving it): an
/// admissible one with its component along the flow F = (v, q̈) taken
/// off so that df·δq = 0 (F is admissible and crosses the section).
fn along_section<M: TaylorSeries<N>, const N: usize>(
    m: &M,
    wall: M::Wall,
    x: &State<N>,
    seed: &mut u64,
) -> Vec<f64> {
    let (dq, dv) = admissible_direction(m, &x.q, &x.v, seed).unwrap();
    let df = m.normal(wall, &x.q);
    let a = dalembert::runtime::dynamics::qdd(m, &x.q, &x.v).unwrap();
    let dot = |a: &[f64; N], b: &[f64; N]| a.iter().zip(b).map(|(x, y)| x * y).sum::<f64>();
    let s = dot(&df, &dq) / dot(&df, &x.v);
    let mut out = vec![0.0; 2 * N];
    for i in 0..N {
        out[i] = dq[i] - s * x.v[i];
        out[N + i] = dv[i] - s * a[i];
    }
    out
}

fn flat<const N: usize>(x: &State<N>) -> Vec<f64> {
    x.q.iter().chain(&x.v).copied().collect()
}

/// DΠ δ against Richardson differences of Π(project(x₀ + εδ)) for random
/// δ along the section: relative error ≤ 1e-6 of |DΠ δ| + |δ|.
fn jacobian_matches<M: TaylorSeries<N>, const N: usize>(m: &M, start: State<N>, returns: usize) {
    let wall = m.walls()[0];
    let settings = dormand_prince(1e-12);
    let section = Section {
        wall,
        returns,
        t_max: 100.0,
    };
    let x0 = periodic::onto_section(m, start, &section, settings).unwrap();
    let x0 = State { t: 0.0, ..x0 };
    let map = return_map(m, x0, &section, settings, Some(1e-12)).unwrap();
    let jacobian = map.jacobian.unwrap();
    let mut seed = 7;
    for _ in 0..3 {
        let d = along_section(m, wall, &x0, &mut seed);
        let (dq, dv): ([f64; N], [f64; N]) = (
            std::array::from_fn(|i| d[i]),
            std::array::from_fn(|i| d[N + i]),
        );
        let (pq, pv) = jacobian.apply(&dq, &dv);
        let predicted: Vec<f64> = pq.iter().chain(&pv).copied().collect();
        let differences = richardson(
            |e| {
                let moved = State {
                    t: 0.0,
                    q: std::array::from_fn(|i| x0.q[i] + e * dq[i]),
                    v: std::array::from_fn(|i| x0.v[i] + e * dv[i]),
                };
                let x = periodic::project(m, &moved, wall).unwrap();
                flat(&return_map(m, x, &section, settings, None).unwrap().state)
            },
            1e-5,
        );
        let size = |v: &[f64]| v.iter().map(|x| x * x).sum::<f64>().sqrt();
        let error: Vec<f64> = predicted
            .iter()
            .zip(&differences)
            .map(|(a, b)| a - b)
            .collect();
        let scale = size(&predicted) + size(&d[..2 * N]);
        assert!(
            size(&error) <= 1e-6 * scale,
            "{}: |DΠ δ − differences| = {:e} against {scale:e}\n{predicted:?}\n{differences:?}",
            m.name(),
            size(&error)
        );
    }
}

/// §3.1's ball in Euler angles, from its own start: the first return
/// is near θ = 0, where the angles' rates are large (|φ̇|, |ψ̇| ≈ 23) and
/// the residual's scale max(1, |x|∞) falls by a factor of 20 as Newton's
/// method proceeds. Its line search lowers |Π(x) − x|₂, which its
/// least-squares step descends; judged by the residual divided by the
/// scale at each trial, no step was accepted after the second (stalled at
/// 1.15). Now the residual falls to 1e-7 and the search reports the state
/// it heads for: the ball resting against the wall (normal velocity below
/// 1e-6), pushed there by its horizontal force. DΠ there agrees with
/// differences.
#[test]
fn the_line_search_lowers_what_the_step_descends() {
    let m = BallWallEuler::default();
    let (residual, normal_velocity) = towards_grazing(&m, BallWallEuler::WALLS[0]);
    assert!(residual < 1e-7 && normal_velocity.abs() < 1e-6);
    let after_one_step = State {
        t: 0.0,
        q: [
            0.5,
            0.0,
            3.1536274183974324,
            0.22211386409401473,
            -0.8464993632659153,
        ],
        v: [
            0.7719487937414058,
            0.03570734425393543,
            -8.304800201933844,
            0.05282952103945207,
            7.01180651587066,
        ],
    };
    jacobian_matches(&m, after_one_step, 1);
}

#[test]
fn return_map_jacobian_against_differences() {
    // Two returns of the spinning ball on the rough floor; the superball
    // meeting the table between its returns to the floor; a chain of three
    // rods whose tip meets the floor (a curved section in its angles); the
    // pendulum at a wall (a holonomic constraint).
    jacobian_matches(&BallBounce::default(), initial(&BallBounce::default()), 2);
    jacobian_matches(&Superball::default(), initial(&Superball::default()), 1);
    jacobian_matches(&Puck::default(), initial(&Puck::default()), 1);
    jacobian_matches(&Chain3::default(), initial(&Chain3::default()), 1);
    jacobian_matches(
        &PendulumWall::default(),
        initial(&PendulumWall::default()),
        1,
    );
}

/// The ball's angular velocity about the fixed x and y axes from its
/// z-x-z Euler angles and their rates (models/ball_bounce.toml).
fn omega_xy(q: &[f64; 6], v: &[f64; 6]) -> (f64, f64) {
    let (phi, theta) = (q[3], q[4]);
    let (theta_dot, psi_dot) = (v[4], v[5]);
    (
        theta_dot * phi.cos() + psi_dot * phi.sin() * theta.sin(),
        theta_dot * phi.sin() - psi_dot * phi.cos() * theta.sin(),
    )
}

/// §3.2.1: the ball thrown to the rough floor returns along its parabola,
/// so the motion is periodic with two bounces. From the paper's data
/// perturbed by 1e-3 in single components, Newton's method reaches an
/// orbit in at most 8 steps with residual ≤ 1e-12, with Dormand–Prince and
/// with Taylor's method.
///
/// What the orbit must be, independently of the search: over two flights
/// the centre comes back only if its horizontal displacement
/// (2ż/g)(v₁ + v₁') vanishes, v₁' = a v₁ + b ω₂ the velocity after the
/// next bounce (Theorem 3.2), which holds exactly when m r v₁ + J ω₂ = 0;
/// likewise m r v₂ − J ω₁ = 0. The period is two flights, 4ż/g.
///
/// The multipliers: the velocity after a bounce is L F v, F = diag(1, 1,
/// −1, 1, 1, 1) the flight's reversal of v₃ and L = I − 2P Theorem 3.2's
/// map, both reflections in the metric of G. L F fixes v₃ and ω₃ and acts
/// on (v₁, ω₂) and (v₂, ω₁) as 2×2 blocks of trace 0 and determinant −1,
/// whose squares are I (Cayley–Hamilton); so two returns map every
/// velocity to itself, DΠ's velocity block is I. The position and
/// attitude do not act on the velocities, and on themselves as I (a
/// translation moves the orbit, and the rotation of the first flight is
/// undone by the second). So DΠ on the section is block triangular with I
/// on the diagonal: all 11 multipliers are 1 (Jordan blocks of size 2:
/// computed to about the square root of DΠ's error).
#[test]
fn section_3_2_1_orbit_and_its_multipliers() {
    let m = BallBounce::default();
    let p = *m.params();
    let section = Section {
        wall: BallBounce::WALLS[0],
        returns: 2,
        t_max: 100.0,
    };
    let taylor = Settings {
        integrator: Integrator::Taylor(Taylor::default()),
        ..Settings::default()
    };
    for (name, settings) in [
        ("Dormand–Prince", dormand_prince(1e-12)),
        ("Taylor", taylor),
    ] {
        // x_dot, y_dot, z_dot, phi_dot, psi_dot.
        for k in [6, 7, 8, 9, 11] {
            let mut start = initial(&m);
            start.v[k - 6] += 1e-3;
            let search = Search {
                settings,
                tolerance: 1e-12,
                ..Search::default()
            };
            let orbit = periodic::find(&m, start, &section, &search)
                .unwrap_or_else(|e| panic!("{name}, component {k}: {e:?}"));
            let at = format!("{name}, component {k}: {orbit:?}");
            assert!(orbit.iterations <= 8, "{at}");
            assert!(orbit.residual <= 1e-12, "{at}");
            let (q, v) = (orbit.state.q, orbit.state.v);
            let (wx, wy) = omega_xy(&q, &v);
            assert!((p.m * p.r * v[0] + p.J * wy).abs() <= 1e-9, "{at}");
            assert!((p.m * p.r * v[1] - p.J * wx).abs() <= 1e-9, "{at}");
            assert!((orbit.period - 4.0 * v[2] / p.g).abs() <= 1e-12, "{at}");
            assert_eq!(orbit.multipliers.len(), 11, "{at}");
            for z in &orbit.multipliers {
                assert!((z[0] - 1.0).hypot(z[1]) <= 1e-5, "{at}");
            }
            assert_eq!(
                periodic::stability(&orbit.multipliers, search.unit),
                Stability::Neutral
            );
        }
    }
}

/// Garwin's superball between the floor and the table: a vertical bounce
/// is periodic with one return to the floor (two collisions). In the
/// metric of G the rough impacts reflect (ẋ, ȧ) across the lines normal
/// to their contact rows, (1/√m, ∓r/√J) after scaling by G^½, at an angle
/// β with cos β = (J − m r²)/(J + m r²) = −3/7 for J = 2/5 m r²; a floor
/// and table pair turns (ẋ, ȧ) by 2β, so the multipliers are e^{±2iβ} =
/// −31/49 ± i√1440/49, and 1 three times (x, the attitude a, and ż, which
/// both walls reverse exactly). Newton's method must reach the vertical
/// bounce (ẋ = ȧ = 0, the rotation's only fixed point) from the model's
/// spinning start; the period is 2(u − w)/g, u the speed leaving the floor
/// and w = √(u² − 2g(h − 2r)) the speed at the table.
#[test]
fn superball_vertical_bounce_and_its_multipliers() {
    let m = Superball::default();
    let p = *m.params();
    let section = Section {
        wall: Superball::WALLS[0],
        returns: 1,
        t_max: 100.0,
    };
    let search = Search {
        settings: dormand_prince(1e-12),
        tolerance: 1e-12,
        ..Search::default()
    };
    let orbit = periodic::find(&m, initial(&m), &section, &search).unwrap();
    let at = format!("{orbit:?}");
    let (x_dot, z_dot, a_dot) = (orbit.state.v[0], orbit.state.v[1], orbit.state.v[2]);
    assert!(x_dot.abs() <= 1e-12 && a_dot.abs() <= 1e-12, "{at}");
    let w = (z_dot * z_dot - 2.0 * p.g * (p.h - 2.0 * p.r)).sqrt();
    assert!(
        (orbit.period - 2.0 * (z_dot - w) / p.g).abs() <= 1e-12,
        "{at}"
    );
    assert_eq!(orbit.collisions, 2, "{at}");
    let (re, im) = (-31.0 / 49.0, 1440f64.sqrt() / 49.0);
    let mut expected = [[1.0, 0.0], [1.0, 0.0], [1.0, 0.0], [re, -im], [re, im]];
    let mut found = orbit.multipliers.clone();
    let order = |a: &[f64; 2], b: &[f64; 2]| a[0].total_cmp(&b[0]).then(a[1].total_cmp(&b[1]));
    expected.sort_by(order);
    found.sort_by(order);
    for (f, e) in found.iter().zip(&expected) {
        assert!(
            (f[0] - e[0]).hypot(f[1] - e[1]) <= 1e-9,
            "{found:?} against {expected:?}"
        );
    }
    assert_eq!(found.len(), 5);
}

/// An angle that returns after a whole turn: the ball of
/// models/ball_bounce.toml bouncing straight up and down at θ = π/2 while
/// it spins about the vertical (φ̇ = ω, every other rate 0). The floor's
/// contact rows do not see that spin, so each bounce only reverses ż, and
/// φ advances by ω·2ż/g per flight. Declared an angle, φ returns when
/// ω·2ż/g = 2π; from ω 2 % off that, Newton's method must reach such an
/// orbit, with the period 2ż/g of the flight and one whole turn of φ.
/// Run on from the orbit for one period, the simulator comes back to the
/// same state, φ + 2π. (Taken as it is, φ would have to return to its own
/// value, which needs ω = 0 or no flight.)
#[test]
fn an_angle_returns_after_a_whole_turn() {
    let m = BallBounce::default();
    let g = m.params().g;
    let (z_dot, flight) = (5.0, 2.0 * 5.0 / g);
    let mut q = [0.0; 6];
    q[2] = m.params().r;
    q[4] = core::f64::consts::FRAC_PI_2;
    let mut v = [0.0; 6];
    v[2] = z_dot;
    v[3] = 1.02 * core::f64::consts::TAU / flight;
    let start = State { t: 0.0, q, v };
    let section = Section {
        wall: BallBounce::WALLS[0],
        returns: 1,
        t_max: 100.0,
    };
    let search = Search {
        settings: dormand_prince(1e-12),
        tolerance: 1e-12,
        angles: periodic::Angles::of(&[3]).unwrap(),
        ..Search::default()
    };
    let orbit = periodic::find(&m, start, &section, &search).unwrap();
    let at = format!("{orbit:?}");
    assert_eq!(orbit.turns, [0, 0, 0, 1, 0, 0], "{at}");
    let (z_dot, omega) = (orbit.state.v[2], orbit.state.v[3]);
    assert!(
        (orbit.period - 2.0 * z_dot / g).abs() <= 1e-12 * orbit.period,
        "{at}"
    );
    assert!(
        (omega * orbit.period - core::f64::consts::TAU).abs() <= 1e-9,
        "{at}"
    );
    let mut sim = Simulator::new(&m, orbit.state, dormand_prince(1e-12)).unwrap();
    let end = loop {
        let step = sim.step(f64::INFINITY).unwrap();
        if step.collision.is_some() {
            break step.state;
        }
    };
    assert!((end.t - orbit.period).abs() <= 1e-12, "{end:?}, {at}");
    let mut expected = orbit.state.q;
    expected[3] += core::f64::consts::TAU;
    let got = end.q.iter().chain(&end.v);
    let want = expected.iter().chain(&orbit.state.v);
    for (i, (g, w)) in got.zip(want).enumerate() {
        assert!((g - w).abs() <= 1e-8, "entry {i} of (q, v): {end:?}, {at}");
    }
}

/// A search that heads for motions along the wall says so: from the puck's
/// own start every full Newton step lands where the puck no longer leaves
/// the wall (its normal velocity 0), only halves of it are taken, and the
/// residual halves each step. Stopped by the step limit, the error is
/// `TowardsGrazing` with a normal velocity at rounding level, not
/// `NoConvergence` (which invites more steps).
#[test]
fn a_search_that_heads_for_grazing_says_so() {
    let m = Puck::default();
    let section = Section {
        wall: Puck::WALLS[0],
        returns: 1,
        t_max: 100.0,
    };
    let e = periodic::find(&m, initial(&m), &section, &Search::default()).unwrap_err();
    assert!(
        matches!(
            e,
            PeriodicError::TowardsGrazing { iterations: 20, residual, normal_velocity }
                if residual < 1e-4 && normal_velocity.abs() < 1e-9
        ),
        "{e:?}"
    );
}

/// A point in the unit disk under gravity (`tests/walls/disk_sqrt.toml`,
/// g = 1) from its file's start: Newton's method closes in on the point
/// sliding along the bottom of the rim, where the flights between
/// collisions, and everything that changes over one, shrink with the
/// normal velocity. There the residual meets the tolerance (period 7e-8,
/// normal velocity 3.5e-8, once reported as an orbit): that is
/// `TowardsGrazing`, not an orbit.
#[test]
fn a_state_sliding_along_the_wall_is_no_orbit() {
    let mut m = common::wall_model::<2>("disk_sqrt");
    assert!(m.set_parameter_named("g", 1.0));
    let (residual, normal_velocity) = towards_grazing(&m, m.walls()[0]);
    assert!(residual < 1e-9 && normal_velocity.abs() < 1e-6);
}

/// The search through one return to `wall` from `m`'s start, which must
/// end in `TowardsGrazing`: its residual and normal velocity.
fn towards_grazing<M: TaylorSeries<N>, const N: usize>(m: &M, wall: M::Wall) -> (f64, f64) {
    let section = Section {
        wall,
        returns: 1,
        t_max: 100.0,
    };
    match periodic::find(m, initial(m), &section, &Search::default()) {
        Err(PeriodicError::TowardsGrazing {
            residual,
            normal_velocity,
            ..
        }) => (residual, normal_velocity),
        other => panic!("{other:?}"),
    }
}

/// What the search cannot do is an error that says so: no return within
/// the time allowed, and a Newton's method given no steps.
#[test]
fn failures_are_reported() {
    let m = PendulumWall::default();
    let short = Section {
        wall: PendulumWall::WALLS[0],
        returns: 1,
        t_max: 0.05,
    };
    let e = periodic::find(&m, initial(&m), &short, &Search::default()).unwrap_err();
    assert!(
        matches!(
            e,
            PeriodicError::Return(ReturnError::NoReturn { met: 0, .. })
        ),
        "{e:?}"
    );
    // The chain falls from rest far from an orbit: no Newton steps, no orbit.
    let chain = Chain3::default();
    let section = Section {
        wall: Chain3::WALLS[0],
        returns: 1,
        t_max: 100.0,
    };
    let search = Search {
        max_iterations: 0,
        ..Search::default()
    };
    let e = periodic::find(&chain, initial(&chain), &section, &search).unwrap_err();
    assert!(
        matches!(e, PeriodicError::NoConvergence { iterations: 0, residual } if residual > 1e-3),
        "{e:?}"
    );
}

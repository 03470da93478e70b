//! Walls narrower than a step: a bump of the floor 2/1000 wide under a
//! long free flight, a thin post on a Chaplygin sleigh's circle, a thin pin
//! on a pendulum's. Samples of f along a step (or a wall's series at its
//! start) see nothing of them: f and its rate there are those of no
//! obstacle at all. Every integrator must meet them at the instants a
//! closed form gives (or, for the pendulum, RK4 with steps far shorter
//! than the pin), never pass through: the simulator proves the stretch of
//! each step before what its samples find clear on boxes that enclose the
//! motion (`runtime/src/simulate/enclosure.rs`).
//!
//! The models are interpreted, as `dalembert simulate FILE` runs them
//! (their interval bounds are the generated code's operations:
//! `tests/interpreted.rs`). Uses the symbolic engine: run one test at a
//! time (`RUST_TEST_THREADS=1`).

mod common;

use dalembert::runtime::prelude::*;
use dalembert::runtime::simulate::{
    Collision, Integrator, Rk4, SeriesRoom, Settings, Simulator, State, Taylor,
};
use dalembert_codegen::interpret::Interpreted;

use common::{dormand_prince, initial, lcg};

fn model<const N: usize>(name: &str) -> Interpreted<N> {
    common::wall_model(name)
}

fn rk4(step: f64) -> Settings {
    Settings {
        integrator: Integrator::Rk4(Rk4 { step }),
        ..Settings::default()
    }
}

/// Every method, with how close its first collision must come to the
/// reference: Dormand–Prince at its default tolerance and at 1e-6 (longer
/// steps), Taylor's method at its default tolerance and at order 8, RK4
/// at a step five times the bump's width.
fn methods() -> Vec<(&'static str, Settings, f64)> {
    let taylor = |t: Taylor| Settings {
        integrator: Integrator::Taylor(t),
        ..Settings::default()
    };
    vec![
        ("dormand-prince", Settings::default(), 1e-9),
        ("dormand-prince 1e-6", dormand_prince(1e-6), 1e-6),
        ("taylor", taylor(Taylor::default()), 1e-9),
        (
            "taylor order 8",
            taylor(Taylor {
                fixed_order: Some(8),
                ..Taylor::default()
            }),
            1e-9,
        ),
        ("rk4 1e-2", rk4(1e-2), 1e-6),
    ]
}

/// The first collision of `m` from `start` before `t_end`, checking that
/// no reported state is beyond the wall.
fn first_collision<M: TaylorSeries<N>, const N: usize>(
    m: &M,
    start: State<N>,
    settings: Settings,
    t_end: f64,
) -> Option<Collision<M::Wall, N>> {
    let mut room = SeriesRoom::new(m);
    let mut sim = Simulator::with_series(&mut room, start, settings).unwrap();
    let mut first = None;
    sim.run(t_end, |s| {
        // Beyond the wall by no more than rounding of q moves f (the
        // bump's slope is about 1/w).
        for &wall in m.walls() {
            let q = &s.state.q;
            let f = m.surface(wall, q);
            let slope = m
                .normal(wall, q)
                .iter()
                .fold(1.0_f64, |a, x| a.max(x.abs()));
            let size = q.iter().fold(1.0_f64, |a, x| a.max(x.abs()));
            assert!(
                f >= -1e-12 * slope * size,
                "beyond the wall at t = {}: f = {f:e}; {settings:?}",
                s.state.t
            );
        }
        first = s.collision;
        first.is_none()
    })
    .unwrap();
    first
}

/// Each method's first collision against `reference` (None: none before
/// `t_end`).
fn check<M: TaylorSeries<N>, const N: usize>(
    what: &str,
    m: &M,
    start: State<N>,
    t_end: f64,
    reference: Option<f64>,
) {
    for (method, settings, within) in methods() {
        let found = first_collision(m, start, settings, t_end).map(|c| c.t);
        match (found, reference) {
            (Some(t), Some(r)) => assert!(
                (t - r).abs() <= within,
                "{what}, {method}: met at {t}, the closed form says {r} (from {start:?})"
            ),
            (None, None) => {}
            _ => panic!(
                "{what}, {method}: met at {found:?}, the closed form says {reference:?} (from {start:?})"
            ),
        }
    }
}

/// Straight flights over the bump from random distances (1 to 40) and
/// heights, at random speeds: met where exp(−(x/w)²) = y + 1/2, i.e. at
/// x = −w √(−log(y + 1/2)), or flown over where y ≥ 1/2.
#[test]
fn a_narrow_bump_under_a_long_flight() {
    let m = model::<2>("floor_bump");
    let w = m.parameter_named("w").unwrap();
    let mut seed = 7;
    for _ in 0..12 {
        let mut u = || lcg(&mut seed);
        let (x0, y0, speed) = (-1.0 - 39.0 * u(), 0.6 * u() - 0.4, 0.5 + 1.5 * u());
        let start = State {
            t: 0.0,
            q: [x0, y0],
            v: [speed, 0.0],
        };
        let x = -w * (-(y0 + 0.5).ln()).sqrt();
        check("bump", &m, start, -x0 / speed + 1.0, Some((x - x0) / speed));
    }
    // Above the bump's top: no collision, however close.
    let over = State {
        t: 0.0,
        q: [-20.0, 0.5 + 1e-6],
        v: [1.0, 0.0],
    };
    check("over the bump", &m, over, 40.0, None);
}

/// The bump with g = 9.81, and its half-width.
fn bump_under_gravity() -> (Interpreted<2>, f64) {
    let mut m = model::<2>("floor_bump");
    assert!(m.set_parameter_named("g", 9.81));
    let w = m.parameter_named("w").unwrap();
    (m, w)
}

/// The first root before `until` of the bump's f along the exact parabola
/// (g = 9.81) from (x0, y0) at (vx, vy): on a grid of 10⁻⁶ s, refined by
/// bisection.
fn first_root(w: f64, (x0, y0): (f64, f64), (vx, vy): (f64, f64), until: f64) -> Option<f64> {
    let f = |t: f64| {
        let (x, y) = (x0 + vx * t, y0 + vy * t - 9.81 * t * t / 2.0);
        y + 0.5 - (-(x / w) * (x / w)).exp()
    };
    let grid = 1e-6;
    let mut t = grid;
    while t < until && f(t) > 0.0 {
        t += grid;
    }
    if t >= until {
        return None;
    }
    let (mut a, mut b) = (t - grid, t);
    for _ in 0..60 {
        let c = 0.5 * (a + b);
        if f(c) > 0.0 { a = c } else { b = c }
    }
    Some(b)
}

/// The same bump under parabolic flights (g = 9.81) launched from the
/// floor's height towards it: the reference is the first root of f along
/// the exact parabola, found on a grid of 10⁻⁶ s and refined by bisection.
#[test]
fn a_narrow_bump_under_a_parabola() {
    let (m, w) = bump_under_gravity();
    let mut seed = 11;
    let mut met = 0;
    for _ in 0..8 {
        let mut u = || lcg(&mut seed);
        let (x0, vx, vy) = (-0.5 - 2.0 * u(), 1.0 + 2.0 * u(), 2.0 + 2.0 * u());
        let y0 = -0.4;
        // The flight lands on the floor y = −1/2 (away from the bump) at
        // `landing`; the first root of f, the bump's or the floor's, is the
        // reference.
        let landing = (vy + (vy * vy + 2.0 * 9.81 * (y0 + 0.5)).sqrt()) / 9.81;
        let reference = first_root(w, (x0, y0), (vx, vy), landing + 1.0).unwrap();
        if reference < landing - 1e-3 {
            met += 1;
        }
        let start = State {
            t: 0.0,
            q: [x0, y0],
            v: [vx, vy],
        };
        check(
            "bump under a parabola",
            &m,
            start,
            landing + 0.1,
            Some(reference),
        );
    }
    // Some of the flights meet the bump before the floor.
    assert!(met >= 2, "{met} of 8 flights meet the bump");
}

/// Flights from the floor to the floor (g = 9.81) that pass the bump in
/// their middle half: a step with both ends on the wall, whose stretch is
/// split into a quarter at each end and the half between
/// (`enclosure.rs`). Launched from y = −1/2 at x0 so that the bump is
/// reached at a fraction 0.3 to 0.7 of the flight, some low enough to hit
/// it, some flying over it: the reference is the first root of f along the
/// exact parabola (a grid of 10⁻⁶ s refined by bisection), the bump's or
/// the landing's.
#[test]
fn a_narrow_bump_in_the_middle_of_a_bounce() {
    let (m, w) = bump_under_gravity();
    let mut seed = 5;
    let (mut hit, mut over) = (0, 0);
    for _ in 0..10 {
        let mut u = || lcg(&mut seed);
        let (vx, vy, fraction) = (0.5 + 1.5 * u(), 3.5 + 3.0 * u(), 0.3 + 0.4 * u());
        let landing = 2.0 * vy / 9.81;
        let x0 = -vx * fraction * landing;
        let reference = match first_root(w, (x0, -0.5), (vx, vy), landing) {
            Some(t) => {
                hit += 1;
                t
            }
            None => {
                over += 1;
                landing
            }
        };
        let start = State {
            t: 0.0,
            q: [x0, -0.5],
            v: [vx, vy],
        };
        check(
            "bump in a bounce",
            &m,
            start,
            landing + 0.1,
            Some(reference),
        );
    }
    assert!(
        hit >= 2 && over >= 2,
        "{hit} flights hit the bump, {over} fly over it"
    );
}

/// The sleigh turns on the unit circle at unit speed (its blade at the
/// centre of mass: speed and turning rate stay constant), so its centre
/// comes within r = w √(log 2) of the post at angle a on that circle (where
/// f = 1/2 − exp(−d²/w²) is zero) at t = a − 2 asin(r/2): a nonholonomic
/// motion, met where the closed form says.
#[test]
fn a_thin_post_on_a_sleighs_circle() {
    let mut m = model::<3>("sleigh_post");
    let r = m.parameter_named("w").unwrap() * 2f64.ln().sqrt();
    for a in [0.9, 2.0, 3.7, 5.5] {
        assert!(m.set_parameter_named("a", a));
        let start = initial(&m);
        check("post", &m, start, 7.0, Some(a - 2.0 * (r / 2.0).asin()));
    }
}

/// A pendulum swinging through a thin pin on its circle (holonomic): met
/// at the instant RK4 with steps of 10⁻⁵ (a hundredth of the time it takes
/// to pass the pin) finds, from random pins on the swing's arc.
#[test]
fn a_thin_pin_on_a_pendulums_circle() {
    let mut m = model::<2>("pendulum_pin");
    let mut seed = 5;
    for _ in 0..4 {
        let a = 1.8 * lcg(&mut seed) - 0.9;
        assert!(m.set_parameter_named("a", a));
        let start = initial(&m);
        let reference = first_collision(&m, start, rk4(1e-5), 3.0).map(|c| c.t);
        assert!(reference.is_some(), "the swing passes the pin at angle {a}");
        check("pin", &m, start, 3.0, reference);
    }
}

//! Derivatives of whole runs by the parameters
//! (`simulate::ParameterSensitivity`) against finite differences of whole
//! simulations: s(T) = ∂x(T)/∂p δp against Richardson-extrapolated central
//! differences of x(T) over runs with the parameters moved along δp, at
//! rtol 1e-12, through at least 10 collisions, and each collision's
//! instant shift ∂t*/∂p δp against the differences of the instants, with
//! every integrator (RK4 not on the sleigh, see there). The start is the same (q₀, v₀) put on each run's constraint manifold
//! (h(q) = 0 by Gauss–Newton, v onto ker A(q)), so where the constraints
//! move with p the start does too: its derivative, by differences of that
//! algebraic map, is s's starting value. Models: a Chaplygin sleigh whose
//! blade offset, rink (a wall through a square root) and tilt are the
//! parameters (interpreted); a spinning ball on a rough floor whose radius
//! moves the wall and the map (generated); a pendulum whose rod length
//! moves its holonomic constraint (generated).
//!
//! Uses the symbolic engine for the interpreted model: run one test at a
//! time (`RUST_TEST_THREADS=1`).

mod common;

use dalembert::models::{BallBounce, PendulumWall};
use dalembert::runtime::prelude::*;
use dalembert::runtime::simulate::{
    ParameterSensitivity, SeriesRoom, Settings, Simulator, State, VariationalError,
};

use common::{integrators, onto_manifold, wall_model};

/// A point of phase space, or a derivative of one: (q, v).
type PhasePair<const N: usize> = ([f64; N], [f64; N]);

/// `m` with its parameters moved by `s·dp`.
fn moved<M: Model<N, N> + Clone, const N: usize>(m: &M, dp: &[f64], s: f64) -> M {
    let mut moved = m.clone();
    for (k, d) in dp.iter().enumerate() {
        let x = m.parameter(k).expect("a parameter for each entry");
        assert!(moved.set_parameter(k, x + s * d));
    }
    moved
}

/// What a run gives: the state at its end, its collision instants, and s
/// with each collision's ∂t*/∂p δp where it was followed.
struct Run<const N: usize> {
    end: State<N>,
    instants: Vec<f64>,
    s: Option<(PhasePair<N>, Vec<f64>)>,
}

/// The run to `t_end` from `start`, s followed along `dp` from `ds0` when
/// asked.
fn run<M: TaylorSeries<N>, const N: usize>(
    m: &M,
    settings: Settings,
    start: ([f64; N], [f64; N]),
    t_end: f64,
    follow: Option<(&[f64], PhasePair<N>)>,
) -> Run<N> {
    let (q, v) = start;
    let mut room = SeriesRoom::new(m);
    let mut sim = Simulator::with_series(&mut room, State { t: 0.0, q, v }, settings)
        .unwrap_or_else(|e| panic!("{}: {e:?}", m.name()));
    let mut s =
        follow.map(|(dp, (dq, dv))| ParameterSensitivity::new(dp, 1e-12).starting_at(dq, dv));
    let (mut instants, mut shifts) = (Vec::new(), Vec::new());
    while sim.state().t < t_end {
        let step = sim
            .step(t_end)
            .unwrap_or_else(|e| panic!("{}: {e:?}", m.name()));
        if let Some(s) = &mut s {
            s.follow(&sim, &step)
                .unwrap_or_else(|e| panic!("{}: {e:?}", m.name()));
            assert_eq!(s.collision_shift().is_some(), step.collision.is_some());
            shifts.extend(s.collision_shift());
        }
        instants.extend(step.collision.map(|c| c.t));
    }
    Run {
        end: *sim.state(),
        instants,
        s: s.map(|s| (s.value(), shifts)),
    }
}

fn flat<const N: usize>((q, v): &([f64; N], [f64; N])) -> Vec<f64> {
    q.iter().chain(v).copied().collect()
}

fn split<const N: usize>(x: &[f64]) -> ([f64; N], [f64; N]) {
    (
        std::array::from_fn(|i| x[i]),
        std::array::from_fn(|i| x[N + i]),
    )
}

/// s(T) against the differences along each direction of `directions`,
/// with the first `methods` integrators of [`integrators`], the
/// differences' steps `scale` times the integrator's own.
fn check<M: TaylorSeries<N> + Clone, const N: usize>(
    m: &M,
    (x0, t_end, scale): (([f64; N], [f64; N]), f64, f64),
    directions: &[(&str, Vec<f64>)],
    methods: usize,
) {
    let start = |m: &M| onto_manifold(m, x0.0, x0.1);
    for (method, settings, eps, tol) in integrators().into_iter().take(methods) {
        for (what, dp) in directions {
            let ds0 = common::richardson(|s| flat(&start(&moved(m, dp, s))), 1e-4);
            let followed = run(m, settings, start(m), t_end, Some((dp, split(&ds0))));
            let collisions = followed.instants.len();
            assert!(
                collisions >= 10,
                "{} ({method}): {collisions} collisions",
                m.name()
            );
            let (value, shifts) = followed.s.unwrap();
            // The end state, then the collision instants.
            let at = |s: f64| -> Vec<f64> {
                let ms = moved(m, dp, s);
                let r = run(&ms, settings, start(&ms), t_end, None);
                assert_eq!(
                    r.instants.len(),
                    collisions,
                    "{} ({method}, {what}): a perturbed run met other walls",
                    m.name()
                );
                let mut x = flat(&(r.end.q, r.end.v));
                x.extend(r.instants);
                x
            };
            let fd = common::richardson(at, 2.0 * eps * scale);
            let (fd_x, fd_t) = fd.split_at(2 * N);
            for (what_of, got, fd) in [("x(T)", &flat(&value)[..], fd_x), ("t*", &shifts, fd_t)] {
                let (worst, size) = common::relative_gap(got, fd);
                eprintln!(
                    "{} ({method}), ∂{what_of}/∂{what}: |s − differences| / |differences| = {worst:.1e} (up to {size:.1e}, {collisions} collisions)",
                    m.name()
                );
                assert!(
                    worst <= tol,
                    "{} ({method}), ∂{what_of}/∂{what}: followed {got:?}, differences {fd:?}",
                    m.name()
                );
            }
        }
    }
}

/// Unit directions for the named parameters, and one along all of them.
fn directions<M: Model<Q, N>, const Q: usize, const N: usize>(
    m: &M,
    names: &[&'static str],
) -> Vec<(&'static str, Vec<f64>)> {
    let all = m.parameter_names();
    let unit = |name: &str| -> Vec<f64> {
        let k = all.iter().position(|p| *p == name).expect("a parameter");
        (0..all.len()).map(|i| (i == k) as u8 as f64).collect()
    };
    let mut out: Vec<_> = names.iter().map(|&n| (n, unit(n))).collect();
    let mixed = (0..all.len()).map(|i| 0.3 + 0.1 * i as f64).collect();
    out.push(("p along (0.3, 0.4, …)", mixed));
    out
}

#[test]
fn the_sleigh_in_an_oval_rink() {
    let m = wall_model::<3>("sleigh_oval");
    let dirs = directions(&m, &["a", "b", "c", "g"]);
    // Along c the run's second derivative is large by t = 20: differences
    // with a step of 1e-5 were off by 1e-4 relative, with 1e-6 and 1e-7
    // within 2e-8 of s. RK4's differences need a step of 1e-4 or more
    // (`integrators`), too large here, so RK4 is left to the other models.
    let x0 = ([0.25, 0.0, 0.25], [1.0, 0.3, 0.5]);
    check(&m, (x0, 20.0, 0.1), &dirs, 2);
}

#[test]
fn the_spinning_ball_on_the_rough_floor() {
    let m = BallBounce::default();
    let dirs = directions(&m, &["r", "g", "J"]);
    let q = [0.0, 0.0, 1.0, 0.3, 1.1, 0.2];
    let v = [0.3, -0.2, 0.4, 0.1, -0.3, 0.2];
    check(&m, ((q, v), 8.0, 1.0), &dirs, 3);
}

#[test]
fn the_pendulum_at_its_wall() {
    let m = PendulumWall::default();
    let dirs = directions(&m, &["l", "d", "g"]);
    let a = 0.3_f64;
    let x0 = ([-(a.sin()), -(a.cos())], [-3.0 * a.cos(), 3.0 * a.sin()]);
    check(&m, (x0, 17.0, 1.0), &dirs, 3);
}

/// A direction of the wrong length has no derivative: an error, not a
/// number.
#[test]
fn a_direction_of_the_wrong_length_is_refused() {
    let m = BallBounce::default();
    let start = common::initial(&m);
    let mut sim = Simulator::new(&m, start, Settings::default()).unwrap();
    let dp = [1.0; 3];
    let mut s = ParameterSensitivity::new(&dp, 1e-10);
    let step = sim.step(1.0).unwrap();
    assert_eq!(s.follow(&sim, &step), Err(VariationalError::NoDerivative));
}

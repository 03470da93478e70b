//! The variational flow through collisions (`simulate::Variational`)
//! against finite differences of whole simulations: Φ(T) δx₀ against
//! Richardson-extrapolated central differences of x(T) over starts moved
//! along admissible directions δx₀ (tangent to the constraint manifold,
//! moved back onto it), at rtol 1e-12, and each collision instant's
//! ∂t*/∂x₀ δx₀ against the differences of the instants; runs through at least 10
//! collisions, with every integrator, on walls through square roots and
//! quotients (interpreted), a nonholonomic sleigh in a round rink
//! (interpreted), a holonomic pendulum at a wall and a spinning ball on a
//! rough floor (generated). And an exact identity: energy is kept by flight
//! and map, so ∇E(x(T))ᵀ Φ(T) δx₀ = ∇E(x₀)ᵀ δx₀; and A(q)q̇ = 0, h(q) = 0
//! hold along every run, so Φ(T) δx₀ is tangent to them (the sleigh's
//! nonholonomic rows, the pendulum's holonomic one).
//!
//! Uses the symbolic engine for the interpreted models: run one test at a
//! time (`RUST_TEST_THREADS=1`).

mod common;

use std::path::Path;

use dalembert::models::{BallBounce, PendulumWall};
use dalembert::runtime::prelude::*;
use dalembert::runtime::simulate::{SeriesRoom, Settings, Simulator, State, Variational};
use dalembert::runtime::taylor::Series;
use dalembert_codegen::interpret::Interpreted;

use common::{admissible_direction, integrators, lcg, onto_manifold};

fn interpreted<const N: usize>(name: &str, g: f64) -> Interpreted<N> {
    let file = Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("tests/walls")
        .join(format!("{name}.toml"));
    let d = dalembert_codegen::derive(&file).unwrap_or_else(|e| panic!("{name}: {e}"));
    let mut m = Interpreted::new(&d).unwrap_or_else(|e| panic!("{name}: {e}"));
    assert!(m.set_parameter_named("g", g));
    m
}

/// ∂t*/∂x₀ of one collision, by (q₀, q̇₀).
type Gradient<const N: usize> = ([f64; N], [f64; N]);

/// What a run gives: its end state, its collision instants, and Φ with
/// each collision's ∂t*/∂x₀ where it was followed.
struct Run<const N: usize> {
    end: State<N>,
    instants: Vec<f64>,
    phi: Option<(Variational<N>, Vec<Gradient<N>>)>,
}

/// The run to `t_end` from (q, v), Φ followed along when asked.
fn run<M: TaylorSeries<N>, const N: usize>(
    m: &M,
    settings: Settings,
    (q, v): ([f64; N], [f64; N]),
    t_end: f64,
    follow: bool,
) -> Run<N> {
    let start = State { t: 0.0, q, v };
    let mut room = SeriesRoom::new(m);
    let mut sim = Simulator::with_series(&mut room, start, settings)
        .unwrap_or_else(|e| panic!("{}: {e:?}", m.name()));
    let mut phi = follow.then(|| Variational::new(1e-12));
    let (mut instants, mut gradients) = (Vec::new(), Vec::new());
    while sim.state().t < t_end {
        let step = sim
            .step(t_end)
            .unwrap_or_else(|e| panic!("{}: {e:?}", m.name()));
        if let Some(p) = &mut phi {
            p.follow(&sim, &step)
                .unwrap_or_else(|e| panic!("{}: {e:?}", m.name()));
            assert_eq!(p.collision_gradient().is_some(), step.collision.is_some());
            gradients.extend(p.collision_gradient());
        }
        instants.extend(step.collision.map(|c| c.t));
    }
    Run {
        end: *sim.state(),
        instants,
        phi: phi.map(|p| (p, gradients)),
    }
}

/// ∇E at (q, v) by central differences.
fn energy_gradient<M: Dynamics<N>, const N: usize>(
    m: &M,
    q: &[f64; N],
    v: &[f64; N],
) -> ([f64; N], [f64; N]) {
    let h = 1e-6;
    let by = |j: usize| {
        let e = |s: f64| {
            let (mut q, mut v) = (*q, *v);
            if j < N {
                q[j] += s
            } else {
                v[j - N] += s
            }
            m.energy(&q, &v)
        };
        (e(h) - e(-h)) / (2.0 * h)
    };
    (std::array::from_fn(by), std::array::from_fn(|i| by(N + i)))
}

fn check<M: TaylorSeries<N>, const N: usize>(m: &M, x0: ([f64; N], [f64; N]), t_end: f64) {
    let x0 = onto_manifold(m, x0.0, x0.1);
    let mut seed = 17_u64;
    let directions: Vec<_> = (0..3)
        .map(|_| admissible_direction(m, &x0.0, &x0.1, &mut seed).expect("a direction"))
        .collect();
    for (method, settings, eps, tol) in integrators() {
        let followed = run(m, settings, x0, t_end, true);
        let (end, collisions) = (followed.end, followed.instants.len());
        assert!(
            collisions >= 10,
            "{} ({method}): {collisions} collisions",
            m.name()
        );
        let (phi, gradients) = followed.phi.unwrap();
        let (ge0, ge1) = (
            energy_gradient(m, &x0.0, &x0.1),
            energy_gradient(m, &end.q, &end.v),
        );
        for (k, (dq, dv)) in directions.iter().enumerate() {
            let (pq, pv) = phi.matrix().apply(dq, dv);
            // The end state, then the collision instants.
            let at = |s: f64| -> Vec<f64> {
                let q: [f64; N] = std::array::from_fn(|i| x0.0[i] + s * dq[i]);
                let v: [f64; N] = std::array::from_fn(|i| x0.1[i] + s * dv[i]);
                let r = run(m, settings, onto_manifold(m, q, v), t_end, false);
                assert_eq!(
                    r.instants.len(),
                    collisions,
                    "{} ({method}): a perturbed run met other walls",
                    m.name()
                );
                let mut x: Vec<f64> = r.end.q.iter().chain(&r.end.v).copied().collect();
                x.extend(r.instants);
                x
            };
            let fd = common::richardson(at, 2.0 * eps);
            let (fd, fd_instants) = fd.split_at(2 * N);
            let got: Vec<f64> = pq.iter().chain(&pv).copied().collect();
            let (worst, scale) = common::relative_gap(&got, fd);
            // ∂t*/∂x₀ · δx₀ for each collision.
            let shifts: Vec<f64> = (gradients.iter())
                .map(|(gq, gv)| (0..N).map(|i| gq[i] * dq[i] + gv[i] * dv[i]).sum())
                .collect();
            let (worst_t, _) = common::relative_gap(&shifts, fd_instants);
            eprintln!(
                "{} ({method}), direction {k}: |Φ δx₀ − differences| / |differences| = {worst:.1e}, instants {worst_t:.1e} ({collisions} collisions)",
                m.name()
            );
            assert!(
                worst <= tol,
                "{} ({method}), direction {k}: Φ δx₀ {got:?}, differences {fd:?}",
                m.name()
            );
            assert!(
                worst_t <= tol,
                "{} ({method}), direction {k}: ∂t*/∂x₀ δx₀ {shifts:?}, differences {fd_instants:?}",
                m.name()
            );
            // ∇E(x(T))ᵀ Φ δx₀ = ∇E(x₀)ᵀ δx₀.
            let dot = |(a, b): &([f64; N], [f64; N]), (c, d): (&[f64; N], &[f64; N])| -> f64 {
                (0..N).map(|i| a[i] * c[i] + b[i] * d[i]).sum()
            };
            let (before, after) = (dot(&ge0, (dq, dv)), dot(&ge1, (&pq, &pv)));
            let size = 1.0
                + before.abs()
                + ge1
                    .0
                    .iter()
                    .chain(&ge1.1)
                    .fold(0.0_f64, |a, x| a.max(x.abs()))
                    * scale;
            assert!(
                (after - before).abs() <= 1e-6 * size,
                "{} ({method}), direction {k}: ∇E·Φδx₀ {after} against ∇E·δx₀ {before}",
                m.name()
            );
            // A(q)q̇ = 0 (and h(q) = 0) hold along every run, so Φ δx₀
            // stays tangent to them: A δv + (∂A/∂q δq) v = 0 and
            // ∂h/∂q δq = 0 at T, ∂A/∂q δq by central differences of A.
            let a = m.constraints(&end.q);
            let along = |s: f64| {
                let q: [f64; N] = std::array::from_fn(|i| end.q[i] + s * pq[i]);
                m.constraints(&q).apply(&end.v)
            };
            let h = 1e-6;
            let (plus, minus, av) = (along(h), along(-h), a.apply(&pv));
            let holonomic = m.holonomic(&end.q).as_slice().len();
            for r in 0..a.len() {
                let rate =
                    av.as_slice()[r] + (plus.as_slice()[r] - minus.as_slice()[r]) / (2.0 * h);
                assert!(
                    rate.abs() <= 1e-6 * scale,
                    "{} ({method}), direction {k}: row {r} of d(A q̇)·Φδx₀ = {rate:e}",
                    m.name()
                );
                if r < holonomic {
                    let dh: f64 = (0..N).map(|i| a.as_slice()[r][i] * pq[i]).sum();
                    assert!(
                        dh.abs() <= 1e-6 * scale,
                        "{} ({method}): dh·Φδq = {dh:e}",
                        m.name()
                    );
                }
            }
        }
    }
}

#[test]
fn a_point_in_a_disk_through_a_square_root_wall() {
    let m = interpreted::<2>("disk_sqrt", 3.0);
    check(&m, ([0.2, -0.5], [1.5, 0.0]), 11.0);
}

#[test]
fn a_point_in_a_disk_with_a_pole_beyond_its_wall() {
    let m = interpreted::<2>("disk_thin_ring", 2.0);
    check(&m, ([-0.2, 0.1], [0.9, -1.1]), 10.0);
}

#[test]
fn the_sleigh_in_its_rink() {
    let m = interpreted::<3>("sleigh_rink", 1.0);
    let phi = 0.25_f64;
    check(
        &m,
        ([0.3, -0.1, phi], [1.2 * phi.cos(), 1.2 * phi.sin(), 0.7]),
        18.0,
    );
}

#[test]
fn the_pendulum_at_its_wall() {
    let m = PendulumWall::default();
    let a = 0.3_f64;
    check(
        &m,
        ([-(a.sin()), -(a.cos())], [-3.0 * a.cos(), 3.0 * a.sin()]),
        17.0,
    );
}

#[test]
fn the_spinning_ball_on_the_rough_floor() {
    let m = BallBounce::default();
    let mut s = 5;
    let q: [f64; 6] = [0.0, 0.0, 1.0, 0.3, 1.1, 0.2];
    let v: [f64; 6] = std::array::from_fn(|_| lcg(&mut s) - 0.5);
    check(&m, (q, v), 8.0);
}

/// The same ball bouncing in place with its file's spin: the flight is a
/// parabola with the angles at constant rates, a polynomial that Taylor's
/// method takes at low orders, but a tilt makes the angles' motion
/// oscillate, so Φ's series need more orders than the motion's.
#[test]
fn the_ball_bouncing_in_place_with_its_spin() {
    let m = BallBounce::default();
    let mut q = m.initial_coordinates();
    q[2] += 0.5; // off the floor, so that moved starts are too
    check(&m, (q, m.initial_velocities()), 9.0);
}

/// A step of Taylor's method is differentiated by its own polynomial: the
/// model's variational series (`TaylorSeries::variational_series`, each
/// column δx₀ a unit vector) at τ against Richardson differences at τ of
/// the motion's series, at the same order, from starts moved along δx₀
/// (off the constraints too: the series extend there). On q̈ through sin,
/// cos and quotients (the ball), through every arc and hyperbolic function
/// (interpreted), with nonholonomic rows (the sleigh, interpreted) and a
/// holonomic one (the pendulum).
fn series_derivative<M: TaylorSeries<N>, const N: usize>(m: &M, (q, v): X<N>, tau: f64) {
    let order = 20;
    let motion = |q: &[f64; N], v: &[f64; N]| {
        let mut s = Series::at(q, v);
        assert!(m.taylor_series(&mut s, &mut Default::default(), order));
        s
    };
    let s = motion(&q, &v);
    let mut worst = 0.0_f64;
    for half in 0..2 {
        let unit = |j: usize| {
            let mut x = ([0.0; N], [0.0; N]);
            [&mut x.0, &mut x.1][half][j] = 1.0;
            x
        };
        let mut columns: [Series<N>; N] = std::array::from_fn(|j| {
            let (dq, dv) = unit(j);
            Series::at(&dq, &dv)
        });
        assert!(
            m.variational_series(&s, &mut columns),
            "{}: no variational series",
            m.name()
        );
        for (j, c) in columns.iter().enumerate() {
            assert_eq!(c.order, order);
            let (dq, dv) = unit(j);
            let at = |h: f64| -> Vec<f64> {
                let q = std::array::from_fn(|i| q[i] + h * dq[i]);
                let v = std::array::from_fn(|i| v[i] + h * dv[i]);
                let (q, v) = motion(&q, &v).state(tau);
                q.iter().chain(&v).copied().collect()
            };
            let fd = common::richardson(at, 1e-3);
            let (gq, gv) = c.state(tau);
            let got: Vec<f64> = gq.iter().chain(&gv).copied().collect();
            let (gap, _) = common::relative_gap(&got, &fd);
            assert!(
                gap <= 1e-10,
                "{}: column {} at τ = {tau}: series {got:?}, differences {fd:?}",
                m.name(),
                half * N + j
            );
            worst = worst.max(gap);
        }
    }
    eprintln!(
        "{}: |variational series − differences of the motion's| / |differences| ≤ {worst:.1e}",
        m.name()
    );
}

/// (q, q̇).
type X<const N: usize> = ([f64; N], [f64; N]);

#[test]
fn a_taylor_step_is_differentiated_by_its_own_polynomial() {
    let ball = BallBounce::default();
    let v: [f64; 6] = [0.3, -0.2, 0.5, 0.4, -0.7, 0.6];
    series_derivative(&ball, ([0.0, 0.0, 1.0, 0.3, 1.1, 0.2], v), 0.2);
    let a = 0.3_f64;
    let pendulum = PendulumWall::default();
    let x = ([-(a.sin()), -(a.cos())], [-3.0 * a.cos(), 3.0 * a.sin()]);
    series_derivative(&pendulum, onto_manifold(&pendulum, x.0, x.1), 0.1);
    let sleigh = interpreted::<3>("sleigh_rink", 1.0);
    let x = (
        [0.3, -0.1, 0.25],
        [1.2 * 0.25_f64.cos(), 1.2 * 0.25_f64.sin(), 0.7],
    );
    series_derivative(&sleigh, x, 0.3);
    let functions = interpreted::<2>("disk_functions", 1.0);
    series_derivative(&functions, ([0.5, 0.1], [1.0, 1.0 / 3.0]), 0.2);
}

/// The energy identity ∇E(x(t))ᵀ Φ(t) δx₀ = ∇E(x₀)ᵀ δx₀ at the end of every
/// step of 10⁴ bounces of the spinning ball on the rough floor from its
/// model file's start (§3.2's superball law at each), with Taylor's method
/// and Dormand–Prince, along three admissible directions; and Φ δx₀
/// tangent to the constraints at the end. Φ grows along the run (the
/// bounce period moves with the energy), so the bound is relative to
/// |∇E(x(t))|·|Φ δx₀|.
#[test]
fn energy_is_kept_through_ten_thousand_bounces() {
    let m = BallBounce::default();
    let start = common::initial(&m);
    let x0 = (start.q, start.v);
    let mut seed = 29_u64;
    let directions: Vec<_> = (0..3)
        .map(|_| admissible_direction(&m, &x0.0, &x0.1, &mut seed).expect("a direction"))
        .collect();
    let dot = |(a, b): &([f64; 6], [f64; 6]), (c, d): (&[f64; 6], &[f64; 6])| -> f64 {
        (0..6).map(|i| a[i] * c[i] + b[i] * d[i]).sum()
    };
    let largest = |x: &[f64]| x.iter().fold(0.0_f64, |a, y| a.max(y.abs()));
    let ge0 = energy_gradient(&m, &x0.0, &x0.1);
    let before: Vec<f64> = directions
        .iter()
        .map(|(dq, dv)| dot(&ge0, (dq, dv)))
        .collect();
    for (method, settings, _, _) in integrators().into_iter().take(2) {
        let mut room = SeriesRoom::new(&m);
        let mut sim = Simulator::with_series(&mut room, start, settings).unwrap();
        let mut phi = Variational::new(1e-12);
        let (mut bounces, mut worst, mut growth) = (0, 0.0_f64, 0.0_f64);
        while bounces < 10_000 {
            // (10⁴ bounces end near t = 4078.)
            let step = sim.step(1e4).unwrap();
            bounces += usize::from(step.collision.is_some());
            phi.follow(&sim, &step).unwrap();
            let s = sim.state();
            let ge = energy_gradient(&m, &s.q, &s.v);
            let size = largest(&ge.0).max(largest(&ge.1));
            for ((dq, dv), e0) in directions.iter().zip(&before) {
                let (pq, pv) = phi.matrix().apply(dq, dv);
                let norm = largest(&pq).max(largest(&pv));
                growth = growth.max(norm);
                worst = worst.max((dot(&ge, (&pq, &pv)) - e0).abs() / (size * norm + e0.abs()));
            }
        }
        eprintln!(
            "{method}: 10⁴ bounces to t = {:.1}, largest |Φ δx₀| {growth:.1e}, largest |∇E·Φδx₀ − ∇E₀·δx₀| / (|∇E||Φδx₀|) = {worst:.1e}",
            sim.state().t
        );
        assert!(worst <= 1e-6, "{method}: {worst:e}");
        // Still tangent to the rolling rows at the end.
        let s = sim.state();
        let a = m.constraints(&s.q);
        for (dq, dv) in &directions {
            let (pq, pv) = phi.matrix().apply(dq, dv);
            let along = |h: f64| {
                let q: [f64; 6] = std::array::from_fn(|i| s.q[i] + h * pq[i]);
                m.constraints(&q).apply(&s.v)
            };
            let (plus, minus, av) = (along(1e-6), along(-1e-6), a.apply(&pv));
            let scale = largest(&pq).max(largest(&pv));
            for r in 0..a.len() {
                let rate = av.as_slice()[r] + (plus.as_slice()[r] - minus.as_slice()[r]) / 2e-6;
                assert!(rate.abs() <= 1e-6 * scale, "{method}: row {r}: {rate:e}");
            }
        }
    }
}

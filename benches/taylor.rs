//! Taylor's method beside Dormand–Prince 5(4) (rtol 1e-10, atol 1e-12, the
//! CLI's default), in one run and in thread CPU time:
//!
//! - `series/ball_bounce/*`: one step's parts alone: the generated
//!   `motion_series` to the default order (20), the floor's
//!   `surface_series` along it, the state at one instant on the series;
//! - `bounce/{dormand_prince,taylor}/{100,1000,10000}`: the §3.2.1
//!   nonholonomic pendulum from just after a bounce, through that many
//!   bounces (throughput in bounces), with the attitude in Euler angles
//!   (`ball_bounce`); `bounce/taylor_reading_energy/10000` reads each
//!   bounce's energy as well;
//! - `bounce_omega/*`: the same with the centre and ω as the state
//!   (`ball_bounce_omega`, no attitude: the flight is a parabola with ω
//!   constant);
//! - `rolling/{ball_wall_euler,ball_wall_quaternion}/{dormand_prince,taylor,taylor_order_20,taylor_order_28}`:
//!   the §3.1 ball, its attitude in Euler angles or as a unit quaternion
//!   (holonomic |e| = 1), driven into the wall by a uniform force, through
//!   100 impacts, and with Taylor's method also at fixed orders (20, the
//!   tolerance's, and 28; `taylor` is at the order the simulator picks
//!   from the model's series work);
//! - `chain/{chain_3,chain_8}/{dormand_prince,taylor,taylor_order_20,dormand_prince_rtol_1e-13,taylor_tolerance_1e-12}`:
//!   the n-link chain's tip on the floor from the model file's start,
//!   through 100 impacts (chain_3's q̈ in closed form, chain_8's by
//!   elimination; the motion is chaotic, so the methods' impacts are not
//!   the same ones), also with both methods at tolerances where their
//!   energy errors match;
//! - `pendulum/{dormand_prince,taylor,taylor_order_20,taylor_order_28}`: the Cartesian
//!   pendulum (holonomic rod) against its wall, through 100 impacts.
//!
//! Before timing, the runs of each group are checked to meet the same
//! number of collisions, and the steps, evaluations and errors of each are printed
//! (bounce-instant and energy errors against the exact §3.2.1 motion). The
//! timed runs are those same runs with the energy left unread (a step works
//! it out only when asked); the bounces' instants are still checked.
//!
//! Run: `cargo bench --bench taylor`.

use std::hint::black_box;

use criterion::{Criterion, Throughput, criterion_group, criterion_main};
use dalembert::models::{
    BallBounce, BallBounceOmega, BallWallEuler, BallWallQuaternion, Chain3, Chain8, PendulumWall,
    ball_bounce,
};
use dalembert::runtime::prelude::*;
use dalembert::runtime::simulate::{
    DormandPrince, Integrator, SeriesRoom, Settings, Simulator, State, Stats, Taylor,
};

#[path = "../tests/common/bounce.rs"]
mod bounce;

#[path = "common/cpu_time.rs"]
mod cpu_time;
use cpu_time::ThreadCpuTime;

/// Taylor's method at its defaults.
fn taylor() -> Settings {
    Settings {
        integrator: Integrator::Taylor(Taylor::default()),
        ..Settings::default()
    }
}

fn methods() -> Vec<(&'static str, Settings)> {
    vec![
        (
            "dormand_prince",
            Settings {
                integrator: Integrator::DormandPrince(DormandPrince::default()),
                ..Settings::default()
            },
        ),
        ("taylor", taylor()),
    ]
}

/// [`methods`] and Taylor's method at fixed orders: the tolerance's (20,
/// where the simulator would otherwise pick the order from the model's
/// series work), and `extra` ones.
fn with_fixed_orders(extra: &[usize]) -> Vec<(&'static str, Settings)> {
    let mut m = methods();
    for &p in [20].iter().chain(extra) {
        let name = match p {
            20 => "taylor_order_20",
            28 => "taylor_order_28",
            _ => unreachable!("name the order {p}"),
        };
        m.push((
            name,
            Settings {
                integrator: Integrator::Taylor(Taylor {
                    fixed_order: Some(p),
                    ..Taylor::default()
                }),
                ..Settings::default()
            },
        ));
    }
    m
}

/// §3.2.1: just after a bounce at x = 0 with u = 2, v = 1.
fn bounce_start(ball: &BallBounce) -> State<6> {
    let (q, v) = bounce::after_bounce(ball);
    State { t: 0.0, q, v }
}

/// Runs `bounces` bounces of `ball` from `start` under gravity `g`;
/// returns the stats, the worst relative error of a bounce instant and,
/// with `read_energy`, the worst relative energy error at a bounce (else
/// 0: a step works out its energy only when asked, so the timed runs leave
/// it to the checks, except the one row that times reading it).
fn bounce_run<M: TaylorSeries<6>>(
    ball: &M,
    start: State<6>,
    g: f64,
    settings: Settings,
    bounces: u64,
    read_energy: bool,
) -> (Stats, f64, f64) {
    let e0 = ball.energy(&start.q, &start.v);
    let mut room = SeriesRoom::new(ball);
    let mut sim = Simulator::with_series(&mut room, start, settings).unwrap();
    let (mut n, mut dt, mut de) = (0u64, 0.0f64, 0.0f64);
    let stats = sim
        .run((bounces as f64 + 0.5) * 4.0 / g, |s| {
            if let Some(c) = s.collision {
                n += 1;
                let exact = (4 * n) as f64 / g;
                dt = dt.max((c.t - exact).abs() / exact);
                // The energy at the step's end: just after the collision,
                // (q, v⁺).
                if read_energy {
                    de = de.max((s.energy(ball) - e0).abs() / e0);
                }
            }
            true
        })
        .unwrap();
    assert_eq!(stats.collisions, bounces);
    (stats, dt, de)
}

/// The series of one step alone: `motion_series` to the default order
/// from §3.2.1's start, and the floor's `surface_series` along it.
fn series(c: &mut Criterion<ThreadCpuTime>) {
    use dalembert::runtime::taylor::{CAPACITY, Series};
    let ball = BallBounce::default();
    let start = bounce_start(&ball);
    let order = Taylor::default().order();
    let mut g = c.benchmark_group("series/ball_bounce");
    // The room for the intermediate series, kept from call to call as the
    // simulator keeps it.
    let mut scratch = ball_bounce::SeriesScratch::default();
    g.bench_function("motion_series", |b| {
        b.iter(|| {
            let mut s = Series::at(black_box(&start.q), black_box(&start.v));
            ball.taylor_series(&mut s, &mut scratch, order);
            s
        })
    });
    let mut s = Series::at(&start.q, &start.v);
    ball.taylor_series(&mut s, &mut scratch, order);
    g.bench_function("surface_series", |b| {
        b.iter(|| {
            let mut f = [0.0; CAPACITY];
            ball.surface_series(
                ball_bounce::Wall::Floor,
                black_box(&s),
                &mut scratch,
                &mut f,
            );
            f
        })
    });
    g.bench_function("state_at", |b| {
        b.iter(|| black_box(&s).state(black_box(0.3)))
    });
    g.finish();
}

/// The §3.2.1 runs of one model in the group `name`.
fn bounce_group<M: TaylorSeries<6>>(
    c: &mut Criterion<ThreadCpuTime>,
    name: &str,
    ball: &M,
    start: State<6>,
    g: f64,
) {
    let mut group = c.benchmark_group(name);
    for bounces in [100u64, 1000, 10_000] {
        for (method, settings) in methods() {
            let (stats, dt, de) = bounce_run(ball, start, g, settings, bounces, true);
            eprintln!(
                "{name}/{method}/{bounces}: {} steps, {} evaluations, bounce-instant error {dt:.1e}, energy error {de:.1e}",
                stats.steps, stats.evaluations
            );
            group.throughput(Throughput::Elements(bounces));
            group.sample_size(if bounces >= 10_000 { 10 } else { 20 });
            group.bench_function(format!("{method}/{bounces}"), |b| {
                b.iter(|| bounce_run(black_box(ball), start, g, settings, bounces, false))
            });
        }
    }
    // What reading the energy at every bounce adds to Taylor's method.
    group.bench_function("taylor_reading_energy/10000", |b| {
        b.iter(|| bounce_run(black_box(ball), start, g, taylor(), 10_000, true))
    });
    group.finish();
}

fn bounce(c: &mut Criterion<ThreadCpuTime>) {
    let ball = BallBounce::default();
    bounce_group(c, "bounce", &ball, bounce_start(&ball), ball.params().g);
    let omega = BallBounceOmega::default();
    let (q, v) = bounce::after_bounce_omega(&omega);
    let start = State { t: 0.0, q, v };
    bounce_group(c, "bounce_omega", &omega, start, omega.params().g);
}

/// Impacts in the `rolling` and `pendulum` runs.
const IMPACTS: u64 = 100;

/// A simulation of `m` from `start` through [`IMPACTS`] collisions: stats
/// and, with `read_energy` (the checks; the timed runs leave it out), the
/// largest relative energy change seen at the end of a step.
fn run<M: TaylorSeries<N>, const N: usize>(
    m: &M,
    start: State<N>,
    settings: Settings,
    read_energy: bool,
) -> (Stats, f64) {
    let e0 = m.energy(&start.q, &start.v);
    let mut room = SeriesRoom::new(m);
    let mut sim = Simulator::with_series(&mut room, start, settings).unwrap();
    let mut de = 0.0f64;
    let mut impacts = 0;
    let stats = sim
        .run(f64::INFINITY, |s| {
            if read_energy {
                de = de.max((s.energy(m) - e0).abs() / e0.abs().max(1e-300));
            }
            impacts += s.collision.is_some() as u64;
            impacts < IMPACTS
        })
        .unwrap();
    assert_eq!(stats.collisions, IMPACTS);
    (stats, de)
}

/// When the [`IMPACTS`]-th collision happens.
fn stats_t<M: TaylorSeries<N>, const N: usize>(m: &M, start: State<N>, settings: Settings) -> f64 {
    let mut room = SeriesRoom::new(m);
    let mut sim = Simulator::with_series(&mut room, start, settings).unwrap();
    let (mut impacts, mut t) = (0, 0.0);
    sim.run(f64::INFINITY, |s| {
        if let Some(c) = s.collision {
            impacts += 1;
            t = c.t;
        }
        impacts < IMPACTS
    })
    .unwrap();
    t
}

fn paired<M: TaylorSeries<N>, const N: usize>(
    c: &mut Criterion<ThreadCpuTime>,
    group: &str,
    m: &M,
    start: State<N>,
    methods: &[(&'static str, Settings)],
) {
    let runs: Vec<_> = methods
        .iter()
        .map(|(name, s)| (*name, *s, run(m, start, *s, true)))
        .collect();
    let mut g = c.benchmark_group(group);
    for (name, settings, (stats, de)) in runs {
        let order = Simulator::with_series(&mut SeriesRoom::new(m), start, settings)
            .unwrap()
            .taylor_order()
            .map_or(String::new(), |p| format!(" (order {p})"));
        eprintln!(
            "{group}/{name}{order}: {} steps, {} evaluations, {} collisions by t = {:.3}, energy error {de:.1e}",
            stats.steps,
            stats.evaluations,
            stats.collisions,
            stats_t(m, start, settings)
        );
        g.sample_size(10);
        g.bench_function(name, |b| {
            b.iter(|| run(black_box(m), start, settings, false))
        });
    }
    g.finish();
}

/// The model file's initial state.
fn initial<M: Dynamics<N>, const N: usize>(m: &M) -> State<N> {
    State {
        t: 0.0,
        q: m.initial_coordinates(),
        v: m.initial_velocities(),
    }
}

fn rolling(c: &mut Criterion<ThreadCpuTime>) {
    let ball = BallWallEuler::default();
    let methods = with_fixed_orders(&[28]);
    paired(
        c,
        "rolling/ball_wall_euler",
        &ball,
        initial(&ball),
        &methods,
    );
    let quat = BallWallQuaternion::default();
    paired(
        c,
        "rolling/ball_wall_quaternion",
        &quat,
        initial(&quat),
        &methods,
    );
}

/// The chains also at matched accuracy: Dormand–Prince tightened to
/// rtol 1e-13 and Taylor's method loosened to a tolerance of 1e-12 reach
/// energy errors of the same size.
fn chain(c: &mut Criterion<ThreadCpuTime>) {
    fn one<M: TaylorSeries<N> + Default, const N: usize>(c: &mut Criterion<ThreadCpuTime>) {
        let m = M::default();
        let mut methods = with_fixed_orders(&[]);
        methods.push((
            "dormand_prince_rtol_1e-13",
            Settings {
                integrator: Integrator::DormandPrince(DormandPrince {
                    rtol: 1e-13,
                    atol: 1e-15,
                    ..DormandPrince::default()
                }),
                ..Settings::default()
            },
        ));
        methods.push((
            "taylor_tolerance_1e-12",
            Settings {
                integrator: Integrator::Taylor(Taylor {
                    tolerance: 1e-12,
                    ..Taylor::default()
                }),
                ..Settings::default()
            },
        ));
        paired(c, &format!("chain/{}", m.name()), &m, initial(&m), &methods);
    }
    one::<Chain3, 3>(c);
    one::<Chain8, 8>(c);
}

fn pendulum(c: &mut Criterion<ThreadCpuTime>) {
    let p = PendulumWall::default();
    let start = State {
        t: 0.0,
        q: [-0.8, -0.6],
        v: [0.0, 0.0],
    };
    paired(c, "pendulum", &p, start, &with_fixed_orders(&[28]));
}

criterion_group! {
    name = benches;
    config = Criterion::default().with_measurement(ThreadCpuTime);
    targets = series, bounce, rolling, chain, pendulum
}
criterion_main!(benches);

//! Taylor's method beside Dormand–Prince 5(4) (rtol 1e-10, atol 1e-12, the
//! CLI's default), in one run and in thread CPU time:
//!
//! - `bounce/{dormand_prince,taylor}/{100,1000,10000}`: the §3.2.1
//!   nonholonomic pendulum from just after a bounce, through that many
//!   bounces (throughput in bounces);
//! - `rolling/ball_wall_euler/{dormand_prince,taylor}`: the §3.1 ball in
//!   Euler angles driven into the wall by a uniform force, through 100
//!   impacts;
//! - `pendulum/{dormand_prince,taylor}`: the Cartesian pendulum (holonomic
//!   rod) against its wall, through 100 impacts.
//!
//! Before timing, each pair of runs is checked to meet the same number of
//! collisions, and the steps, evaluations and errors of both are printed
//! (bounce-instant and energy errors against the exact §3.2.1 motion).
//!
//! Run: `cargo bench --bench taylor`.

use std::hint::black_box;

use criterion::{Criterion, Throughput, criterion_group, criterion_main};
use dalembert::models::{BallBounce, BallWallEuler, PendulumWall, ball_bounce};
use dalembert::runtime::prelude::*;
use dalembert::runtime::simulate::{
    DormandPrince, Integrator, Settings, Simulator, State, Stats, Taylor,
};

#[path = "common/cpu_time.rs"]
mod cpu_time;
use cpu_time::ThreadCpuTime;

fn methods() -> [(&'static str, Settings); 2] {
    [
        (
            "dormand_prince",
            Settings {
                integrator: Integrator::DormandPrince(DormandPrince::default()),
                ..Settings::default()
            },
        ),
        (
            "taylor",
            Settings {
                integrator: Integrator::Taylor(Taylor::default()),
                ..Settings::default()
            },
        ),
    ]
}

/// §3.2.1: just after a bounce at x = 0 with u = 2, v = 1.
fn bounce_start(ball: &BallBounce) -> State<6> {
    let p = ball.params();
    let q = [0.0, 0.0, p.r, 0.0, std::f64::consts::FRAC_PI_2, 0.0];
    let v_minus = [-1.0, 0.0, -2.0, 0.0, 0.0, -p.r * p.m / p.J];
    State {
        t: 0.0,
        q,
        v: ball.collide(ball_bounce::Wall::Floor, &q, &v_minus),
    }
}

/// Runs `bounces` bounces; returns the stats, the worst relative error of
/// a bounce instant and the worst relative energy error at a bounce.
fn bounce_run(ball: &BallBounce, settings: Settings, bounces: u64) -> (Stats, f64, f64) {
    let start = bounce_start(ball);
    let g = ball.params().g;
    let e0 = ball.energy(&start.q, &start.v);
    let mut sim = Simulator::new(ball, start, settings).unwrap();
    let (mut n, mut dt, mut de) = (0u64, 0.0f64, 0.0f64);
    let stats = sim
        .run((bounces as f64 + 0.5) * 4.0 / g, |s| {
            if let Some(c) = s.collision {
                n += 1;
                let exact = (4 * n) as f64 / g;
                dt = dt.max((c.t - exact).abs() / exact);
                de = de.max((ball.energy(&c.q, &c.v_plus) - e0).abs() / e0);
            }
            true
        })
        .unwrap();
    assert_eq!(stats.collisions, bounces);
    (stats, dt, de)
}

fn bounce(c: &mut Criterion<ThreadCpuTime>) {
    let ball = BallBounce::default();
    let mut group = c.benchmark_group("bounce");
    for bounces in [100u64, 1000, 10_000] {
        for (name, settings) in methods() {
            let (stats, dt, de) = bounce_run(&ball, settings, bounces);
            eprintln!(
                "bounce/{name}/{bounces}: {} steps, {} evaluations, bounce-instant error {dt:.1e}, energy error {de:.1e}",
                stats.steps, stats.evaluations
            );
            group.throughput(Throughput::Elements(bounces));
            group.sample_size(if bounces >= 10_000 { 10 } else { 20 });
            group.bench_function(format!("{name}/{bounces}"), |b| {
                b.iter(|| bounce_run(black_box(&ball), settings, bounces))
            });
        }
    }
    group.finish();
}

/// Impacts in the `rolling` and `pendulum` runs.
const IMPACTS: u64 = 100;

/// A simulation of `m` from `start` through [`IMPACTS`] collisions: stats
/// and the largest relative energy change seen at the end of a step.
fn run<M: Surfaces<N>, const N: usize>(m: &M, start: State<N>, settings: Settings) -> (Stats, f64) {
    let e0 = m.energy(&start.q, &start.v);
    let mut sim = Simulator::new(m, start, settings).unwrap();
    let mut de = 0.0f64;
    let mut impacts = 0;
    let stats = sim
        .run(f64::INFINITY, |s| {
            de = de.max((s.energy - e0).abs() / e0.abs().max(1e-300));
            impacts += s.collision.is_some() as u64;
            impacts < IMPACTS
        })
        .unwrap();
    assert_eq!(stats.collisions, IMPACTS);
    (stats, de)
}

/// When the [`IMPACTS`]-th collision happens.
fn stats_t<M: Surfaces<N>, const N: usize>(m: &M, start: State<N>, settings: Settings) -> f64 {
    let mut sim = Simulator::new(m, start, settings).unwrap();
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

fn paired<M: Surfaces<N>, const N: usize>(
    c: &mut Criterion<ThreadCpuTime>,
    group: &str,
    m: &M,
    start: State<N>,
) {
    let runs: Vec<_> = methods()
        .iter()
        .map(|(name, s)| (*name, *s, run(m, start, *s)))
        .collect();
    let mut g = c.benchmark_group(group);
    for (name, settings, (stats, de)) in runs {
        eprintln!(
            "{group}/{name}: {} steps, {} evaluations, {} collisions by t = {:.3}, energy error {de:.1e}",
            stats.steps,
            stats.evaluations,
            stats.collisions,
            stats_t(m, start, settings)
        );
        g.sample_size(10);
        g.bench_function(name, |b| b.iter(|| run(black_box(m), start, settings)));
    }
    g.finish();
}

fn rolling(c: &mut Criterion<ThreadCpuTime>) {
    let ball = BallWallEuler::default();
    let start = State {
        t: 0.0,
        q: ball.initial_coordinates(),
        v: ball.initial_velocities(),
    };
    paired(c, "rolling/ball_wall_euler", &ball, start);
}

fn pendulum(c: &mut Criterion<ThreadCpuTime>) {
    let p = PendulumWall::default();
    let start = State {
        t: 0.0,
        q: [-0.8, -0.6],
        v: [0.0, 0.0],
    };
    paired(c, "pendulum", &p, start);
}

criterion_group! {
    name = benches;
    config = Criterion::default().with_measurement(ThreadCpuTime);
    targets = bounce, rolling, pendulum
}
criterion_main!(benches);

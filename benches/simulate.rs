//! Motion between collisions and the hybrid simulator, in one run:
//!
//! - `eom/<model>/qdd`: q̈ at one state by `runtime::dynamics::qdd`, what
//!   the simulator calls (the generated closed form; the numeric solve for
//!   a model without one, such as the structured `chain_8`), side by side
//!   with `eom/<model>/numeric`: q̈ and λ by the runtime's numeric solve
//!   (`runtime::dynamics::accelerations`: the generated G, h, A, Ȧq̇ and two
//!   fixed-size Cholesky solves);
//! - `step/<model>/<method>`: one accepted integrator step from the model
//!   file's initial state, for every model of the `eom` rows, projection and
//!   crossing checks included;
//! - `simulate/ball_bounce_{100,1000}_bounces`: the §3.2.1 nonholonomic
//!   pendulum from the model file's initial state through 100 and 1000
//!   bounces (throughput in bounces per second; the longer run takes more
//!   steps per bounce: the attitude drifts by rounding, docs/performance.md);
//! - `simulate/rolling_ball_5s`: the §3.1 ball rolling under a uniform force
//!   into the wall and back, 5 s of motion (throughput in steps per second).
//!
//! Run: `cargo bench --bench simulate`.

use std::hint::black_box;

use criterion::{BatchSize, Criterion, Throughput, criterion_group, criterion_main};
use dalembert::models::{BallBounce, BallWallEuler, Chain3, Chain8, PendulumWall, Puck};
use dalembert::runtime::dynamics::{accelerations, qdd};
use dalembert::runtime::prelude::*;
use dalembert::runtime::simulate::{Integrator, Rk4, Settings, Simulator, State};

fn initial<M: Dynamics<N>, const N: usize>(m: &M) -> State<N> {
    State {
        t: 0.0,
        q: m.initial_coordinates(),
        v: m.initial_velocities(),
    }
}

fn eom<M: Dynamics<N> + Default, const N: usize>(c: &mut Criterion) {
    let m = M::default();
    let s = initial(&m);
    c.bench_function(&format!("eom/{}/qdd", m.name()), |b| {
        b.iter(|| qdd(black_box(&m), black_box(&s.q), black_box(&s.v)).unwrap())
    });
    c.bench_function(&format!("eom/{}/numeric", m.name()), |b| {
        b.iter(|| accelerations(black_box(&m), black_box(&s.q), black_box(&s.v)).unwrap())
    });
}

fn rk4() -> Settings {
    Settings {
        integrator: Integrator::Rk4(Rk4 { step: 1e-3 }),
        ..Settings::default()
    }
}

fn step<M: Surfaces<N> + Default, const N: usize>(c: &mut Criterion) {
    let m = M::default();
    for (name, settings) in [("dormand_prince", Settings::default()), ("rk4", rk4())] {
        c.bench_function(&format!("step/{}/{name}", m.name()), |b| {
            b.iter_batched(
                || Simulator::new(&m, initial(&m), settings).unwrap(),
                |mut sim| black_box(sim.step(f64::INFINITY).unwrap()),
                BatchSize::SmallInput,
            )
        });
    }
}

fn simulate(c: &mut Criterion) {
    let ball = BallBounce::default();
    // §3.2.1 with the file's u = 2: a flight lasts 2u/g.
    let flight = 2.0 * 2.0 / ball.params().g;
    let mut group = c.benchmark_group("simulate");
    for bounces in [100, 1000] {
        group.throughput(Throughput::Elements(bounces));
        group.bench_function(format!("ball_bounce_{bounces}_bounces"), |b| {
            b.iter(|| {
                let mut sim = Simulator::new(&ball, initial(&ball), Settings::default()).unwrap();
                let stats = sim.run((bounces as f64 + 0.5) * flight, |_| true).unwrap();
                assert_eq!(stats.collisions, bounces);
                stats
            })
        });
    }
    let rolling = BallWallEuler::default();
    let run = || {
        let mut sim = Simulator::new(&rolling, initial(&rolling), Settings::default()).unwrap();
        sim.run(5.0, |_| true).unwrap()
    };
    group.throughput(Throughput::Elements(run().steps));
    group.bench_function("rolling_ball_5s", |b| b.iter(run));
    group.finish();
}

fn all(c: &mut Criterion) {
    eom::<BallBounce, 6>(c);
    eom::<BallWallEuler, 5>(c);
    eom::<PendulumWall, 2>(c);
    eom::<Puck, 3>(c);
    eom::<Chain3, 3>(c);
    eom::<Chain8, 8>(c);
    step::<BallBounce, 6>(c);
    step::<BallWallEuler, 5>(c);
    step::<PendulumWall, 2>(c);
    step::<Puck, 3>(c);
    step::<Chain3, 3>(c);
    step::<Chain8, 8>(c);
    simulate(c);
}

criterion_group!(benches, all);
criterion_main!(benches);

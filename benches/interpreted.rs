//! A model file interpreted (`dalembert simulate path/to/model.toml`, the
//! programs of `dalembert_codegen::interpret`) against the same model's
//! generated, compiled code, in one run: 1 s of simulated motion from the
//! model file's initial state with Dormand–Prince (rtol 1e-10, atol 1e-12),
//! collisions included. Before measuring, each pair of runs is checked to
//! take the same steps to the same states (bit for bit).
//!
//! - `interpreted/<model>/compiled` and `interpreted/<model>/interpreted`:
//!   time per run, throughput in integrator steps per second.
//!
//! Run: `cargo bench --bench interpreted` (derives the models first: it takes
//! the generator's lock, as `cargo test` does).

use std::hint::black_box;
use std::path::Path;

use criterion::{Criterion, Throughput, criterion_group, criterion_main};
use dalembert::models::{BallBounce, BallWallEuler, Chain3, Chain8, PendulumWall, Puck};
use dalembert::runtime::prelude::*;
use dalembert::runtime::simulate::{Settings, Simulator, State, Stats};
use dalembert_codegen::interpret::Interpreted;

/// Simulated time of each run.
const T_END: f64 = 1.0;

fn run<M: Surfaces<N>, const N: usize>(m: &M) -> (Stats, State<N>) {
    let start = State {
        t: 0.0,
        q: m.initial_coordinates(),
        v: m.initial_velocities(),
    };
    let mut sim = Simulator::new(m, start, Settings::default()).unwrap();
    let stats = sim.run(T_END, |_| true).unwrap();
    (stats, *sim.state())
}

fn pair<M: Surfaces<N> + Default, const N: usize>(c: &mut Criterion) {
    let compiled = M::default();
    let file = Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("models")
        .join(format!("{}.toml", compiled.name()));
    let d = dalembert_codegen::derive(&file).unwrap();
    let interpreted = Interpreted::<N>::new(&d).unwrap();
    let (stats, end) = run(&compiled);
    let (stats_i, end_i) = run(&interpreted);
    assert_eq!(
        stats.steps,
        stats_i.steps,
        "{}: steps differ",
        compiled.name()
    );
    assert_eq!(end.q, end_i.q, "{}: end states differ", compiled.name());
    assert_eq!(end.v, end_i.v, "{}: end states differ", compiled.name());
    let mut g = c.benchmark_group(format!("interpreted/{}", compiled.name()));
    g.throughput(Throughput::Elements(stats.steps));
    g.bench_function("compiled", |b| b.iter(|| run(black_box(&compiled))));
    g.bench_function("interpreted", |b| b.iter(|| run(black_box(&interpreted))));
    g.finish();
}

fn all(c: &mut Criterion) {
    pair::<BallBounce, 6>(c);
    pair::<BallWallEuler, 5>(c);
    pair::<PendulumWall, 2>(c);
    pair::<Puck, 3>(c);
    pair::<Chain3, 3>(c);
    pair::<Chain8, 8>(c);
}

criterion_group!(benches, all);
criterion_main!(benches);

//! Collision maps of the paper's models, side by side in one run:
//!
//! - `generated`: the code dalembert generates from `models/ball_*.toml`;
//! - `hand`: the paper's closed forms (Theorems 3.1 and 3.2) written by hand,
//!   recomputing the parameter combinations on every call;
//! - `hand_precomputed`: the same with the parameter combinations computed
//!   once (as generated code does since it keeps its parameter-only values);
//! - `generic_static`: P from G and B by the runtime's heap-free generic path
//!   (Cholesky + Gram–Schmidt on fixed-size arrays), then (I − 2P)v;
//! - `generic_dynamic`: P = G⁻¹Bᵀ(BG⁻¹Bᵀ)⁻¹B with nalgebra's heap-allocated
//!   dynamic matrices on every call, then (I − 2P)v.
//!
//! - `chain_collide/chain_N`: the n-link chain family's collision map as
//!   generated (the form the generator found cheapest: its header says
//!   which), and `chain_collide/chain_N_runtime_solve` the same map from the
//!   generated G and B by the runtime's fixed-size Cholesky factorisation
//!   and constrained solve (how structured walls were evaluated before the
//!   generator wrote the elimination out).
//!
//! Every path runs over the same 1024 inputs in turn, after all paths are
//! checked to agree on each; time is the thread's CPU time.
//!
//! Run: `cargo bench --bench collision`.

use std::hint::black_box;

use criterion::{BenchmarkGroup, Criterion, criterion_group, criterion_main};
use dalembert::models::{BallFloor, BallWall};
use dalembert::runtime::linalg::{correction, projector, reflect};
use dalembert::runtime::prelude::*;
use nalgebra::{DMatrix, DVector};

#[path = "common/cpu_time.rs"]
mod cpu_time;
use cpu_time::ThreadCpuTime;

#[path = "common/hand.rs"]
mod hand;
use hand::{Hand31, Hand32, hand_3_1, hand_3_2};

/// P from G and B with dynamic matrices, then (I − 2P)v.
fn generic_dynamic(g: &DMatrix<f64>, b: &DMatrix<f64>, v: &DVector<f64>) -> DVector<f64> {
    let g_inv = g.clone().cholesky().expect("G > 0").inverse();
    let x = &g_inv * b.transpose();
    let m = b * &x;
    let p = x * m.try_inverse().expect("B full rank") * b;
    v - 2.0 * p * v
}

fn dynamic_inputs<M: Walls<0, N>, const N: usize>(
    model: &M,
    wall: M::Wall,
) -> (DMatrix<f64>, DMatrix<f64>) {
    let g = model.mass_matrix(&[]);
    let rows = model.wall_rows(wall, &[]);
    let gd = DMatrix::from_fn(N, N, |i, j| g[i][j]);
    let bd = DMatrix::from_fn(rows.len(), N, |i, j| rows.as_slice()[i][j]);
    (gd, bd)
}

#[path = "common/inputs.rs"]
mod inputs;
use inputs::{cycle, inputs};

/// The paths for one instantaneous model's first wall, after checking that
/// the generated, hand-written and generic maps agree on every input.
fn compare<M: Walls<0, N>, const N: usize>(
    c: &mut Criterion<ThreadCpuTime>,
    group: &str,
    model: &M,
    vs: &[[f64; N]],
    hand: impl Fn(&[f64; N]) -> [f64; N],
    precomputed: impl Fn(&[f64; N]) -> [f64; N],
) {
    let wall = model.walls()[0];
    let (gd, bd) = dynamic_inputs(model, wall);
    let generic_static = |v: &[f64; N]| {
        let m = black_box(model);
        let rows = m.wall_rows(wall, &[]);
        let p = projector(&m.mass_matrix(&[]), rows.as_slice()).expect("P");
        reflect(&p, v)
    };
    let generic_dynamic = |v: &[f64; N]| {
        let out = generic_dynamic(black_box(&gd), black_box(&bd), &DVector::from_row_slice(v));
        std::array::from_fn(|i| out[i])
    };
    for v in vs {
        let generated = model.collide(wall, &[], v);
        for (path, other) in [
            ("hand", hand(v)),
            ("hand, precomputed", precomputed(v)),
            ("generic static", generic_static(v)),
            ("generic dynamic", generic_dynamic(v)),
        ] {
            for i in 0..N {
                assert!(
                    (generated[i] - other[i]).abs() <= 1e-12 * (1.0 + generated[i].abs()),
                    "{group}: {path} differs at {i} for {v:?}"
                );
            }
        }
    }
    let mut g = c.benchmark_group(group);
    cycle(&mut g, "generated", vs, |v| {
        black_box(model).collide(wall, &[], v)
    });
    cycle(&mut g, "hand", vs, hand);
    cycle(&mut g, "hand_precomputed", vs, precomputed);
    cycle(&mut g, "generic_static", vs, generic_static);
    cycle(&mut g, "generic_dynamic", vs, generic_dynamic);
    g.finish();
}

fn section_3_1(c: &mut Criterion<ThreadCpuTime>) {
    let ball = BallWall::default();
    let p = *ball.params();
    // Admissible velocities: w1 = -v2/r, w2 = v1/r.
    let vs = inputs(|[v1, v2, _, _, w3]| [v1, v2, -v2 / p.r, v1 / p.r, w3]);
    let hand = |v: &[f64; 5]| hand_3_1(black_box(p.m), black_box(p.r), black_box(p.J), v);
    let once = Hand31::new(p.m, p.r, p.J);
    let precomputed = |v: &[f64; 5]| black_box(&once).collide(v);
    compare(c, "collision_3_1", &ball, &vs, hand, precomputed);
}

fn section_3_2(c: &mut Criterion<ThreadCpuTime>) {
    let ball = BallFloor::default();
    let p = *ball.params();
    let vs = inputs(|v: [f64; 6]| v);
    let hand = |v: &[f64; 6]| hand_3_2(black_box(p.m), black_box(p.r), black_box(p.J), v);
    let once = Hand32::new(p.m, p.r, p.J);
    let precomputed = |v: &[f64; 6]| black_box(&once).collide(v);
    compare(c, "collision_3_2", &ball, &vs, hand, precomputed);
}

/// The n-link chain family: the collision map at the model file's initial
/// configuration, n = 1…8, generated and by the runtime's solve from G and
/// B; both checked equal first.
fn chains(c: &mut Criterion<ThreadCpuTime>) {
    fn one<M: Surfaces<N> + Default, const N: usize>(g: &mut BenchmarkGroup<'_, ThreadCpuTime>) {
        let m = M::default();
        let q = m.initial_coordinates();
        let v: [f64; N] = std::array::from_fn(|i| 0.3 - 0.1 * i as f64);
        let w = m.walls()[0];
        let solve = |q: &[f64; N], v: &[f64; N]| -> [f64; N] {
            let b = m.wall_rows(w, q);
            let r = b.apply(v);
            let d = correction(&m.mass_matrix(q), b.as_slice(), r.as_slice())
                .expect("G > 0 and B of full rank");
            std::array::from_fn(|i| v[i] - 2.0 * d[i])
        };
        let (generated, solved) = (m.collide(w, &q, &v), solve(&q, &v));
        for (x, y) in generated.iter().zip(&solved) {
            assert!(
                (x - y).abs() <= 1e-12 * (1.0 + y.abs()),
                "{}: {generated:?} vs {solved:?}",
                m.name()
            );
        }
        g.bench_function(m.name(), |b| {
            b.iter(|| m.collide(w, black_box(&q), black_box(&v)))
        });
        g.bench_function(format!("{}_runtime_solve", m.name()), |b| {
            b.iter(|| solve(black_box(&q), black_box(&v)))
        });
    }
    use dalembert::models::*;
    let mut g = c.benchmark_group("chain_collide");
    one::<Chain1, 1>(&mut g);
    one::<Chain2, 2>(&mut g);
    one::<Chain3, 3>(&mut g);
    one::<Chain4, 4>(&mut g);
    one::<Chain5, 5>(&mut g);
    one::<Chain6, 6>(&mut g);
    one::<Chain7, 7>(&mut g);
    one::<Chain8, 8>(&mut g);
    g.finish();
}

criterion_group! {
    name = benches;
    config = Criterion::default().with_measurement(ThreadCpuTime);
    targets = section_3_1, section_3_2, chains
}
criterion_main!(benches);
